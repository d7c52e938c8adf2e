"""Averages and distances against scipy (Rotation.mean, Slerp, matrices), closed forms and planted outliers."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation, Slerp

from conftest import random_quaternions, rotation_angle
from strapdown.rotations.average import average_two, chordal_distance, geodesic_distance, mean


def scipy_mean(q, weights=None):
    return Rotation.from_quat(q, scalar_first=True).mean(weights=weights).as_quat(scalar_first=True)


def cluster(center, n, sigma, rng):
    """n attitudes scattered about `center` by body-frame rotation vectors of σ (rad) per axis."""
    noise = Rotation.from_rotvec(sigma * rng.standard_normal((n, 3)))
    return (Rotation.from_quat(center, scalar_first=True) * noise).as_quat(scalar_first=True)


def test_mean_matches_scipy(rng):
    for _ in range(200):
        n = int(rng.integers(2, 40))
        center = random_quaternions(1, rng)[0]
        spread = rng.choice([1e-4, 0.1, 1.0])
        q = cluster(center, n, spread, rng) * rng.choice([-1, 1], (n, 1))
        weights = rng.uniform(0.1, 2.0, n)
        assert rotation_angle(mean(q), scipy_mean(q)) <= 1e-12
        assert rotation_angle(mean(q, weights), scipy_mean(q, weights)) <= 1e-12


def test_mean_of_uniform_random_attitudes_matches_scipy(rng):
    q = random_quaternions(1000, rng)
    assert rotation_angle(mean(q), scipy_mean(q)) <= 1e-12


def test_mean_is_sign_invariant_and_canonical(rng):
    q = cluster(random_quaternions(1, rng)[0], 50, 0.3, rng)
    flips = rng.choice([-1.0, 1.0], (50, 1))
    m = mean(q)
    np.testing.assert_allclose(mean(q * flips), m, atol=1e-15)
    np.testing.assert_allclose(mean(-q), m, atol=1e-15)
    assert m[0] >= 0
    assert abs(np.linalg.norm(m) - 1) < 1e-15
    # non-unit input stands for the rotation of q / |q|
    np.testing.assert_allclose(mean(q * rng.uniform(0.1, 10, (50, 1))), m, atol=1e-15)


def test_mean_minimises_the_chordal_cost(rng):
    """Σ w ‖R(m) - R(q_i)‖²_F (scipy matrices) is least at the mean: perturbations only increase it."""
    q = cluster(random_quaternions(1, rng)[0], 30, 0.5, rng)
    w = rng.uniform(0.5, 1.5, 30)
    mats = Rotation.from_quat(q, scalar_first=True).as_matrix()

    def cost(m):
        return np.sum(w * np.sum((Rotation.from_quat(m, scalar_first=True).as_matrix() - mats) ** 2, axis=(1, 2)))

    best = cost(mean(q, w))
    for d in 1e-4 * rng.standard_normal((50, 3)):
        moved = Rotation.from_quat(mean(q, w), scalar_first=True) * Rotation.from_rotvec(d)
        assert cost(moved.as_quat(scalar_first=True)) > best


def test_mean_axis_and_weights_broadcast(rng):
    q = cluster(random_quaternions(1, rng)[0], 24, 0.4, rng).reshape(2, 3, 4, 4)
    w = rng.uniform(0.1, 1, (2, 3, 4))
    by_last = mean(q, w, axis=-2)
    assert by_last.shape == (2, 3, 4)
    for i in range(2):
        for j in range(3):
            assert rotation_angle(by_last[i, j], scipy_mean(q[i, j], w[i, j])) <= 1e-12
    by_first = mean(q, w, axis=0)
    assert by_first.shape == (3, 4, 4)
    assert rotation_angle(by_first[1, 2], scipy_mean(q[:, 1, 2], w[:, 1, 2])) <= 1e-12
    pair = mean(q, w, axis=(0, 2))
    assert pair.shape == (3, 4)
    assert rotation_angle(pair[1], scipy_mean(q[:, 1].reshape(-1, 4), w[:, 1].reshape(-1))) <= 1e-12
    assert rotation_angle(mean(q, w), scipy_mean(q.reshape(-1, 4), w.reshape(-1))) <= 1e-12
    # weights of shape (4,) broadcast along the last leading axis
    w4 = np.array([1.0, 2.0, 0.5, 0.0])
    assert rotation_angle(mean(q, w4, axis=-2)[1, 1], scipy_mean(q[1, 1], w4)) <= 1e-12
    assert mean(q.astype(np.float32), axis=-2).dtype == np.float32


def test_outliers_planted_are_flagged_and_inliers_are_not(rng):
    for trial in range(20):
        center = random_quaternions(1, rng)[0]
        inliers = cluster(center, 200, np.radians(1.0), rng)
        n_out = int(rng.integers(1, 30))
        outliers = cluster(center, n_out, np.radians(40.0), rng)
        far = Rotation.from_quat(outliers, scalar_first=True).inv() * Rotation.from_quat(center, scalar_first=True)
        outliers = outliers[far.magnitude() > np.radians(15)]  # gross errors only
        q = np.vstack([inliers, outliers])
        order = rng.permutation(len(q))
        planted = np.zeros(len(q), bool)
        planted[200:] = True
        m, flags = mean(q[order], return_outliers=True)
        np.testing.assert_array_equal(flags, planted[order], err_msg=f"trial {trial}")
        # the mean returned is that of the inliers, as scipy computes it
        assert rotation_angle(m, scipy_mean(inliers)) <= 1e-12
        # a fixed threshold (radians) flags the same here
        _, fixed = mean(q[order], return_outliers=True, threshold=np.radians(10))
        np.testing.assert_array_equal(fixed, planted[order])


def test_outlier_flags_per_group_and_edge_cases(rng):
    center = random_quaternions(1, rng)[0]
    q = cluster(center, 60, 0.01, rng).reshape(3, 20, 4)
    q[1, 7] = cluster(center, 1, 1.0, rng)[0] * -1
    _, flags = mean(q, axis=1, return_outliers=True)
    assert flags.shape == (3, 20)
    expected = np.zeros((3, 20), bool)
    expected[1, 7] = True
    np.testing.assert_array_equal(flags, expected)
    # identical attitudes: nothing is an outlier (rounding-level distances are never flagged)
    same = np.repeat(center[None], 10, axis=0) * np.where(np.arange(10) % 2, -1, 1)[:, None]
    assert not mean(same, return_outliers=True)[1].any()
    # threshold 0 flags every attitude not at the mean (beyond rounding)
    two = cluster(center, 2, 0.1, rng)
    assert mean(two, return_outliers=True, threshold=0.0)[1].all()


def test_average_two_equals_slerp_half_and_mean(rng):
    p = random_quaternions(5000, rng)
    q = random_quaternions(5000, rng)
    ours = average_two(p, q)
    half = np.empty_like(ours)
    for i in range(5000):
        rots = Rotation.from_quat(np.stack([p[i], q[i]]), scalar_first=True)
        half[i] = Slerp([0.0, 1.0], rots)(0.5).as_quat(scalar_first=True)
    assert rotation_angle(ours, half).max() <= 1e-12
    # and it is the mean of the two
    means = np.array([scipy_mean(np.stack([p[i], q[i]])) for i in range(200)])
    assert rotation_angle(ours[:200], means).max() <= 1e-12
    # equidistant from both (geodesic, via scipy)
    rp = Rotation.from_quat(p, scalar_first=True)
    rq = Rotation.from_quat(q, scalar_first=True)
    ra = Rotation.from_quat(ours, scalar_first=True)
    np.testing.assert_allclose((rp.inv() * ra).magnitude(), (rq.inv() * ra).magnitude(), atol=1e-12)
    # sign-invariant in both arguments (the result lies in p's hemisphere)
    np.testing.assert_allclose(average_two(p, -q), ours, atol=1e-15)
    np.testing.assert_allclose(average_two(-p, q), -ours, atol=1e-15)
    assert (np.einsum("ni,ni->n", ours, p) > 0).all()


def test_average_two_at_180_degrees_and_dtype():
    p = np.array([1.0, 0, 0, 0])
    q = np.array([0.0, 0, 0, 1])  # 180° about z: p·q = 0
    np.testing.assert_allclose(average_two(p, q), [np.sqrt(0.5), 0, 0, np.sqrt(0.5)], atol=1e-16)
    assert average_two(p.astype(np.float32), q.astype(np.float32)).dtype == np.float32


def test_distances_match_scipy_matrices(rng):
    p = random_quaternions(10_000, rng)
    q = random_quaternions(10_000, rng)
    rp = Rotation.from_quat(p, scalar_first=True)
    rq = Rotation.from_quat(q, scalar_first=True)
    frob = np.linalg.norm(rp.as_matrix() - rq.as_matrix(), axis=(1, 2))
    np.testing.assert_allclose(chordal_distance(p, q), frob, rtol=1e-12, atol=1e-15)
    angle = (rp.inv() * rq).magnitude()
    np.testing.assert_allclose(geodesic_distance(p, q), angle, atol=1e-12)
    np.testing.assert_allclose(chordal_distance(p, q), 2 * np.sqrt(2) * np.sin(angle / 2), rtol=1e-12)
    # sign invariance, non-unit input, broadcasting
    np.testing.assert_allclose(chordal_distance(-3 * p, 0.5 * q), chordal_distance(p, q), rtol=1e-13)
    np.testing.assert_allclose(geodesic_distance(-p, q), geodesic_distance(p, q), atol=1e-15)
    assert chordal_distance(p[:5, None], q[None, :7]).shape == (5, 7)


def test_distances_of_tiny_angles_are_accurate():
    for angle in (1e-3, 1e-8, 1e-12):
        q = [np.cos(angle / 2), 0, np.sin(angle / 2), 0]
        assert geodesic_distance([1.0, 0, 0, 0], q) == pytest.approx(angle, rel=1e-12)
        assert chordal_distance([1.0, 0, 0, 0], q) == pytest.approx(2 * np.sqrt(2) * np.sin(angle / 2), rel=1e-12)


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: mean([[1.0, 0, 0, np.nan]]), r"q\[0, 3\] is NaN"),
        (lambda: mean([[1.0, 0, 0, 0], [0, 0, 0, 0]]), r"q\[1\] is a zero quaternion"),
        (lambda: mean([[1.0, 0, 0]]), r"q must have shape \(\.\.\., 4\)"),
        (lambda: mean(np.ones((3, 4)), [1.0, -1, 1]), r"weights\[1\] is negative"),
        (lambda: mean(np.ones((3, 4)), [0.0, 0, 0]), "weights sum to zero"),
        (
            lambda: mean(np.ones((2, 3, 4)), [[1.0, 1, 1], [0, 0, 0]], axis=1),
            r"weights sum to zero for the mean at index \[1\]",
        ),
        (lambda: mean(np.ones((3, 4)), [1.0, 1.0]), "do not broadcast"),
        (lambda: mean(np.ones((3, 4)), [1.0, np.inf, 1.0]), r"weights\[1\] is infinite"),
        (lambda: mean(np.ones((3, 4)), axis=1), "components"),
        (lambda: mean(np.ones((3, 4)), axis=-1), "components"),
        (lambda: mean(np.ones((3, 4)), axis=2), "out of range"),
        (lambda: mean(np.ones((3, 2, 4)), axis=(0, 0)), "repeats"),
        (lambda: mean(np.ones((3, 4)), axis=1.5), "axis must be"),
        (lambda: mean(np.ones((0, 4))), "no attitudes"),
        (lambda: mean(np.ones((3, 4)), return_outliers=True, threshold=-1.0), "threshold"),
        (lambda: mean(np.ones((3, 4)), return_outliers=True, threshold=np.nan), "threshold is NaN"),
        (lambda: average_two([1.0, 0, 0, 0], [0.0, 0, 0, 0]), "q is a zero quaternion"),
        (lambda: average_two([np.nan, 0, 0, 0], [1.0, 0, 0, 0]), r"p\[0\] is NaN"),
        (lambda: chordal_distance([1.0, 0, 0, 0], [0.0, 0, 0, 0]), "q is a zero quaternion"),
        (lambda: geodesic_distance([0.0, 0, 0, 0], [1.0, 0, 0, 0]), "p is a zero quaternion"),
    ],
)
def test_invalid_input_raises_naming_the_argument(call, match):
    with pytest.raises(ValueError, match=match):
        call()
