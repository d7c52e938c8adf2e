"""Numba kernels for :mod:`strapdown.rotations.quaternion` (private).

The kernels take validated, C-contiguous (n, 4) arrays.  An operand with a single row is broadcast against the
other inside the loop, so a constant quaternion is never copied n times.  ``qmul`` is the scalar Hamilton product
that the other kernels in the package (integrators, filters) call in their own loops.
"""

from __future__ import annotations

import numba as nb

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)


@nb.njit(cache=True)
def qmul(aw, ax, ay, az, bw, bx, by, bz):
    """Hamilton product of two quaternions given by components (Gajda 2.14, reordered scalar first).

    Each vector component sums its terms in pairs, ``(aw b + bw a) + (a × b)``, and each pair cancels exactly
    when b is a's conjugate: so ``q* ⊗ q`` and ``q ⊗ q*`` have a vector part of exactly zero (a constant attitude
    has exactly zero rate in a spline), where left-to-right sums left a rounding error of 3e-17.
    """
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        (aw * bx + ax * bw) + (ay * bz - az * by),
        (aw * by + ay * bw) + (az * bx - ax * bz),
        (aw * bz + az * bw) + (ax * by - ay * bx),
    )


@nb.njit(cache=True)
def multiply_rows(p, q, out):
    """out[n] = p[n] ⊗ q[n]; p or q may have one row, broadcast against the other."""
    n_rows = out.shape[0]
    if p.shape[0] == 1 and n_rows > 1:  # one fixed rotation (a frame change): constants in registers
        pw, px, py, pz = p[0, 0], p[0, 1], p[0, 2], p[0, 3]
        for n in range(n_rows):
            w, x, y, z = qmul(pw, px, py, pz, q[n, 0], q[n, 1], q[n, 2], q[n, 3])
            out[n, 0] = w
            out[n, 1] = x
            out[n, 2] = y
            out[n, 3] = z
        return
    p_step = 1 if p.shape[0] > 1 else 0
    q_step = 1 if q.shape[0] > 1 else 0
    for n in range(n_rows):
        i = n * p_step
        j = n * q_step
        w, x, y, z = qmul(p[i, 0], p[i, 1], p[i, 2], p[i, 3], q[j, 0], q[j, 1], q[j, 2], q[j, 3])
        out[n, 0] = w
        out[n, 1] = x
        out[n, 2] = y
        out[n, 3] = z


@nb.njit(cache=True)
def unit_again(w, x, y, z):
    """A quaternion off unit norm by rounding only, brought back: one Newton step for 1/|q|, ``(3 - |q|²)/2``.

    For ``|q|² = 1 + δ`` the factor is ``1 - δ/2``, which leaves ``|q| = 1 - (3/8) δ² + O(δ³)`` (nabbla part 9,
    eqs. 6-7): for the ``δ`` of a few ulps that a product of unit quaternions carries, the remaining error is the
    rounding of the four multiplications alone (≤ 3.4e-16 in float64 over 10⁶ random products), without the
    square root and division of ``q / |q|``.  Only for quaternions that are unit to rounding (``|δ| ≪ 1``).
    """
    s = 1.5 - 0.5 * (w * w + x * x + y * y + z * z)
    return w * s, x * s, y * s, z * s


@nb.njit(cache=True)
def multiply_unit_rows(p, q, out):
    """Out = p ⊗ q brought back to unit norm (:func:`unit_again`), for unit p and q, on flat (4n,) views.

    The composition of :class:`strapdown.Attitude`: without it rounding grows |q| by a few ulps per product,
    geometrically in chains such as ``r = r * p * r`` (|q| - 1 = 0.28 after 50).  p and q have 4n components
    each, or 4 (one quaternion for every row).  Flat indexing and one loop per case, with a single quaternion
    held in locals, let the compiler keep the Newton step at no cost over :func:`multiply_rows`
    (benchmarks/bench_composition.py).
    """
    m = out.shape[0] // 4
    if p.shape[0] == q.shape[0]:
        for n in range(m):
            k = 4 * n
            w, x, y, z = qmul(p[k], p[k + 1], p[k + 2], p[k + 3], q[k], q[k + 1], q[k + 2], q[k + 3])
            w, x, y, z = unit_again(w, x, y, z)
            out[k], out[k + 1], out[k + 2], out[k + 3] = w, x, y, z
    elif q.shape[0] == 4:
        bw, bx, by, bz = q[0], q[1], q[2], q[3]
        for n in range(m):
            k = 4 * n
            w, x, y, z = qmul(p[k], p[k + 1], p[k + 2], p[k + 3], bw, bx, by, bz)
            w, x, y, z = unit_again(w, x, y, z)
            out[k], out[k + 1], out[k + 2], out[k + 3] = w, x, y, z
    else:
        aw, ax, ay, az = p[0], p[1], p[2], p[3]
        for n in range(m):
            k = 4 * n
            w, x, y, z = qmul(aw, ax, ay, az, q[k], q[k + 1], q[k + 2], q[k + 3])
            w, x, y, z = unit_again(w, x, y, z)
            out[k], out[k + 1], out[k + 2], out[k + 3] = w, x, y, z


@nb.njit(cache=True)
def best_reduction_rows(p, left, right, left_best, right_best):
    """For each p[n], the pair (i, j) with the largest |w| of left[i] ⊗ p[n] ⊗ right[j] (first such pair, i major).

    |w| = |cos(angle/2)|, so this is the pair of least rotation angle; ``w(l ⊗ m) = l · m̄`` with m̄ = (w, -v) of
    m = p ⊗ r, which costs four products per left element.
    """
    for n in range(p.shape[0]):
        best = -1.0
        bi = 0
        bj = 0
        for j in range(right.shape[0]):
            mw, mx, my, mz = qmul(
                p[n, 0], p[n, 1], p[n, 2], p[n, 3], right[j, 0], right[j, 1], right[j, 2], right[j, 3]
            )
            for i in range(left.shape[0]):
                s = abs(left[i, 0] * mw - left[i, 1] * mx - left[i, 2] * my - left[i, 3] * mz)
                if s > best or (s == best and (i < bi or (i == bi and j < bj))):
                    best = s
                    bi = i
                    bj = j
        left_best[n] = bi
        right_best[n] = bj
