import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions
from strapdown import as_scipy, from_scipy, to_scipy
from strapdown import quaternion as quat


def test_round_trip_keeps_scalar_first(rng):
    q = random_quaternions(100, rng)
    rot = as_scipy(q)
    np.testing.assert_allclose(rot.as_quat(), np.roll(q, -1, axis=-1), atol=1e-16)  # scipy: scalar last
    np.testing.assert_allclose(from_scipy(rot), q, atol=1e-16)


def test_apply_is_rotate(rng):
    q = random_quaternions(100, rng)
    v = rng.standard_normal((100, 3))
    np.testing.assert_allclose(as_scipy(q).apply(v), quat.rotate(q, v), atol=1e-14)


def test_errors():
    with pytest.raises(ValueError, match=r"scipy\.spatial\.transform\.Rotation"):
        from_scipy(np.eye(3))
    with pytest.raises(ValueError, match="zero quaternion"):
        as_scipy([0.0, 0, 0, 0])
    assert from_scipy(Rotation.identity()).shape == (4,)


def test_to_scipy_is_the_name_of_release_0_1_for_as_scipy():
    assert to_scipy is as_scipy
