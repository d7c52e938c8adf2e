"""Numba kernels for :mod:`strapdown.rotations.mrp` and :mod:`strapdown.rotations.davenport` (private).

The kernels take rows (any strides) and compute in float64 whatever the storage type; the callers allocate
``out`` in the input's dtype.  They check their input as they go, in the same pass (a separate validation pass
would cost as much as the conversion): each returns -1, or the index of the first row that is not finite (or, for
quaternions, is zero), and the caller then lets :mod:`strapdown._support.validate` raise its usual error for that input.
Quaternions of any finite non-zero size are used.
"""

from __future__ import annotations

import math

import numba as nb

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ._quaternion_numba import qmul


@nb.njit(cache=True, error_model="numpy")
def from_mrp_rows(p, out):
    """Quaternions q = [1 - |p|², 2 p] / (1 + |p|²) (Shuster 1993, §8), computed without overflow.

    With b = max(1, max|p_i|) and p' = p/b, numerator and denominator divided by b² give
    q = [1/b² - |p'|², 2 p'/b] / (1/b² + |p'|²): the same for |p| ≤ 1 (b = 1), and for the shadow parameters of
    a rotation near 360° (|p| → ∞) no square overflows (1/b² underflows harmlessly to 0).  No branch on |p|
    either, so a mix of short and shadow sets costs no mispredicted jumps.
    """
    bad = -1
    for n in range(out.shape[0]):
        x = float(p[n, 0])
        y = float(p[n, 1])
        z = float(p[n, 2])
        big = max(abs(x), abs(y), abs(z))
        # each component on its own: max() drops a NaN that is not first (every comparison with it is false)
        if bad < 0 and not (abs(x) < math.inf and abs(y) < math.inf and abs(z) < math.inf):
            bad = n
        b = max(1.0, big)
        xs = x / b
        ys = y / b
        zs = z / b
        s2 = xs * xs + ys * ys + zs * zs
        inv = 1.0 / (b * b)
        den = inv + s2
        out[n, 0] = (inv - s2) / den
        f = 2.0 / (b * den)
        out[n, 1] = xs * f
        out[n, 2] = ys * f
        out[n, 3] = zs * f
    return bad


@nb.njit(cache=True, inline="always", error_model="numpy")
def _quaternion_row(q, n):
    """Row n of q in float64, and its squared norm."""
    w = float(q[n, 0])
    x = float(q[n, 1])
    y = float(q[n, 2])
    z = float(q[n, 3])
    return w, x, y, z, w * w + x * x + y * y + z * z


@nb.njit(cache=True, inline="always", error_model="numpy")
def _ordinary(n2):
    """Whether a squared norm is far from overflow and underflow (False for zero, NaN and infinity too)."""
    return n2 > 1e-290 and n2 < 1e290


@nb.njit(cache=True, inline="always", error_model="numpy")
def _rescaled(w, x, y, z):
    """The row scaled by a power of two (exact; the rotation is unchanged) so that its squared norm is ordinary.

    Returns the components and the new squared norm, which is 0, NaN or infinite for a zero or non-finite row.
    """
    big = max(abs(w), abs(x), abs(y), abs(z))
    if big > 0.0 and big < math.inf:
        e = math.frexp(big)[1]
        w = math.ldexp(w, -e)
        x = math.ldexp(x, -e)
        y = math.ldexp(y, -e)
        z = math.ldexp(z, -e)
    return w, x, y, z, w * w + x * x + y * y + z * z


@nb.njit(cache=True, inline="always", error_model="numpy")
def _mrp(w, x, y, z, n2):
    """The MRP sgn(w) v / (|q| + |w|) of one row, scale-invariant in q."""
    # sgn(w) without a branch on it (its sign is random for random attitudes: a branch would be mispredicted
    # half the time); the tie w = ±0 is rare and takes the canonical rule
    s = math.copysign(1.0, w)
    if w == 0.0:
        s = -1.0 if (x < 0.0 or (x == 0.0 and (y < 0.0 or (y == 0.0 and z < 0.0)))) else 1.0
    f = s / (math.sqrt(n2) + abs(w))
    return x * f, y * f, z * f


@nb.njit(cache=True, error_model="numpy")
def as_mrp_rows(q, out):
    """MRPs p = v / (|q| + |w|) with the sign of w: the short set, |p| = tan(χ/4) ≤ 1 for χ in [0, π].

    At w = 0 (χ = 180°) both sets have |p| = 1; the sign rule of ``quaternion.canonical`` (first non-zero
    component positive) picks one, so q and -q agree.  Quaternions of any finite non-zero size are used: rows
    whose squared norm would overflow or underflow (|q| beyond about 1e±145, never for float32) are redone
    after an exact rescaling, in a second loop, so that the first one stays simple enough to vectorise.
    """
    odd = -1
    for n in range(out.shape[0]):
        w, x, y, z, n2 = _quaternion_row(q, n)
        if odd < 0 and not _ordinary(n2):
            odd = n
        out[n, 0], out[n, 1], out[n, 2] = _mrp(w, x, y, z, n2)
    if odd < 0:
        return -1
    for n in range(odd, out.shape[0]):
        w, x, y, z, n2 = _quaternion_row(q, n)
        if not _ordinary(n2):
            w, x, y, z, n2 = _rescaled(w, x, y, z)
            if not _ordinary(n2):
                return n  # zero, NaN or infinite
            out[n, 0], out[n, 1], out[n, 2] = _mrp(w, x, y, z, n2)
    return -1


@nb.njit(cache=True, error_model="numpy")
def from_axes_rows(angles, axes, extrinsic, out):
    """out[n] = e(n_1, a_1) ⊗ e(n_2, a_2) ⊗ ... (intrinsic) or ... ⊗ e(n_2, a_2) ⊗ e(n_1, a_1) (extrinsic).

    e(n, a) = [cos(a/2), sin(a/2) n] for the unit axes ``axes`` (k, 3); ``angles`` is (N, k).
    """
    k = axes.shape[0]
    bad = -1
    for n in range(out.shape[0]):
        w, x, y, z = 1.0, 0.0, 0.0, 0.0
        for m in range(k):
            h = 0.5 * float(angles[n, m])
            if bad < 0 and not abs(h) < math.inf:
                bad = n
            c = math.cos(h)
            s = math.sin(h)
            ex, ey, ez = s * axes[m, 0], s * axes[m, 1], s * axes[m, 2]
            if extrinsic:
                w, x, y, z = qmul(c, ex, ey, ez, w, x, y, z)
            else:
                w, x, y, z = qmul(w, x, y, z, c, ex, ey, ez)
        out[n, 0] = w
        out[n, 1] = x
        out[n, 2] = y
        out[n, 3] = z
    return bad


@nb.njit(cache=True, error_model="numpy")
def _wrap(a):
    """An angle in (-3π, 3π) wrapped into (-π, π]."""
    while a > math.pi:
        a -= 2.0 * math.pi
    while a <= -math.pi:
        a += 2.0 * math.pi
    return a


@nb.njit(cache=True, error_model="numpy")
def as_davenport_rows(q, n1, n2, n3, lam, flip, extrinsic, scale, out):
    """Davenport angles of the extrinsic sequence (n1, n2, n3) (the caller reverses an intrinsic one).

    Shuster and Markley (2003), in the direct half-angle form of Bernardes and Viollet (2022) as scipy uses it:
    with λ the angle from n1 to n3 about n2 (made ≥ 0 by flipping n2, ``flip``), the quaternion
    q' = [cos(λ/2), sin(λ/2) n2] ⊗ q has the components a = w', b = v'·n1, c = v'·n2, d = v'·(n1 × n2), and
        a + i b = cos(β/2) e^{i(α+γ)/2},   c + i d = sin(β/2) e^{i(γ-α)/2},   β_Davenport = β - λ.
    Both half angles come from the same quaternion, so no threshold is needed near gimbal lock; only at the lock
    itself (c = d = 0 or a = b = 0 exactly) the third angle is set to 0 and the first carries the rotation.
    """
    cx = n1[1] * n2[2] - n1[2] * n2[1]
    cy = n1[2] * n2[0] - n1[0] * n2[2]
    cz = n1[0] * n2[1] - n1[1] * n2[0]
    ch = math.cos(0.5 * lam)
    sh = math.sin(0.5 * lam)
    bad = -1
    for n in range(out.shape[0]):
        qw = float(q[n, 0])
        qx = float(q[n, 1])
        qy = float(q[n, 2])
        qz = float(q[n, 3])
        # a, b, c and d are linear in q and only their ratios count (atan2, hypot): any finite non-zero size will do
        big = max(abs(qw), abs(qx), abs(qy), abs(qz))
        if bad < 0 and not (big > 0.0 and big < math.inf):
            bad = n
        w, x, y, z = qmul(ch, sh * n2[0], sh * n2[1], sh * n2[2], qw, qx, qy, qz)
        a = w
        b = x * n1[0] + y * n1[1] + z * n1[2]
        c = x * n2[0] + y * n2[1] + z * n2[2]
        d = x * cx + y * cy + z * cz
        half_sum = math.atan2(b, a)
        half_diff = math.atan2(d, c)
        middle = 2.0 * math.atan2(math.hypot(c, d), math.hypot(a, b))
        if c == 0.0 and d == 0.0:  # β = 0: only α + γ is defined
            first = 2.0 * half_sum
            third = 0.0
        elif a == 0.0 and b == 0.0:  # β = π: only γ - α is defined
            first = -2.0 * half_diff if extrinsic else 2.0 * half_diff
            third = 0.0
        elif extrinsic:
            first = half_sum - half_diff
            third = half_sum + half_diff
        else:
            first = half_sum + half_diff
            third = half_sum - half_diff
        middle -= lam
        if flip:
            middle = -middle
        out[n, 0] = _wrap(first) * scale
        out[n, 1] = middle * scale
        out[n, 2] = _wrap(third) * scale
    return bad
