"""Attitude propagation: closed forms, nabbla's worked example, coning constants, convergence orders, streaming."""

import math
import warnings

import numpy as np
import pytest

import strapdown as sd
from conftest import rotation_angle
from motion import coning_increments, coning_q, coning_rate, generic_increments, generic_q, generic_rate
from strapdown import METHODS, AttitudeIntegrator, SingularityError, integrate
from strapdown import quaternion as quat

QUATERNION_METHODS = [m for m in METHODS if m not in ("euler-angles", "dcm", "euler-parameters", "rotation-vector")]
BASELINES = ["euler-angles", "dcm", "euler-parameters", "rotation-vector"]


def closed_form_constant(q0, omega, t):
    """q0 ⊗ exp(ω t / 2) with libm's sin and cos (accurate range reduction for large angles)."""
    out = []
    for tk in t:
        v = [c * tk / 2 for c in omega]
        a = math.sqrt(sum(c * c for c in v))
        s = math.sin(a) / a if a else 1.0
        out.append([math.cos(a), v[0] * s, v[1] * s, v[2] * s])
    return quat.multiply(q0, np.array(out))


# ---------------------------------------------------------------------------------------------------------------
# exactness
@pytest.mark.parametrize("parallel", [False, True])
@pytest.mark.parametrize("omega", [[1.0, 0, 0], [0, -0.5, 0], [0.375, -0.625, 0.25], [1.5, 1.25, -0.875]])
def test_exact_constant_rate_million_steps(omega, parallel):
    """Issue 3: constant rate about any axis, 10^6 steps: within 1e-12 rad of the closed form, |q| - 1 <= 1e-14.

    dt = 2^-10 s and rates with few binary digits make ω t exact, so the closed form is exact to rounding.
    """
    n = 1_000_000
    dt = 2.0**-10
    q0 = sd.from_euler([0.3, -0.2, 0.1], "ZYX")
    q = integrate(np.tile(omega, (n, 1)), dt, q0=q0, method="exact", parallel=parallel)
    idx = np.linspace(0, n, 41).astype(int)
    truth = closed_form_constant(q0, omega, idx * dt)
    assert rotation_angle(q[idx], truth).max() <= 1e-12
    assert np.abs(np.linalg.norm(q, axis=-1) - 1).max() <= 1e-14


def test_exact_is_exact_for_piecewise_constant_rates(rng):
    g = rng.standard_normal((50, 3))
    dt = rng.uniform(0.001, 0.05, 50)
    q = integrate(g, dt)
    ref = np.array([1.0, 0, 0, 0])
    for k in range(50):
        ref = quat.multiply(ref, sd.from_rotvec(g[k] * dt[k]))
        assert rotation_angle(q[k + 1], ref) <= 1e-15


def test_zero_rate_is_identity_without_division():
    q = integrate(np.zeros((10, 3)), 0.01, q0=[0.5, 0.5, 0.5, 0.5])
    np.testing.assert_array_equal(q, np.tile([0.5, 0.5, 0.5, 0.5], (11, 1)))


def test_taylor_branch_and_trig_branch_agree():
    """The step quaternion switches from the series to sin/cos at |φ|/2 = 0.25: both sides are exact."""
    for half in (0.2499999, 0.25, 0.2500001, 1.0, 3.0):
        axis = np.array([0.48, -0.6, 0.64])
        q = integrate([2 * half * axis], 1.0)[1]
        np.testing.assert_allclose(q, [np.cos(half), *(np.sin(half) * axis)], atol=2e-16)


# ---------------------------------------------------------------------------------------------------------------
# nabbla part 9
def _nabbla(**options):
    return integrate(np.tile([0, 0, 5.0], (72, 1)), input="increment", degrees=True, method="first-order", **options)


def test_nabbla_unnormalised():
    lam = _nabbla(normalize="none")[-1]
    assert lam[0] == pytest.approx(-1.0709, abs=5e-5)  # printed: -1.0709 + 0.00213k
    assert lam[3] == pytest.approx(0.00213, abs=5e-6)
    np.testing.assert_array_equal(lam[1:3], 0)


def test_nabbla_normalised():
    lam = _nabbla(normalize="exact")[-1]
    assert lam[0] == pytest.approx(-0.999998, abs=5e-7)  # printed: -0.999998 + 0.001991k
    assert lam[3] == pytest.approx(0.001991, abs=5e-7)
    # after 360° the truth is -1 (the identity): the angle error is 0.228°
    assert np.degrees(quat.angle_between(lam, [1.0, 0, 0, 0])) == pytest.approx(0.228, abs=5e-4)


def test_nabbla_series_normalisation():
    once = _nabbla(normalize="series", normalize_every=72)[-1]
    assert np.linalg.norm(once) == pytest.approx(0.9923, abs=5e-5)
    twice = _nabbla(normalize="series", normalize_every=36)[-1]
    assert np.linalg.norm(twice) == pytest.approx(0.9984, abs=5e-5)  # the article prints 0.9983 (rounding)


def test_nabbla_first_order_dcm():
    """The first-order DCM update C (I + [φ×]): x and y columns grow to 1.314 and the angle is off by 0.91°."""
    integ = AttitudeIntegrator("dcm", input="increment", degrees=True, scheme="euler")
    q = integ.update(np.tile([0, 0, 5.0], (72, 1)))
    c = integ.state.extra["base"][0].reshape(3, 3)
    np.testing.assert_allclose(np.linalg.norm(c, axis=0), [1.314, 1.314, 1.0], atol=5e-4)
    assert np.degrees(quat.angle_between(q[-1], [1.0, 0, 0, 0])) == pytest.approx(0.91, abs=5e-3)


# ---------------------------------------------------------------------------------------------------------------
# coning (math.md §6)
ALPHA = np.radians(1.0)
OMEGA = 2 * np.pi * 10.0


def _coning_drift(method, data, h, duration=20.0, alpha=ALPHA):
    n = round(duration / h)
    n -= n % 12
    t = np.arange(n + 1) * h
    q0 = coning_q(t[:1], alpha, OMEGA)[0]
    if data == "increment":
        q = integrate(coning_increments(t, alpha, OMEGA), q0=q0, method=method, input="increment")
    else:  # rate samples at the start ("start") or the middle ("mid") of each step
        shift = h / 2 if data == "mid" else 0.0
        q = integrate(coning_rate(t[:-1] + shift, alpha, OMEGA), h, q0=q0, method=method)
    e = sd.as_rotvec(quat.multiply(q, quat.conjugate(coning_q(t, alpha, OMEGA))))
    # pure coning is time-shift invariant up to a rotation about x: e_x grows linearly, fit its slope
    return np.polyfit(t[n // 2 :], e[n // 2 :, 0], 1)[0]


@pytest.mark.parametrize(
    ("method", "data", "update_samples", "constant", "power"),
    [
        ("exact", "increment", 1, -1 / 12, 2),  # one-sample exp(Δθ): math.md §6.3
        ("first-order", "increment", 1, -1 / 12, 2),
        ("coning1-prev", "increment", 1, -1 / 60, 4),
        ("coning2", "increment", 2, -1 / 960, 4),
        ("coning3-poly", "increment", 1, 1 / 80, 4),
        ("exact", "mid", 1, -1 / 24, 2),  # rate-sampled exp(ω_mid h)
        ("first-order", "mid", 1, -1 / 24, 2),
        ("exact", "start", 1, -1 / 24, 2),  # the long-run figure for start-of-step samples (math.md §7 note)
        ("rk4", "start", 2, 1 / 960, 4),  # stages on samples t, t + h/2, t + h
        # [derived] rate samples -> increments by the cubic: the quadrature's in-phase error (11/720)(Ωh)⁴ on the
        # y, z increments adds to the two-sample 1/60 (per sample): -(1/60 + 11/720) = -23/720
        ("coning2", "start", 1, -23 / 720, 4),
    ],
)
def test_coning_drift_constants(method, data, update_samples, constant, power):
    """Measured drift within 5 % of ρ α² Ω (ΩT)^p, T the update interval (math.md §6.3), at Ωh = 0.157."""
    h = 0.0025
    measured = _coning_drift(method, data, h)
    predicted = constant * ALPHA**2 * OMEGA * (OMEGA * update_samples * h) ** power
    assert measured / predicted == pytest.approx(1.0, abs=0.05)


def _per_update_ratio(method, size, rho, alpha_deg, omega_t=0.8, phases=400):
    """Secular x error of single updates started from the truth, averaged over the cone phase, over ρ α²Ω(ΩT)^2N."""
    alpha = np.radians(alpha_deg)
    big_t = omega_t / OMEGA
    h = big_t / size
    ex = []
    for t0 in np.linspace(0, 2 * np.pi / OMEGA, phases, endpoint=False):
        t = t0 + np.arange(size + 1) * h
        q0 = coning_q(t[:1], alpha, OMEGA)[0]
        q = integrate(coning_increments(t, alpha, OMEGA), q0=q0, method=method, input="increment")[-1]
        ex.append(sd.as_rotvec(quat.multiply(q, quat.conjugate(coning_q(t[-1:], alpha, OMEGA)[0])))[0])
    return np.mean(ex) / big_t / (-rho * alpha**2 * OMEGA * omega_t ** (2 * size))


@pytest.mark.parametrize(("method", "size", "rho"), [("coning3", 3, 1 / 204120), ("coning4", 4, 1 / 82575360)])
def test_coning_optimised_per_update_constants(method, size, rho):
    """The higher-order sets drift too little to measure on long runs; measure single updates from the truth
    (math.md §6.3: α = 0.1°, ΩT = 0.8).  ρ_N is the α² coefficient; coning4 also has an α⁴ term of relative
    size ∝ α² (+19 % at 0.1°), removed by Richardson extrapolation from α = 0.1° and 0.2°."""
    r1 = _per_update_ratio(method, size, rho, 0.1)
    r2 = _per_update_ratio(method, size, rho, 0.2)
    assert (4 * r1 - r2) / 3 == pytest.approx(1.0, abs=0.05)


def test_coning_term_is_nonzero_and_cuts_the_drift():
    """The classic bug: a coning correction that is always zero.  Two orthogonal increments must give
    exp((a1 + a2 + ⅔ a1×a2)/2), and under coning the two-sample drift must be far below the one-sample one."""
    a1 = np.array([0.01, 0.0, 0.0])
    a2 = np.array([0.0, 0.02, 0.0])
    q = integrate([a1, a2], method="coning2", input="increment")[-1]
    expected = sd.from_rotvec(a1 + a2 + 2 / 3 * np.cross(a1, a2))
    assert rotation_angle(q, expected) < 1e-16
    assert rotation_angle(q, sd.from_rotvec(a1 + a2)) > 1e-4 / 3
    one = _coning_drift("exact", "increment", 0.0025)
    two = _coning_drift("coning2", "increment", 0.0025)
    assert abs(two) < abs(one) / 100


# ---------------------------------------------------------------------------------------------------------------
# convergence orders on a generic smooth motion (final error at T = 2 s)
def _run_error(method, data, h):
    """Largest attitude error over a 2 s generic motion, past the first four samples.

    The first samples are skipped because the one-sample start of the Savage recursion (no previous increment)
    gives the in-group output at sample 1 a bounded O(h³) error that is never fed back."""
    n = round(2.0 / h)
    t = np.arange(n + 1) * h
    q0 = generic_q(t[:1])[0]
    if data == "increment":
        q = integrate(generic_increments(t), q0=q0, method=method, input="increment")
    elif data == "average":
        q = integrate(generic_increments(t) / h, h, q0=q0, method=method, input="average")
    else:
        shift = h / 2 if data == "mid" else 0.0
        q = integrate(generic_rate(t[:-1] + shift), h, q0=q0, method=method)
    return rotation_angle(q[4:], generic_q(t[4:])).max()


@pytest.mark.parametrize(
    ("method", "data", "order"),
    [
        ("exact", "start", 1),
        ("first-order", "start", 1),
        ("second-order", "start", 1),
        ("cayley", "start", 1),
        ("exact", "mid", 2),
        ("first-order", "mid", 2),
        ("exact", "average", 2),
        ("exact", "increment", 2),
        ("cayley", "increment", 2),
        ("rk4", "start", 4),
        ("coning2", "increment", 4),
        ("coning2", "start", 4),
        ("coning4-poly", "increment", 4),
        ("euler-angles", "start", 4),
        ("dcm", "start", 4),
        ("euler-parameters", "start", 4),
        ("rotation-vector", "start", 4),
    ],
)
def test_convergence_order(method, data, order):
    errors = [_run_error(method, data, h) for h in (0.02, 0.01, 0.005)]
    slopes = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    np.testing.assert_allclose(slopes, order, atol=0.15)


# ---------------------------------------------------------------------------------------------------------------
# sampling convention: which sample covers which interval
def test_sample_k_covers_step_k():
    g = np.array([[0.3, 0.0, 0.0], [0.0, 0.7, 0.0]])
    q = integrate(g, 0.1)
    np.testing.assert_allclose(q[1], sd.from_rotvec(g[0] * 0.1), atol=1e-17)
    np.testing.assert_allclose(q[2], quat.multiply(q[1], sd.from_rotvec(g[1] * 0.1)), atol=1e-16)


def test_rate_samples_are_start_of_step_instants_for_rk4():
    """About a fixed axis with ω(t) = a + b t the angle is a t + b t²/2.  rk4 reads sample k as ω(t_k): exact.
    Read as an interval average the same numbers would be off by b h / 2 per step."""
    a, b, h, n = 0.4, 0.9, 0.005, 400
    t = np.arange(n + 1) * h
    axis = np.array([0.6, 0.0, 0.8])
    q = integrate(np.outer(a + b * t[:-1], axis), h, method="rk4")
    truth = sd.from_rotvec(np.outer(a * t + b * t**2 / 2, axis))
    assert rotation_angle(q, truth).max() < 1e-9  # RK4's own truncation of exp, O(φ⁵) per step
    # the same numbers read as interval averages describe another motion, b h / 2 slower in every step
    assert rotation_angle(integrate(np.outer(a + b * t[:-1], axis), h, input="average"), truth).max() > 1e-3


def test_average_samples_are_interval_means():
    a, b, h, n = 0.4, 0.9, 0.05, 40
    t = np.arange(n + 1) * h
    axis = np.array([0.0, 1.0, 0.0])
    means = a + b * (t[:-1] + h / 2)
    for method in ("exact", "coning2", "coning3-poly"):  # the exponential-based ones (rk4 truncates exp: O(φ⁵))
        q = integrate(np.outer(means, axis), h, method=method, input="average")
        np.testing.assert_allclose(q, sd.from_rotvec(np.outer(a * t + b * t**2 / 2, axis)), atol=1e-14)


# ---------------------------------------------------------------------------------------------------------------
# vertical flight
def _climb(method, **options):
    """A loop's vertical climb: 90°/s about the body y axis from level flight heading 30°, 3 s."""
    h = 0.01
    q0 = sd.from_euler([30.0, 0.0, 0.0], "ZYX", degrees=True)
    q = integrate(np.tile([0.0, np.pi / 2, 0.0], (300, 1)), h, q0=q0, method=method, **options)
    truth = closed_form_constant(q0, [0.0, np.pi / 2, 0.0], np.arange(301) * h)
    return q, truth


PER_STEP_ERROR = {"first-order": 1 / 12, "second-order": 1 / 24, "cayley": 1 / 48}  # × (|φ|)³, math.md §7


def rk4_constant_rate_angle(phi):
    """Angle turned by one RK4 step at constant rate: R(z) = 1 + z + z²/2 + z³/6 + z⁴/24 with z = i φ/2."""
    return 2 * np.arctan2(phi / 2 - phi**3 / 48, 1 - phi**2 / 8 + phi**4 / 384)


@pytest.mark.parametrize("method", QUATERNION_METHODS)
def test_vertical_climb_quaternion_methods_stay_exact(method):
    """Through pitch 90°: no singularity, and the error does not depend on the attitude (Gajda 3a, 3b).

    Body-rate updates compose on the right, so q0 only rotates the whole trajectory: the error of the climb
    must equal, to rounding, the error of the same rates integrated from the identity, which never goes
    vertical.  The value itself is the method's closed-form per-step error, or ~0 for the exact ones."""
    q, truth = _climb(method)
    assert np.isfinite(q).all()
    err = rotation_angle(q, truth)
    level = integrate(np.tile([0.0, np.pi / 2, 0.0], (300, 1)), 0.01, method=method)
    level_truth = closed_form_constant([1.0, 0, 0, 0], [0.0, np.pi / 2, 0.0], np.arange(301) * 0.01)
    np.testing.assert_allclose(err, rotation_angle(level, level_truth), atol=1e-13)
    phi = np.pi / 2 * 0.01
    if method in PER_STEP_ERROR:
        np.testing.assert_allclose(err[-1], 300 * PER_STEP_ERROR[method] * phi**3, rtol=1e-3)
    elif method == "rk4":  # double steps whose stages fall on samples
        np.testing.assert_allclose(err[-1], 150 * abs(rk4_constant_rate_angle(2 * phi) - 2 * phi), rtol=1e-3)
    else:
        assert err.max() < 1e-13


def test_vertical_climb_euler_angles_report_the_singularity():
    with pytest.raises(SingularityError, match=r"euler-angles: step 9\d .*pitch ±90°"):
        _climb("euler-angles")
    q, truth = _climb("euler-angles", on_singular="nan")
    first_nan = np.flatnonzero(np.isnan(q).any(axis=-1))[0]
    assert 90 <= first_nan <= 101  # pitch reaches 90° at t = 1 s, sample 100
    assert rotation_angle(q[:first_nan], truth[:first_nan]).max() < 1e-3
    with pytest.warns(RuntimeWarning, match="euler-angles"):
        _climb("euler-angles", on_singular="warn")
    integ = AttitudeIntegrator("euler-angles", on_singular="nan")
    integ.update(np.tile([0.0, np.pi / 2, 0.0], (300, 1)), 0.01)
    assert integ.singular_steps and all(b == 0 for b, _ in integ.singular_steps)


def test_euler_parameters_are_singular_at_the_identity():
    with pytest.raises(SingularityError, match="euler-parameters: step 0"):
        integrate(np.ones((5, 3)), 0.01, method="euler-parameters")
    q = integrate(np.ones((5, 3)), 0.01, method="euler-parameters", q0=sd.from_euler([0.5, 0.2, 0.1], "ZYX"))
    assert np.isfinite(q).all()


def test_rotation_vector_is_singular_at_180_degrees():
    with pytest.raises(SingularityError, match="rotation-vector"):
        integrate(np.tile([0.0, 0.0, np.pi], (200, 1)), 0.01, method="rotation-vector")


# ---------------------------------------------------------------------------------------------------------------
# streaming, variable steps, many bodies
def _random_chunks(n, rng):
    cuts = np.sort(rng.choice(np.arange(1, n), size=6, replace=False))
    return np.split(np.arange(n), cuts)


def _stream(method, g, dt, chunks, **options):
    integ = AttitudeIntegrator(method, q0=[0.9, 0.1, -0.3, 0.2], **options)
    parts = [integ.update(g[c], dt) for c in chunks]
    parts.append(integ.finish())
    return np.concatenate(parts)


@pytest.mark.parametrize("method", METHODS)
def test_chunked_equals_whole_bit_for_bit(method, rng):
    n = 500
    g = 0.3 * generic_rate(np.arange(n) * 0.01) + 0.05 * rng.standard_normal((n, 3))
    whole = integrate(g, 0.01, q0=[0.9, 0.1, -0.3, 0.2], method=method, parallel=False)
    for _ in range(3):
        chunked = _stream(method, g, 0.01, _random_chunks(n, rng), parallel=False)
        assert np.concatenate([whole[:1], chunked]).tobytes() == whole.tobytes()


@pytest.mark.parametrize("method", ["exact", "first-order", "cayley"])
def test_parallel_scan_matches_sequential(method, rng):
    n = 200_000
    g = rng.standard_normal((n, 3))
    seq = integrate(g, 0.005, method=method, parallel=False)
    par = integrate(g, 0.005, method=method, parallel=True)
    assert rotation_angle(par, seq).max() <= 1e-12
    chunked = _stream(method, g, 0.005, _random_chunks(n, rng), parallel=True)
    seq_q0 = integrate(g, 0.005, method=method, parallel=False, q0=[0.9, 0.1, -0.3, 0.2])
    assert rotation_angle(chunked, seq_q0[1:]).max() <= 1e-12


@pytest.mark.parametrize("method", METHODS)
def test_uniform_timestamps_equal_scalar_dt(method):
    n = 300
    h = 2.0**-7  # exactly representable: t[k+1] - t[k] == h exactly
    g = generic_rate(np.arange(n) * h)
    by_dt = integrate(g, h, method=method, q0=generic_q([0.0])[0], on_singular="warn")
    by_t = integrate(g, t=5.0 + np.arange(n + 1) * h, method=method, q0=generic_q([0.0])[0], on_singular="warn")
    assert by_t.tobytes() == by_dt.tobytes()
    by_array = integrate(g, np.full(n, h), method=method, q0=generic_q([0.0])[0], on_singular="warn")
    assert by_array.tobytes() == by_dt.tobytes()


def test_large_absolute_timestamps_lose_nothing():
    """Times are used relative to t[0]: Unix-time stamps give the same result as dt (bit for bit here, since
    1.7e9 + k 2^-7 is exactly representable)."""
    n = 1000
    h = 2.0**-7
    g = generic_rate(np.arange(n) * h)
    for method in ("rk4", "exact", "coning2"):
        by_dt = integrate(g, h, method=method)
        by_t = integrate(g, t=1.7e9 + np.arange(n + 1) * h, method=method)
        assert by_t.tobytes() == by_dt.tobytes()


def test_irregular_timestamps_rk4_stays_accurate(rng):
    n = 400
    t = np.cumsum(np.r_[0.0, rng.uniform(0.004, 0.006, n)])
    q = integrate(generic_rate(t[:-1]), t=t, method="rk4", q0=generic_q(t[:1])[0])
    assert rotation_angle(q, generic_q(t)).max() < 1e-8


@pytest.mark.parametrize("method", METHODS)
def test_many_bodies_equal_one_by_one(method, rng):
    bodies, n = 3, 200
    g = np.stack([generic_rate(np.arange(n) * 0.01 + b) for b in range(bodies)])
    q0 = np.array([generic_q([float(b)])[0] for b in range(bodies)])
    together = integrate(g, 0.01, q0=q0, method=method, parallel=False)
    assert together.shape == (bodies, n + 1, 4)
    for b in range(bodies):
        alone = integrate(g[b], 0.01, q0=q0[b], method=method, parallel=False)
        assert together[b].tobytes() == alone.tobytes()


def test_streaming_lag_and_state_round_trip(rng):
    g = generic_rate(np.arange(100) * 0.01)
    integ = AttitudeIntegrator("rk4")
    first = integ.update(g[:50], 0.01)
    assert len(first) < 50  # waits for the samples its cubic needs
    saved = integ.state
    rest = integ.update(g[50:], 0.01)
    tail = integ.finish()
    other = AttitudeIntegrator("rk4")
    other.update(g[:1], 0.01)
    other.state = saved
    rest2 = other.update(g[50:], 0.01)
    tail2 = other.finish()
    assert np.concatenate([rest, tail]).tobytes() == np.concatenate([rest2, tail2]).tobytes()
    assert len(first) + len(rest) + len(tail) == 100
    with pytest.raises(ValueError, match="finished"):
        integ.update(g[:5], 0.01)


# ---------------------------------------------------------------------------------------------------------------
# frames, units, dtypes, normalisation
def test_reference_frame_rates_constant_closed_form():
    omega_ref = [0.2, -0.5, 0.3]
    q0 = sd.from_euler([0.4, 0.1, -0.2], "ZYX")
    for method in ("exact", "rk4", "coning2", "cayley"):
        q = integrate(np.tile(omega_ref, (200, 1)), 0.01, q0=q0, method=method, rate_frame="reference")
        truth = quat.multiply(closed_form_constant([1.0, 0, 0, 0], omega_ref, np.arange(201) * 0.01), q0)
        assert rotation_angle(q, truth).max() < 1e-6 if method == "cayley" else 1e-13


def test_reference_frame_rates_generic_motion():
    h = 0.005
    t = np.arange(401) * h
    q_true = generic_q(t)
    omega_ref = quat.rotate(q_true[:-1], generic_rate(t[:-1]))
    q = integrate(omega_ref, h, q0=q_true[0], method="rk4", rate_frame="reference")
    assert rotation_angle(q, q_true).max() < 1e-9
    inc_ref = quat.rotate(generic_q(t[:-1] + h / 2), generic_increments(t))  # mid-step frame: second order
    q = integrate(inc_ref, q0=q_true[0], method="exact", input="increment", rate_frame="reference")
    assert rotation_angle(q, q_true).max() < 1e-5


def test_degrees_and_float32():
    g = np.tile([0.0, 0.0, 90.0], (100, 1))
    q = integrate(g, 0.01, degrees=True)
    np.testing.assert_allclose(q[-1], [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)], atol=1e-15)
    q32 = integrate(g.astype(np.float32), 0.01, degrees=True)
    assert q32.dtype == np.float32
    np.testing.assert_allclose(q32, q, atol=1e-7)


def test_first_order_without_normalisation_grows_as_predicted():
    phi = 0.02
    q = integrate(np.tile([phi, 0, 0], (500, 1)), input="increment", method="first-order", normalize="none")
    np.testing.assert_allclose(np.linalg.norm(q[-1]), (1 + phi**2 / 4) ** 250, rtol=1e-13)


def test_renormalisation_schedule():
    g = np.tile([0.1, 0.05, 0.0], (30, 1))
    q = integrate(g, input="increment", method="first-order", normalize="exact", normalize_every=10)
    norms = np.linalg.norm(q, axis=-1)
    np.testing.assert_allclose(norms[[10, 20, 30]], 1, atol=1e-15)
    assert (norms[[5, 15, 25]] > 1 + 1e-6).all()


# ---------------------------------------------------------------------------------------------------------------
# bad input
@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"gyro": [[0, 0, np.nan]], "dt": 0.01}, r"gyro\[0, 2\] is NaN"),
        ({"gyro": [[0, np.inf, 0]], "dt": 0.01}, r"gyro\[0, 1\] is infinite"),
        ({"gyro": [[0, 0]], "dt": 0.01}, r"gyro must have shape \(N, 3\)"),
        ({"gyro": [0, 0, 1], "dt": 0.01}, r"gyro must have shape"),
        ({"gyro": np.zeros((3, 3))}, "dt or t is required"),
        ({"gyro": np.zeros((3, 3)), "dt": 0.0}, "dt must be positive"),
        ({"gyro": np.zeros((3, 3)), "dt": [0.1, -0.1, 0.1]}, r"dt\[1\] is not positive"),
        ({"gyro": np.zeros((3, 3)), "dt": [0.1, 0.1]}, "one entry per sample"),
        ({"gyro": np.zeros((3, 3)), "t": [0, 1, 1, 2]}, "not strictly increasing at sample 1"),
        ({"gyro": np.zeros((3, 3)), "t": [0, 1, 0.5, 2]}, "not strictly increasing at sample 1"),
        ({"gyro": np.zeros((3, 3)), "t": [0, 1, np.nan, 2]}, r"t\[2\] is NaN"),
        ({"gyro": np.zeros((3, 3)), "t": [0, 1, 2]}, r"t must have N \+ 1 = 4 entries"),
        ({"gyro": np.zeros((3, 3)), "dt": 0.1, "t": [0, 1, 2, 3]}, "either dt or t"),
        ({"gyro": np.zeros((3, 3)), "dt": 0.1, "q0": [0, 0, 0, 0]}, "q0 is a zero quaternion"),
        ({"gyro": np.zeros((3, 3)), "dt": 0.1, "method": "rk5"}, "method must be one of"),
        ({"gyro": np.zeros((3, 3)), "dt": 0.1, "input": "angle"}, "input must be one of"),
        ({"gyro": np.zeros((3, 3)), "dt": 0.1, "method": "dcm", "rate_frame": "reference"}, "body rates"),
        ({"gyro": np.zeros((2, 3, 3)), "dt": 0.1, "q0": np.ones((3, 4))}, "q0 has 3 rows but gyro has 2"),
        ({"gyro": np.zeros((3, 3)), "dt": 0.1, "normalize_every": 0}, "normalize_every"),
        (
            {"gyro": np.zeros((2, 3, 3)), "dt": 0.1, "method": "first-order", "normalize": "series", "parallel": True},
            "parallel=True needs one body",
        ),
    ],
)
def test_bad_input(kwargs, match):
    kwargs = dict(kwargs)
    gyro = kwargs.pop("gyro")
    dt = kwargs.pop("dt", None)
    with pytest.raises(ValueError, match=match):
        integrate(gyro, dt, **kwargs)


def test_warn_mode_counts(recwarn):
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        _climb("euler-angles", on_singular="warn")
    assert any("step(s)" in str(w.message) for w in recwarn)


@pytest.mark.parametrize("method", ["exact", "first-order", "cayley"])
@pytest.mark.parametrize("n", [100, 100_000])  # sequential loop and two-core scan
def test_non_finite_samples_anywhere_are_reported(method, n):
    for where in (0, n // 3, n - 1):
        for bad in (np.nan, np.inf, -np.inf):
            g = np.full((n, 3), 0.1)
            g[where, 1] = bad
            with pytest.raises(ValueError, match=rf"gyro\[{where}, 1\] is (NaN|infinite)"):
                integrate(g, 0.01, method=method)


def test_overflowing_steps_are_reported_and_the_stream_survives():
    integ = AttitudeIntegrator("exact")
    integ.update(np.full((10, 3), 0.1), 0.01)
    before = integ.state
    with pytest.raises(ValueError, match=r"gyro sample 10 turns by 1e\+306 rad in one step"):
        integ.update(np.full((10, 3), 1e308), 0.01)
    after = integ.state
    np.testing.assert_array_equal(after.q, before.q)
    assert after.steps_in == before.steps_in
