"""RotationSpline against scipy's RotationSpline, finite differences, and strapdown's own integrator."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.spatial.transform import RotationSpline as ScipySpline

from conftest import random_quaternions, random_walk_quaternions, rotation_angle
from strapdown import angle_between, integrate
from strapdown.propagate.interpolate import RotationSpline


@pytest.fixture
def converged_scipy(monkeypatch):
    """scipy's spline iterated to convergence (its default stops at a change of 1e-9, or after 10 steps)."""
    monkeypatch.setattr(ScipySpline, "TOL", 1e-15)
    monkeypatch.setattr(ScipySpline, "MAX_ITER", 5000)
    return ScipySpline


@pytest.mark.parametrize("step", [0.01, 0.3, None])  # None: independent uniformly random attitudes
def test_matches_scipy(step, rng, converged_scipy):
    n = 60
    t = np.cumsum(rng.uniform(0.05, 1.0, n))
    q = random_quaternions(n, rng) if step is None else random_walk_quaternions(n, step, rng)
    q *= rng.choice([-1.0, 1.0], (n, 1))  # signs must not matter
    ours = RotationSpline(t, q)
    theirs = converged_scipy(t, Rotation.from_quat(q, scalar_first=True))
    tn = np.concatenate([t, rng.uniform(t[0], t[-1], 5000)])
    assert rotation_angle(ours(tn), theirs(tn).as_quat(scalar_first=True)).max() < 1e-13
    rate, acc = theirs(tn, 1), theirs(tn, 2)
    # 1e-12 relative to the size of the signal (rates up to ~30 rad/s, accelerations ~1e3 for random data)
    np.testing.assert_allclose(ours(tn, 1), rate, rtol=0, atol=1e-12 * max(1, np.abs(rate).max()))
    np.testing.assert_allclose(ours(tn, 2), acc, rtol=0, atol=1e-12 * max(1, np.abs(acc).max()))


def test_passes_through_samples_with_c2_continuity(rng):
    n = 30
    t = np.cumsum(rng.uniform(0.1, 1.0, n))
    q = random_walk_quaternions(n, 0.4, rng)
    s = RotationSpline(t, q)
    assert rotation_angle(s(t), q).max() < 1e-14
    eps = 1e-9
    inner = t[1:-1]
    for order in (1, 2):  # rate and acceleration just before and just after every inner knot agree
        jump = np.abs(s(inner + eps, order) - s(inner - eps, order)).max()
        scale = np.abs(s(inner, order)).max()
        assert jump < 1e-6 * scale
    # the third derivative does jump: the spline is C², not C³ (so the test above can fail)
    d3 = (s(inner + 2 * eps, 2) - s(inner + eps, 2)) / eps - (s(inner - eps, 2) - s(inner - 2 * eps, 2)) / eps
    assert np.abs(d3).max() > 1e-3


def test_rates_are_the_derivative_of_the_attitude(rng):
    # body rate: q* dq/dt = (0, ω/2); reference rate: dq/dt q* = (0, ω_ref/2); by central differences
    t = np.arange(20.0)
    s = RotationSpline(t, random_walk_quaternions(20, 0.5, rng))
    tn = rng.uniform(1, 18, 200)
    h = 1e-6
    dq = (s(tn + h) - s(tn - h)) / (2 * h)
    q = s(tn)
    conj = q * [1, -1, -1, -1]
    np.testing.assert_allclose(s(tn, 1), 2 * _vec(_mul(conj, dq)), atol=1e-7)
    np.testing.assert_allclose(s(tn, 1, rate_frame="reference"), 2 * _vec(_mul(dq, conj)), atol=1e-7)
    dw = (s(tn + h, 1) - s(tn - h, 1)) / (2 * h)
    np.testing.assert_allclose(s(tn, 2), dw, atol=1e-6)
    dw_ref = (s(tn + h, 1, rate_frame="reference") - s(tn - h, 1, rate_frame="reference")) / (2 * h)
    np.testing.assert_allclose(s(tn, 2, rate_frame="reference"), dw_ref, atol=1e-6)


def _mul(p, q):
    """Hamilton product written out independently of strapdown (scalar first)."""
    pw, pv = p[..., 0], p[..., 1:]
    qw, qv = q[..., 0], q[..., 1:]
    w = pw * qw - np.sum(pv * qv, axis=-1)
    v = pw[..., None] * qv + qw[..., None] * pv + np.cross(pv, qv)
    return np.concatenate([w[..., None], v], axis=-1)


def _vec(q):
    return q[..., 1:]


def test_rates_integrate_back_to_the_knots():
    """10⁴ knots of smooth motion at 100 Hz: the spline's body rates, integrated by RK4, land on its attitudes."""
    from strapdown.simulate import RandomMotion

    n = 10_001
    t = np.arange(n) / 100.0
    q = RandomMotion(duration=t[-1] + 0.01, seed=1, rate_scale=2.0).attitude(t)
    s = RotationSpline(t, q)
    errors = []
    for sub in (4, 8):
        ts = np.linspace(t[0], t[-1], (n - 1) * sub + 1)
        q_int = integrate(s(ts[:-1], 1), t=ts, q0=s(t[0]), method="rk4", input="rate")
        errors.append(angle_between(q_int[::sub], q).max())
    assert errors[1] < 1e-10
    assert errors[0] / errors[1] > 8  # fourth order: the rates are the attitudes' derivative, not just close


def test_two_samples_is_slerp_at_constant_rate():
    q1 = [np.cos(0.5), 0, np.sin(0.5), 0]  # 1 rad about y
    s = RotationSpline([0.0, 2.0], [[1.0, 0, 0, 0], q1])
    np.testing.assert_allclose(s([0.0, 0.7, 2.0], 1), [[0, 0.5, 0]] * 3, atol=1e-15)
    np.testing.assert_allclose(s([0.3, 1.9], 2), 0, atol=1e-15)
    np.testing.assert_allclose(s(1.0), [np.cos(0.25), 0, np.sin(0.25), 0], atol=1e-15)


def test_extrapolation_refused_or_as_scipy(rng, converged_scipy):
    t = np.arange(6.0)
    q = random_walk_quaternions(6, 0.3, rng)
    with pytest.raises(ValueError, match=r"t\[1\] = 5.5 is outside the knots.*extrapolate=True"):
        RotationSpline(t, q)([1.0, 5.5])
    s = RotationSpline(t, q, extrapolate=True)
    theirs = converged_scipy(t, Rotation.from_quat(q, scalar_first=True))
    tn = np.array([-0.3, 5.2])
    assert rotation_angle(s(tn), theirs(tn).as_quat(scalar_first=True)).max() < 1e-13
    np.testing.assert_allclose(s(tn, 1), theirs(tn, 1), atol=1e-12)


def test_several_series_at_once_are_the_single_splines(rng):
    t = np.cumsum(rng.uniform(0.1, 1.0, 12))
    q = np.stack([random_walk_quaternions(12, 0.4, rng) for _ in range(6)], axis=1).reshape(12, 2, 3, 4)
    batch = RotationSpline(t, q)
    tn = rng.uniform(t[0], t[-1], (7, 5))
    for order, size in ((0, 4), (1, 3), (2, 3)):
        got = batch(tn, order, rate_frame="reference")
        assert got.shape == (7, 5, 2, 3, size)
        for i in range(2):
            for j in range(3):
                one = RotationSpline(t, q[:, i, j])(tn, order, rate_frame="reference")
                np.testing.assert_allclose(got[..., i, j, :], one, rtol=0, atol=1e-15 * max(1, np.abs(one).max()))
    assert batch.rates.shape == (12, 2, 3, 3)


def test_unsettled_knot_rates_are_reported(rng):
    t = np.cumsum(rng.uniform(0.05, 1.0, 60))
    q = random_quaternions(60, rng)  # increments of up to π: the iteration needs tens of steps
    with pytest.warns(RuntimeWarning, match="did not settle"):
        s = RotationSpline(t, q, max_iter=3)
    assert s.iterations == 3
    assert RotationSpline(t, q).iterations > 3


def test_float32_shapes_and_errors(rng):
    t = np.arange(5.0)
    q = random_walk_quaternions(5, 0.3, rng).astype(np.float32)
    s = RotationSpline(t, q)
    assert s(np.array([[0.5, 1.5], [2.5, 3.5]])).shape == (2, 2, 4)
    assert s(1.5, 1).shape == (3,) and s(1.5, 2).dtype == np.float32
    with pytest.raises(ValueError, match="order must be 0"):
        s(1.0, 3)
    with pytest.raises(ValueError, match="rate_frame"):
        s(1.0, 1, rate_frame="NED")
    with pytest.raises(ValueError, match="strictly increasing"):
        RotationSpline([0.0, 1.0, 1.0], q[:3])
    with pytest.raises(ValueError, match=r"shape \(n, \.\.\., 4\) with n = len\(t\) = 5"):
        RotationSpline(t, q[None])
    with pytest.raises(ValueError, match="n ≥ 2"):
        RotationSpline([0.0], q[:1])


def test_invariance_under_constant_rotations(rng):
    """Physics the construction must respect (independent of scipy): a fixed change of reference frame does not
    change the body rates, and a fixed change of body axes rotates them (the spline is equivariant)."""
    from strapdown.rotations.quaternion import multiply, rotate

    t = np.cumsum(rng.uniform(0.1, 1.0, 15))
    q = random_walk_quaternions(15, 0.5, rng)
    p, c = random_quaternions(2, rng)
    tn = rng.uniform(t[0], t[-1], 300)
    base = RotationSpline(t, q)
    left = RotationSpline(t, multiply(p, q))  # the same motion seen from a turned reference frame
    right = RotationSpline(t, multiply(q, c))  # the same motion of body axes turned by c
    c_inv = c * [1, -1, -1, -1]
    assert rotation_angle(left(tn), multiply(p, base(tn))).max() < 1e-13
    assert rotation_angle(right(tn), multiply(base(tn), c)).max() < 1e-13
    for order in (1, 2):
        np.testing.assert_allclose(left(tn, order), base(tn, order), atol=1e-12)
        np.testing.assert_allclose(right(tn, order), rotate(c_inv, base(tn, order)), atol=1e-12)
        np.testing.assert_allclose(
            left(tn, order, rate_frame="reference"), rotate(p, base(tn, order, rate_frame="reference")), atol=1e-12
        )


def test_time_reversal_is_third_order(rng):
    # Each cubic is anchored at its segment's first sample, so the spline played backwards is not exactly the same
    # curve (as scipy's): the two agree at the samples and differ by a third-order term in the step size
    differences = []
    t = np.cumsum(rng.uniform(0.5, 1.0, 30))
    for step in (0.1, 0.05):
        q = random_walk_quaternions(30, step, np.random.default_rng(5))  # the same path, half the angles
        fwd = RotationSpline(t, q)
        back = RotationSpline(-t[::-1], q[::-1])
        assert rotation_angle(back(-t), q).max() < 1e-14
        tn = np.linspace(t[3], t[-4], 3000)
        differences.append(rotation_angle(back(-tn), fwd(tn)).max())
        np.testing.assert_allclose(back(-tn, 1), -fwd(tn, 1), atol=10 * differences[-1])
    assert 7 < differences[0] / differences[1] < 9  # (0.1 / 0.05)³ = 8
