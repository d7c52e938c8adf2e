"""Gajda (1988), implemented literally from the printed formulas in his layout (p1, p2, p3, p4) = (x, y, z, w),
as an oracle for strapdown's general functions."""

import numpy as np
import pytest

from conftest import random_quaternions, wrapped
from strapdown import as_euler, as_matrix, from_euler, from_rotvec, multiply


def gajda_2_16(psi, theta, phi):
    """(2.16), in Gajda's component order t1..t4 = x, y, z, w; half angles."""
    cps, sps = np.cos(psi / 2), np.sin(psi / 2)
    cth, sth = np.cos(theta / 2), np.sin(theta / 2)
    cph, sph = np.cos(phi / 2), np.sin(phi / 2)
    t1 = cps * cth * sph - sps * sth * cph
    t2 = cps * sth * cph + sps * cth * sph
    t3 = sps * cth * cph - cps * sth * sph
    t4 = cps * cth * cph + sps * sth * sph
    return np.stack([t4, t1, t2, t3], axis=-1)  # reordered to [w, x, y, z]


def gajda_2_13(q):
    """(2.13): the matrix B (reference -> body) from a quaternion, with p1..p4 = x, y, z, w."""
    p4, p1, p2, p3 = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack(
        [
            np.stack([2 * (p1**2 + p4**2) - 1, 2 * (p1 * p2 + p3 * p4), 2 * (p1 * p3 - p2 * p4)], -1),
            np.stack([2 * (p1 * p2 - p3 * p4), 2 * (p2**2 + p4**2) - 1, 2 * (p2 * p3 + p1 * p4)], -1),
            np.stack([2 * (p1 * p3 + p2 * p4), 2 * (p2 * p3 - p1 * p4), 2 * (p3**2 + p4**2) - 1], -1),
        ],
        axis=-2,
    )


def gajda_2_10(psi, theta, phi):
    """(2.10): B from yaw Ψ, pitch Θ, roll Φ."""
    cps, sps, cth, sth, cph, sph = (
        np.cos(psi),
        np.sin(psi),
        np.cos(theta),
        np.sin(theta),
        np.cos(phi),
        np.sin(phi),
    )
    return np.stack(
        [
            np.stack([cps * cth, sps * cth, -sth], -1),
            np.stack([-sps * cph + cps * sth * sph, cps * cph + sps * sth * sph, cth * sph], -1),
            np.stack([sps * sph + cps * sth * cph, -cps * sph + sps * sth * cph, cth * cph], -1),
        ],
        axis=-2,
    )


def gajda_stage_4(b, literal=False):
    """Stage 4: angles from B.  `literal` uses the printed indices B(3,1), B(3,2), B(2,1); the corrected version
    reads B(1,3), B(2,3), B(1,2), the entries that (2.10) and (2.13) actually give (math.md §2.1)."""
    if literal:
        b13, b23, b12 = b[..., 2, 0], b[..., 2, 1], b[..., 1, 0]
    else:
        b13, b23, b12 = b[..., 0, 2], b[..., 1, 2], b[..., 0, 1]
    theta = np.arcsin(np.clip(-b13, -1, 1))
    ct = np.cos(theta)
    xm = ct + b[..., 2, 2]
    phi = np.where(xm == 0, np.pi, 2 * np.arctan(b23 / np.where(xm == 0, 1, xm)))
    xn = ct + b[..., 0, 0]
    psi_star = 2 * np.arctan(b12 / np.where(xn == 0, 1, xn))
    psi = np.where(xn == 0, np.pi, np.where(psi_star < 0, psi_star + 2 * np.pi, psi_star))
    return np.stack([psi, theta, phi], axis=-1)


@pytest.fixture
def attitudes(rng):
    n = 10_000
    return rng.uniform(0, 2 * np.pi, n), rng.uniform(-np.pi / 2, np.pi / 2, n), rng.uniform(-np.pi, np.pi, n)


def test_2_16_equals_from_euler_zyx(attitudes):
    psi, theta, phi = attitudes
    ours = from_euler(np.stack(attitudes, -1), "ZYX")
    np.testing.assert_allclose(ours, gajda_2_16(psi, theta, phi), rtol=0, atol=4.5e-16)


def test_2_13_and_2_10_agree_and_are_the_transpose_of_as_matrix(attitudes):
    psi, theta, phi = attitudes
    t = gajda_2_16(psi, theta, phi)
    b_quat = gajda_2_13(t)
    b_angles = gajda_2_10(psi, theta, phi)
    np.testing.assert_allclose(b_quat, b_angles, atol=2e-15)
    np.testing.assert_allclose(as_matrix(t).swapaxes(-1, -2), b_quat, atol=2e-15)


def test_stage_4_corrected_agrees_with_as_euler(rng):
    q = random_quaternions(10_000, rng)
    gajda = gajda_stage_4(gajda_2_13(q))
    ours = as_euler(q, "ZYX", yaw_range="positive")
    # Gajda's ranges: yaw [0, 2π), pitch [-π/2, π/2], roll (-π, π].  His formulas lose precision where our
    # atan2 form does not: asin near ±90° (1/cos Θ) and the half-angle arctan near 180° of yaw or roll, whose
    # denominator cos Θ (1 + cos Ψ) vanishes there.  The tolerance is that conditioning times a few ulp.
    c = np.cos(ours[:, 1])
    cond = 1 / c + 1 / (c * (1 + np.cos(ours[:, 0]))) + 1 / (c * (1 + np.cos(ours[:, 2])))
    err = np.abs(wrapped(gajda - ours))
    assert (err <= 1e-14 * cond[:, None]).all()
    assert np.median(err) <= 1e-15
    assert (ours[:, 0] >= 0).all() and (ours[:, 0] < 2 * np.pi).all()


def test_stage_4_as_printed_has_the_index_slip(rng):
    """The printed indices give the signs of roll and yaw wrong: errors of order π (math.md §2.1)."""
    q = random_quaternions(1000, rng)
    literal = gajda_stage_4(gajda_2_13(q), literal=True)
    ours = as_euler(q, "ZYX", yaw_range="positive")
    assert np.abs(wrapped(literal - ours)).max() > 3.0


def test_stage_2_is_from_rotvec_and_zero_rate_gives_identity(rng):
    omega = rng.standard_normal((100, 3))
    dt = 0.01
    rate = np.linalg.norm(omega, axis=-1)
    phi = rate * dt  # stage 2 b1
    q = np.column_stack([np.cos(phi / 2), omega / rate[:, None] * np.sin(phi / 2)[:, None]])
    np.testing.assert_allclose(from_rotvec(omega * dt), q, atol=1e-17)
    np.testing.assert_array_equal(from_rotvec([0.0, 0.0, 0.0]), [1.0, 0, 0, 0])  # stage 2 b2


def test_loop_constant_rate_matches_closed_form():
    """Stages 2, 3, 5 for 1000 steps at constant ω equal exp(ωT/2) (math.md §2.1: 2.4e-14)."""
    omega = np.array([0.3, -0.2, 0.5])
    dt = 0.01
    p = from_euler([0.4, 0.2, -0.1], "ZYX")
    start = p
    dq = from_rotvec(omega * dt)
    for _ in range(1000):
        p = multiply(p, dq)
    exact = multiply(start, from_rotvec(omega * 1000 * dt))
    assert np.abs(p - exact).max() < 1e-13


def test_vertical_flight_signs():
    """Gajda: B13 < 0 (B(3,1) as printed) means nose up, > 0 nose down; angles stay defined."""
    for pitch, nose_up in ((89.9, True), (-89.9, False), (90.0, True), (-90.0, False)):
        q = from_euler([123.0, pitch, 45.0], "ZYX", degrees=True)
        b13 = gajda_2_13(q)[0, 2]
        assert (b13 < 0) == nose_up
        a = as_euler(q, "ZYX", degrees=True, yaw_range="positive")
        assert np.isfinite(a).all()
        assert a[1] == pytest.approx(pitch, abs=1e-12)
