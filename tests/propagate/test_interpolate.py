"""Attitude interpolation against scipy's Slerp, an independent squad, and finite-difference rates."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from conftest import random_quaternions, rotation_angle
from strapdown.propagate.interpolate import resample, slerp_series, squad_series


def rot(q):
    return Rotation.from_quat(q, scalar_first=True)


def random_walk(n, step, rng):
    """n attitudes, each a random rotation of about `step` rad from the previous one; signs scrambled."""
    steps = Rotation.from_rotvec(step * rng.standard_normal((n - 1, 3)))
    r = [rot(random_quaternions(1, rng)[0])]
    for s in steps:
        r.append(r[-1] * s)
    q = Rotation.concatenate(r).as_quat(scalar_first=True)
    return q * rng.choice([-1.0, 1.0], (n, 1))


def irregular_times(n, rng):
    return np.cumsum(rng.uniform(0.2, 2.0, n)) - 1.0


def body_rate(q0, q1, dt):
    """Mean body rate from q0 to q1 over dt (scipy): rotvec(R0ᵀ R1) / dt."""
    return (rot(q0).inv() * rot(q1)).as_rotvec() / dt


def test_slerp_matches_scipy(rng):
    for step in (0.05, 0.5, 1.5):
        n = 60
        t = irregular_times(n, rng)
        q = random_walk(n, step, rng)
        t_new = rng.uniform(t[0], t[-1], 10_000)
        ours = slerp_series(t, q, t_new)
        expected = Slerp(t, rot(q))(t_new).as_quat(scalar_first=True)
        assert rotation_angle(ours, expected).max() <= 1e-12
        assert np.abs(np.linalg.norm(ours, axis=-1) - 1).max() <= 1e-15


@pytest.mark.parametrize("interp", [slerp_series, squad_series])
def test_interpolation_passes_through_the_samples(interp, rng):
    t = irregular_times(40, rng)
    q = random_walk(40, 0.4, rng)
    at_knots = interp(t, q, t)
    assert rotation_angle(at_knots, q).max() <= 1e-15
    # the ends exactly, up to the sign of the aligned series
    np.testing.assert_array_equal(
        np.abs(at_knots[[0, -1]]), np.abs(q[[0, -1]] / np.linalg.norm(q[[0, -1]], axis=-1)[:, None])
    )


@pytest.mark.parametrize("interp", [slerp_series, squad_series])
def test_output_is_continuous_in_sign(interp, rng):
    t = irregular_times(30, rng)
    q = random_walk(30, 0.3, rng)
    dense = interp(t, q, np.linspace(t[0], t[-1], 20_000))
    assert (np.einsum("ni,ni->n", dense[1:], dense[:-1]) > 0.99).all()


def shoemake(t, q, t_new):
    """Shoemake's squad for uniform times, written with scipy rotations (log = rotvec / 2), no strapdown code."""
    r = rot(q)
    n = len(q)
    a = []
    for i in range(n):
        if i in (0, n - 1):
            a.append(r[i])
            continue
        d = ((r[i].inv() * r[i + 1]).as_rotvec() + (r[i].inv() * r[i - 1]).as_rotvec()) / 2  # logs
        a.append(r[i] * Rotation.from_rotvec(-2 * d / 4))
    a = Rotation.concatenate(a)

    def slerp(p, q_, s):
        return p * Rotation.from_rotvec(s * (p.inv() * q_).as_rotvec())

    out = []
    for tn in t_new:
        i = min(int(np.searchsorted(t, tn, side="right")) - 1, n - 2)
        s = (tn - t[i]) / (t[i + 1] - t[i])
        out.append(slerp(slerp(r[i], r[i + 1], s), slerp(a[i], a[i + 1], s), 2 * s * (1 - s)))
    return Rotation.concatenate(out).as_quat(scalar_first=True)


def test_squad_with_uniform_times_is_shoemakes(rng):
    t = 0.25 * np.arange(25)
    q = random_walk(25, 0.4, rng)
    t_new = rng.uniform(t[0], t[-1], 2000)
    assert rotation_angle(squad_series(t, q, t_new), shoemake(t, q, t_new)).max() <= 1e-12


def test_squad_is_c1_at_the_knots(rng):
    """Finite-difference body rates just before and just after every knot agree; slerp's jump."""
    n = 25
    t = irregular_times(n, rng)
    q = random_walk(n, 0.4, rng)
    h = 1e-6
    knots = t[1:-1]
    for interp, continuous in ((squad_series, True), (slerp_series, False)):
        before = interp(t, q, knots - h)
        at = interp(t, q, knots)
        after = interp(t, q, knots + h)
        left = body_rate(before, at, h)
        right = body_rate(at, after, h)
        jump = np.linalg.norm(left - right, axis=-1) / np.linalg.norm(left, axis=-1)
        if continuous:
            assert jump.max() <= 1e-4
            # and the rate at a knot is the central difference of the samples: (θ_{i-1} + θ_i)/(h_{i-1} + h_i)
            theta = (rot(q[:-1]).inv() * rot(q[1:])).as_rotvec()
            expected = (theta[:-1] + theta[1:]) / (t[2:] - t[:-2])[:, None]
            np.testing.assert_allclose(right, expected, rtol=0, atol=1e-4 * np.abs(expected).max())
        else:
            assert np.median(jump) >= 0.05


def test_constant_rate_is_reproduced_with_irregular_times(rng):
    """A steady rotation about a fixed axis: both methods are exact at any time, whatever the spacing."""
    t = irregular_times(20, rng)
    omega = np.array([0.3, -0.2, 0.5])
    q0 = random_quaternions(1, rng)[0]
    truth = lambda tt: (rot(q0) * Rotation.from_rotvec(np.outer(tt, omega))).as_quat(scalar_first=True)  # noqa: E731
    t_new = rng.uniform(t[0], t[-1], 1000)
    for method in ("slerp", "squad"):
        assert rotation_angle(resample(t, truth(t), t_new, method=method), truth(t_new)).max() <= 1e-12


def test_shapes_broadcasting_and_dtypes(rng):
    t = np.linspace(0, 1, 10)
    q = random_walk(30, 0.2, rng).reshape(10, 3, 4)
    t_new = rng.uniform(0, 1, (2, 5))
    for method in ("slerp", "squad"):
        out = resample(t, q, t_new, method=method)
        assert out.shape == (2, 5, 3, 4)
        for j in range(3):
            np.testing.assert_allclose(out[..., j, :], resample(t, q[:, j], t_new, method=method), atol=1e-15)
        assert resample(t, q.astype(np.float32), t_new, method=method).dtype == np.float32
        assert resample(t, q, 0.5, method=method).shape == (3, 4)
    # two samples: squad is slerp
    q2 = random_quaternions(2, rng)
    np.testing.assert_allclose(squad_series([0, 1], q2, t_new), slerp_series([0, 1], q2, t_new), atol=1e-15)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: slerp_series([0.0, 1.0, 1.0], np.ones((3, 4)), [0.5]), r"t\[2\] = 1.0 is not after t\[1\] = 1.0"),
        (lambda: squad_series([0.0, 2.0, 1.0], np.ones((3, 4)), [0.5]), r"t\[2\] = 1.0 is not after t\[1\]"),
        (lambda: slerp_series([0.0, np.nan], np.ones((2, 4)), [0.5]), r"t\[1\] is NaN"),
        (lambda: slerp_series([0.0], np.ones((1, 4)), [0.0]), r"t must have shape \(n,\) with n ≥ 2"),
        (lambda: slerp_series([[0.0, 1.0]], np.ones((2, 4)), [0.5]), r"t must have shape \(n,\)"),
        (lambda: slerp_series([0.0, 1.0], np.ones((3, 4)), [0.5]), r"q must have shape \(n, \.\.\., 4\) with n = len"),
        (lambda: slerp_series([0.0, 1.0], np.ones(4), [0.5]), r"q must have shape \(n, \.\.\., 4\)"),
        (lambda: slerp_series([0.0, 1.0], np.ones((2, 3)), [0.5]), r"q must have shape \(\.\.\., 4\)"),
        (lambda: squad_series([0.0, 1.0], [[1.0, 0, 0, 0], [0, 0, 0, 0]], [0.5]), r"q\[1\] is a zero quaternion"),
        (lambda: slerp_series([0.0, 1.0], np.ones((2, 4)), [0.5, 1.5]), r"t_new\[1\] = 1.5 is outside"),
        (lambda: squad_series([0.0, 1.0], np.ones((2, 4)), -0.1), r"t_new = -0.1 is outside"),
        (lambda: slerp_series([0.0, 1.0], np.ones((2, 4)), [np.nan]), r"t_new\[0\] is NaN"),
        (lambda: resample([0.0, 1.0], np.ones((2, 4)), [0.5], method="linear"), "method must be one of"),
    ],
)
def test_invalid_input_raises_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()
