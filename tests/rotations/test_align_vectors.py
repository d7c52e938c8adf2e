"""wahba.align_vectors against scipy's Rotation.align_vectors (its test_rotation.py cases re-expressed)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions, rotation_angle
from strapdown import Attitude
from strapdown.rotations.wahba import align_vectors


def scipy_align(a, b, weights=None):
    rot, rssd = Rotation.align_vectors(a, b, weights=weights)
    return rot.as_quat(scalar_first=True), rssd


def test_single_pair_is_the_minimal_rotation(rng):
    for _ in range(200):
        a, b = rng.standard_normal((2, 3)) * rng.uniform(0.1, 10, (2, 1))
        q, rssd = align_vectors(a, b)
        want, want_rssd = scipy_align(a, b)
        assert rotation_angle(q, want) < 1e-14
        assert abs(rssd - want_rssd) < 1e-12 * max(1, want_rssd)
        # minimal: the axis is perpendicular to both vectors, the angle the one between them
        angle = np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b)
        assert abs(2 * np.arctan2(np.linalg.norm(q[1:]), abs(q[0])) - angle) < 1e-14
        assert abs(q[1:] @ a) < 1e-14 * np.linalg.norm(a) and abs(q[1:] @ b) < 1e-14 * np.linalg.norm(b)


def test_parallel_and_antiparallel_pairs():
    # scipy's test_align_vectors_parallel / _antiparallel
    a = [[1.0, 0, 0], [0, 1, 0]]
    b = [[0.0, 1, 0], [0, 1, 0]]
    expected = [[0, 1, 0], [-1, 0, 0], [0, 0, 1]]
    q, _ = align_vectors(a, b, weights=[np.inf, 1])
    np.testing.assert_allclose(Attitude(q).as_matrix(), expected, atol=1e-15)
    q, _ = align_vectors(a[0], b[0])
    np.testing.assert_allclose(Attitude(q).as_matrix(), expected, atol=1e-15)
    for v in ([1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [1.0, 2, 3]):
        q, _ = align_vectors(v, -np.array(v))
        np.testing.assert_allclose(Attitude(q).apply(-np.array(v)), v, atol=1e-14)


def test_infinite_weight_with_more_vectors_matches_scipy(rng):
    for m in (2, 3, 5):
        for _ in range(100):
            q_true = random_quaternions(1, rng)[0]
            b = rng.standard_normal((m, 3))
            a = Attitude(q_true).apply(b) + 0.05 * rng.standard_normal((m, 3))
            w = rng.uniform(0.1, 2, m)
            w[rng.integers(m)] = np.inf
            q, rssd = align_vectors(a, b, w)
            want, want_rssd = scipy_align(a, b, w)
            assert rotation_angle(q, want) < 1e-13
            assert abs(rssd - want_rssd) < 1e-12
            # the primary pair is met exactly (in direction)
            p = int(np.flatnonzero(np.isinf(w))[0])
            c = Attitude(q).apply(b[p])
            np.testing.assert_allclose(c / np.linalg.norm(c), a[p] / np.linalg.norm(a[p]), atol=1e-14)


def test_infinite_weight_is_the_limit_of_large_weights(rng):
    b = rng.standard_normal((3, 3))
    a = Attitude(random_quaternions(1, rng)[0]).apply(b) + 0.05 * rng.standard_normal((3, 3))
    q_inf, _ = align_vectors(a, b, [np.inf, 1, 1])
    q_big, _ = align_vectors(a, b, [1e9, 1, 1])
    assert rotation_angle(q_inf, q_big) < 1e-7


def test_primary_only_when_every_secondary_is_parallel(rng):
    a_p = rng.standard_normal(3)
    b_p = rng.standard_normal(3)
    a = np.stack([a_p, 2 * a_p, -a_p])  # secondaries along the primary axis: no angle about it to fix
    b = np.stack([b_p, 3 * b_p, b_p])
    q, _ = align_vectors(a, b, [np.inf, 1, 1])
    q_primary, _ = align_vectors(a_p, b_p)
    assert rotation_angle(q, q_primary) < 1e-15
    # scipy takes atan2 of the rounding residues here, an arbitrary turn about the primary (3.1 rad for this seed);
    # exact secondaries along the primary must leave the primary's minimal rotation
    c = Attitude(q).apply(b[0])
    np.testing.assert_allclose(c / np.linalg.norm(c), a_p / np.linalg.norm(a_p), atol=1e-15)


def test_many_vectors_is_kabsch_and_vectorised(rng):
    b = rng.standard_normal((20, 6, 3))
    q_true = random_quaternions(20, rng)
    a = Attitude(q_true[:, None, :]).apply(b) + 0.01 * rng.standard_normal((20, 6, 3))
    w = rng.uniform(0.5, 2, 6)
    q, rssd = align_vectors(a, b, w)
    assert q.shape == (20, 4) and rssd.shape == (20,)
    for i in range(20):
        want, want_rssd = scipy_align(a[i], b[i], w)
        assert rotation_angle(q[i], want) < 1e-12
        assert abs(rssd[i] - want_rssd) < 1e-10
    q32, _ = align_vectors(a.astype(np.float32), b.astype(np.float32), w)
    assert q32.dtype == np.float32 and rotation_angle(q32, q).max() < 1e-5


def test_bad_input():
    with pytest.raises(ValueError, match="only one weight may be infinite"):
        align_vectors([[1.0, 0, 0], [0, 1, 0]], [[1.0, 0, 0], [0, 1, 0]], [np.inf, np.inf])
    with pytest.raises(ValueError, match="same shape"):
        align_vectors([[1.0, 0, 0]], [[1.0, 0, 0], [0, 1, 0]])
    with pytest.raises(ValueError, match="negative"):
        align_vectors([[1.0, 0, 0], [0, 1, 0]], [[1.0, 0, 0], [0, 1, 0]], [1.0, -1.0])
    with pytest.raises(ValueError, match="primary vector a"):
        align_vectors([[0.0, 0, 0], [0, 1, 0]], [[1.0, 0, 0], [0, 1, 0]], [np.inf, 1.0])
    with pytest.raises(ValueError, match=r"weights must have shape \(2,\)"):
        align_vectors([[1.0, 0, 0], [0, 1, 0]], [[1.0, 0, 0], [0, 1, 0]], [1.0])


def test_attitude_align_vectors_carries_frames(rng):
    b = rng.standard_normal((4, 3))
    a = rng.standard_normal((4, 3))
    att, rssd = Attitude.align_vectors(a, b, reference="NED", body="FRD")
    q, want = align_vectors(a, b)
    assert (att.reference, att.body) == ("NED", "FRD") and rotation_angle(att.q, q) == 0 and rssd == want


def test_scipy_align_constrain_values():
    # scipy test_align_vectors_align_constrain: primary +X of B onto +Y of A, secondary fixes the turn about it
    m_expected = np.array([[0.0, 0, 1], [1, 0, 0], [0, 1, 0]])
    a = np.array([[0.0, 1, 0], [0, 1, 1]])
    q, rssd = align_vectors(a, [[1.0, 0, 0], [1, 1, 0]], [np.inf, 1])
    np.testing.assert_allclose(Attitude(q).as_matrix(), m_expected, atol=1e-12)
    assert abs(rssd) < 1e-12
    q, rssd = align_vectors(a, [[1.0, 0, 0], [1, 2, 0]], [np.inf, 1])
    np.testing.assert_allclose(Attitude(q).as_matrix(), m_expected, atol=1e-12)
    assert abs(rssd - 1.0) < 1e-12
    q, rssd = align_vectors([[-1.0, 3, 2], [1, -1, 2]], [[1.0, 2, 3], [-2, 3, -1]], [np.inf, 1])
    np.testing.assert_allclose(Attitude(q).apply([1.0, 2, 3]), [-1, 3, 2], atol=1e-12)
    assert abs(rssd - 1.3101595297515016) < 1e-12


def test_one_pair_with_an_infinite_weight_has_zero_rssd():
    """The constrained pair is met exactly and adds nothing to the rssd, as in scipy (0.0), not inf · rounding."""
    q, rssd = align_vectors([1.0, 0, 0], [0.0, 1, 0], weights=[np.inf])
    assert rssd == 0.0
    np.testing.assert_allclose(Attitude(q).apply([0.0, 1, 0]), [1, 0, 0], atol=1e-15)
    _, rssd = align_vectors([2.0, 0, 0], [0.0, 1, 0], weights=[4.0])  # a finite weight still weighs: √(4 · 1²)
    assert rssd == pytest.approx(2.0, abs=1e-15)
