"""Direction-cosine matrices.

``as_matrix(q)`` is the body-to-reference matrix C with ``v_ref = C v_body`` (math.md, R(q)).  Gajda's matrix B
(2.10, 2.13) maps reference coordinates to body coordinates, so **B = Cᵀ**.  Gajda's stage 4 reads B with
transposed indices (it writes B(3,1), B(3,2), B(2,1) where (2.10) and (2.13) give B13, B23, B12); strapdown never
reads angles off matrix elements (see :mod:`strapdown.rotations.euler`), so that slip cannot reach it.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["as_matrix", "from_matrix"]


def as_matrix(q, *, check: bool = True) -> np.ndarray:
    """Body-to-reference direction-cosine matrices ``C = R(q)``, ``v_ref = C @ v_body``.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions ``[w, x, y, z]``; a non-unit ``q`` gives the matrix of ``q / |q|``.

    Returns
    -------
    numpy.ndarray, shape (..., 3, 3)
        Rotation matrices.  Gajda's B (2.13) is the transpose, ``as_matrix(q).swapaxes(-1, -2)``.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_matrix
    >>> as_matrix([np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]).round(12)   # yaw 90 deg
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    q = _v.rotations(q, "q", check=check)
    shape = q.shape[:-1]
    rows = np.ascontiguousarray(q.reshape(-1, 4))
    out = np.empty((rows.shape[0], 3, 3), dtype=q.dtype)
    from ._matrix_numba import as_matrix_rows

    as_matrix_rows(rows, out)
    return out.reshape((*shape, 3, 3))


def _nearest_rotation(c: np.ndarray) -> np.ndarray:
    """Orthogonal polar factor of each matrix (the nearest rotation in the Frobenius norm), via the SVD."""
    u, _, vt = np.linalg.svd(c)
    d = np.sign(np.linalg.det(u @ vt))
    u[..., :, 2] *= d[..., None]
    return u @ vt


def from_matrix(c, *, orthonormalize: bool = False, atol: float = 1e-5, check: bool = True) -> np.ndarray:
    """Attitude quaternions from body-to-reference rotation matrices (largest-pivot method).

    Parameters
    ----------
    c : array_like, shape (..., 3, 3)
        Proper rotation matrices C with ``v_ref = C v_body`` (for Gajda's B pass ``B.T``).
    orthonormalize : bool
        First replace each matrix by the nearest rotation (orthogonal polar factor, from the SVD).  Use this
        for noisy or drifted matrices, e.g. a direction-cosine matrix integrated without re-orthogonalisation.
    atol : float
        Without ``orthonormalize``, a matrix with ``max |CᵀC - I| > atol`` is rejected.  The default accepts
        matrices printed with six decimals.
    check : bool
        Reject NaN, infinities, improper (det ≤ 0) and non-orthonormal matrices (default).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions in canonical sign (w ≥ 0; see :func:`strapdown.rotations.quaternion.canonical`).

    Raises
    ------
    ValueError
        For a matrix that is not a proper rotation within ``atol``, naming the first offending index.

    Notes
    -----
    Shepperd's method: of ``4w², 4x², 4y², 4z²`` (read off the trace and the diagonal) the largest is found by a
    square root, and the other three components by dividing off-diagonal sums and differences by it.  The
    divisor is never below 1/2, so the result is accurate for every rotation, including 180° ones.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_matrix
    >>> yaw90 = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    >>> from_matrix(yaw90)
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    if isinstance(atol, bool) or not isinstance(atol, int | float | np.integer | np.floating) or not atol >= 0:
        raise ValueError(f"atol must be a non-negative number (the largest |CᵀC - I| accepted), got {atol!r}")
    c = _v.as_float_array(c, "c")
    if c.ndim < 2 or c.shape[-2:] != (3, 3):
        raise ValueError(f"c must have shape (..., 3, 3) (rotation matrices), got shape {c.shape}")
    if check:
        _v.check_finite(c, "c")
    if orthonormalize:
        if check:
            det = np.linalg.det(c)
            if not (det > 0).all():
                raise ValueError(
                    f"c{_v.first_index(~(det > 0))} is an improper matrix (det ≤ 0); "
                    "a reflection has no rotation quaternion"
                )
        c = _nearest_rotation(c).astype(c.dtype, copy=False)
    shape = c.shape[:-2]
    rows = np.ascontiguousarray(c.reshape(-1, 3, 3))
    n = rows.shape[0]
    out = np.empty((n, 4), dtype=c.dtype)
    orth_err = np.empty(n, dtype=np.float64)
    det = np.empty(n, dtype=np.float64)
    from .._support.uncompiled import call
    from ._matrix_numba import from_matrix_rows

    call(from_matrix_rows, rows, out, orth_err, det, python_seconds=6e-6 * n)  # 6 µs a row uncompiled
    if check:
        bad = ~(orth_err <= atol)
        if bad.any():
            raise ValueError(
                f"c{_v.first_index(bad.reshape(shape))} is not a rotation matrix: max |CᵀC - I| = "
                f"{orth_err[bad][0]:.3g} > atol={atol:g}; pass orthonormalize=True to use the nearest rotation"
            )
        bad = ~(det > 0)
        if bad.any():
            raise ValueError(
                f"c{_v.first_index(bad.reshape(shape))} is an improper matrix (det = {det[bad][0]:.3g}); "
                "a reflection has no rotation quaternion"
            )
    return out.reshape((*shape, 4))
