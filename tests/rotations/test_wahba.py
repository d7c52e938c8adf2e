"""Wahba solvers, TRIAD and the static attitude against scipy's align_vectors, closed forms and Monte Carlo.

Accuracy is stated against the conditioning of each problem: the gap g between the two largest eigenvalues of
Davenport's K (divided by the total weight, so g is in [0, 2]) computed here by numpy.  A backward-stable solver
errs by about ε/g; scipy's SVD does too.  So the bounds are 1e-12 rad where g ≥ 0.01 (99% of random problems) and
err · g ≤ 2e-14 everywhere.
"""

import functools
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions, rotation_angle
from strapdown.rotations.wahba import davenport, olae, quest, static_attitude, triad

N_PROBLEMS = 10_000
SOLVERS = {"davenport": davenport, "quest": quest, "olae": olae}
NED_TO_ENU = np.array([[0.0, 1, 0], [1, 0, 0], [0, 0, -1]])
NED_TO_NWU = np.diag([1.0, -1, -1])


def unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def scipy_matrix(q):
    return Rotation.from_quat(q, scalar_first=True).as_matrix()


def scipy_quat(matrix):
    return Rotation.from_matrix(matrix).as_quat(scalar_first=True)


def perturb(v, sigma, rng):
    """Unit directions turned by small random rotations perpendicular to them, σ (rad) per axis."""
    v = unit(v)
    noise = np.asarray(sigma)[..., None] * rng.standard_normal(v.shape)
    noise -= np.sum(noise * v, axis=-1, keepdims=True) * v
    return unit(v + noise)


def eigengap(body, reference, weights):
    """(λ1 - λ2) / Σ a of Davenport's K, built here from math.md §4.2 for the conditioning only."""
    b = np.einsum("ni,nij,nik->njk", weights, unit(body), unit(reference)) / weights.sum(-1)[:, None, None]
    k = np.zeros((len(b), 4, 4))
    sigma = np.trace(b, axis1=1, axis2=2)
    z = np.stack([b[:, 1, 2] - b[:, 2, 1], b[:, 2, 0] - b[:, 0, 2], b[:, 0, 1] - b[:, 1, 0]], axis=-1)
    k[:, 0, 0] = sigma
    k[:, 0, 1:] = z
    k[:, 1:, 0] = z
    k[:, 1:, 1:] = b + b.transpose(0, 2, 1) - sigma[:, None, None] * np.eye(3)
    lam = np.linalg.eigvalsh(k)
    return lam[:, -1] - lam[:, -2]


@functools.cache
def problems(sigma, seed=7):
    """10⁴ random problems: random attitude, 2-6 random directions, random weights, reference noise σ (rad)."""
    rng = np.random.default_rng(seed)
    q = random_quaternions(N_PROBLEMS, rng)
    m = rng.integers(2, 7, N_PROBLEMS)
    body = unit(rng.standard_normal((N_PROBLEMS, 6, 3)))
    reference = np.einsum("nij,nkj->nki", scipy_matrix(q), body)
    if sigma:
        reference = perturb(reference, np.full(reference.shape[:-1], sigma), rng)
    weights = rng.uniform(0.2, 1.0, (N_PROBLEMS, 6))
    optimum = np.empty((N_PROBLEMS, 4))
    gap = np.empty(N_PROBLEMS)
    for i in range(N_PROBLEMS):
        k = m[i]
        rot, _ = Rotation.align_vectors(reference[i, :k], body[i, :k], weights=weights[i, :k])
        optimum[i] = rot.as_quat(scalar_first=True)
    for k in range(2, 7):
        idx = m == k
        gap[idx] = eigengap(body[idx, :k], reference[idx, :k], weights[idx, :k])
    return SimpleNamespace(q=q, m=m, body=body, reference=reference, weights=weights, optimum=optimum, gap=gap)


def solve(solver, p):
    out = np.empty((N_PROBLEMS, 4))
    for k in range(2, 7):
        idx = p.m == k
        out[idx] = solver(p.body[idx, :k], p.reference[idx, :k], p.weights[idx, :k])
    return out


def assert_optimal(err, gap):
    well = gap >= 0.01
    assert well.mean() > 0.98
    assert err[well].max() <= 1e-12
    assert (err * gap).max() <= 2e-14


@pytest.mark.parametrize("name", list(SOLVERS))
def test_noise_free_problems_are_solved_exactly(name):
    p = problems(0.0)
    ours = solve(SOLVERS[name], p)
    assert_optimal(rotation_angle(ours, p.optimum), p.gap)
    assert_optimal(rotation_angle(ours, p.q), p.gap)
    # unit norm and canonical sign
    assert np.abs(np.linalg.norm(ours, axis=-1) - 1).max() < 4e-16
    assert (ours[:, 0] >= 0).all()


@pytest.mark.parametrize("name", ["davenport", "quest"])
def test_noisy_problems_match_scipy_optimum(name):
    p = problems(1e-3)
    ours = solve(SOLVERS[name], p)
    err = rotation_angle(ours, p.optimum)
    assert err.max() <= 1e-10  # the bound, everywhere
    assert_optimal(err, p.gap)


def test_quest_agrees_with_davenport():
    for sigma in (0.0, 1e-3, 1e-2):
        p = problems(sigma)
        err = rotation_angle(solve(quest, p), solve(davenport, p))
        assert_optimal(err, p.gap)


def test_olae_bias_is_bounded():
    """OLAE weighs observation i by cos² of half the angle between b_i and r_i, not by a_i alone: measured here."""
    sigma = 1e-3
    p = problems(sigma)
    ours = solve(olae, p)
    dev = rotation_angle(ours, p.optimum)
    # Distance to Wahba's optimum, in units of the noise: median 0.10, 99% 0.77, worst 0.92 σ/g.
    assert np.median(dev) <= 0.15 * sigma
    assert np.percentile(dev, 99) <= 1.0 * sigma
    assert (dev * p.gap).max() <= 2.0 * sigma
    # Against the truth OLAE is nearly as good as the optimum (rms 1.74 vs 1.70 mrad here).
    rms = np.sqrt(np.mean(rotation_angle(ours, p.q) ** 2))
    rms_optimal = np.sqrt(np.mean(rotation_angle(p.optimum, p.q) ** 2))
    assert rms <= 1.05 * rms_optimal


def test_olae_three_vectors_against_math_md(rng):
    """math.md §4.2 reports ≤ 0.12° from Davenport at 1e-3 noise (three equally weighted vectors).

    Over 10⁴ random problems here the median is 0.006°, 99.9% are below 0.08° and the worst is 0.13°, in a nearly
    degenerate geometry: the deviation scales as σ/g (at most 1.3 σ/g over three seeds).
    """
    n = 10_000
    q = random_quaternions(n, rng)
    body = unit(rng.standard_normal((n, 3, 3)))
    reference = perturb(np.einsum("nij,nkj->nki", scipy_matrix(q), body), np.full((n, 3), 1e-3), rng)
    dev = np.degrees(rotation_angle(olae(body, reference), davenport(body, reference)))
    gap = eigengap(body, reference, np.ones((n, 3)))
    assert np.percentile(dev, 99.9) <= 0.1
    assert dev[gap >= 0.1].max() <= 0.12
    assert dev.max() <= 0.2
    assert (np.radians(dev) * gap).max() <= 2e-3


@pytest.mark.parametrize("name", list(SOLVERS))
def test_rotations_of_180_degrees(name, rng):
    """QUEST and OLAE are singular at 180° in their own frame; the sequential rotations must hide it."""
    axes = np.vstack([np.eye(3), unit(rng.standard_normal((200, 3)))])
    angles = np.concatenate([np.full(203, np.pi), np.pi - np.logspace(-12, -1, 200), np.pi - rng.uniform(0, 1, 3)])
    axes = np.vstack([axes, unit(rng.standard_normal((203, 3)))])
    q = Rotation.from_rotvec(axes * angles[:, None]).as_quat(scalar_first=True)
    body = unit(rng.standard_normal((len(q), 3, 3)))
    reference = np.einsum("nij,nkj->nki", scipy_matrix(q), body)
    ours = SOLVERS[name](body, reference)
    gap = eigengap(body, reference, np.ones((len(q), 3)))
    assert_optimal(rotation_angle(ours, q), gap)


@pytest.mark.parametrize("name", list(SOLVERS))
def test_raw_vectors_match_scipy_with_normalize_false(name, rng):
    """normalize=False: a pair weighs a |b| |r|, exactly scipy's objective on raw vectors."""
    n = 300
    q = random_quaternions(n, rng)
    body = rng.standard_normal((n, 4, 3)) * rng.uniform(0.1, 10, (n, 4, 1))
    reference = np.einsum("nij,nkj->nki", scipy_matrix(q), body) * rng.uniform(0.5, 2, (n, 4, 1))
    reference = reference + 1e-3 * rng.standard_normal(reference.shape)
    weights = rng.uniform(0.2, 1, (n, 4))
    ours = SOLVERS[name](body, reference, weights, normalize=False)
    expected = np.array(
        [
            Rotation.align_vectors(reference[i], body[i], weights=weights[i])[0].as_quat(scalar_first=True)
            for i in range(n)
        ]
    )
    err = rotation_angle(ours, expected)
    if name == "olae":
        assert err.max() <= 5e-3
    else:
        assert err.max() <= 1e-12
    # and with normalize=True the lengths do not matter at all
    np.testing.assert_allclose(
        SOLVERS[name](body, reference, weights), SOLVERS[name](unit(body), unit(reference), weights), atol=1e-14
    )


@pytest.mark.parametrize("name", list(SOLVERS))
def test_broadcasting_and_dtypes(name, rng):
    solver = SOLVERS[name]
    q = random_quaternions(1, rng)[0]
    catalogue = unit(rng.standard_normal((4, 3)))  # fixed reference vectors
    body = perturb(np.broadcast_to(catalogue @ scipy_matrix(q), (2, 3, 4, 3)), np.full((2, 3, 4), 1e-3), rng)
    weights = np.array([1.0, 2.0, 0.5, 1.0])
    full = solver(body, np.broadcast_to(catalogue, body.shape).copy(), np.broadcast_to(weights, (2, 3, 4)).copy())
    short = solver(body, catalogue, weights)
    assert short.shape == (2, 3, 4)
    np.testing.assert_array_equal(short, full)
    loop = np.array([solver(b, catalogue, weights) for b in body.reshape(-1, 4, 3)]).reshape(2, 3, 4)
    np.testing.assert_array_equal(short, loop)
    single = solver(body[0, 0], catalogue)
    assert single.shape == (4,)
    out32 = solver(body.astype(np.float32), catalogue.astype(np.float32))
    assert out32.dtype == np.float32
    assert rotation_angle(out32, solver(body, catalogue)).max() < 1e-6
    assert solver(body.astype(np.float32), catalogue).dtype == np.float64


@pytest.mark.parametrize("name", list(SOLVERS))
def test_zero_weights_drop_observations(name, rng):
    q = random_quaternions(50, rng)
    body = unit(rng.standard_normal((50, 5, 3)))
    reference = perturb(np.einsum("nij,nkj->nki", scipy_matrix(q), body), np.full((50, 5), 1e-2), rng)
    weights = rng.uniform(0.5, 1, (50, 5))
    weights[:, 3:] = 0
    solver = SOLVERS[name]
    err = rotation_angle(solver(body, reference, weights), solver(body[:, :3], reference[:, :3], weights[:, :3]))
    assert err.max() <= 1e-13


@pytest.mark.parametrize("name", list(SOLVERS))
def test_degenerate_problems_return_an_optimal_attitude(name, rng):
    """One direction (or all parallel): the attitude is not unique, but the result maps it exactly, never NaN."""
    q = random_quaternions(100, rng)
    b = unit(rng.standard_normal((100, 1, 3)))
    r = np.einsum("nij,nkj->nki", scipy_matrix(q), b)
    for body, reference in ((b, r), (np.concatenate([b, 2 * b], 1), np.concatenate([r, 3 * r], 1))):
        ours = SOLVERS[name](body, reference)
        assert np.isfinite(ours).all()
        mapped = np.einsum("nij,nj->ni", scipy_matrix(ours), body[:, 0])
        np.testing.assert_allclose(
            mapped, reference[:, 0] / np.linalg.norm(reference[:, 0], axis=-1)[:, None], atol=1e-12
        )


def test_covariance_closed_form():
    """Two perpendicular directions with σ = 1 mrad: the angle about each is seen by one, about z by both."""
    body = np.array([[1.0, 0, 0], [0, 1, 0]])
    weights = np.array([1e6, 1e6])
    for solver in (davenport, quest):
        _, cov = solver(body, body, weights, return_covariance=True)
        np.testing.assert_allclose(cov, np.diag([1e-6, 1e-6, 0.5e-6]), rtol=1e-14, atol=1e-22)
        # scaling the weights by c scales the covariance by 1/c, not the attitude
        _, cov2 = solver(body, body, 4 * weights, return_covariance=True)
        np.testing.assert_allclose(cov2, cov / 4, rtol=1e-14, atol=1e-22)
        # a single direction: the rotation about it is unobservable
        _, cov1 = solver(body[:1], body[:1], return_covariance=True)
        assert np.isposinf(cov1).all()


@pytest.mark.parametrize("name", ["davenport", "quest"])
def test_covariance_matches_monte_carlo(name):
    """Shuster's covariance against the scatter of 20 000 noisy solutions (body-frame error, rad²)."""
    rng = np.random.default_rng(3)
    trials = 20_000
    q_true = random_quaternions(1, rng)[0]
    sigma = np.array([1e-3, 2e-3, 0.5e-3, 3e-3])
    body_true = unit(rng.standard_normal((4, 3)))
    reference = body_true @ scipy_matrix(q_true).T
    body = perturb(np.broadcast_to(body_true, (trials, 4, 3)), np.broadcast_to(sigma, (trials, 4)), rng)
    q_est, cov = SOLVERS[name](body, reference, 1 / sigma**2, return_covariance=True)
    assert cov.shape == (trials, 3, 3)
    est = Rotation.from_quat(q_est, scalar_first=True)
    err = (est.inv() * Rotation.from_quat(q_true, scalar_first=True)).as_rotvec()  # body-frame error
    scatter = err.T @ err / trials
    predicted = cov.mean(axis=0)
    # whiten: the scatter in the predicted metric must be the identity within sampling error (~1.4% here)
    w, v = np.linalg.eigh(predicted)
    root = v @ np.diag(w**-0.5) @ v.T
    ratio = np.linalg.eigvalsh(root @ scatter @ root)
    assert np.all(np.abs(ratio - 1) <= 0.10), ratio
    np.testing.assert_allclose(np.diag(scatter), np.diag(predicted), rtol=0.10)


def test_triad_exact_for_two_noise_free_vectors(rng):
    n = N_PROBLEMS
    q = random_quaternions(n, rng)
    b1, b2 = unit(rng.standard_normal((2, n, 3)))
    m = scipy_matrix(q)
    r1 = np.einsum("nij,nj->ni", m, b1) * 3.0  # lengths do not matter
    r2 = np.einsum("nij,nj->ni", m, b2) * 0.5
    ours = triad(b1, b2, r1, r2)
    err = rotation_angle(ours, q)
    sine = np.linalg.norm(np.cross(b1, b2), axis=-1)
    assert err[sine >= 0.01].max() <= 1e-13
    assert (err * sine).max() <= 1e-15
    assert (ours[:, 0] >= 0).all()


def test_triad_maps_the_first_pair_exactly_with_noise(rng):
    n = N_PROBLEMS
    q = random_quaternions(n, rng)
    b1, b2 = unit(rng.standard_normal((2, n, 3)))
    m = scipy_matrix(q)
    r1 = perturb(np.einsum("nij,nj->ni", m, b1), np.full(n, 1e-2), rng)
    r2 = perturb(np.einsum("nij,nj->ni", m, b2), np.full(n, 1e-2), rng)
    ours = triad(b1, b2, r1, r2)
    mapped = np.einsum("nij,nj->ni", scipy_matrix(ours), b1)
    assert np.abs(mapped - r1).max() <= 2e-15
    # the second pair only fixes the rotation about the first: b2, r2 and r1 are coplanar after the rotation
    mapped2 = np.einsum("nij,nj->ni", scipy_matrix(ours), b2)
    assert np.abs(np.einsum("ni,ni->n", np.cross(r1, r2), mapped2)).max() <= 2e-15
    # and within the noise of the truth, which the second vector's noise amplifies as it nears the first
    sine = np.linalg.norm(np.cross(b1, b2), axis=-1)
    assert (rotation_angle(ours, q) * sine).max() <= 0.1


def test_triad_broadcasts_and_matches_scipy_for_two_vectors(rng):
    """Noise-free with a fixed reference pair (a catalogue) against align_vectors."""
    q = random_quaternions(200, rng)
    r = unit(rng.standard_normal((2, 3)))
    body = np.einsum("nji,kj->nki", scipy_matrix(q), r)  # R^T r
    ours = triad(body[:, 0], body[:, 1], r[0], r[1])
    expected = np.array([Rotation.align_vectors(r, body[i])[0].as_quat(scalar_first=True) for i in range(len(q))])
    assert rotation_angle(ours, expected).max() <= 1e-13
    assert triad(body[:, 0].astype(np.float32), body[:, 1], r[0], r[1]).dtype == np.float64
    assert triad(*(x.astype(np.float32) for x in (body[:, 0], body[:, 1], r[0], r[1]))).dtype == np.float32


def static_readings(q, field_ned, g=9.81):
    """Specific force (up, +g) and field, NED → body: v_body = Rᵀ v_ned."""
    m = scipy_matrix(q)
    acc = np.einsum("nji,j->ni", m, [0.0, 0.0, -g])
    mag = np.einsum("nji,nj->ni", m, field_ned)
    return acc, mag


def test_static_attitude_ned_enu_nwu(rng):
    n = 5_000
    q = random_quaternions(n, rng)
    dip = rng.uniform(-np.radians(80), np.radians(80), n)
    strength = rng.uniform(20, 60, n)
    field = strength[:, None] * np.column_stack([np.cos(dip), np.zeros(n), np.sin(dip)])  # magnetic north, down
    acc, mag = static_readings(q, field)
    acc = acc + 0.0  # noise-free
    ned = static_attitude(acc, mag)
    assert rotation_angle(ned, q).max() <= 1e-12
    for frame, matrix in (("ENU", NED_TO_ENU), ("NWU", NED_TO_NWU)):
        expected = scipy_quat(matrix @ scipy_matrix(q))
        assert rotation_angle(static_attitude(acc, mag, frame), expected).max() <= 1e-12


def test_static_attitude_declination_and_units(rng):
    n = 1_000
    q = random_quaternions(n, rng)
    dec = rng.uniform(-0.5, 0.5, n)
    field = np.column_stack([30 * np.cos(dec), 30 * np.sin(dec), np.full(n, 40.0)])  # true-north frame
    acc, mag = static_readings(q, field)
    assert rotation_angle(static_attitude(acc, mag, declination=dec), q).max() <= 1e-12
    assert rotation_angle(static_attitude(acc, mag, declination=np.degrees(dec), degrees=True), q).max() <= 1e-12
    # without declination the heading is off by exactly the declination, about the vertical
    heading_error = rotation_angle(static_attitude(acc, mag), q)
    np.testing.assert_allclose(heading_error, np.abs(dec), atol=1e-12)
    # any scale: g in m/s² or in g, field in µT or gauss
    np.testing.assert_allclose(
        static_attitude(acc / 9.81, mag * 0.01, declination=dec), static_attitude(acc, mag, declination=dec), atol=1e-15
    )
    out32 = static_attitude(acc.astype(np.float32), mag.astype(np.float32), declination=dec)
    assert out32.dtype == np.float32


def test_static_attitude_level_and_inverted():
    mag = [20.0, 0.0, 45.0]
    np.testing.assert_allclose(static_attitude([0, 0, -9.81], mag), [1, 0, 0, 0], atol=1e-15)
    # upside down (rolled 180°): the accelerometer reads +g along body z, the field's down part flips too
    q = static_attitude([0, 0, 9.81], [20.0, 0.0, -45.0])
    assert rotation_angle(q, [0, 1, 0, 0]) <= 1e-15
    # facing east: yaw 90°
    q = static_attitude([0, 0, -9.81], [0.0, -20.0, 45.0])
    assert rotation_angle(q, [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]) <= 1e-15


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: davenport([[1.0, 0, np.nan], [0, 1, 0]], [[1.0, 0, 0], [0, 1, 0]]), r"body\[0, 2\] is NaN"),
        (lambda: quest([[1.0, 0, 0], [0, 1, 0]], [[1.0, 0, 0], [0, np.inf, 0]]), r"reference\[1, 1\] is infinite"),
        (lambda: olae([1.0, 0, 0], [1.0, 0, 0]), r"body must have shape \(\.\.\., m, 3\)"),
        (lambda: davenport(np.ones((2, 4)), np.ones((2, 4))), r"body must have shape \(\.\.\., 3\)"),
        (lambda: quest(np.ones((5, 2, 3)), np.ones((5, 3, 3))), "body has 2 observations per epoch"),
        (lambda: olae([[1.0, 0, 0], [0, 0, 0]], [[1.0, 0, 0], [0, 1, 0]]), r"body\[1\] is a zero vector"),
        (lambda: davenport(np.ones((4, 2, 3)), np.zeros((2, 3))), r"reference\[0\] is a zero vector"),
        (lambda: quest(np.ones((2, 3)), np.ones((2, 3)), [1.0, -1.0]), r"weights\[1\] is negative"),
        (lambda: olae(np.ones((2, 3)), np.ones((2, 3)), [0.0, 0.0]), "weights are all zero"),
        (
            lambda: davenport(np.ones((3, 2, 3)), np.ones((2, 3)), [[1.0, 1], [0, 0], [1, 1]]),
            r"weights\[1\] are all zero",
        ),
        (lambda: quest(np.ones((2, 3)), np.ones((2, 3)), [1.0, 1.0, 1.0]), r"weights must have shape \(\.\.\., 2\)"),
        (lambda: quest(np.ones((2, 3)), np.ones((2, 3)), [1.0, np.nan]), r"weights\[1\] is NaN"),
        (lambda: davenport(np.ones((4, 2, 3)), np.ones((3, 2, 3))), "do not broadcast"),
        (lambda: davenport(np.ones((2, 3)), np.ones((2, 3)) * 1e200), r"reference\[0\] has a length too large"),
        (lambda: triad([1.0, 0, 0], [2.0, 0, 0], [1.0, 0, 0], [0, 1, 0]), r"b2 is parallel to b1"),
        (
            lambda: triad([[1.0, 0, 0]] * 2, [0, 1.0, 0], [1.0, 0, 0], [[0, 1, 0], [-3, 0, 0]]),
            r"r2\[1\] is parallel to r1\[1\]",
        ),
        (lambda: triad([0.0, 0, 0], [0, 1.0, 0], [1.0, 0, 0], [0, 1, 0]), "b1 is a zero vector"),
        (lambda: triad([1.0, 0, 0], [0, 1.0, 0], [1.0, 0, np.nan], [0, 1, 0]), r"r1\[2\] is NaN"),
        (lambda: static_attitude([0, 0, -9.8], [0, 0, 40.0]), "mag is parallel to acc"),
        (lambda: static_attitude([0, 0, 0.0], [20, 0, 40.0]), "acc is a zero vector"),
        (lambda: static_attitude([0, 0, -9.8], [[20, 0, 40.0], [0, 0, 0]]), r"mag\[1\] is a zero vector"),
        (lambda: static_attitude([0, 0, -9.8], [20, 0, 40.0], "FRD"), "frame must name a reference frame"),
        (lambda: static_attitude([0, 0, -9.8], [20, 0, 40.0], declination=np.nan), "declination is NaN"),
        (lambda: static_attitude(np.ones((3, 3)), np.ones((2, 3))), "do not broadcast"),
    ],
)
def test_invalid_input_raises_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()
