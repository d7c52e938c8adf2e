"""Magnetometer calibration on simulated readings with exact truth (hard iron, soft iron, noise, outliers)."""

import json

import numpy as np
import pytest

from strapdown.calibrate import Calibration, InsufficientMotionError, load, magnetometer, save
from strapdown.simulate.imu import TriadModel, corrupt

FIELD = 48.0  # µT


def symmetric_truth(a):
    """The symmetric W with W A orthogonal, W = (A Aᵀ)^(-1/2): what an ellipsoid fit can see (independent of
    the fit's code: eigendecomposition of A Aᵀ)."""
    values, vectors = np.linalg.eigh(a @ a.T)
    return (vectors / np.sqrt(values)) @ vectors.T


def random_directions(n, rng):
    u = rng.standard_normal((n, 3))
    return u / np.linalg.norm(u, axis=1, keepdims=True)


def worst_model(rng):
    """Hard iron up to 50 µT, soft iron: 20 % scale and 10 % cross-coupling (not symmetric), 0.3 µT noise."""
    bias = rng.uniform(-50, 50, 3)
    bias[rng.integers(3)] = 50.0 * rng.choice([-1, 1])
    soft = np.eye(3) + np.diag(rng.choice([-0.2, 0.2], 3)) + 0.1 * rng.choice([-1, 1], (3, 3)) * (1 - np.eye(3))
    return TriadModel(bias=bias, soft_iron=soft, noise_density=0.3 / np.sqrt(100.0))


def readings(model, n, rng):
    h = FIELD * random_directions(n, rng)
    return corrupt(model, h, 0.01, "rate", rng)


def test_monte_carlo_parameters_within_reported_uncertainty():
    z_offset, z_matrix, norm_std = [], [], []
    for seed in range(12):
        rng = np.random.default_rng(seed)
        model = worst_model(rng)
        m = readings(model, 1500, rng)
        cal = magnetometer(m, field_strength=FIELD)
        truth = symmetric_truth(model.matrix)
        z_offset.append((cal.offset - model.bias) / cal.offset_sigma)
        z_matrix.append(((cal.matrix - truth) / cal.matrix_sigma)[np.triu_indices(3)])
        c = cal.apply(m)
        u = c / np.linalg.norm(c, axis=1, keepdims=True)
        # noise n of 0.3 µT per axis reaches the calibrated norm as uᵀ W n: std 0.3 |W u|
        expected = 0.3 * np.sqrt(np.mean(np.sum((u @ truth) ** 2, axis=1)))
        norm_std.append(np.std(np.linalg.norm(c, axis=1)) / expected)
    z = np.concatenate([np.ravel(z_offset), np.ravel(z_matrix)])
    # the errors over their reported sigmas are standard normal: rms near 1 (108 values: ±0.2 is 3 sigma)
    assert 0.75 < np.sqrt(np.mean(z**2)) < 1.25
    assert np.max(np.abs(z)) < 4.5
    # the calibrated field norm is constant within the noise: its scatter is the noise's, no model error left
    assert np.max(norm_std) < 1.08


def test_unknown_field_strength_keeps_the_gain_and_fits_the_magnitude():
    rng = np.random.default_rng(5)
    model = worst_model(rng)
    m = readings(model, 2000, rng)
    cal = magnetometer(m)
    assert np.linalg.det(cal.matrix) == pytest.approx(1.0, abs=1e-9)
    # |W_true h| = |h| for W = (A Aᵀ)^(-1/2); scaled to det 1 the magnitude becomes FIELD det(W)^(-1/3)
    expected = FIELD * np.linalg.det(symmetric_truth(model.matrix)) ** (-1 / 3)
    q = cal.quality
    assert abs(q["field_strength"] - expected) < 4 * q["field_strength_sigma"]
    assert q["coverage"] == 1.0 and min(q["direction_spread"]) > 0.8


def test_outliers_do_not_pull_the_robust_fit():
    rng = np.random.default_rng(7)
    model = worst_model(rng)
    m = readings(model, 2000, rng)
    spikes = rng.choice(len(m), 100, replace=False)  # 5 % of the samples hit by a passing magnet
    m[spikes] += rng.uniform(20, 60, (100, 1)) * random_directions(100, rng)
    robust = magnetometer(m, field_strength=FIELD)
    plain = magnetometer(m, field_strength=FIELD, robust=False)
    err_robust = np.linalg.norm(robust.offset - model.bias)
    err_plain = np.linalg.norm(plain.offset - model.bias)
    assert err_robust < 0.1 < err_plain
    assert robust.quality["outliers"] >= 0.04


def test_one_axis_turning_is_refused_naming_the_axis():
    rng = np.random.default_rng(1)
    a = np.linspace(0, 8 * np.pi, 2000)
    dip = np.radians(66)
    h = FIELD * np.column_stack([np.cos(dip) * np.cos(a), -np.cos(dip) * np.sin(a), np.full_like(a, np.sin(dip))])
    m = corrupt(TriadModel(bias=[10, 20, -5], noise_density=0.03), h, 0.01, "rate", rng)
    with pytest.raises(InsufficientMotionError, match=r"one\s+axis only.*\(≈ z\).*other two axes"):
        magnetometer(m)


def test_still_sensor_and_narrow_cone_are_refused():
    rng = np.random.default_rng(2)
    still = np.tile([10.0, 20.0, 40.0], (500, 1)) + 0.3 * rng.standard_normal((500, 3))
    with pytest.raises(InsufficientMotionError, match="not turned"):
        magnetometer(still)
    # yaw with a slight wobble of the x axis: the field stays within ±5° of a cone about x
    a = np.linspace(0, 8 * np.pi, 3000)
    wob = np.radians(5) * np.sin(0.3 * a)
    h = FIELD * np.column_stack([0.4 + 0 * a, 0.9165 * np.cos(a), 0.9165 * np.sin(a)])
    h[:, 0], h[:, 1] = np.cos(wob) * h[:, 0] - np.sin(wob) * h[:, 1], np.sin(wob) * h[:, 0] + np.cos(wob) * h[:, 1]
    with pytest.raises(InsufficientMotionError, match=r"\(≈ x\)"):
        magnetometer(h + 0.3 * rng.standard_normal(h.shape))


def test_bad_input_is_named():
    with pytest.raises(ValueError, match=r"mag must have shape \(N, 3\)"):
        magnetometer(np.zeros((100, 2)))
    with pytest.raises(ValueError, match="at least 30"):
        magnetometer(np.ones((10, 3)))
    with pytest.raises(ValueError, match="field_strength"):
        magnetometer(np.ones((100, 3)), field_strength=-1)


def test_nan_rows_skipped_json_round_trip_and_float32(tmp_path):
    rng = np.random.default_rng(3)
    model = worst_model(rng)
    m = readings(model, 1000, rng)
    with_gaps = m.copy()
    with_gaps[::7] = np.nan
    cal = magnetometer(with_gaps, field_strength=FIELD, frame="FLU")
    assert cal.quality["samples"] == len(m) - len(m[::7])
    save(tmp_path / "cal.json", cal)
    back = load(tmp_path / "cal.json")["mag"]
    assert back.frame == "FLU" and back.units == "uT"
    np.testing.assert_array_equal(back.offset, cal.offset)
    np.testing.assert_array_equal(back.matrix_sigma, cal.matrix_sigma)
    out32 = back.apply(m.astype(np.float32))
    assert out32.dtype == np.float32
    np.testing.assert_allclose(out32, cal.apply(m), atol=1e-3)
    np.testing.assert_allclose(back.invert(back.apply(m)), m, atol=1e-9)
    assert np.isnan(cal.apply(with_gaps)[0]).all()
    (tmp_path / "bad.json").write_text('{"format": "other"}')
    with pytest.raises(ValueError, match="not a strapdown calibration file"):
        Calibration.load(tmp_path / "bad.json")
    doc = json.loads((tmp_path / "cal.json").read_text())
    doc["calibrations"] *= 2  # one sensor twice: which one applies would be an accident of order
    (tmp_path / "twice.json").write_text(json.dumps(doc))
    with pytest.raises(ValueError, match=r"twice.json holds two mag calibrations \(entries 0 and 1\)"):
        load(tmp_path / "twice.json")
    # the same rule where calibrations are written or handed to a pipeline, and only Calibration objects pass
    from strapdown.calibrate import by_sensor

    for give in (lambda *c: save(tmp_path / "two.json", *c), lambda *c: by_sensor(list(c))):
        with pytest.raises(ValueError, match="two mag calibrations given"):
            give(cal, cal)
        with pytest.raises(ValueError, match="Calibration objects, got dict"):
            give(cal, {"sensor": "gyroscope"})
    assert not (tmp_path / "two.json").exists()
    # a file of release 0.1 named the sensor in full: it still loads, under the library's one name
    old = json.loads((tmp_path / "cal.json").read_text())
    old["calibrations"][0]["sensor"] = "magnetometer"
    (tmp_path / "old.json").write_text(json.dumps(old))
    assert list(load(tmp_path / "old.json")) == ["mag"]
    assert Calibration.load(tmp_path / "old.json", sensor="magnetometer").sensor == "mag"


def test_a_small_patch_of_directions_is_refused():
    """Moving without turning (BROAD's translation trials): ±15° about one attitude, readings in a small patch."""
    rng = np.random.default_rng(8)
    tilt = np.radians(15) * rng.uniform(-1, 1, (3000, 2))
    base = np.array([0.4, 0.0, 0.9165])
    h = FIELD * (base + np.column_stack([tilt[:, 0], tilt[:, 1], -0.4 * tilt[:, 0]]))
    h = FIELD * h / np.linalg.norm(h, axis=1, keepdims=True)
    m = corrupt(TriadModel(bias=[5, -3, 8], noise_density=0.03), h, 0.01, "rate", rng)
    with pytest.raises(InsufficientMotionError, match="small patch"):
        magnetometer(m)
    with pytest.raises(InsufficientMotionError, match="small patch"):
        magnetometer(m, field_strength=FIELD)


def test_warranted_only_when_the_fit_removes_most_of_the_norm_scatter():
    rng = np.random.default_rng(9)
    u = random_directions(3000, rng)
    # a calibrated sensor in a field whose strength varies by ±1.5 µT from place to place: nothing to correct
    strength = FIELD + 1.5 * np.sin(np.linspace(0, 40, 3000))
    calibrated = magnetometer(u * strength[:, None] + 0.3 * rng.standard_normal((3000, 3)))
    assert not calibrated.quality["warranted"]
    assert calibrated.quality["norm_scatter_raw"] == pytest.approx(1.5 / np.sqrt(2), rel=0.15)
    # a real hard and soft iron is worth correcting
    model = worst_model(rng)
    assert magnetometer(readings(model, 3000, rng)).quality["warranted"]


def test_gyro_finds_the_rotation_the_field_alone_cannot():
    """A magnetometer turned 5.4° against the gyro axes: the ellipsoid fit leaves the field turned by that much,
    the gyro-aided fit puts it in the gyro's axes (the sensor's true body field, from the exact truth)."""
    from strapdown import as_matrix, from_rotvec
    from strapdown.rotations.quaternion import conjugate, rotate
    from strapdown.simulate import ImuModel, MagneticField, RandomMotion, sample

    turn = as_matrix(from_rotvec(np.radians([3.0, -2.0, 4.0])))
    soft = turn @ np.array([[1.1, 0.05, 0.0], [0.05, 0.92, 0.03], [0.0, 0.03, 1.04]])
    gyro = TriadModel(bias=np.radians([0.3, -0.2, 0.25]), noise_density=1e-4)
    imu = ImuModel(gyro=gyro, mag=TriadModel(bias=[20.0, -10.0, 15.0], soft_iron=soft, noise_density=0.03))
    motion = RandomMotion(duration=120.0, seed=4, rate_scale=1.5, bandwidth=0.3, acceleration_scale=0.3)
    data = sample(motion, 100.0, imu=imu)
    truth = rotate(conjugate(data.q_true[:-1]), np.broadcast_to(MagneticField().ned(), data.mag.shape))

    def angle_rms(cal):
        c = cal.apply(data.mag)
        cos = np.sum(c * truth, axis=1) / np.linalg.norm(c, axis=1) / np.linalg.norm(truth, axis=1)
        return np.degrees(np.sqrt(np.mean(np.arccos(np.clip(cos, -1, 1)) ** 2)))

    field_only = magnetometer(data.mag, field_strength=50.0)
    aided = magnetometer(data.mag, field_strength=50.0, gyro=data.gyro, fs=100.0, gyro_bias=gyro.bias)
    expected = np.degrees(np.arccos((np.trace(turn) - 1) / 2))
    assert angle_rms(field_only) == pytest.approx(expected, abs=1.5)
    assert aided.quality["gyro_alignment_deg"] == pytest.approx(expected, abs=0.3)
    assert angle_rms(aided) < 0.6  # the noise: 0.3 µT per sample of 50 µT is 0.34° per sample
    np.testing.assert_allclose(aided.matrix @ imu.mag.matrix, np.eye(3), atol=6e-3)
    with pytest.raises(ValueError, match="gyro has shape"):
        magnetometer(data.mag, gyro=data.gyro[:10], fs=100.0)
