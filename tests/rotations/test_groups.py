"""strapdown.rotations.groups and Attitude.reduce: group axioms, brute-force reduction, frames (scipy's own cases
run in test_scipy_rotation_groups.py)."""

import numpy as np
import pytest

from conftest import rotation_angle
from strapdown import Attitude, multiply
from strapdown.rotations.groups import create_group, reduce

ORDERS = {"I": 60, "O": 24, "T": 12, "C1": 1, "C5": 5, "D1": 2, "D4": 8}


@pytest.mark.parametrize("name", ORDERS)
def test_groups_are_closed_distinct_and_of_their_order(name):
    g = create_group(name, "y")
    assert g.shape == (ORDERS[name], 4)
    np.testing.assert_array_equal(g[0], [1.0, 0.0, 0.0, 0.0])
    products = multiply(g[:, None], g[None, :]).reshape(-1, 4)
    nearest = rotation_angle(products[:, None], g[None, :]).min(axis=1)
    assert nearest.max() < 1e-12  # every product is an element again
    distinct = rotation_angle(g[:, None], g[None, :]) + np.eye(len(g))
    assert distinct.min() > 0.1


def test_reduce_is_the_brute_force_minimum(rng):
    left, right = create_group("O"), create_group("D3", "x")
    q = Attitude.random(40, rng).q
    out, i, j = reduce(q, left, right)
    every = multiply(multiply(left[None, :, None], q[:, None, None]), right[None, None, :])
    angles = 2 * np.arccos(np.clip(np.abs(every[..., 0]), 0, 1)).reshape(40, -1)
    np.testing.assert_allclose(2 * np.arccos(np.clip(np.abs(out[:, 0]), 0, 1)), angles.min(axis=1), atol=1e-12)
    assert rotation_angle(out, multiply(multiply(left[i], q), right[j])).max() < 1e-15


def test_reduce_checks_frames():
    cube = Attitude.create_group("O", frame="crystal")
    a = Attitude.random(5, rng=1, reference="crystal", body="crystal")
    reduced, i, j = a.reduce(cube, cube, return_indices=True)
    assert (reduced.reference, reduced.body) == ("crystal", "crystal") and i.shape == j.shape == (5,)
    with pytest.raises(ValueError, match="body"):
        Attitude.random(5, rng=1, reference="NED", body="FRD").reduce(right=cube)
    with pytest.raises(TypeError, match="left must be an Attitude"):
        a.reduce(left=cube.q)
