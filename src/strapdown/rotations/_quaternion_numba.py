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
    """Hamilton product of two quaternions given by components (Gajda 2.14, reordered scalar first)."""
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
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
