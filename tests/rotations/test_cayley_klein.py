import numpy as np
import pytest
from scipy.linalg import expm

from conftest import random_quaternions, rotation_angle
from strapdown import as_cayley_klein, as_matrix, as_rotvec, from_cayley_klein, multiply

SIGMA = np.array([[[0, 1], [1, 0]], [[0, -1j], [1j, 0]], [[1, 0], [0, -1]]])  # Pauli σ1, σ2, σ3


def test_pauli_exponential_rowe_eq_21(rng):
    """Rowe eqs. 19-21: Q = σ0 cos(θ/2) - i (n·σ) sin(θ/2) = exp(-i σ·θ/2), computed here by scipy's expm."""
    q = random_quaternions(200, rng)
    theta = as_rotvec(q)
    u = as_cayley_klein(q)
    for k in range(200):
        ref = expm(-0.5j * np.einsum("i,ijk->jk", theta[k], SIGMA))
        # as_rotvec picks the short way round, so compare up to the sign of q
        assert min(np.abs(u[k] - ref).max(), np.abs(u[k] + ref).max()) < 1e-14


def test_homomorphism_and_su2(rng):
    p = random_quaternions(1000, rng)
    q = random_quaternions(1000, rng)
    up, uq = as_cayley_klein(p), as_cayley_klein(q)
    np.testing.assert_allclose(as_cayley_klein(multiply(p, q)), up @ uq, atol=1e-15)
    eye = np.broadcast_to(np.eye(2), up.shape)
    np.testing.assert_allclose(up @ np.conj(up.swapaxes(-1, -2)), eye, atol=1e-15)
    np.testing.assert_allclose(np.linalg.det(up), 1, atol=1e-15)


def test_vector_rotation(rng):
    q = random_quaternions(100, rng)
    v = rng.standard_normal((100, 3))
    u = as_cayley_klein(q)
    vs = np.einsum("ni,ijk->njk", v, SIGMA)
    rotated = u @ vs @ np.conj(u.swapaxes(-1, -2))
    cv = np.einsum("nij,nj->ni", as_matrix(q), v)
    np.testing.assert_allclose(rotated, np.einsum("ni,ijk->njk", cv, SIGMA), atol=1e-14)


def test_round_trip(rng):
    q = random_quaternions(1000, rng)
    np.testing.assert_allclose(from_cayley_klein(as_cayley_klein(q)), q, atol=1e-15)
    q32 = q.astype(np.float32)
    assert as_cayley_klein(q32).dtype == np.complex64
    back = from_cayley_klein(as_cayley_klein(q32))
    assert back.dtype == np.float32
    assert rotation_angle(back, q).max() < 1e-6


def test_rejects_non_su2():
    with pytest.raises(ValueError, match=r"u is not in SU\(2\)"):
        from_cayley_klein(np.array([[1, 0], [0, -1]], dtype=complex))
    with pytest.raises(ValueError, match=r"u is not in SU\(2\)"):
        from_cayley_klein(2 * np.eye(2, dtype=complex))
    with pytest.raises(ValueError, match=r"u must have shape"):
        from_cayley_klein(np.eye(3))
    with pytest.raises(ValueError, match=r"is not finite"):
        from_cayley_klein(np.array([[np.nan, 0], [0, 1]]))
