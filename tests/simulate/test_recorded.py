"""Synthetic IMU data from recorded attitudes: mocap-style samples -> spline -> gyro -> integration -> samples."""

import numpy as np
import pytest

from strapdown import angle_between, from_rotvec
from strapdown.rotations.frames import change_frame, frame_matrix
from strapdown.simulate import ImuModel, RandomMotion, RecordedMotion, TriadModel, sample_recorded


@pytest.fixture(scope="module")
def capture():
    """60 s of smooth motion captured at 100 Hz (rates up to ~3 rad/s), with its exact truth."""
    t = np.arange(6001) / 100.0 + 12.5  # a capture clock that does not start at 0
    truth = RandomMotion(duration=60.0, seed=2, rate_scale=2.0)
    return t, truth.attitude(t - 12.5), truth


def test_rotation_vectors_integrate_back_onto_the_samples(capture):
    t, q, _ = capture
    data = sample_recorded(t, q, gyro="rotvec")  # at the capture's own rate: one reading per sample interval
    assert data.gyro.shape == (6000, 3)
    np.testing.assert_allclose(data.t, t, atol=1e-9)
    assert angle_between(data.integrate("exact"), q).max() < 1e-12


def test_increments_at_400_hz_integrate_onto_the_samples(capture):
    t, q, _ = capture
    errors = []
    for rate in (400.0, 1000.0):
        data = sample_recorded(t, q, rate, gyro="increment")
        step = int(rate // 100)
        errors.append(angle_between(data.integrate("coning2")[::step], q).max())
    assert errors[0] < 2e-9  # 6000 samples, 24000 gyro readings
    assert errors[0] / errors[1] > 20  # coning2 is fourth order: (1000/400)^4 = 39 when the readings are exact


def test_readings_follow_the_true_motion_between_the_samples(capture):
    # the spline is an interpolant of the recording: well inside it, its rate is the motion's to 1e-7 rad/s
    t, q, truth = capture
    data = sample_recorded(t, q, 100.0, gyro="rate")
    err = np.abs(data.gyro - truth.rate(t[:-1] - 12.5)).max(axis=-1)
    assert err[20:-20].max() < 1e-6
    assert err[0] > 1e-3  # the end conditions (mean rate of the end segments) cost accuracy at the ends only


def test_frames_of_the_recording_are_the_frames_of_the_readings(capture):
    t, q, _ = capture
    t, q = t[:501], q[:501]
    ned = sample_recorded(t, q, 200.0, reference="NED", body="FRD", gyro="increment")
    q_enu = change_frame(q, ref_from="NED", ref_to="ENU", body_from="FRD", body_to="FLU")
    enu = sample_recorded(t, q_enu, 200.0, reference="ENU", body="FLU", gyro="increment")
    to_flu = frame_matrix("FRD", "FLU")
    np.testing.assert_allclose(enu.gyro, ned.gyro @ to_flu.T, atol=1e-13)
    np.testing.assert_allclose(enu.acc, ned.acc @ to_flu.T, atol=1e-12)
    np.testing.assert_allclose(enu.mag, ned.mag @ to_flu.T, atol=1e-10)
    assert (enu.reference, enu.body) == ("ENU", "FLU")
    # at rest, FLU up: the accelerometer reads +g along body z (specific force)
    still = sample_recorded([0.0, 1.0], np.tile([1.0, 0, 0, 0], (2, 1)), 10.0, reference="ENU", body="FLU")
    np.testing.assert_allclose(still.acc, np.tile([0, 0, 9.80665 * 0.1], (10, 1)), atol=1e-12)  # increments


def test_positions_add_the_kinematic_acceleration():
    # a turntable: radius 0.5 m, 1 rad/s about up (ENU), the sensor's x pointing outwards; exact specific force
    # in FLU is (−ω² r, 0, g): centripetal inwards plus gravity's reaction
    w, r = 1.0, 0.5
    t = np.arange(0, 20.0, 0.005)
    q = from_rotvec(np.outer(w * t, [0.0, 0.0, 1.0]))
    pos = r * np.stack([np.cos(w * t), np.sin(w * t), 0 * t], -1)
    data = sample_recorded(t, q, 200.0, reference="ENU", body="FLU", positions=pos, gyro="rate")
    inner = slice(200, -200)  # the natural spline's zero end accelerations fade within a few samples
    np.testing.assert_allclose(data.acc[inner], np.tile([-(w**2) * r, 0.0, 9.80665], (len(t) - 401, 1)), atol=1e-6)
    np.testing.assert_allclose(data.gyro[inner], np.tile([0, 0, w], (len(t) - 401, 1)), atol=1e-12)
    motion = RecordedMotion(t, q, reference="ENU", body="FLU", positions=pos)
    a_ned = motion.acceleration([10.0])[0]
    np.testing.assert_allclose(a_ned, frame_matrix("ENU", "NED") @ (-(w**2) * pos[2000]), atol=1e-6)


def test_imu_errors_come_from_the_imu_model(capture):
    t, q, _ = capture
    t, q = t[:301], q[:301]
    bias = np.array([0.01, -0.02, 0.005])
    ideal = sample_recorded(t, q, 100.0, gyro="average")
    biased = sample_recorded(t, q, 100.0, gyro="average", imu=ImuModel(gyro=TriadModel(bias=bias)))
    np.testing.assert_allclose(biased.gyro - ideal.gyro, np.tile(bias, (300, 1)), atol=1e-12)
    noisy = sample_recorded(t, q, 100.0, gyro="average", imu=ImuModel.consumer_mems(), seed=3)
    again = sample_recorded(t, q, 100.0, gyro="average", imu=ImuModel.consumer_mems(), seed=3)
    np.testing.assert_array_equal(noisy.gyro, again.gyro)
    assert np.abs(noisy.gyro - ideal.gyro).max() > 1e-4


def test_bad_input():
    q = np.tile([1.0, 0, 0, 0], (3, 1))
    with pytest.raises(ValueError, match="reference must name a frame with a vertical axis"):
        RecordedMotion([0.0, 1, 2], q, reference="world")
    with pytest.raises(ValueError, match="strictly increasing"):
        RecordedMotion([0.0, 1, 1], q)
    with pytest.raises(ValueError, match=r"positions must have shape \(n, 3\) = \(3, 3\)"):
        RecordedMotion([0.0, 1, 2], q, positions=np.zeros((2, 3)))


def test_an_attitude_brings_its_frames(capture):
    from strapdown import Attitude

    t, q, _ = capture
    t, q = t[:201], q[:201]
    enu = Attitude(q, "NED", "FRD").to_frame("ENU", "FLU")
    data = sample_recorded(t, enu, 100.0, gyro="rotvec")
    assert (data.reference, data.body) == ("ENU", "FLU")
    assert angle_between(data.integrate("exact"), enu.q).max() < 1e-12
    with pytest.raises(ValueError, match="reference='NED' but the Attitude q names its reference 'ENU'"):
        sample_recorded(t, enu, reference="NED")
