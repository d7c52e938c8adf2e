"""Bad arguments give a ValueError that names the argument (issue 14, "errors that name the wrong thing")."""

import numpy as np
import pytest

import strapdown as sd
from strapdown import quaternion as quat
from strapdown.evaluate.metrics import error_quaternion
from strapdown.fusion import Mahony, tilt_from_pitch_roll, tilt_from_up
from strapdown.rotations.average import average_two, chordal_distance, mean

TWO, THREE = np.tile([1.0, 0, 0, 0], (2, 1)), np.tile([1.0, 0, 0, 0], (3, 1))


@pytest.mark.parametrize(
    ("call", "first", "second"),
    [
        (lambda: quat.multiply(TWO, THREE), "p", "q"),
        (lambda: quat.angle_between(TWO, THREE), "p", "q"),
        (lambda: quat.power(TWO, [1.0, 2.0, 3.0]), "q", "t"),
        (lambda: quat.slerp(TWO, THREE, 0.5), "p", "q"),
        (lambda: quat.slerp(TWO, TWO, [0.1, 0.2, 0.3]), "p", "t"),
        (lambda: quat.rotate(TWO, np.ones((3, 3))), "q", "v"),
        (lambda: sd.from_axis_angle(np.ones((2, 3)), [1.0, 2.0, 3.0]), "axis", "angle"),
        (lambda: average_two(TWO, THREE), "p", "q"),
        (lambda: chordal_distance(TWO, THREE), "p", "q"),
        (lambda: tilt_from_pitch_roll([0.1, 0.2], [0.1, 0.2, 0.3]), "pitch", "roll"),
        (lambda: error_quaternion(TWO, THREE), "q_est", "q_ref"),
    ],
)
def test_shapes_that_do_not_broadcast_name_both_arguments(call, first, second):
    # numpy's own message said "shape mismatch: objects cannot be broadcast ... arg 0"
    with pytest.raises(ValueError, match=rf"^{first} and {second} do not broadcast: leading shapes"):
        call()


def test_change_frame_names_its_own_arguments():
    with pytest.raises(ValueError, match=r"^ref_from='NEE' repeats a direction"):
        sd.change_frame([1.0, 0, 0, 0], ref_from="NEE", ref_to="ENU")
    with pytest.raises(ValueError, match=r"^ref_to='ENX' mixes"):
        sd.change_frame([1.0, 0, 0, 0], ref_from="NED", ref_to="ENX")
    with pytest.raises(ValueError, match=r"^body_to='FRX' mixes"):
        sd.change_frame([1.0, 0, 0, 0], body_from="FRD", body_to="FRX")
    with pytest.raises(ValueError, match=r"^ref_from='FRD' is a body frame; ref_from must be a reference frame"):
        sd.change_frame([1.0, 0, 0, 0], ref_from="FRD", ref_to="FLU")


def test_estimator_frame_is_named_frame():
    with pytest.raises(ValueError, match=r"^frame must be three axis letters"):
        Mahony(frame="XYZW")
    with pytest.raises(ValueError, match=r"^frame='FRD' is a body frame"):
        Mahony(frame="FRD")


@pytest.mark.parametrize("shape", [2.5, -1, (2, -3), True, "3"])
def test_identity_shape_is_checked(shape):
    with pytest.raises(ValueError, match="shape must be a non-negative integer"):
        quat.identity(shape)


def test_identity_dtype_is_checked():
    with pytest.raises(ValueError, match="dtype must be float32 or float64"):
        quat.identity(2, dtype=np.int64)
    assert quat.identity((2, 0)).shape == (2, 0, 4)


def test_mean_threshold_is_checked_without_return_outliers():
    q = np.tile([1.0, 0, 0, 0], (3, 1))
    with pytest.raises(ValueError, match="threshold must be one non-negative angle"):
        mean(q, threshold=-1)
    with pytest.raises(ValueError, match="give it with return_outliers=True"):
        mean(q, threshold=0.1)


@pytest.mark.parametrize("atol", ["x", -1.0, None, np.nan])
def test_from_matrix_atol_is_checked(atol):
    with pytest.raises(ValueError, match="atol must be a non-negative number"):
        sd.from_matrix(np.eye(3), atol=atol)


def test_complex_input_is_refused_by_name():
    from strapdown.evaluate.metrics import rmse

    with pytest.raises(ValueError, match="x must be real, got a complex array"):
        rmse(np.array([1 + 1j, 2.0]))
    with pytest.raises(ValueError, match="acc must be real"):
        Mahony().update(np.zeros((3, 3)), np.ones((3, 3)) * (1 + 0j), dt=0.01)


@pytest.mark.parametrize(("seed", "message"), [(-1, "got -1"), (1.5, "got 1.5"), ("0", "got '0'"), (True, "got True")])
def test_simulate_seed_is_checked(seed, message):
    from strapdown.simulate import ConstantRotation, RandomMotion, sample

    with pytest.raises(ValueError, match=rf"seed must be a non-negative integer, {message}"):
        sample(ConstantRotation([0.0, 0.0, 1.0], duration=1.0), 10.0, seed=seed)
    with pytest.raises(ValueError, match=rf"seed must be a non-negative integer, {message}"):
        RandomMotion(1.0, seed=seed)


def test_simulate_refuses_a_rate_that_would_exhaust_memory():
    from strapdown.simulate import ConstantRotation, sample

    # 1e9 Hz over 1 s asked for terabytes and failed with a MemoryError
    with pytest.raises(ValueError, match=r"rate_hz=1e\+09 over 1 s makes 1e\+09 samples"):
        sample(ConstantRotation([0.0, 0.0, 1.0], duration=1.0), 1e9)
    with pytest.raises(ValueError, match="rate_hz must be a positive number, got 'x'"):
        sample(ConstantRotation([0.0, 0.0, 1.0], duration=1.0), "x")


# --- dtype: float32 in, float32 out, Python floats do not widen -----------------------------------------------
def test_python_floats_keep_float32():
    p = np.array([1.0, 0, 0, 0], dtype=np.float32)
    q = np.array([0.0, 1.0, 0, 0], dtype=np.float32)
    assert quat.slerp(p, q, 0.3).dtype == np.float32
    assert quat.power(q, 2.0).dtype == np.float32
    assert sd.from_axis_angle(np.array([0, 0, 1], dtype=np.float32), 0.5).dtype == np.float32
    # an explicit float64 array still widens
    assert quat.slerp(p, q, np.float64(0.3)).dtype == np.float32
    assert quat.slerp(p, q, np.array([0.3])).dtype == np.float64
    # the values are those of float64 to float32 rounding: slerp(1, i, 0.3) = [cos 27°, sin 27°, 0, 0]
    np.testing.assert_allclose(quat.slerp(p, q, 0.3), [np.cos(0.15 * np.pi), np.sin(0.15 * np.pi), 0, 0], atol=1e-7)


def test_tilt_from_up_keeps_float32():
    got = tilt_from_up(np.array([[0.0, 0, 1], [0.0, 0, -1], [0, 1, 1]], dtype=np.float32))
    assert got.dtype == np.float32
    np.testing.assert_allclose(got[2], [np.cos(np.pi / 8), np.sin(np.pi / 8), 0, 0], atol=1e-7)


def test_attitude_offline_names_a_bad_mag_and_refuses_complex_acc():
    from strapdown.fusion import attitude_offline

    g, a = np.zeros((50, 3)), np.tile([0.0, 0.0, 9.81], (50, 1))
    with pytest.raises(ValueError, match=r"mag must have shape \(\.\.\., 3\)"):
        attitude_offline(g, a, 0.5, dt=0.01)  # an IndexError before
    with pytest.raises(ValueError, match="acc must be real, got a complex array"):
        attitude_offline(g, a * (1 + 0j), dt=0.01)  # accepted, imaginary part dropped, before
