"""Accelerometer calibration from static poses (simulated with exact truth) and the rest finder (simulated, and
on BROAD's breaks when ../shared/data/broad is present)."""

import numpy as np
import pytest

from conftest import BROAD_DIR
from strapdown.calibrate import GRAVITY, InsufficientMotionError, accelerometer, find_rests
from strapdown.simulate.imu import TriadModel, corrupt

DATA = BROAD_DIR / "data_mat"
needs_broad = pytest.mark.skipif(not DATA.is_dir(), reason="BROAD data not present (../shared/data/broad)")

SIX = GRAVITY * np.vstack([np.eye(3), -np.eye(3)])  # +x, +y, +z, -x, -y, -z up


def model():
    """A consumer-grade accelerometer with every error the fit should find (scale, cross-axis, bias)."""
    m = np.array([[0, 0.004, -0.003], [0.002, 0, 0.005], [-0.006, 0.001, 0]])
    return TriadModel.accelerometer(
        bias_mg=[30, -20, 45], noise_density_ug_sqrt_hz=200, scale_factor_ppm=[8000, -5000, 3000]
    ), m


def recording(truths, rng, seconds=3.0, fs=100.0, move=1.5):
    """Rests at the given specific forces joined by tumbles (large scatter) between them, sampled at fs."""
    base, mis = model()
    tm = TriadModel(bias=base.bias, noise_density=base.noise_density, scale_factor=base.scale_factor, misalignment=mis)
    parts = []
    for k, f in enumerate(truths):
        if k:
            parts.append(np.tile(f, (int(move * fs), 1)) + 4.0 * rng.standard_normal((int(move * fs), 3)))
        parts.append(np.tile(f, (int(seconds * fs), 1)))
    truth = np.concatenate(parts)
    return corrupt(tm, truth, 1 / fs, "average", rng), tm


def test_six_poses_recovered_within_the_noise():
    z = []
    for seed in range(8):
        rng = np.random.default_rng(seed)
        acc, tm = recording(SIX, rng)
        cal = accelerometer(acc, fs=100.0)
        q = cal.quality
        assert q["poses"] == 6 and sorted(q["faces"]) == ["+x", "+y", "+z", "-x", "-y", "-z"]
        z.append((cal.offset - tm.bias) / cal.offset_sigma)
        z.append((np.array(q["scale_factor"]) - tm.scale_factor) / np.array(q["scale_factor_sigma"]))
        off = ~np.eye(3, dtype=bool)
        err = np.array(q["misalignment"])[off] - tm.misalignment[off]
        z.append(err / np.array(q["misalignment_sigma"])[off])
        # the calibrated rests read exactly gravity: the inverse of the true model within the noise
        truth_inv = np.linalg.inv(tm.matrix)
        assert np.all(np.abs(cal.matrix - truth_inv) < 5 * cal.matrix_sigma)
    z = np.concatenate(z)
    assert 0.7 < np.sqrt(np.mean(z**2)) < 1.3  # 96 standard-normal values
    assert np.max(np.abs(z)) < 4.5


def test_many_tilted_poses_use_the_ellipsoid_fit():
    rng = np.random.default_rng(11)
    u = rng.standard_normal((14, 3))
    acc, tm = recording(GRAVITY * u / np.linalg.norm(u, axis=1, keepdims=True), rng)
    cal = accelerometer(acc, fs=100.0)
    assert cal.method == "ellipsoid" and cal.quality["poses"] == 14
    assert np.all(np.abs(cal.offset - tm.bias) < 4.5 * cal.offset_sigma)
    rest = cal.apply(acc[:300].mean(axis=0))
    assert np.linalg.norm(rest) == pytest.approx(GRAVITY, abs=3e-3)


def test_one_pose_and_degenerate_poses_are_refused():
    rng = np.random.default_rng(0)
    acc, _ = recording(SIX[:1], rng)
    with pytest.raises(InsufficientMotionError, match=r"1 pose found \(\+x\).*six faces.*missing: -x, \+y, -y"):
        accelerometer(acc, fs=100.0)
    acc, _ = recording(np.vstack([SIX[2], SIX[5], SIX[2], SIX[5]]), rng)  # z up and down only
    with pytest.raises(InsufficientMotionError, match=r"missing: \+x, -x, \+y, -y"):
        accelerometer(acc, fs=100.0)
    with pytest.raises(InsufficientMotionError, match="no rest found"):
        accelerometer(5 * rng.standard_normal((1000, 3)), fs=100.0)


def test_rest_finder_on_simulated_rests():
    rng = np.random.default_rng(4)
    acc, _ = recording(SIX, rng, seconds=3.0, move=1.5)
    rests = find_rests(acc, fs=100.0)
    assert len(rests) == 6
    starts = np.arange(6) * 450  # 300 rest + 150 moving samples per pose
    assert np.all(rests[:, 0] >= starts) and np.all(rests[:, 1] <= starts + 300)
    assert np.all(rests[:, 1] - rests[:, 0] > 250)  # all but the edges within half a window of the motion


@needs_broad
def test_rest_finder_on_broad_breaks():
    """BROAD's trials with breaks: every rest found lies in a break (movement == 0), every break of 5 s or more
    holds a rest, and the accelerometer fit then refuses (the breaks are all on one face) naming the missing faces."""
    from strapdown.evaluate.broad import load_trial

    for path in sorted(DATA.glob("*with_breaks*.mat")):
        trial = load_trial(path)
        rests = find_rests(trial.acc, trial.gyro, fs=trial.rate)
        assert len(rests) >= 3, path.name
        for a, b in rests:
            assert np.mean(trial.movement[a:b]) < 0.02, (path.name, a / trial.rate, b / trial.rate)
        still = ~trial.movement
        edges = np.diff(np.concatenate([[0], still.astype(int), [0]]))
        for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True):
            if b - a >= 5 * trial.rate:
                assert np.any((rests[:, 0] < b) & (rests[:, 1] > a)), (path.name, a / trial.rate)
        with pytest.raises(InsufficientMotionError, match="missing"):
            accelerometer(trial.acc, gyro=trial.gyro, fs=trial.rate)


def test_many_poses_near_one_face_are_refused_naming_the_axis():
    """Ten rests all within 20° of z up: enough poses for the ellipsoid fit, but gravity never along x or y."""
    rng = np.random.default_rng(12)
    tilt = np.radians(20) * rng.uniform(-1, 1, (10, 2))
    up = np.column_stack([np.sin(tilt[:, 0]), np.sin(tilt[:, 1]), np.ones(10)])
    acc, _ = recording(GRAVITY * up / np.linalg.norm(up, axis=1, keepdims=True), rng)
    with pytest.raises(InsufficientMotionError, match=r"cone around sensor axis .*\(≈ z\)"):
        accelerometer(acc, fs=100.0)
