"""The AttitudeEstimator: bias and scale estimation, magnetic disturbances, sensors at different rates, offline
mode, streaming, and the issue-7 figures on BROAD (skipped without the data).  The truth comes from the
simulator (exact) or from BROAD's optical reference."""

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from strapdown import change_frame
from strapdown.evaluate.metrics import attitude_errors, rmse
from strapdown.fusion import (
    FLAG_ACC_REJECTED,
    FLAG_BIAS_AT_LIMIT,
    FLAG_MAG_REJECTED,
    FLAG_REST,
    AttitudeEstimator,
    AttitudeParams,
    attitude,
    attitude_offline,
)
from strapdown.rotations.quaternion import multiply, rotate
from strapdown.simulate import (
    ConstantRotation,
    ImuModel,
    MagneticDisturbance,
    MagneticField,
    RandomMotion,
    RockingPlatform,
    TriadModel,
    sample,
)
from strapdown.simulate.trajectories import Trajectory

BIAS = np.radians(0.5)  # 0.5°/s on every axis
FIELD = MagneticField(declination_deg=0.0)  # magnetic north = true north, so the truth's heading is the field's
BROAD = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "broad" / "data_mat"


def sim(traj, *, bias=BIAS, disturbances=(), imu=None):
    imu = imu or ImuModel(gyro=TriadModel(bias=bias))
    return sample(
        traj,
        100.0,
        gyro="average",
        imu=imu,
        reference="ENU",
        body="FLU",
        magnetic_field=FIELD,
        disturbances=disturbances,
    )


def within_after(bias, true, tol):
    """Seconds after which each bias component stays within tol of the truth (100 Hz)."""
    ok = np.abs(bias - true) < tol
    return np.array([(np.flatnonzero(~ok[:, i])[-1] + 1) * 0.01 if (~ok[:, i]).any() else 0.0 for i in range(3)])


def deg(x):
    return np.degrees(x)


@pytest.fixture(scope="module")
def rocking():
    """The patent's platform rocking and turning in place (never at rest): level on average."""
    return sim(RockingPlatform(duration=240.0, speed=0.0, bump_amplitude=0.0))


def test_bias_in_motion_horizontal_from_gravity_vertical_needs_the_magnetometer(rocking):
    six = attitude(rocking.gyro, rocking.acc, dt=0.01)
    nine = attitude(rocking.gyro, rocking.acc, rocking.mag, dt=0.01)
    assert not (six.flags & FLAG_REST).any()
    t6 = within_after(six.bias, BIAS, np.radians(0.05))
    t9 = within_after(nine.bias, BIAS, np.radians(0.05))
    assert (t6[:2] < 30).all() and (t9[:2] < 30).all()  # horizontal: measured 13-15 s
    assert t9[2] < 150  # vertical with the magnetometer: measured 92 s
    assert t6[2] == 240.0  # without it never within 0.05°/s here (it wanders with the rocking) ...
    sigma6 = six.extra["bias_sigma"][-1]
    assert sigma6[2] > 5 * sigma6[0]  # ... and the filter says so: its vertical uncertainty stays large


def test_bias_of_a_body_turning_every_way_needs_no_magnetometer():
    d = sim(RandomMotion(duration=120.0, seed=3, acceleration_scale=0.0))
    est = attitude(d.gyro, d.acc, dt=0.01)
    assert (within_after(est.bias, BIAS, np.radians(0.05)) < 40).all()  # measured 10-20 s


def test_bias_at_rest_on_every_axis():
    bias = np.radians([0.4, -0.3, 0.2])
    est = AttitudeEstimator().update(np.tile(bias, (1000, 1)), np.tile([0.0, 0.0, 9.81], (1000, 1)), dt=0.01)
    rest = (est.flags & FLAG_REST) > 0
    assert not rest[:149].any() and rest[151:].all()  # rest_time 1.5 s
    np.testing.assert_allclose(est.bias[-1], bias, atol=np.radians(1e-4))
    assert (est.extra["bias_sigma"][-1] < np.radians(0.01)).all()


def test_scale_factor_errors_are_learnt():
    # a motion that turns about every axis at 30-40°/s rms; scale errors of up to 0.4 %, prior 1 %
    scale = np.array([0.004, -0.003, 0.002])
    imu = ImuModel(gyro=TriadModel(scale_factor=scale))
    d = sim(RandomMotion(duration=200.0, seed=3, acceleration_scale=0.0, rate_scale=2.0), imu=imu)
    f = AttitudeEstimator(AttitudeParams(scale_sigma_init=0.01))
    est = f.update(d.gyro, d.acc, dt=0.01)
    # scale errors are weakly observable: this motion learns them to about a tenth (measured 0.12), others less
    assert np.linalg.norm(f.scale - scale) < 0.2 * np.linalg.norm(scale)
    without = attitude(d.gyro, d.acc, dt=0.01, params=AttitudeParams(scale_sigma_init=0.0))
    incl = [rmse(attitude_errors(e.q, d.q_true[1:])["inclination"][10000:]) for e in (est, without)]
    assert incl[0] < 0.8 * incl[1]  # measured 0.72


def test_magnet_nearby_for_ten_seconds_is_flagged_and_heading_survives():
    magnet = MagneticDisturbance(50.0, 60.0, (30.0, 10.0, -20.0))  # µT, in the reference frame
    d = sim(RandomMotion(duration=120.0, seed=5, acceleration_scale=0.0), bias=0.0, disturbances=[magnet])
    t = np.arange(1, len(d.gyro) + 1) * 0.01
    est = attitude(d.gyro, d.acc, d.mag, dt=0.01)
    flagged = (est.flags & FLAG_MAG_REJECTED) > 0
    assert flagged[(t > 50.5) & (t < 59.5)].all() and not flagged[(t < 49.5) | (t > 62)].any()
    heading = deg(attitude_errors(est.q, d.q_true[1:])["heading"])
    assert heading[t >= 50].max() < 0.5  # measured 0.31°
    # without rejection the magnet turns the heading by degrees
    blind = attitude(
        d.gyro, d.acc, d.mag, dt=0.01, params=AttitudeParams(mag_norm_threshold=10.0, mag_dip_threshold=3.0)
    )
    assert deg(attitude_errors(blind.q, d.q_true[1:])["heading"])[t >= 50].max() > 3.0


def test_new_environment_is_accepted_and_the_old_one_recognised():
    # a lasting change (60 s, longer than mag_new_time) is taken as the new field; the old one comes back at once
    change = MagneticDisturbance(40.0, 100.0, (0.0, 15.0, 10.0), ramp=0.5)
    d = sim(RandomMotion(duration=160.0, seed=8, acceleration_scale=0.0), bias=0.0, disturbances=[change])
    t = np.arange(1, len(d.gyro) + 1) * 0.01
    flagged = (attitude(d.gyro, d.acc, d.mag, dt=0.01).flags & FLAG_MAG_REJECTED) > 0
    assert flagged[(t > 41) & (t < 55)].all()  # rejected while it might be passing
    assert not flagged[(t > 65) & (t < 99)].any()  # accepted after mag_new_time
    assert not flagged[t > 102].any()  # the original field is recognised when it returns


def test_sensors_at_different_rates():
    d = sim(RandomMotion(duration=60.0, seed=2, acceleration_scale=0.0), bias=0.0)
    mag = d.mag.copy()
    mag[np.arange(len(mag)) % 4 != 0] = np.nan  # magnetometer at 25 Hz
    acc = d.acc.copy()
    acc[np.arange(len(acc)) % 2 == 1] = np.nan  # accelerometer at 50 Hz
    est = attitude(d.gyro, acc, mag, dt=0.01)
    full = attitude(d.gyro, d.acc, d.mag, dt=0.01)
    np.testing.assert_array_equal((est.flags & FLAG_ACC_REJECTED) > 0, np.isnan(acc[:, 0]))
    errors = [deg(rmse(attitude_errors(e.q, d.q_true[1:])["total"][2000:])) for e in (est, full)]
    assert errors[0] < 0.3 and abs(errors[0] - errors[1]) < 0.02  # measured 0.138° and 0.135°
    # gaps may fall anywhere in the chunks
    f = AttitudeEstimator()
    parts = [f.update(d.gyro[i : i + 777], acc[i : i + 777], mag[i : i + 777], dt=0.01) for i in range(0, 6000, 777)]
    np.testing.assert_array_equal(np.concatenate([p.q for p in parts]), est.q)


def test_frames_chunks_and_state():
    d = sim(RandomMotion(duration=30.0, seed=4))
    enu = attitude(d.gyro, d.acc, d.mag, dt=0.01)
    ned = attitude(d.gyro, d.acc, d.mag, dt=0.01, frame="NED")
    np.testing.assert_allclose(change_frame(enu.q, ref_from="ENU", ref_to="NED"), ned.q, atol=1e-12)
    f = AttitudeEstimator()
    parts, start = [], 0
    for size in (1, 17, 0, 333, 1000):
        sl = slice(start, start + size)
        parts.append(f.update(d.gyro[sl], d.acc[sl], d.mag[sl], dt=0.01))
        start += size
    g = AttitudeEstimator()
    g.state = f.state
    parts.append(g.update(d.gyro[start:], d.acc[start:], d.mag[start:], dt=0.01))
    np.testing.assert_array_equal(np.concatenate([p.q for p in parts]), enu.q)
    np.testing.assert_array_equal(np.concatenate([p.bias for p in parts if len(p)]), enu.bias)
    np.testing.assert_array_equal(g.bias, enu.bias[-1])
    assert set(f.state) >= {"q_gyro", "q_correction", "bias_scale", "covariance", "mag_reference"}


def test_offline_beats_online_and_keeps_the_frame():
    # translation makes the online filter lag; the backward pass cancels the lag
    d = sim(RandomMotion(duration=90.0, seed=6, acceleration_scale=2.0))
    online = attitude(d.gyro, d.acc, d.mag, dt=0.01)
    offline = attitude_offline(d.gyro, d.acc, d.mag, dt=0.01)
    e_on, e_off = (rmse(attitude_errors(e.q, d.q_true[1:])["total"]) for e in (online, offline))
    assert e_off < 0.7 * e_on
    six = attitude_offline(d.gyro, d.acc, dt=0.01)
    assert rmse(attitude_errors(six.q, d.q_true[1:])["inclination"]) < rmse(
        attitude_errors(attitude(d.gyro, d.acc, dt=0.01).q, d.q_true[1:])["inclination"]
    )
    ned = attitude_offline(d.gyro, d.acc, d.mag, dt=0.01, frame="NED")
    np.testing.assert_allclose(change_frame(offline.q, ref_from="ENU", ref_to="NED"), ned.q, atol=1e-9)
    with_t = attitude_offline(d.gyro, d.acc, d.mag, t=np.arange(len(d.gyro)) * 0.01)
    np.testing.assert_allclose(with_t.q, offline.q, atol=1e-9)


def test_start_from_the_first_samples():
    q_true = Rotation.from_euler("ZYX", [1.0, 0.3, -0.2])
    up = q_true.inv().apply([0.0, 0.0, 9.81])
    field = q_true.inv().apply(FIELD.ned()[[1, 0, 2]] * [1, 1, -1])  # NED -> ENU
    est = attitude(np.zeros((50, 3)), np.tile(up, (50, 1)), np.tile(field, (50, 1)), dt=0.01)
    assert deg(attitude_errors(est.q[0], q_true.as_quat()[[3, 0, 1, 2]])["total"]) < 1e-9
    assert deg(attitude_errors(est.q[-1], q_true.as_quat()[[3, 0, 1, 2]])["total"]) < 1e-6


def test_bad_input_is_named():
    g = np.zeros((5, 3))
    a = np.tile([0.0, 0.0, 9.81], (5, 1))
    bad = a.copy()
    bad[2, 1] = np.nan
    with pytest.raises(ValueError, match=r"acc\[2\] is partly NaN"):
        attitude(g, bad, dt=0.01)
    with pytest.raises(ValueError, match="acc has no sample in the first chunk"):
        attitude(g, np.full((5, 3), np.nan), dt=0.01)
    gb = g.copy()
    gb[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"gyro\[1, 0\] is NaN"):
        attitude(gb, a, dt=0.01)
    with pytest.raises(ValueError, match="tau_acc must be positive"):
        AttitudeParams(tau_acc=0.0)
    with pytest.raises(ValueError, match="bias_noise_mag must be non-negative"):
        AttitudeParams(bias_noise_mag=-1.0)
    with pytest.raises(ValueError, match="update_rate must be a finite number"):
        AttitudeParams(update_rate=float("inf"))
    with pytest.raises(ValueError, match="mag_dip_threshold is in radians"):
        AttitudeParams(mag_dip_threshold=10.0)
    # the offline form validates as the online one does, and an empty recording is no error
    with pytest.raises(ValueError, match="give exactly one of dt"):
        attitude_offline(g, a)
    with pytest.raises(ValueError, match="mag has 3 samples but gyro has 5"):
        attitude_offline(g, a, a[:3], dt=0.01)
    with pytest.raises(ValueError, match=r"t is not strictly increasing at sample 1: 1\.0 -> 0\.99"):
        attitude_offline(g, a, t=1.0 - 0.01 * np.arange(5))
    empty = attitude_offline(g[:0], a[:0], a[:0], dt=0.01)
    assert empty.q.shape == (0, 4) and empty.bias.shape == (0, 3)


@pytest.mark.skipif(not BROAD.is_dir(), reason="BROAD data not present (../shared/data/broad)")
def test_broad_figures_of_issue_7():
    from strapdown.evaluate.broad import load_trials
    from strapdown.evaluate.evaluation import evaluate

    trials = load_trials(BROAD)
    six = evaluate("attitude", trials)
    nine = evaluate("attitude", trials, mag=True)
    offline = evaluate(lambda t: attitude_offline(t.gyro, t.acc, t.mag, dt=t.dt), trials, heading_offset=False)
    assert six.mean("inclination") <= 0.70  # measured 0.643 (VQF 0.764)
    assert nine.mean("total") <= 2.2  # measured 1.956 (VQF 2.398)
    assert offline.mean("total") <= 1.9  # measured 1.813 (offline VQF 2.070)


def test_the_magnetometer_moves_the_heading_only():
    # online: the 6D part is the same with or without the magnetometer until the vertical bias diverges;
    # offline: exactly the same inclination, even with an uncalibrated magnetometer disturbed all the time
    d = sim(RandomMotion(duration=60.0, seed=9), imu=ImuModel(mag=TriadModel(bias=[25.0, -10.0, 5.0])))
    six = attitude_offline(d.gyro, d.acc, dt=0.01)
    nine = attitude_offline(d.gyro, d.acc, d.mag, dt=0.01)
    assert (nine.flags & FLAG_MAG_REJECTED).any()
    incl6, incl9 = (attitude_errors(e.q, d.q_true[1:])["inclination"] for e in (six, nine))
    np.testing.assert_allclose(incl9, incl6, atol=1e-9)
    assert np.isfinite(nine.q).all()


@pytest.fixture(scope="module")
def driving():
    """The wheelchair driving and turning, and its kinematic acceleration (wheel odometry would give it; here the
    simulator's truth: the specific force less gravity at the mid-step attitude)."""
    d = sim(RockingPlatform(duration=120.0))
    q_mid = d.q_true[1:] + d.q_true[:-1]
    q_mid /= np.linalg.norm(q_mid, axis=1, keepdims=True)
    return d, d.acc - Rotation.from_quat(q_mid[:, [1, 2, 3, 0]]).inv().apply([0.0, 0.0, 9.80665])


def test_known_acceleration_is_subtracted(driving):
    # centripetal and speed-change accelerations tilt the estimate unless given
    d, known = driving
    plain = attitude(d.gyro, d.acc, dt=0.01)
    aided = attitude(d.gyro, d.acc, dt=0.01, known_acc=known)
    incl = [deg(rmse(attitude_errors(e.q, d.q_true[1:])["inclination"][3000:])) for e in (plain, aided)]
    assert incl[1] < 0.1 < 0.3 < incl[0]
    with pytest.raises(ValueError, match="known_acc must have the shape of acc"):
        attitude(d.gyro, d.acc, dt=0.01, known_acc=known[:10])


@pytest.mark.parametrize("gap_s", [1.5, 5.0])
def test_an_accelerometer_gap_does_not_upset_the_filter(gap_s):
    # a sensor held still; the accelerometer silent for a while: nothing happened, so nothing may change (the
    # filter once stepped over the gap with new coefficients on old states and turned the estimate upside down)
    q = Rotation.from_euler("ZYX", [0.0, 20.0, 10.0], degrees=True)
    n = 6000
    acc = np.tile(q.inv().apply([0.0, 0.0, 9.81]), (n, 1))
    acc[1000 : 1000 + int(gap_s * 100)] = np.nan
    est = attitude(np.zeros((n, 3)), acc, dt=0.01)
    truth = np.tile(q.as_quat()[[3, 0, 1, 2]], (n, 1))
    assert deg(attitude_errors(est.q, truth)["inclination"]).max() < 1e-6


def test_a_steady_turn_is_not_rest():
    # a turntable at 30 deg/s: gyro and accelerometer are steady, but the mean rate is no bias
    d = sample(
        ConstantRotation(np.radians([0.0, 0.0, 30.0]), duration=60.0),
        100.0,
        reference="ENU",
        body="FLU",
        magnetic_field=FIELD,
    )
    est = attitude(d.gyro, d.acc, d.mag, dt=0.01)
    assert not (est.flags & FLAG_REST).any()
    assert deg(np.abs(est.bias).max()) < 0.01
    assert deg(rmse(attitude_errors(est.q, d.q_true[1:])["heading"])) < 0.5


def test_any_first_chunk_starts_alike():
    # 1 kHz, magnetometer at 10 Hz from the sixth row on: sample-by-sample streaming equals one call
    d = sample(
        RandomMotion(duration=4.0, seed=2, acceleration_scale=0.0), 1000.0, reference="ENU", body="FLU",
        magnetic_field=FIELD,
    )  # fmt: skip
    mag = np.full_like(d.mag, np.nan)
    mag[5::100] = d.mag[5::100]
    whole = attitude(d.gyro, d.acc, mag, dt=0.001)
    f = AttitudeEstimator()
    ones = np.concatenate(
        [f.update(d.gyro[i : i + 1], d.acc[i : i + 1], mag[i : i + 1], dt=0.001).q for i in range(400)]
    )
    np.testing.assert_array_equal(ones, whole.q[:400])
    # the heading comes from the first field at once, not after tau_mag: from the end of the first block on
    first = int(np.ceil(1000.0 / AttitudeParams().update_rate)) + 1
    assert deg(attitude_errors(whole.q[first:], d.q_true[first + 1 :])["heading"]).max() < 0.5


def test_a_late_first_accelerometer_sample_is_turned_back_to_the_start():
    d = sim(RandomMotion(duration=20.0, seed=3, acceleration_scale=0.0), bias=0.0)
    acc = d.acc.copy()
    acc[:50] = np.nan  # the accelerometer starts half a second after the gyro
    est = attitude(d.gyro, acc, dt=0.01)
    incl = deg(attitude_errors(est.q, d.q_true[1:])["inclination"])
    assert incl.max() < 0.5  # measured 0.17°; taken as it was at the start, up to 40°


def test_parameters_from_a_mapping_and_numpy_scalars():
    g = np.zeros((50, 3))
    a = np.tile([0.0, 0.0, 9.81], (50, 1))
    by_name = attitude(g, a, dt=0.01, params={"tau_acc": 2.0, "update_rate": np.int64(10)})
    np.testing.assert_array_equal(by_name.q, attitude(g, a, dt=0.01, params=AttitudeParams(2.0, update_rate=10.0)).q)
    assert AttitudeParams(tau_acc=np.float32(3.0)).tau_acc == 3.0
    with pytest.raises(ValueError, match="unknown AttitudeParams field"):
        attitude_offline(g, a, dt=0.01, params={"tau": 1.0})
    with pytest.raises(ValueError, match="dt must be a scalar or have one entry per sample"):
        attitude_offline(g, a, dt=np.full(48, 0.01))


def test_offline_heading_follows_a_vertical_bias_to_the_ends():
    # a level platform: the 6D passes cannot learn the vertical bias, their heading drifts in a ramp, and the
    # offline heading must follow it to both ends of the record rather than lag it by tau_mag times its slope
    d = sim(RockingPlatform(duration=120.0), bias=np.radians([0.0, 0.0, 0.5]))
    online, offline = (f(d.gyro, d.acc, d.mag, dt=0.01) for f in (attitude, attitude_offline))
    on, off = (deg(attitude_errors(e.q, d.q_true[1:])["heading"]) for e in (online, offline))
    assert rmse(off) < 1.0 and rmse(off) < 0.25 * rmse(on)  # measured 0.36° against 4.67° (8.3° with a plain mean)
    assert max(off[1000], off[11000]) < 1.0  # at 10 s and 110 s


def test_local_linear_smoothing_reproduces_a_line_through_gaps():
    from strapdown.fusion._attitude_numba import smooth_directions

    rng = np.random.default_rng(1)
    dts = np.r_[0.0, rng.uniform(0.005, 0.02, 999)]
    t = np.cumsum(dts)
    v = np.column_stack([1.0 + 0.3 * t, -2.0 * t])
    w = np.ones(1000)
    w[300:500] = 0.0  # a long gap
    w[-50:] = 0.0  # and one at the end: the line is extrapolated, not held
    np.testing.assert_allclose(smooth_directions(v, w, dts, 3.0), v, atol=1e-9)


@pytest.mark.parametrize("density_deg", [0.005, 0.02, 0.05])
def test_bias_sigma_at_rest_is_honest_for_noisy_gyros(density_deg):
    # the rest mean is as noisy as the gyro makes it: the error must stay within 3 sigma, and sigma small
    rng = np.random.default_rng(3)
    n = 30000
    bias = np.radians([0.4, -0.3, 0.2])
    gyro = bias + rng.normal(0.0, np.radians(density_deg) * 10.0, (n, 3))  # density × √(100 Hz)
    q = Rotation.from_euler("ZYX", [0.0, 10.0, 5.0], degrees=True)
    acc = q.inv().apply([0.0, 0.0, 9.81]) + rng.normal(0.0, 0.01, (n, 3))
    est = attitude(gyro, acc, dt=0.01)
    err, sigma = np.abs(est.bias - bias)[2000:], est.extra["bias_sigma"][2000:]
    assert (err > 3 * sigma).mean() < 0.01  # with a fixed measurement noise: 50-70 % for the two noisier gyros
    assert deg(sigma.max()) < 3 * density_deg  # and still learnt: measured about 1.4 times the density


def test_offline_takes_a_known_acceleration_and_reports_the_bias_sigma(driving):
    d, known = driving
    plain = attitude_offline(d.gyro, d.acc, dt=0.01)
    aided = attitude_offline(d.gyro, d.acc, dt=0.01, known_acc=known)
    incl = [deg(rmse(attitude_errors(e.q, d.q_true[1:])["inclination"])) for e in (plain, aided)]
    assert incl[1] < 0.75 * incl[0]  # measured 0.43° against 0.62°
    # both ends know the bias from the pass that has seen the whole record: the mean is as good as the better
    sigma = aided.extra["bias_sigma"]
    assert sigma.shape == (len(d.gyro), 3) and np.all(sigma > 0)
    err = np.abs(aided.bias - BIAS)[:, :2]  # horizontal: observable on the level platform
    assert (err < 3 * sigma[:, :2]).mean() > 0.95
    assert deg(err[[0, -1]]).max() < 0.05


def test_a_start_in_motion_averages_out_the_first_accelerations():
    # bodies that accelerate from the first sample on: the start averages the accelerometer (and the heading)
    # instead of trusting the first sample for several time constants
    incl, head = [], []
    for seed in range(6):
        d = sample(RandomMotion(duration=30.0, seed=seed), 100.0, reference="ENU", body="FLU", magnetic_field=FIELD)
        e = attitude_errors(attitude(d.gyro, d.acc, d.mag, dt=0.01).q, d.q_true[1:])
        incl.append(deg(rmse(e["inclination"][:1000])))
        head.append(deg(rmse(e["heading"])))
    assert np.mean(incl) < 4.5 and np.mean(head) < 7.0  # measured 3.8° and 5.4° (5.0° and 10.3° from the 1st sample)


# --- irregular sampling (issue 13) ------------------------------------------------------------------------------


def test_the_low_pass_steps_exactly_over_any_interval():
    # the accelerometer filter's step (lowpass2) against the closed-form step response of the second-order
    # Butterworth with poles (-1 ± i)/tau: y(t) = 1 - exp(-t/tau) (cos(t/tau) + sin(t/tau)), for random intervals
    from strapdown.fusion._kernels_numba import lowpass2

    tau = 3.5
    rng = np.random.default_rng(1)
    h = rng.choice([0.001, 0.01, 0.02, 0.3, 2.0], size=400)
    y, v = 0.0, 0.0
    t = np.cumsum(h)
    out = []
    for step in h:
        p00, p01, p10, p11 = lowpass2(step, tau)
        d = y - 1.0
        y, v = 1.0 + p00 * d + p01 * v, p10 * d + p11 * v
        out.append(y)
    closed = 1.0 - np.exp(-t / tau) * (np.cos(t / tau) + np.sin(t / tau))
    np.testing.assert_allclose(out, closed, atol=1e-11)


def _irregular(d, rng, drop=0.1):
    """Rows of a regular record dropped at random (true end-of-step times kept), and NaN acc/mag rows."""
    n = d.gyro.shape[0]
    keep = rng.random(n) >= drop
    keep[0] = True
    acc, mag = d.acc.copy(), d.mag.copy()
    for arr in (acc, mag):
        gone = rng.random(n) < drop
        gone[0] = False
        arr[gone] = np.nan
    return keep, acc, mag


@pytest.fixture(scope="module")
def moving_consumer():
    """Two minutes of a body turning and accelerating every way, a consumer-grade IMU (noise, bias, scale)."""
    imu = replace_clock(ImuModel.consumer_mems())
    return sample(
        RandomMotion(duration=120.0, seed=4), 100.0, imu=imu, reference="ENU", body="FLU", magnetic_field=FIELD
    )


def replace_clock(imu):
    from dataclasses import replace as dc_replace

    from strapdown.simulate.imu import ClockModel

    return dc_replace(imu, clock=ClockModel())  # the rows are dropped here, on the regular record's own times


def test_dropped_rows_and_missing_samples_cost_little(moving_consumer):
    # 10 % of the rows lost (their true times given) or 10 % of the accelerometer and magnetometer rows NaN:
    # the inputs lose a tenth of their samples, so the errors may move by a little, not by a factor (before the
    # low-pass stepped exactly over any interval, dropping rows multiplied the errors 4-7 times on BROAD)
    d = moving_consumer
    t = d.t[1:]
    truth = d.q_true[1:]
    keep, acc, mag = _irregular(d, np.random.default_rng(7))
    settled = t > 20.0
    for use_mag, metric in ((False, "inclination"), (True, "total")):
        m = d.mag if use_mag else None

        def err(q, rows, metric=metric):
            return deg(rmse(attitude_errors(q, truth[rows])[metric][settled[rows]]))

        every = np.ones(len(t), bool)
        regular = err(attitude(d.gyro, d.acc, m, t=t).q, every)
        dropped = err(attitude(d.gyro[keep], d.acc[keep], None if m is None else m[keep], t=t[keep]).q, keep)
        missing = err(attitude(d.gyro, acc, mag if use_mag else None, t=t).q, every)
        assert dropped < 1.1 * regular + 0.02, (metric, regular, dropped)
        assert missing < 1.1 * regular + 0.02, (metric, regular, missing)


def test_the_rate_is_interpolated_across_a_gap():
    # a body accelerating its turn steadily (rate linear in time), a fifth of the rows lost at random: the rate
    # interpolated across each gap integrates a linear rate exactly (a regular lower rate is no gap: the nominal
    # interval follows it)
    alpha = np.radians(20.0)  # rad/s², about x, from rest
    dt = 0.01
    n = 800
    tk = np.arange(1, n + 1) * dt
    gyro = np.zeros((n, 3))
    gyro[:, 0] = alpha * (tk - 0.5 * dt)  # the mean rate over each step (an integrating gyro)
    angle = 0.5 * alpha * tk**2
    truth = np.column_stack([np.cos(angle / 2), np.sin(angle / 2), 0 * angle, 0 * angle])
    acc = np.column_stack([0 * angle, 9.81 * np.sin(angle), 9.81 * np.cos(angle)])  # at a fixed point: only g
    keep = np.random.default_rng(2).random(n) >= 0.2
    keep[0] = True
    params = AttitudeParams(tau_acc=1000.0)  # the gyro alone: the test is of the integration
    est = AttitudeEstimator(params, q0=truth[0]).update(gyro[keep], acc[keep], t=tk[keep])  # q0: at the 1st time
    err = deg(attitude_errors(est.q, truth[keep])["total"])
    # applying each row's rate over the whole gap errs by alpha dt²/2 per lost row: 0.001° each, 0.16° in all;
    # what is left (measured 0.0009°): in runs of lost rows the nominal interval has begun to follow the longer
    # intervals (2 % per step), as it must to take a lasting lower rate as regular
    assert err.max() < 0.002


@pytest.mark.skipif(not BROAD.is_dir(), reason="BROAD data not present (../shared/data/broad)")
def test_broad_with_dropped_rows_and_missing_samples():
    # issue 13: 10 % of the rows dropped at random (true times given), or 10 % of the accelerometer and of the
    # magnetometer rows NaN: every mean within 10 % of the regular record's (before: 9D ×5 and ×2, 6D ×7 and ×3)
    from strapdown.evaluate.broad import load_trials
    from strapdown.evaluate.metrics import rmse_errors

    sums = np.zeros((3, 3))
    for trial in load_trials(BROAD):
        rng = np.random.default_rng(int(trial.name[:2]))
        n = len(trial)
        keep = rng.random(n) >= 0.1
        keep[0] = True
        acc, mag = trial.acc.copy(), trial.mag.copy()
        for arr in (acc, mag):
            gone = rng.random(n) < 0.1
            gone[0] = False
            arr[gone] = np.nan
        every = np.ones(n, bool)
        variants = [
            (trial.gyro, trial.acc, trial.mag, {"dt": trial.dt}, every),
            (trial.gyro[keep], trial.acc[keep], trial.mag[keep], {"t": np.arange(n)[keep] * trial.dt}, keep),
            (trial.gyro, acc, mag, {"dt": trial.dt}, every),
        ]
        for i, (g, a, m, timing, rows) in enumerate(variants):
            truth, moving = trial.quat[rows], trial.movement[rows]
            sums[i, 0] += rmse_errors(attitude(g, a, m, **timing).q, truth, moving)["total"]
            sums[i, 1] += rmse_errors(attitude(g, a, **timing).q, truth, moving, heading_offset=True)["inclination"]
            sums[i, 2] += rmse_errors(attitude_offline(g, a, m, **timing).q, truth, moving)["total"]
    assert (sums[1:] <= 1.1 * sums[0]).all(), sums / 22  # measured within -2 % .. +2 % (offline inclination +7 %)


# --- the bias prior (issue 13) -----------------------------------------------------------------------------------


@pytest.mark.parametrize("axis", [0, 2])
def test_a_large_bias_is_learnt_not_clipped_and_flagged(axis):
    # 4.5°/s on one axis (a real EuRoC-style recording), twice the prior's spread: learnt within 5 % on a body
    # turning every way (horizontal axes from gravity, the vertical one from the field), and flagged once the
    # estimate passes 2°/s; the old clip held it at 2°/s, so the attitude drifted at 2.5°/s between corrections
    bias = np.zeros(3)
    bias[axis] = np.radians(4.5)
    d = sim(RandomMotion(duration=120.0, seed=3, acceleration_scale=0.0), bias=bias)
    est = attitude(d.gyro, d.acc, d.mag, dt=0.01)
    late = slice(9000, None)  # the last 30 s
    err = np.abs(est.bias[late, axis] - bias[axis])
    assert err.max() < 0.05 * bias[axis]
    flagged = (est.flags & FLAG_BIAS_AT_LIMIT) > 0
    past = np.abs(est.bias[:, axis]) > np.radians(2.0)
    np.testing.assert_array_equal(flagged, past)  # the flag says where the estimate is past the prior's spread ...
    assert flagged[late].all()
    small = attitude(d.gyro - bias + np.radians(1.0), d.acc, d.mag, dt=0.01)  # ... and stays off for 1°/s
    assert not (small.flags & FLAG_BIAS_AT_LIMIT).any()


def test_a_large_bias_at_rest_is_learnt():
    # at rest the mean rate is a bias if the prior finds it plausible (within three spreads: 6°/s)
    bias = np.radians([0.0, 4.5, 0.0])
    est = attitude(np.tile(bias, (1000, 1)), np.tile([0.0, 0.0, 9.81], (1000, 1)), dt=0.01)
    np.testing.assert_allclose(est.bias[-1], bias, atol=0.01 * bias[1])
    assert (est.flags[-1] & FLAG_REST) and (est.flags[-1] & FLAG_BIAS_AT_LIMIT)


def test_linear_acceleration_makes_the_motion_bias_measurement_noisier():
    # ideal sensors (no bias to learn) on bodies accelerating at about 2 m/s²: the low-passed acceleration moves
    # the correction as a bias error would; trusting those measurements less keeps the inclination closer
    def incl(params):
        out = []
        for seed in range(4):
            d = sample(RandomMotion(duration=30.0, seed=seed), 100.0, reference="ENU", body="FLU", magnetic_field=FIELD)
            e = attitude_errors(attitude(d.gyro, d.acc, d.mag, dt=0.01, params=params).q, d.q_true[1:])
            out.append(deg(rmse(e["inclination"][1000:])))
        return np.mean(out)

    aware, blind = incl(None), incl({"bias_noise_acc_factor": 0.0})
    assert aware < 0.95 * blind  # measured 0.88


# --- the magnetometer start and heading acquisition (issue 13) ---------------------------------------------------


def _heading_after(seconds, disturbances=(), seeds=range(6)):
    """The largest heading error (deg) after `seconds` of bodies moving from the first sample on (about 1 m/s²
    of linear acceleration: more tilts the 6D frame, and a tilt error ε shows as ε tan(dip) of heading)."""
    worst = []
    for seed in seeds:
        d = sample(
            RandomMotion(duration=30.0, seed=seed, acceleration_scale=1.0),
            100.0,
            reference="ENU",
            body="FLU",
            magnetic_field=FIELD,
            disturbances=disturbances,
        )
        heading = deg(np.abs(attitude_errors(attitude(d.gyro, d.acc, d.mag, dt=0.01).q, d.q_true[1:])["heading"]))
        worst.append(heading[d.t[1:] >= seconds].max())
    return np.array(worst)


def test_heading_is_acquired_within_ten_seconds_of_a_start_in_motion():
    # the heading mean restarts when the start's plain accelerometer mean hands over to the filter (its tilt,
    # and so the field's heading in it, is poorer before); VQF measured 1.75° mean, 4.2° worst on these
    # (issue 29: within 2° on every seed, not on the mean)
    worst = _heading_after(10.0)
    assert worst.max() < 2.0, worst  # measured 1.25° mean, 1.87° worst (2.29° before the accelerometer-bias guard)


def test_a_transient_first_field_is_not_taken_as_the_reference():
    # a phone's first second of magnetometer readings 3x too strong (a 100 µT field carried along, in body axes):
    # the first field is a candidate until it has stayed consistent for mag_start_time (2 s); the field after it
    # replaces it and sets the heading afresh.  Trusting the first field held the heading 40-100° off for the 20 s
    # a new environment takes to be accepted
    magnet = MagneticDisturbance(-1.0, 1.0, (100.0, 0.0, 0.0), frame="body", ramp=0.0)
    assert _heading_after(5.0, [magnet]).max() < 5.0


# --- offline: a smoother of the bias (issue 13) ------------------------------------------------------------------


def test_offline_smooths_the_bias_so_the_start_knows_it_too():
    # 0.5°/s on every axis, a body turning every way from the first sample: the forward pass needs 10-20 s to
    # learn the bias; the smoother gives the start the bias the rest of the record shows, and the attitude of
    # the first seconds is taken with it
    d = sim(RandomMotion(duration=120.0, seed=3, acceleration_scale=0.0))
    online = attitude(d.gyro, d.acc, d.mag, dt=0.01)
    offline = attitude_offline(d.gyro, d.acc, d.mag, dt=0.01)
    assert np.abs(online.bias[0] - BIAS).min() > 0.9 * BIAS  # the forward pass starts from nothing ...
    # ... the smoothed bias is as good at the start as anywhere (measured within 0.16°/s everywhere; the forward
    # pass's is off by up to 0.23°/s even after 10 s)
    assert np.abs(offline.bias - BIAS).max() < np.radians(0.2)
    first = slice(0, 2000)  # 20 s
    incl = [deg(rmse(attitude_errors(e.q, d.q_true[1:])["inclination"][first])) for e in (online, offline)]
    assert incl[1] < 0.25 * incl[0]  # measured 0.14° against 1.32°


def test_an_uncalibrated_accelerometer_bias_is_guarded_against():
    # 20/-15/10 mg on the accelerometer, an ideal gyro, a body turning every way, 2 and 10 minutes: the bias in use
    # lessens the accelerometer's error (a shrunk estimate: never the wrong way, and the error as a whole down),
    # and the inclination is better than with the bias left out (measured 1.27° against 1.45° and 1.25° against
    # 1.50°).  x, the axis this motion shows best, is found (0.18 of 0.20 m/s² after 10 minutes); z, which it shows
    # least, is overestimated (0.19 of 0.10: the body's linear acceleration, read through few turns), y is still
    # within its uncertainty and left out
    acc_bias = np.array([20.0, -15.0, 10.0]) * 9.80665e-3
    for seconds in (120.0, 600.0):
        d = sim(RandomMotion(duration=seconds, seed=0), bias=0.0, imu=ImuModel(acc=TriadModel(bias=acc_bias)))
        settled = slice(1000, None)
        f = AttitudeEstimator()  # modelled by default (acc_bias_sigma_init 0.1 m/s²)
        modelled = f.update(d.gyro, d.acc, dt=0.01)
        plain = attitude(d.gyro, d.acc, dt=0.01, params={"acc_bias_sigma_init": 0.0})
        incl = [deg(rmse(attitude_errors(e.q, d.q_true[1:])["inclination"][settled])) for e in (modelled, plain)]
        assert incl[0] < 0.92 * incl[1], incl
        used = f.acc_bias_in_use
        assert (used * acc_bias >= 0).all(), used
        assert np.linalg.norm(used - acc_bias) < 0.8 * np.linalg.norm(acc_bias), used
    assert abs(used[0] - acc_bias[0]) < 0.15 * abs(acc_bias[0]), used


def test_a_pendulum_is_a_lever_arm_not_an_accelerometer_bias():
    # A sensor at the bob of a 0.5 m pendulum (swinging 30° at its natural rate, its plane turning at 5°/s; an
    # ideal IMU): the turn about the pivot accelerates it by ω̇ × r + ω × (ω × r), along the rod on average.
    # The lever-arm states find the rod (sensor axes FLU: r = (0, 0, -0.5) m; measured -0.475 m, sideways within
    # 2 mm), and the accelerometer bias in use stays zero; without the lever arm the same motion is read as a
    # bias of 0.57 m/s² along the rod (attitude_estimator.py, step 3)
    d = sim(_Pendulum(120.0), bias=0.0, imu=ImuModel.ideal())
    f = AttitudeEstimator()
    f.update(d.gyro, d.acc, dt=0.01)
    assert abs(f.lever_arm[2] + 0.5) < 0.05, f.lever_arm
    assert np.abs(f.lever_arm[:2]).max() < 0.01, f.lever_arm
    assert np.abs(f.acc_bias_in_use).max() < 0.02, f.acc_bias_in_use
    without = AttitudeEstimator({"lever_arm_sigma_init": 0.0})
    without.update(d.gyro, d.acc, dt=0.01)
    assert without.lever_arm.tolist() == [0.0, 0.0, 0.0]
    assert without.acc_bias_in_use[2] > 0.3, without.acc_bias_in_use  # the test can fail: measured 0.57


class _Pendulum(Trajectory):
    """A pendulum of ``length`` m swinging at sqrt(g/L), amplitude 30°, its plane turning at 5°/s about the
    vertical; the sensor at the bob (NED, FRD: the rod along body z, the pivot at -L z), so its position is R r with
    r = (0, 0, L) and its acceleration d²(R r)/dt² (central differences of the exact attitude)."""

    def __init__(self, duration, length=0.5, amplitude_deg=30.0, precession_deg_s=5.0):
        self.duration, self.length = duration, length
        self.amplitude, self.precession = np.radians(amplitude_deg), np.radians(precession_deg_s)
        self.omega = np.sqrt(9.80665 / length)

    def _angles(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        theta = self.amplitude * np.cos(self.omega * t)
        return theta, -self.amplitude * self.omega * np.sin(self.omega * t), self.precession * t

    def attitude(self, t):
        theta, _, psi = self._angles(t)
        zero = 0.0 * psi
        yaw = np.column_stack([np.cos(psi / 2), zero, zero, np.sin(psi / 2)])
        return multiply(yaw, np.column_stack([np.cos(theta / 2), np.sin(theta / 2), zero, zero]))

    def rate(self, t):
        theta, theta_dot, _ = self._angles(t)
        return np.column_stack([theta_dot, self.precession * np.sin(theta), self.precession * np.cos(theta)])

    def acceleration(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        h = 1e-3

        def position(s):
            return rotate(self.attitude(s), np.tile([0.0, 0.0, self.length], (s.size, 1)))

        return (position(t + h) - 2.0 * position(t) + position(t - h)) / (h * h)


def test_a_steady_turn_does_not_hand_the_accelerometer_bias_to_the_gyro():
    # A consumer IMU (20/-15/10 mg accelerometer bias, 0.3/-0.4/0.2 °/s gyro bias) on a 30°/s turntable for ten
    # minutes.  Both biases are fixed in the body and tilt the estimate alike, so the data cannot tell them apart.
    # If the gyro's update took as known only the bias in use (the readings' shrinkage, k 1), the part kept out of
    # the readings would pass to the gyro's bias block by block, and the error would keep growing: measured 0.79°
    # over the second and third minutes, 1.0° over the last two.  With the gyro's own, smaller k (0.7) it holds,
    # 0.53° then 0.56° (attitude_estimator.py, step 3).
    imu = replace_clock(ImuModel.consumer_mems())
    d = sample(
        ConstantRotation(np.radians([0.0, 0.0, 30.0]), duration=600.0),
        100.0,
        gyro="average",
        imu=imu,
        reference="ENU",
        body="FLU",
        seed=0,
    )
    errors = {}
    for k in (AttitudeParams().gyro_acc_bias_significance, 1.0):
        e = attitude(d.gyro, d.acc, dt=0.01, params={"gyro_acc_bias_significance": k})
        incl = deg(attitude_errors(e.q, d.q_true[1:])["inclination"])
        errors[k] = rmse(incl[6000:18000]), rmse(incl[48000:])  # minutes 2-3, minutes 9-10
    (early, late), (early_1, late_1) = errors.values()
    assert late < 1.15 * early, errors
    assert late_1 > 1.2 * early_1, errors  # the test can fail: the readings' k lets it grow
    assert late < 0.7 * late_1, errors


def test_a_calibrated_accelerometer_keeps_its_readings():
    # no accelerometer bias: what the regression finds stays within its uncertainty, so none is subtracted
    # (the shrinkage, acc_bias_significance), and the inclination is what it was without the states
    d = sim(RandomMotion(duration=120.0, seed=2, acceleration_scale=0.0), bias=0.0)
    f = AttitudeEstimator()
    modelled = f.update(d.gyro, d.acc, dt=0.01)
    plain = attitude(d.gyro, d.acc, dt=0.01, params={"acc_bias_sigma_init": 0.0})
    incl = [deg(rmse(attitude_errors(e.q, d.q_true[1:])["inclination"][1000:])) for e in (modelled, plain)]
    assert np.abs(f.acc_bias_in_use).max() < 0.01, f.acc_bias_in_use  # 1 mg
    assert incl[0] < 1.05 * incl[1] + 0.01, incl  # measured 0.062° both


def _butterworth_gain(omega, tau):
    """|H(iω)| of the estimator's low-pass, H(s) = (2/τ²) / (s² + 2s/τ + 2/τ²) (poles (-1 ± i)/τ)."""
    w0 = 2.0 / tau**2
    return w0 / np.hypot(w0 - omega**2, 2.0 * omega / tau)


def test_offline_inclination_filter_is_zero_phase_with_the_squared_gain():
    # A level body shaken along x at 0.2 Hz (velocity bounded), an ideal IMU: the filter in I leaves LP[a]/g of
    # tilt.  Online that is |H| A/g, lagging; offline the forward-backward pass must leave |H|² A/g in phase
    # with the acceleration (closed form above, τ = tau_acc · offline_time_factor), not the Re H of a mean of
    # two one-way passes (its attenuation is that of one pass)
    p = AttitudeParams()
    tau, amp, omega, dt = p.tau_acc * p.offline_time_factor, 2.0, 2 * np.pi * 0.2, 0.01
    t = np.arange(0.0, 300.0, dt)
    acc = np.column_stack([amp * np.sin(omega * t), 0 * t, np.full_like(t, 9.80665)])
    est = attitude_offline(np.zeros((t.size, 3)), acc, dt=dt, params={"bias_sigma_init": 1e-9, "scale_sigma_init": 0})
    tilt = 2.0 * est.q[:, 2] / est.q[:, 0]  # about y: the level body's pitch error, small
    mid = (t > 60.0) & (t < 240.0)  # away from the ends' start-up
    basis = np.column_stack([np.sin(omega * t[mid]), np.cos(omega * t[mid]), np.ones(mid.sum())])
    (in_phase, quadrature, _), *_ = np.linalg.lstsq(basis, tilt[mid], rcond=None)
    expected = amp / 9.80665 * _butterworth_gain(omega, tau) ** 2
    assert abs(abs(in_phase) - expected) < 0.03 * expected, (in_phase, expected)
    assert abs(quadrature) < 0.03 * expected  # zero phase
    online = attitude(np.zeros((t.size, 3)), acc, dt=dt, params={"bias_sigma_init": 1e-9, "scale_sigma_init": 0})
    tilt_online = 2.0 * online.q[mid, 2] / online.q[mid, 0]
    online_amp = np.hypot(*np.linalg.lstsq(basis, tilt_online, rcond=None)[0][:2])
    assert abs(online_amp - amp / 9.80665 * _butterworth_gain(omega, p.tau_acc)) < 0.03 * online_amp


def test_unit_norm_between_renormalisations():
    # The gyro frame is renormalised every few steps only (RENORM_STEPS): a step keeps |q| to its rounding, so
    # the attitudes stay unit to a few 1e-16 (the property the estimator promises), also spinning at 20 rad/s.
    n = 100_000
    t = np.arange(n) * 1e-3
    gyro = np.column_stack([20.0 * np.cos(0.3 * t), 20.0 * np.sin(0.7 * t), np.full(n, 5.0)])
    acc = np.tile([0.5, -0.3, 9.8], (n, 1))
    est = attitude(gyro, acc, dt=1e-3)
    assert np.abs(np.linalg.norm(est.q, axis=1) - 1.0).max() < 2e-15
    # a state from before the renormalisation count existed restores, and continues as from a count of 0
    f = AttitudeEstimator()
    f.update(gyro[:5003], acc[:5003], dt=1e-3)
    old = f.state
    assert old["gyro_steps_unnormalised"][0] == 5003 % 8  # the steps since the last renormalisation
    del old["gyro_steps_unnormalised"]
    g = AttitudeEstimator()
    g.state = old
    q = g.update(gyro[5003:], acc[5003:], dt=1e-3).q
    assert np.abs(np.linalg.norm(q, axis=1) - 1.0).max() < 2e-15
    np.testing.assert_allclose(q, est.q[5003:], atol=1e-12)
    old["gyro_steps_unnormalised"] = np.array([-1e18])  # out of range: renormalised at once, not in 1e18 steps
    g.state = old
    q = g.update(gyro[5003:], acc[5003:], dt=1e-3).q
    assert np.abs(np.linalg.norm(q, axis=1) - 1.0).max() < 2e-15


def test_blocks_of_any_length_with_any_chunking():
    # Intervals from a tenth of a block to several blocks (the estimator sizes its per-block buffers from the
    # longest): the bias, piecewise constant per block, is the same under any chunking and has a row per sample.
    rng = np.random.default_rng(3)
    d = sim(RandomMotion(duration=60.0, seed=5, acceleration_scale=0.0), bias=0.0)
    keep = np.sort(rng.choice(len(d.gyro), size=1500, replace=False))
    t = keep * 0.01  # gaps of up to seconds between the kept samples
    est = attitude(d.gyro[keep], d.acc[keep], t=t)
    assert est.bias.shape == (len(keep), 3) and est.extra["bias_sigma"].shape == (len(keep), 3)
    f = AttitudeEstimator()
    parts = [f.update(d.gyro[keep[i : i + 97]], d.acc[keep[i : i + 97]], t=t[i : i + 97]) for i in range(0, 1500, 97)]
    np.testing.assert_array_equal(np.concatenate([p.q for p in parts]), est.q)
    np.testing.assert_array_equal(np.concatenate([p.bias for p in parts]), est.bias)
    np.testing.assert_array_equal(np.concatenate([p.extra["bias_sigma"] for p in parts]), est.extra["bias_sigma"])
    # regular sampling at the shortest interval a block allows a bound for (T / dt just over 2)
    n = 2001
    fast = attitude(np.zeros((n, 3)), np.tile([0.0, 0.0, 9.81], (n, 1)), dt=0.2 / 2.0001)
    assert fast.bias.shape == (n, 3) and np.isfinite(fast.bias).all()
