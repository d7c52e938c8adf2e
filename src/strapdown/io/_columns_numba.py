"""Numba kernel for :func:`strapdown.io.tables.attitude_columns` (private): quaternion and Euler columns in one pass.

The file commands write each attitude as the columns qw, qx, qy, qz and three Euler angles.  Converting with
``as_euler`` and then transposing both (N, 4) and (N, 3) into the writer's contiguous columns read and wrote
every value three times; this kernel reads each quaternion once and writes its seven column entries, rounded
to the output type (float32 or float64) on the store.  The angles are those of
:func:`strapdown.rotations._euler_numba.as_euler_rows` bit for bit: the same inlined steps in the same order, in float64
(the pipeline's quaternions are float64), followed by the ``yaw_range="positive"`` fold of
:func:`strapdown.as_euler` in float64, and only then the rounding to the output type.  It releases the GIL, so
the reader's and writer's threads run meanwhile.

The block loop of ``as_euler_rows`` is run here rather than called, its step (``block_rows``) inlined: calling it
on slices of 4096 rows into a small (4096, 3) array and copying from there took 5.3 against 4.2 ms per 2^18
rows (same bits; interleaved micro-benchmark, notes/h-io3.md).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ..rotations._euler_numba import BLOCK, block_rows, block_scratch


@nb.njit(cache=True, nogil=True, error_model="numpy")
def quat_euler_columns(q, qe, euler, i, j, k, proper, sign, intrinsic, scale, half, full, positive, out):
    """out[0:4, n] = q[n] and, with `euler`, out[4:7, n] = the Euler angles of qe[n] (as ``as_euler_rows``).

    `q` and `qe` are C-contiguous float64 (N, 4): the quaternions written, and the same ones as validated for
    the angles (``_validate.rotations`` may rescale a row by a power of two, which leaves its angles alone).
    The axes, `proper`, `sign`, `intrinsic`, `scale`, `half` and `full` are those ``as_euler`` passes to
    ``as_euler_rows`` for float64 input; `positive` applies its ``yaw_range="positive"`` fold to the outer angle
    (column 0 for intrinsic sequences, 2 for extrinsic).  `out` is C-ordered (4 or 7, N), float32 or float64.
    """
    n_rows = q.shape[0]
    for n in range(n_rows):
        out[0, n] = q[n, 0]
        out[1, n] = q[n, 1]
        out[2, n] = q[n, 2]
        out[3, n] = q[n, 3]
    if not euler:
        return
    outer = 0 if intrinsic else 2
    scratch = block_scratch()
    angles = np.empty((BLOCK, 3))
    for start in range(0, n_rows, BLOCK):
        stop = min(start + BLOCK, n_rows)
        block_rows(qe, start, stop, i, j, k, proper, sign, intrinsic, scale, False, half, full, scratch, angles, 0)
        if positive:  # as_euler: angle[angle < 0] += full, then angle[angle >= full] -= full, in float64
            for r in range(stop - start):
                a = angles[r, outer]
                a = a + full if a < 0.0 else a
                angles[r, outer] = a - full if a >= full else a
        for r in range(stop - start):
            out[4, start + r] = angles[r, 0]
            out[5, start + r] = angles[r, 1]
            out[6, start + r] = angles[r, 2]
