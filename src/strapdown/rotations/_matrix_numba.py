"""Numba kernels for :mod:`strapdown.rotations.matrix` (private)."""

from __future__ import annotations

import math

import numba as nb

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)


@nb.njit(cache=True)
def as_matrix_rows(q, out):
    """out[n] = R(q[n]), the body-to-reference matrix, exact for any non-zero q (scaled by 2/|q|²)."""
    for n in range(q.shape[0]):
        w = q[n, 0]
        x = q[n, 1]
        y = q[n, 2]
        z = q[n, 3]
        s = 2.0 / (w * w + x * x + y * y + z * z)
        xx = s * x * x
        yy = s * y * y
        zz = s * z * z
        xy = s * x * y
        xz = s * x * z
        yz = s * y * z
        wx = s * w * x
        wy = s * w * y
        wz = s * w * z
        out[n, 0, 0] = 1.0 - (yy + zz)
        out[n, 0, 1] = xy - wz
        out[n, 0, 2] = xz + wy
        out[n, 1, 0] = xy + wz
        out[n, 1, 1] = 1.0 - (xx + zz)
        out[n, 1, 2] = yz - wx
        out[n, 2, 0] = xz - wy
        out[n, 2, 1] = yz + wx
        out[n, 2, 2] = 1.0 - (xx + yy)


@nb.njit(cache=True, inline="always")
def _pivot(four_sq, d0, d1, d2):
    """Shepperd's step for the largest component c, 4c² = ``four_sq``: c and the other three, ``d / (4c)``."""
    r = math.sqrt(four_sq)
    f = 0.5 / r
    return 0.5 * r, d0 * f, d1 * f, d2 * f


@nb.njit(cache=True)
def shepperd(c00, c01, c02, c10, c11, c12, c20, c21, c22):
    """Largest-pivot (Shepperd 1978) unit quaternion of a rotation matrix, canonical sign (w > 0, ties x, y, z).

    Of 4w², 4x², 4y², 4z² (= 1 + tr, 1 + 2 C00 - tr, ...) the largest is taken from the diagonal, which keeps
    the square root away from zero and the divisor at least 1/2; the other three components come from the
    off-diagonal sums and differences.  The four candidates sum to 4, so the largest is at least 1 for any
    matrix and nothing here can divide by zero; a matrix that is not a rotation gives a meaningless result.
    """
    tr = c00 + c11 + c22
    if tr >= c00 and tr >= c11 and tr >= c22:
        w, x, y, z = _pivot(1.0 + tr, c21 - c12, c02 - c20, c10 - c01)
    elif c00 >= c11 and c00 >= c22:
        x, w, y, z = _pivot(1.0 + 2.0 * c00 - tr, c21 - c12, c01 + c10, c02 + c20)
    elif c11 >= c22:
        y, w, x, z = _pivot(1.0 + 2.0 * c11 - tr, c02 - c20, c01 + c10, c12 + c21)
    else:
        z, w, x, y = _pivot(1.0 + 2.0 * c22 - tr, c10 - c01, c02 + c20, c12 + c21)
    inv = 1.0 / math.sqrt(w * w + x * x + y * y + z * z)
    if w < 0.0 or (w == 0.0 and (x < 0.0 or (x == 0.0 and (y < 0.0 or (y == 0.0 and z < 0.0))))):
        inv = -inv
    return w * inv + 0.0, x * inv + 0.0, y * inv + 0.0, z * inv + 0.0


@nb.njit(cache=True)
def from_matrix_rows(c, out, orth_err, det):
    """Shepperd quaternion of each matrix, with its orthogonality error max |CᵀC - I| and determinant."""
    for n in range(c.shape[0]):
        c00 = float(c[n, 0, 0])
        c01 = float(c[n, 0, 1])
        c02 = float(c[n, 0, 2])
        c10 = float(c[n, 1, 0])
        c11 = float(c[n, 1, 1])
        c12 = float(c[n, 1, 2])
        c20 = float(c[n, 2, 0])
        c21 = float(c[n, 2, 1])
        c22 = float(c[n, 2, 2])
        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = shepperd(c00, c01, c02, c10, c11, c12, c20, c21, c22)
        # CᵀC - I, entry by entry (symmetric: six distinct entries)
        e = abs(c00 * c00 + c10 * c10 + c20 * c20 - 1.0)
        e = max(e, abs(c01 * c01 + c11 * c11 + c21 * c21 - 1.0))
        e = max(e, abs(c02 * c02 + c12 * c12 + c22 * c22 - 1.0))
        e = max(e, abs(c00 * c01 + c10 * c11 + c20 * c21))
        e = max(e, abs(c00 * c02 + c10 * c12 + c20 * c22))
        e = max(e, abs(c01 * c02 + c11 * c12 + c21 * c22))
        orth_err[n] = e
        det[n] = c00 * (c11 * c22 - c12 * c21) - c01 * (c10 * c22 - c12 * c20) + c02 * (c10 * c21 - c11 * c20)
