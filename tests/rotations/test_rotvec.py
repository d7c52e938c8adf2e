import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions, rotation_angle
from strapdown import as_axis_angle, as_gibbs, as_rotvec, from_axis_angle, from_gibbs, from_rotvec


@pytest.fixture(scope="module")
def rotations():
    rot = Rotation.random(100_000, rng=np.random.default_rng(5))
    return rot, rot.as_quat(scalar_first=True), rot.as_rotvec()


def test_as_rotvec_matches_scipy(rotations):
    _, q, rv = rotations
    assert np.abs(as_rotvec(q) - rv).max() <= 1e-12
    assert np.abs(as_rotvec(-q) - rv).max() <= 1e-12


def test_from_rotvec_matches_scipy(rotations):
    _, q, rv = rotations
    assert rotation_angle(from_rotvec(rv), q).max() <= 1e-12


def test_from_rotvec_is_the_exponential_beyond_pi():
    # 3π/2 about z: exp keeps w < 0 rather than jumping to the short way round
    q = from_rotvec([0, 0, 1.5 * np.pi])
    np.testing.assert_allclose(q, [np.cos(0.75 * np.pi), 0, 0, np.sin(0.75 * np.pi)], atol=1e-16)


def test_tiny_rotation_vectors_keep_precision():
    for v in ([1e-300, 0, 0], [1e-12, -3e-12, 2e-12], [0, 0, 1e-5]):
        v = np.array(v)
        q = from_rotvec(v)
        np.testing.assert_allclose(q[1:], v / 2, rtol=1e-11, atol=0)
        np.testing.assert_allclose(as_rotvec(q), v, rtol=1e-11, atol=0)


def test_degrees(rng):
    v = rng.uniform(-100, 100, (100, 3))
    np.testing.assert_allclose(from_rotvec(v, degrees=True), from_rotvec(np.radians(v)), atol=1e-16)
    q = random_quaternions(100, rng)
    np.testing.assert_allclose(as_rotvec(q, degrees=True), np.degrees(as_rotvec(q)), rtol=1e-15)


def test_axis_angle_gajda_2_12(rng):
    axis = rng.standard_normal((1000, 3))
    angle = rng.uniform(-2 * np.pi, 2 * np.pi, 1000)
    q = from_axis_angle(axis, angle)
    n = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    np.testing.assert_allclose(q[:, 0], np.cos(angle / 2), atol=1e-16)
    np.testing.assert_allclose(q[:, 1:], n * np.sin(angle / 2)[:, None], atol=1e-16)
    back_axis, back_angle = as_axis_angle(q)
    assert (back_angle >= 0).all() and (back_angle <= np.pi).all()
    assert rotation_angle(from_axis_angle(back_axis, back_angle), q).max() <= 1e-15
    np.testing.assert_allclose(np.linalg.norm(back_axis, axis=-1), 1, atol=1e-15)


def test_axis_angle_identity_and_broadcast():
    axis, angle = as_axis_angle([1.0, 0, 0, 0])
    np.testing.assert_array_equal(axis, [1.0, 0, 0])
    assert angle == 0
    q = from_axis_angle([0, 0, 1], [0, 90, 180], degrees=True)
    np.testing.assert_allclose(q[:, 0], np.cos(np.radians([0, 45, 90])), atol=1e-16)


def test_gibbs_closed_form(rng):
    axis = rng.standard_normal((1000, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    angle = rng.uniform(0, 0.99 * np.pi, 1000)
    q = from_axis_angle(axis, angle)
    expected = axis * np.tan(angle / 2)[:, None]
    np.testing.assert_allclose(as_gibbs(q), 2 * expected, rtol=1e-12, atol=1e-15)  # Gajda (1.4)
    np.testing.assert_allclose(as_gibbs(q, "rodrigues"), expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_array_equal(as_gibbs(-q), as_gibbs(q))
    assert rotation_angle(from_gibbs(2 * expected), q).max() <= 1e-14
    assert rotation_angle(from_gibbs(expected, "rodrigues"), q).max() <= 1e-14


def test_gibbs_vectors_too_long_to_square_still_give_the_rotation():
    # [1, g] / sqrt(1 + |g|²) with g = θ/2 (Gajda 1.4): w = 2/θ, the vector part the unit axis
    for dtype, theta in ((np.float64, 1e300), (np.float32, 1e30)):
        q = from_gibbs(np.array([0.0, -theta, 0.0], dtype=dtype))
        assert q.dtype == dtype
        np.testing.assert_allclose(q, np.array([2 / theta, 0.0, -1.0, 0.0], dtype=dtype), rtol=1e-6)


def test_gibbs_is_infinite_at_180_degrees():
    with pytest.raises(ValueError, match=r"q is a 180° rotation.*Gibbs vector is infinite"):
        as_gibbs([0.0, 0, 1, 0])
    with pytest.raises(ValueError, match=r"gibbs\[0\] is infinite"):
        from_gibbs([np.inf, 0, 0])
    with pytest.raises(ValueError, match="convention"):
        as_gibbs([1.0, 0, 0, 0], convention="cayley")


def test_bad_input():
    with pytest.raises(ValueError, match=r"axis\[1\] is a zero vector"):
        from_axis_angle([[1, 0, 0], [0, 0, 0]], 1.0)
    with pytest.raises(ValueError, match=r"rotvec\[2\] is NaN"):
        from_rotvec([0, 0, np.nan])
    with pytest.raises(ValueError, match=r"angle is NaN"):
        from_axis_angle([1, 0, 0], np.nan)
