"""Sampling: readings consistent with the truth in every form and frame, errors reproducible."""

import numpy as np
import pytest

from conftest import rotation_angle
from strapdown import quaternion as quat
from strapdown.simulate import (
    GRAVITY,
    ClockModel,
    ConstantRotation,
    ImuModel,
    MagneticDisturbance,
    MagneticField,
    RandomMotion,
    TriadModel,
    hammerhead_loop,
    sample,
)


@pytest.mark.parametrize(("reference", "body"), [("NED", "FRD"), ("ENU", "FLU"), ("NWU", "FLU"), ("ENU", "RFU")])
@pytest.mark.parametrize("gyro", ["average", "increment", "rotvec"])
def test_ideal_readings_reproduce_the_truth_in_any_frame(reference, body, gyro):
    data = sample(hammerhead_loop(), 100.0, gyro=gyro, reference=reference, body=body)
    assert rotation_angle(data.integrate("exact"), data.q_true).max() < 1e-10


def test_rate_readings_are_instants_at_the_step_starts():
    traj = RandomMotion(duration=4.0, seed=2)
    data = sample(traj, 50.0, gyro="rate")
    np.testing.assert_allclose(data.gyro, traj.rate(data.t[:-1]), atol=1e-15)
    q = data.integrate("rk4")
    assert rotation_angle(q, data.q_true).max() < 1e-6


def test_average_readings_are_means():
    traj = RandomMotion(duration=4.0, seed=2)
    data = sample(traj, 50.0, gyro="average")
    np.testing.assert_allclose(data.gyro * 0.02, traj.increments(data.t), atol=1e-15)


@pytest.mark.parametrize(("reference", "body", "up_axis"), [("NED", "FRD", -2), ("ENU", "FLU", 2), ("NED", "FLU", 2)])
def test_accelerometer_reads_plus_g_up_at_rest(reference, body, up_axis):
    still = ConstantRotation([0.0, 0.0, 0.0], duration=1.0)
    data = sample(still, 10.0, reference=reference, body=body, gyro="rate")
    expected = np.zeros(3)
    expected[abs(up_axis)] = np.sign(up_axis) * GRAVITY
    np.testing.assert_allclose(data.acc, np.tile(expected, (10, 1)), atol=1e-12)


def test_magnetometer_reads_the_field_in_body_axes():
    field = MagneticField(48.0, 63.0, -5.0)
    inc, dec = np.radians(63.0), np.radians(-5.0)
    ned = 48.0 * np.array([np.cos(inc) * np.cos(dec), np.cos(inc) * np.sin(dec), np.sin(inc)])
    data = sample(RandomMotion(duration=3.0, seed=4), 20.0, magnetic_field=field)
    # the attitude maps body to NED: the body reading is C^T m
    np.testing.assert_allclose(data.mag, quat.rotate(quat.conjugate(data.q_true[:-1]), ned), atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(data.mag, axis=1), 48.0, atol=1e-12)


def test_magnetic_disturbance_adds_inside_its_window():
    still = ConstantRotation([0.0, 0.0, 0.0], duration=10.0)
    d = MagneticDisturbance(3.0, 6.0, (0.0, 40.0, 0.0), ramp=0.5)
    clean = sample(still, 10.0)
    dist = sample(still, 10.0, disturbances=[d])
    diff = dist.mag - clean.mag
    t = clean.t[:-1]
    np.testing.assert_allclose(diff[(t < 3.0) | (t > 6.0)], 0, atol=1e-12)
    np.testing.assert_allclose(
        diff[(t > 3.5) & (t < 5.5)], np.tile([0, 40, 0], (((t > 3.5) & (t < 5.5)).sum(), 1)), atol=1e-12
    )
    carried = sample(still, 10.0, disturbances=[MagneticDisturbance(3.0, 6.0, (0.0, 40.0, 0.0), frame="body")])
    np.testing.assert_allclose(
        (carried.mag - clean.mag)[(t > 3.5) & (t < 5.5)], diff[(t > 3.5) & (t < 5.5)], atol=1e-12
    )


def test_errors_are_seeded_and_reproducible():
    imu = ImuModel.consumer_mems()
    a = sample(hammerhead_loop(), 100.0, imu=imu, seed=7)
    b = sample(hammerhead_loop(), 100.0, imu=imu, seed=7)
    c = sample(hammerhead_loop(), 100.0, imu=imu, seed=8)
    for name in ("t", "gyro", "acc", "mag"):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()
        assert getattr(a, name).tobytes() != getattr(c, name).tobytes()


def test_constant_gyro_bias_shows_as_drift():
    bias = np.radians([0.5, -0.3, 0.2])
    imu = ImuModel(gyro=TriadModel(bias=bias))
    still = ConstantRotation([0.0, 0.0, 0.0], duration=10.0)
    data = sample(still, 100.0, imu=imu, gyro="average")
    np.testing.assert_allclose(data.gyro, np.tile(bias, (1000, 1)), atol=1e-15)
    q = data.integrate("exact")
    assert rotation_angle(q[-1], data.q_true[-1]) == pytest.approx(np.linalg.norm(bias) * 10, rel=1e-9)


def test_dropped_samples_and_jitter():
    imu = ImuModel(clock=ClockModel(jitter=1e-4, drop_probability=0.05))
    data = sample(hammerhead_loop(), 100.0, imu=imu, gyro="rate", seed=3)
    n = data.gyro.shape[0]
    assert data.t.shape == (n + 1,) and data.q_true.shape == (n + 1, 4)
    assert 0.9 * 3000 < n < 0.98 * 3000
    assert (np.diff(data.t) > 0).all()
    gaps = np.diff(data.t)
    assert gaps.max() > 0.015  # a drop leaves a step of about two samples
    q = data.integrate("rk4")  # irregular timestamps: still close, not exact
    assert rotation_angle(q, data.q_true).max() < 1e-2


def test_bad_arguments():
    with pytest.raises(ValueError, match="gyro must be one of"):
        sample(hammerhead_loop(), 100.0, gyro="angle")
    with pytest.raises(ValueError, match="rate_hz"):
        sample(hammerhead_loop(), -1.0)
    with pytest.raises(ValueError, match="dst"):
        sample(hammerhead_loop(), 10.0, body="XYZ")
    with pytest.raises(ValueError, match="holds no sample"):
        sample(hammerhead_loop(), 10.0, duration=0.01)
    with pytest.raises(ValueError, match="stop must come after start"):
        MagneticDisturbance(5.0, 4.0)


def test_a_duration_is_what_the_file_lasts_or_refused():
    # `strapdown simulate --scenario random --duration 180` wrote 60 s (the scenario's default) without a word
    from strapdown.simulate.scenarios import scenario

    for name in ("random", "coning", "rocking"):
        assert scenario(name, 180.0).duration == 180.0
    data = sample(scenario("random", 30.0), 50.0, duration=30.0)
    assert data.t[-1] == pytest.approx(30.0, abs=0.02)
    with pytest.raises(ValueError, match=r"duration=100 s is longer than the hammerhead-loop scenario \(30 s\)"):
        scenario("hammerhead-loop", 100.0)
    with pytest.raises(ValueError, match=r"duration=31 s is longer than the trajectory \(30 s\)"):
        sample(hammerhead_loop(), 10.0, duration=31.0)
    with pytest.raises(ValueError, match="duration must be a number of seconds > 0"):
        scenario("random", 0.0)
