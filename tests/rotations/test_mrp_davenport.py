"""MRPs, Davenport angles and one- or two-axis Euler sequences against scipy (scipy's test_rotation.py cases)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions, rotation_angle, wrapped
from strapdown import as_davenport, as_mrp, from_davenport, from_euler, from_mrp
from strapdown.rotations.mrp import shadow_mrp

EX, EY, EZ = np.eye(3)


def rot(q):
    return Rotation.from_quat(q, scalar_first=True)


# ---------------------------------------------------------------------------------------------- MRP
def test_as_mrp_matches_scipy_and_is_short(rng):
    q = random_quaternions(10_000, rng)
    p = as_mrp(q)
    np.testing.assert_allclose(p, rot(q).as_mrp(), atol=1e-15)
    assert (np.linalg.norm(p, axis=-1) <= 1 + 1e-15).all()
    np.testing.assert_array_equal(as_mrp(-q), p)  # sign-invariant


def test_mrp_closed_forms():
    # |p| = tan(χ/4): scipy's test_from_mrp / test_as_mrp values
    np.testing.assert_allclose(as_mrp([np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]), [0, 0, np.tan(np.pi / 8)])
    np.testing.assert_allclose(as_mrp([0.0, 0.0, 0.0, 1.0]), [0, 0, 1])
    np.testing.assert_allclose(from_mrp([0.0, 0.0, 1.0]), [0, 0, 0, 1], atol=1e-16)
    np.testing.assert_array_equal(from_mrp(np.zeros((2, 3))), [[1, 0, 0, 0]] * 2)


def test_from_mrp_matches_scipy_both_sets(rng):
    p = rng.standard_normal((10_000, 3)) * rng.uniform(0, 3, (10_000, 1))  # short and shadow sets

    ours = from_mrp(p)
    theirs = Rotation.from_mrp(p).as_quat(scalar_first=True)
    assert rotation_angle(ours, theirs).max() < 2e-15
    np.testing.assert_allclose(np.linalg.norm(ours, axis=-1), 1, atol=1e-15)


def test_mrp_round_trip_and_shadow(rng):
    q = random_quaternions(5000, rng)
    p = as_mrp(q)
    assert rotation_angle(from_mrp(p), q).max() < 2e-15
    assert rotation_angle(from_mrp(shadow_mrp(p)), q).max() < 2e-15  # the other set, the same rotation
    # a rotation near 360° written with huge shadow parameters: no overflow of |p|²
    q_big = from_mrp([[0.0, 0.0, 1e200], [0.0, 0.0, -3e38]])
    np.testing.assert_allclose(q_big, [[-1, 0, 0, 0], [-1, 0, 0, 0]], atol=1e-30)


def test_mrp_float32_and_shapes(rng):
    q = random_quaternions(12, rng).reshape(3, 4, 4).astype(np.float32)
    p = as_mrp(q)
    assert p.dtype == np.float32 and p.shape == (3, 4, 3)
    q2 = from_mrp(p)
    assert q2.dtype == np.float32 and q2.shape == (3, 4, 4)
    assert rotation_angle(q2, q).max() < 1e-6
    assert as_mrp(q[0, 0]).shape == (3,)


def test_mrp_errors():
    with pytest.raises(ValueError, match="mrp"):
        from_mrp([np.nan, 0, 0])
    with pytest.raises(ValueError, match="zero quaternion"):
        as_mrp([0, 0, 0, 0])
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3\)"):
        from_mrp([1.0, 2.0])
    with pytest.raises(ValueError, match="shadow set is at infinity"):
        shadow_mrp([0.0, 0.0, 0.0])


# ---------------------------------------------------------------------------------------------- Davenport
AXES = {
    "basis zyx": [EZ, EY, EX],
    "proper xyx": [EX, EY, EX],
    "scipy doc": [[2, 0, 0], [0, 1, 0], [1, 0, 1]],  # not normalised, n1·n3 ≠ 0
    "lambda > 90": [[1, 0, 0], [0, 0, 1], [-0.3, -1, 0]],
    "negative lambda": [[1, 0, 0], [0, 0, 1], [0.3, -1, 0]],
    "tilted": [[1, 1, 0], [-1, 1, 1], [1, 0, 1]],
}


@pytest.mark.parametrize("order", ["extrinsic", "intrinsic", "e", "i"])
@pytest.mark.parametrize("name", list(AXES))
def test_davenport_matches_scipy(name, order, rng):
    axes = np.array(AXES[name], dtype=float)
    angles = rng.uniform(-np.pi, np.pi, (5000, 3))
    ours = from_davenport(axes, order, angles)
    theirs = Rotation.from_davenport(axes, order, angles).as_quat(scalar_first=True)
    assert rotation_angle(ours, theirs).max() < 2e-15
    q = random_quaternions(5000, rng)
    got = as_davenport(q, axes, order)
    want = rot(q).as_davenport(axes, order)
    np.testing.assert_allclose(wrapped(got - want), 0, atol=1e-13)  # outer angles: ill-conditioned near the lock
    assert rotation_angle(from_davenport(axes, order, got), q).max() < 2e-15  # the angles rebuild q


def test_davenport_ranges_and_degrees(rng):
    axes = np.array(AXES["scipy doc"], dtype=float)
    unit = axes / np.linalg.norm(axes, axis=-1, keepdims=True)
    lam = np.arccos(unit[0] @ unit[2])  # λ, the angle from n1 to n3 (here about +n2)
    a = as_davenport(random_quaternions(20_000, rng), axes, "e")
    assert (a[:, 1] >= -lam - 1e-15).all() and (a[:, 1] <= np.pi - lam + 1e-15).all()
    assert (np.abs(a[:, [0, 2]]) <= np.pi).all()
    d = as_davenport(from_davenport(axes, "e", [90, 45, 30], degrees=True), axes, "e", degrees=True)
    np.testing.assert_allclose(d, [90, 45, 30], atol=1e-12)


def test_davenport_gimbal_lock_is_exact():
    # x-y-x at β = 0 is e_x(α + γ) = [cos δ, sin δ, 0, 0]; at β = π it is [0, 0, cos δ, sin δ] (δ = (γ - α)/2,
    # by hand).  Exactly there: third angle 0, middle angle 0 or π, the rotation kept (scipy also zeroes the third)
    d = 0.4
    for order in ("e", "i"):
        for q, beta in (([np.cos(d), np.sin(d), 0, 0], 0.0), ([0, 0, np.cos(d), np.sin(d)], np.pi)):
            a = as_davenport(q, [EX, EY, EX], order)
            assert a[2] == 0 and a[1] == beta
            assert rotation_angle(from_davenport([EX, EY, EX], order, a), q) < 1e-15
    # one ulp away from the lock both outer angles are kept and still rebuild the rotation
    q = from_davenport([EX, EY, EX], "e", [0.3, 1e-300, 0.5])
    a = as_davenport(q, [EX, EY, EX], "e")
    assert a[2] != 0 and rotation_angle(from_davenport([EX, EY, EX], "e", a), q) < 1e-15


def test_davenport_one_and_two_axes_and_scalars():
    # scipy's test_from_davenport_single_rotation / _one_or_two_axes
    np.testing.assert_allclose(from_davenport(EZ, "e", 90, degrees=True), [np.sqrt(0.5), 0, 0, np.sqrt(0.5)])
    two = from_davenport([EZ, EX], "e", [[90, 45], [35, 45]], degrees=True)
    theirs = Rotation.from_davenport([EZ, EX], "e", [[90, 45], [35, 45]], degrees=True).as_quat(scalar_first=True)
    assert two.shape == (2, 4) and rotation_angle(two, theirs).max() < 1e-15


def test_davenport_errors():
    with pytest.raises(ValueError, match="not perpendicular"):
        from_davenport([EX, [1, 1, 0], EX], "e", [1, 2, 3])
    with pytest.raises(ValueError, match="order"):
        from_davenport([EX, EY, EZ], "x", [1, 2, 3])
    with pytest.raises(ValueError, match=r"angles must have shape \(\.\.\., 2\)"):
        from_davenport([EX, EY], "e", [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="three axes"):
        as_davenport([1.0, 0, 0, 0], [EX, EY], "e")
    with pytest.raises(ValueError, match="zero vector"):
        from_davenport([EX, [0, 0, 0]], "e", [1.0, 2.0])


def test_davenport_float32(rng):
    q = random_quaternions(100, rng).astype(np.float32)
    a = as_davenport(q, [EZ, EY, EX], "i")
    assert a.dtype == np.float32
    back = from_davenport([EZ, EY, EX], "i", a)
    assert back.dtype == np.float32 and rotation_angle(back, q).max() < 1e-6


# ---------------------------------------------------------------------------------------------- short Euler
@pytest.mark.parametrize("seq", ["x", "Y", "z", "xy", "ZY", "zx", "XZ"])
def test_short_euler_matches_scipy(seq, rng):
    angles = rng.uniform(-np.pi, np.pi, (1000, len(seq)))
    ours = from_euler(angles, seq)
    theirs = Rotation.from_euler(seq, angles).as_quat(scalar_first=True)
    assert rotation_angle(ours, theirs).max() < 1e-15


def test_euler_scalar_angle_for_one_axis():
    np.testing.assert_allclose(from_euler(90.0, "z", degrees=True), [np.sqrt(0.5), 0, 0, np.sqrt(0.5)])
    assert from_euler([[0.1], [0.2]], "x").shape == (2, 4)
    assert from_euler(np.float32(0.5), "y").dtype == np.float32
    with pytest.raises(ValueError, match="one angle per axis"):
        from_euler([0.1, 0.2], "x")
    with pytest.raises(ValueError, match="repeats an axis"):
        from_euler([0.1, 0.2], "xx")
    with pytest.raises(ValueError, match="mixes upper and lower"):
        from_euler([0.1, 0.2], "xY")


# ---------------------------------------------------------------------------------------------- scipy's own values
def test_scipy_generic_mrp_values():
    # scipy test_from_generic_mrp / test_as_generic_mrp / test_past_180_degree_rotation (scalar-last there)
    got = from_mrp([[1, 2, 2], [1, -1, 0.5], [0, 0, 0]])
    expected_last = np.array([[0.2, 0.4, 0.4, -0.8], [0.61538462, -0.61538462, 0.30769231, -0.38461538], [0, 0, 0, 1]])
    assert rotation_angle(got, np.roll(expected_last, 1, axis=-1)).max() < 1e-7
    q_last = np.array([[1, 2, -1, 0.5], [1, -1, 1, 0.0003], [0, 0, 0, 1]])
    expected = [[0.33333333, 0.66666667, -0.33333333], [0.57725028, -0.57725028, 0.57725028], [0, 0, 0]]
    np.testing.assert_allclose(as_mrp(np.roll(q_last, 1, axis=-1)), expected, atol=1e-8)
    np.testing.assert_allclose(as_mrp(from_euler([270.0, 0, 0], "xyz", degrees=True)), [-np.tan(np.pi / 8), 0, 0])


def test_scipy_davenport_degenerate_cases():
    # scipy test_as_davenport_degenerate: middle angle at 0 or π minus λ, any λ; the angles rebuild the rotation
    rnd = np.random.RandomState(0)
    angles = np.empty((5, 3))
    angles[:, 0] = rnd.uniform(-np.pi, np.pi, 5)
    middle = np.array([rnd.choice([0, np.pi]) for _ in range(5)])
    angles[:, 2] = rnd.uniform(-np.pi, np.pi, 5)
    for lam in rnd.uniform(0, np.pi, 5):
        e3 = Rotation.from_rotvec(lam * EY).apply(EX)
        axes = np.stack([EX, EY, e3])
        angles[:, 1] = middle - lam
        for order in ("extrinsic", "intrinsic"):
            ax = axes if order == "intrinsic" else axes[::-1]
            q = from_davenport(ax, order, angles)
            back = from_davenport(ax, order, as_davenport(q, ax, order))
            assert rotation_angle(back, q).max() < 1e-14


def test_quaternions_of_any_finite_size(rng):
    # a rotation quaternion's norm does not matter: 1e±200 (whose |q|² over- or underflows) and subnormal rows
    # give the results of the unit quaternion, with no warning
    q = random_quaternions(50, rng)
    axes = [EZ, EY, EX]
    for scale in (1e200, 1e-200, 1e-310):
        np.testing.assert_allclose(as_mrp(q * scale), as_mrp(q), atol=1e-15 if scale > 1e-300 else 1e-7)
        np.testing.assert_allclose(
            wrapped(as_davenport(q * scale, axes, "i") - as_davenport(q, axes, "i")),
            0,
            atol=1e-13 if scale > 1e-300 else 1e-6,
        )
    assert np.isfinite(as_mrp([5e-324, 0, 0, 0])).all()
