"""Swing-twist, shortest arc and attitude error: properties checked with scipy rotations and plain linear algebra."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions, rotation_angle
from strapdown.rotations.decompose import attitude_error, shortest_arc, swing_twist


def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def hamilton(p, q):
    """Hamilton product written out here (not strapdown's), scalar first."""
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack(
        [
            pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw,
        ],
        axis=-1,
    )


def apply(q, v):
    return np.einsum("...ij,...j->...i", Rotation.from_quat(q, scalar_first=True).as_matrix(), v)


@pytest.mark.parametrize("frame", ["body", "reference"])
def test_swing_twist_properties(frame, rng):
    q = random_quaternions(20_000, rng)
    n = unit(rng.standard_normal((20_000, 3)))
    swing, twist = swing_twist(q, 3.7 * n, frame=frame)
    # recomposition is exact, sign included
    product = hamilton(swing, twist) if frame == "body" else hamilton(twist, swing)
    assert np.abs(product - q).max() <= 1e-15
    # twist: a rotation about n (vector part parallel to n); swing: axis perpendicular to n
    assert np.linalg.norm(np.cross(twist[:, 1:], n), axis=-1).max() <= 1e-15
    assert np.abs(np.einsum("ni,ni->n", swing[:, 1:], n)).max() <= 1e-15
    # unit quaternions
    assert np.abs(np.linalg.norm(swing, axis=-1) - 1).max() <= 1e-15
    assert np.abs(np.linalg.norm(twist, axis=-1) - 1).max() <= 1e-15
    # the twist leaves n fixed
    np.testing.assert_allclose(apply(twist, n), n, atol=1e-14)


def test_swing_is_the_shortest_arc_of_the_axis(rng):
    """frame='body': the swing turns n to where q points it, by the smallest rotation (scipy align_vectors)."""
    q = random_quaternions(500, rng)
    n = unit(rng.standard_normal((500, 3)))
    swing, _ = swing_twist(q, n)
    target = apply(q, n)
    np.testing.assert_allclose(apply(swing, n), target, atol=1e-14)
    expected = np.array([Rotation.align_vectors(target[i], n[i])[0].as_quat(scalar_first=True) for i in range(500)])
    assert rotation_angle(swing, expected).max() <= 1e-12


def test_swing_twist_of_euler_angles():
    """Pitch then roll: the twist about the body x axis is the roll; yaw then pitch: about the vertical, the yaw."""
    yaw, pitch, roll = 0.7, -0.4, 1.1
    q = Rotation.from_euler("YX", [pitch, roll]).as_quat(scalar_first=True)
    swing, twist = swing_twist(q, [1.0, 0, 0])
    np.testing.assert_allclose(twist, Rotation.from_rotvec([roll, 0, 0]).as_quat(scalar_first=True), atol=1e-15)
    np.testing.assert_allclose(swing, Rotation.from_rotvec([0, pitch, 0]).as_quat(scalar_first=True), atol=1e-15)
    q = Rotation.from_euler("ZY", [yaw, pitch]).as_quat(scalar_first=True)
    swing, twist = swing_twist(q, [0, 0, 1.0], frame="reference")
    np.testing.assert_allclose(twist, Rotation.from_rotvec([0, 0, yaw]).as_quat(scalar_first=True), atol=1e-15)
    np.testing.assert_allclose(swing, Rotation.from_rotvec([0, pitch, 0]).as_quat(scalar_first=True), atol=1e-15)
    # with all three angles the split differs from the Euler factors, but the twist still turns about the axis
    q = Rotation.from_euler("ZYX", [yaw, pitch, roll]).as_quat(scalar_first=True)
    swing, twist = swing_twist(q, [0, 0, 1.0], frame="reference")
    assert abs(swing[3]) <= 1e-16
    np.testing.assert_allclose(hamilton(twist, swing), q, atol=1e-15)


def test_swing_twist_degenerate_and_pure_cases(rng):
    n = np.array([0.0, 0, 1])
    # 180° about an axis perpendicular to n: w = 0 and v·n = 0, the twist is undefined -> identity
    q = np.array([0.0, 0.6, 0.8, 0.0])
    swing, twist = swing_twist(q, n)
    np.testing.assert_array_equal(twist, [1.0, 0, 0, 0])
    np.testing.assert_array_equal(swing, q)
    # a pure twist and a pure swing
    q = Rotation.from_rotvec([0, 0, 2.5]).as_quat(scalar_first=True)
    swing, twist = swing_twist(q, n)
    np.testing.assert_allclose(swing, [1, 0, 0, 0], atol=1e-16)
    np.testing.assert_allclose(twist, q, atol=1e-16)
    q = Rotation.from_rotvec([0.3, -0.2, 0]).as_quat(scalar_first=True)
    swing, twist = swing_twist(q, n)
    np.testing.assert_allclose(twist, [1, 0, 0, 0], atol=1e-16)
    np.testing.assert_allclose(swing, q, atol=1e-16)
    # broadcasting, non-unit q, float32
    q = random_quaternions(6, rng).reshape(2, 3, 4)
    swing, twist = swing_twist(5 * q, [0, 1.0, 0])
    assert swing.shape == twist.shape == (2, 3, 4)
    np.testing.assert_allclose(hamilton(swing, twist), q, atol=1e-15)
    s32, t32 = swing_twist(q.astype(np.float32), np.float32([0, 1, 0]))
    assert s32.dtype == t32.dtype == np.float32


def test_shortest_arc_maps_u_to_v(rng):
    u = rng.standard_normal((20_000, 3)) * rng.uniform(0.01, 100, (20_000, 1))
    v = rng.standard_normal((20_000, 3))
    q = shortest_arc(u, v)
    np.testing.assert_allclose(apply(q, unit(u)), unit(v), atol=2e-15)
    # the axis is perpendicular to both, and the angle is the angle between them
    axis = q[:, 1:]
    assert np.abs(np.einsum("ni,ni->n", axis, unit(u))).max() <= 1e-15
    assert np.abs(np.einsum("ni,ni->n", axis, unit(v))).max() <= 1e-15
    angle = Rotation.from_quat(q, scalar_first=True).magnitude()
    between = np.arccos(np.clip(np.einsum("ni,ni->n", unit(u), unit(v)), -1, 1))
    np.testing.assert_allclose(angle, between, atol=1e-7)  # arccos is the inaccurate side here
    assert (q[:, 0] >= 0).all()
    # it is scipy's single-vector align_vectors (the minimal rotation)
    expected = np.array([Rotation.align_vectors(v[i], u[i])[0].as_quat(scalar_first=True) for i in range(300)])
    assert rotation_angle(q[:300], expected).max() <= 1e-12


@pytest.mark.parametrize("delta", [0.0, 1e-300, 1e-12, 1e-8, 1e-4])
def test_shortest_arc_near_parallel_and_antiparallel(delta, rng):
    for u in (np.array([1.0, 0, 0]), unit(rng.standard_normal(3)), np.array([0.0, -2.0, 0.0])):
        perp = unit(np.cross(u, rng.standard_normal(3)))
        for sign in (1.0, -1.0):
            v = sign * unit(u) + delta * perp
            q = shortest_arc(u, v)
            assert np.isfinite(q).all()
            assert abs(np.linalg.norm(q) - 1) <= 2e-16
            np.testing.assert_allclose(apply(q, unit(u)), unit(v), atol=4e-16)
            expected_angle = np.arctan2(delta, sign * 1.0) if delta else (0.0 if sign > 0 else np.pi)
            assert Rotation.from_quat(q, scalar_first=True).magnitude() == pytest.approx(
                abs(expected_angle), rel=1e-12, abs=4e-16
            )
            if sign < 0 and delta == 0:  # exactly antiparallel: 180° about an axis perpendicular to u
                assert abs(q[0]) <= 1e-16
                assert abs(np.dot(q[1:], unit(u))) <= 1e-16


def test_shortest_arc_tiny_angles_and_dtypes():
    q = shortest_arc([1.0, 0, 0], [1.0, 1e-10, 0])
    np.testing.assert_allclose(q, [1.0, 0, 0, 0.5e-10], rtol=1e-15)
    q = shortest_arc([1e-200, 0, 0], [0, 3e-200, 0])  # tiny vectors still have a direction
    np.testing.assert_allclose(q, [np.sqrt(0.5), 0, 0, np.sqrt(0.5)], rtol=1e-15)
    assert shortest_arc(np.float32([1, 0, 0]), np.float32([0, 1, 0])).dtype == np.float32
    assert shortest_arc(np.ones((4, 1, 3)), np.ones((5, 3))).shape == (4, 5, 4)


def test_attitude_error_never_unwinds(rng):
    q = random_quaternions(20_000, rng)
    q_ref = random_quaternions(20_000, rng)
    e = attitude_error(q, q_ref)
    assert (e[:, 0] >= 0).all()
    # the angle is the rotation angle between the attitudes (scipy), in [0, π]
    angle = (Rotation.from_quat(q_ref, scalar_first=True).inv() * Rotation.from_quat(q, scalar_first=True)).magnitude()
    rv = attitude_error(q, q_ref, rotvec=True)
    np.testing.assert_allclose(np.linalg.norm(rv, axis=-1), angle, atol=1e-12)
    assert np.linalg.norm(rv, axis=-1).max() <= np.pi
    # sign-invariant in both arguments
    for a, b in ((-q, q_ref), (q, -q_ref), (-q, -q_ref)):
        np.testing.assert_array_equal(attitude_error(a, b), e)
        np.testing.assert_array_equal(attitude_error(a, b, rotvec=True), rv)


def test_attitude_error_frames(rng):
    q = random_quaternions(1000, rng)
    q_ref = random_quaternions(1000, rng)
    body = attitude_error(q, q_ref)
    ref = attitude_error(q, q_ref, frame="reference")
    # q = q_ref ⊗ e_body = e_ref ⊗ q_ref, up to sign
    assert rotation_angle(hamilton(q_ref, body), q).max() <= 1e-15
    assert rotation_angle(hamilton(ref, q_ref), q).max() <= 1e-15
    # the same rotation, its axis seen in the two frames: axis_ref = R(q_ref) axis_body
    rv_body = attitude_error(q, q_ref, rotvec=True)
    rv_ref = attitude_error(q, q_ref, frame="reference", rotvec=True)
    np.testing.assert_allclose(apply(q_ref, rv_body), rv_ref, atol=1e-12)


def test_attitude_error_small_and_at_180():
    q_ref = np.array([1.0, 0, 0, 0])
    q = -np.array([np.cos(1e-9), np.sin(1e-9), 0, 0])  # 2e-9 rad about x, other hemisphere
    np.testing.assert_allclose(attitude_error(q, q_ref, rotvec=True), [2e-9, 0, 0], rtol=1e-12, atol=0)
    e = attitude_error([0.0, 0, -1, 0], q_ref)  # exactly 180°: the canonical rule picks +y
    np.testing.assert_array_equal(e, [0.0, 0, 1, 0])
    assert attitude_error(np.float32([1, 0, 0, 0]), np.float32([0, 1, 0, 0])).dtype == np.float32


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: swing_twist([1.0, 0, 0, 0], [0, 0, 0.0]), "axis is a zero vector"),
        (lambda: swing_twist([1.0, 0, 0, np.nan], [0, 0, 1.0]), r"q\[3\] is NaN"),
        (lambda: swing_twist([0.0, 0, 0, 0], [0, 0, 1.0]), "q is a zero quaternion"),
        (lambda: swing_twist([1.0, 0, 0, 0], [0, 1.0]), r"axis must have shape \(\.\.\., 3\)"),
        (lambda: swing_twist([1.0, 0, 0, 0], [0, 0, 1.0], frame="world"), "frame must be one of"),
        (lambda: swing_twist(np.ones((2, 4)), np.ones((3, 3))), "do not broadcast"),
        (lambda: shortest_arc([0.0, 0, 0], [1.0, 0, 0]), "u is a zero vector"),
        (lambda: shortest_arc([1.0, 0, 0], [[1.0, 0, 0], [0, 0, 0]]), r"v\[1\] is a zero vector"),
        (lambda: shortest_arc([1.0, np.inf, 0], [1.0, 0, 0]), r"u\[1\] is infinite"),
        (lambda: shortest_arc(np.ones((2, 3)), np.ones((3, 3))), "do not broadcast"),
        (lambda: attitude_error([1.0, 0, 0, 0], [0.0, 0, 0, 0]), "q_ref is a zero quaternion"),
        (lambda: attitude_error([np.nan, 0, 0, 0], [1.0, 0, 0, 0]), r"q\[0\] is NaN"),
        (lambda: attitude_error([1.0, 0, 0, 0], [1.0, 0, 0, 0], frame="inertial"), "frame must be one of"),
        (lambda: attitude_error(np.ones((2, 4)), np.ones((3, 4))), "do not broadcast"),
    ],
)
def test_invalid_input_raises_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()
