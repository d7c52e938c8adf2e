import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_quaternions, rotation_angle
from strapdown import as_matrix, from_matrix


@pytest.fixture(scope="module")
def rotations():
    rot = Rotation.random(100_000, rng=np.random.default_rng(11))
    return rot, rot.as_quat(scalar_first=True), rot.as_matrix()


def test_as_matrix_matches_scipy(rotations):
    _, q, m = rotations
    assert np.abs(as_matrix(q) - m).max() <= 1e-15


def test_as_matrix_non_unit_quaternion(rotations):
    _, q, m = rotations
    assert np.abs(as_matrix(3.5 * q[:1000]) - m[:1000]).max() <= 2e-15


def test_from_matrix_matches_scipy(rotations):
    _, q, m = rotations
    ours = from_matrix(m)
    assert rotation_angle(ours, q).max() <= 1e-12
    assert (ours[:, 0] >= 0).all()
    assert np.abs(np.linalg.norm(ours, axis=-1) - 1).max() <= 3e-16


def test_from_matrix_180_degree_rotations(rng):
    """Largest pivot: rotations by exactly π (trace -1, w = 0) come back to full precision."""
    axis = rng.standard_normal((10_000, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    # C = 2 n nᵀ - I for a half turn about n
    c = 2 * axis[:, :, None] * axis[:, None, :] - np.eye(3)
    q = from_matrix(c)
    assert np.abs(q[:, 0]).max() <= 1e-15
    assert np.abs(np.abs(np.sum(q[:, 1:] * axis, axis=-1)) - 1).max() <= 1e-15


def test_from_matrix_near_180_degrees(rng):
    axis = rng.standard_normal((1000, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    rot = Rotation.from_rotvec(axis * (np.pi - 1e-9))
    assert rotation_angle(from_matrix(rot.as_matrix()), rot.as_quat(scalar_first=True)).max() < 1e-15


def test_round_trip_and_orthonormality(rng):
    q = random_quaternions(10_000, rng)
    c = as_matrix(q)
    np.testing.assert_allclose(c @ c.swapaxes(-1, -2), np.broadcast_to(np.eye(3), c.shape), atol=2e-15)
    np.testing.assert_allclose(np.linalg.det(c), 1, atol=2e-15)
    assert rotation_angle(from_matrix(c), q).max() <= 1e-15


def _davenport(m):
    """Optimal quaternion of a noisy matrix (Bar-Itzhack 2000): eigenvector of the largest eigenvalue of the
    symmetric K built from M; an independent route to the nearest rotation."""
    k = np.empty((*m.shape[:-2], 4, 4))
    k[..., 0, 0] = m[..., 0, 0] + m[..., 1, 1] + m[..., 2, 2]
    k[..., 0, 1] = k[..., 1, 0] = m[..., 2, 1] - m[..., 1, 2]
    k[..., 0, 2] = k[..., 2, 0] = m[..., 0, 2] - m[..., 2, 0]
    k[..., 0, 3] = k[..., 3, 0] = m[..., 1, 0] - m[..., 0, 1]
    k[..., 1, 1] = m[..., 0, 0] - m[..., 1, 1] - m[..., 2, 2]
    k[..., 1, 2] = k[..., 2, 1] = m[..., 0, 1] + m[..., 1, 0]
    k[..., 1, 3] = k[..., 3, 1] = m[..., 0, 2] + m[..., 2, 0]
    k[..., 2, 2] = -m[..., 0, 0] + m[..., 1, 1] - m[..., 2, 2]
    k[..., 2, 3] = k[..., 3, 2] = m[..., 1, 2] + m[..., 2, 1]
    k[..., 3, 3] = -m[..., 0, 0] - m[..., 1, 1] + m[..., 2, 2]
    _, vec = np.linalg.eigh(k)
    return vec[..., :, -1]


def test_orthonormalize_noisy_matrices(rng):
    q = random_quaternions(2000, rng)
    noisy = as_matrix(q) + 1e-3 * rng.standard_normal((2000, 3, 3))
    with pytest.raises(ValueError, match=r"c\[0\] is not a rotation matrix.*orthonormalize=True"):
        from_matrix(noisy)
    ours = from_matrix(noisy, orthonormalize=True)
    assert rotation_angle(ours, _davenport(noisy)).max() < 1e-12


def test_tolerance_accepts_six_decimal_matrices(rng):
    q = random_quaternions(1000, rng)
    printed = np.round(as_matrix(q), 6)
    assert rotation_angle(from_matrix(printed), q).max() < 1e-5


def test_gajda_b_is_the_transpose(rng):
    q = random_quaternions(10, rng)
    v = rng.standard_normal((10, 3))
    b = as_matrix(q).swapaxes(-1, -2)  # reference -> body
    v_ref = np.einsum("nij,nj->ni", as_matrix(q), v)
    np.testing.assert_allclose(np.einsum("nij,nj->ni", b, v_ref), v, atol=1e-14)


def test_float32(rng):
    q = random_quaternions(100, rng).astype(np.float32)
    c = as_matrix(q)
    assert c.dtype == np.float32
    out = from_matrix(c)
    assert out.dtype == np.float32
    assert rotation_angle(out, q).max() < 1e-6


def test_bad_matrices():
    with pytest.raises(ValueError, match=r"c is an improper matrix"):
        from_matrix(np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(ValueError, match=r"c is an improper matrix"):
        from_matrix(np.diag([1.0, 1.0, -1.0]), orthonormalize=True)
    with pytest.raises(ValueError, match=r"c is not a rotation matrix"):
        from_matrix(2 * np.eye(3))
    c = np.stack([np.eye(3), np.eye(3)])
    c[1, 1, 2] = np.nan
    with pytest.raises(ValueError, match=r"c\[1, 1, 2\] is NaN"):
        from_matrix(c)
    with pytest.raises(ValueError, match=r"c must have shape \(\.\.\., 3, 3\)"):
        from_matrix(np.eye(4))
    with pytest.raises(ValueError, match="zero quaternion"):
        as_matrix([0.0, 0, 0, 0])
