"""Numba kernels for :mod:`strapdown.integrate`: the step-quaternion methods (private).

exact, first-order, second-order and cayley all update ``q_{k+1} = q_k ⊗ m(φ_k)`` with a step quaternion that
depends on the step's rotation vector φ_k alone, so the attitudes are prefix products of independent factors.
Two kernels compute them: a sequential loop (the reference, and the streaming path, bit-identical under any
chunking) and a blocked prefix scan (within rounding of the sequential one), built twice: in parallel and on
one thread, with the same result (:mod:`strapdown._support.threads` chooses).  The entry kernels release the GIL
(``nogil``), so that other Python threads (the background Parquet writer, a threaded Dask worker) run meanwhile.

Every kernel computes in float64 whatever the storage type, and reads φ_k = g[k] · h[k·hstep] · scale, so the same
code serves rates with a scalar or per-step dt, interval averages and increments (h = 1), in rad or deg.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ..rotations._quaternion_numba import qmul

KIND_EXACT = 0
KIND_FIRST = 1
KIND_SECOND = 2
KIND_CAYLEY = 3

NORM_NONE = 0
NORM_EXACT = 1
NORM_SERIES = 2

# Below this squared half angle (|φ|/2 < 0.25 rad, i.e. 28.6° per step) the Taylor series of cos and sin(x)/x in
# u = x² with terms to u^7 is exact to double precision: the first omitted terms are u^8/16! < 1.2e-23 and
# u^8/17! < 6.6e-25.  No square root, sine or cosine is needed (issue 3).
TAYLOR_LIMIT = 0.0625
TAYLOR_SHORT = 0.01


@nb.njit(cache=True, inline="always", error_model="numpy")
def exp_half_minus_one(px, py, pz):
    """exp(φ/2) - 1 = [cos|φ/2| - 1, φ/2 · sin|φ/2| / |φ/2|] (Gajda stage 2), with no cancellation in cos - 1.

    φ = 0 needs no division.  Returning the step quaternion minus one lets the update be q + q ⊗ (m - 1): one
    rounding of an O(1) number per component and step instead of seven, which removes a rounding bias that
    otherwise reaches 2e-12 rad over 10^6 steps (the test of a constant rate).
    """
    ax = 0.5 * px
    ay = 0.5 * py
    az = 0.5 * pz
    u = ax * ax + ay * ay + az * az
    if u < TAYLOR_SHORT:  # |φ/2| < 0.1: terms to u^4; the first omitted are u^5/10! < 2.8e-17, u^5/11! < 2.6e-18
        cm1 = u * (-1.0 / 2.0 + u * (1.0 / 24.0 + u * (-1.0 / 720.0 + u * (1.0 / 40320.0))))
        s = 1.0 + u * (-1.0 / 6.0 + u * (1.0 / 120.0 + u * (-1.0 / 5040.0 + u * (1.0 / 362880.0))))
    elif u < TAYLOR_LIMIT:  # |φ/2| < 0.25: terms to u^7
        cm1 = u * (
            -1.0 / 2.0
            + u
            * (
                1.0 / 24.0
                + u
                * (
                    -1.0 / 720.0
                    + u
                    * (1.0 / 40320.0 + u * (-1.0 / 3628800.0 + u * (1.0 / 479001600.0 + u * (-1.0 / 87178291200.0))))
                )
            )
        )
        s = 1.0 + u * (
            -1.0 / 6.0
            + u
            * (
                1.0 / 120.0
                + u
                * (
                    -1.0 / 5040.0
                    + u
                    * (
                        1.0 / 362880.0
                        + u * (-1.0 / 39916800.0 + u * (1.0 / 6227020800.0 + u * (-1.0 / 1307674368000.0)))
                    )
                )
            )
        )
    else:
        x = math.sqrt(u)
        sh = math.sin(0.5 * x)
        cm1 = -2.0 * sh * sh  # cos x - 1
        s = math.sin(x) / x
    return cm1, s * ax, s * ay, s * az


@nb.njit(cache=True, inline="always", error_model="numpy")
def step_minus_one(kind, px, py, pz):
    """m(φ) - 1 for the step quaternion m of each method (math.md §4, §7)."""
    if kind == KIND_EXACT:
        return exp_half_minus_one(px, py, pz)
    if kind == KIND_FIRST:  # nabbla part 9: m = 1 + φ/2
        return 0.0, 0.5 * px, 0.5 * py, 0.5 * pz
    if kind == KIND_SECOND:  # Taylor of exp(φ/2) to second order: m = (1 - |φ|²/8) + φ/2
        return -0.125 * (px * px + py * py + pz * pz), 0.5 * px, 0.5 * py, 0.5 * pz
    # Cayley m = (1 + w)(1 - w)^-1 with w = φ/4: unit norm by construction, angle 4 atan|w|
    wx = 0.25 * px
    wy = 0.25 * py
    wz = 0.25 * pz
    w2 = wx * wx + wy * wy + wz * wz
    inv = 1.0 / (1.0 + w2)
    return -2.0 * w2 * inv, 2.0 * wx * inv, 2.0 * wy * inv, 2.0 * wz * inv


@nb.njit(cache=True, inline="always", error_model="numpy")
def advance(w, x, y, z, dw, dx, dy, dz):
    """Q ⊗ (1 + d) computed as q + q ⊗ d."""
    ew, ex, ey, ez = qmul(w, x, y, z, dw, dx, dy, dz)
    return w + ew, x + ex, y + ey, z + ez


BLOCK = 512  # samples per pass: the buffers stay in L1


@nb.njit(cache=True, error_model="numpy")
def _half_angles(g, lo, hi, h, hstep, scale, ax, ay, az, u):
    """Half rotation vectors a = φ/2 of samples lo..hi into separate x, y, z buffers, and |a|².

    A plain scalar loop: it turns the interleaved (n, 3) samples into contiguous columns, which the next pass
    needs to vectorise (strided loads kept LLVM's vector code three times slower than scalar columns).
    """
    for i in range(hi - lo):
        k = lo + i
        f = 0.5 * h[k * hstep] * scale
        x = g[k, 0] * f
        y = g[k, 1] * f
        z = g[k, 2] * f
        ax[i] = x
        ay[i] = y
        az[i] = z
        u[i] = x * x + y * y + z * z


@nb.njit(cache=True, error_model="numpy")
def _steps_minus_one(kind, m, ax, ay, az, u, cm):
    """m(φ) - 1 of a block, branch-free so that LLVM vectorises it: cm ← scalar part, a ← vector part.

    exact uses the Taylor series to u^7 everywhere here (exact to double precision for u < 0.0625); the chain
    pass recomputes the rare larger steps with sin and cos.  No fast-math: a sample's result must not depend on
    whether it falls in the vector body or the scalar remainder (bit-identical chunking).
    """
    if kind == KIND_EXACT:
        for i in range(m):
            v = u[i]
            c = v * (
                -1.0 / 2.0
                + v
                * (
                    1.0 / 24.0
                    + v
                    * (
                        -1.0 / 720.0
                        + v
                        * (
                            1.0 / 40320.0
                            + v * (-1.0 / 3628800.0 + v * (1.0 / 479001600.0 + v * (-1.0 / 87178291200.0)))
                        )
                    )
                )
            )
            s = 1.0 + v * (
                -1.0 / 6.0
                + v
                * (
                    1.0 / 120.0
                    + v
                    * (
                        -1.0 / 5040.0
                        + v
                        * (
                            1.0 / 362880.0
                            + v * (-1.0 / 39916800.0 + v * (1.0 / 6227020800.0 + v * (-1.0 / 1307674368000.0)))
                        )
                    )
                )
            )
            cm[i] = c
            ax[i] *= s
            ay[i] *= s
            az[i] *= s
    elif kind == KIND_FIRST:
        for i in range(m):
            cm[i] = 0.0
    elif kind == KIND_SECOND:  # -|φ|²/8 = -u/2
        for i in range(m):
            cm[i] = -0.5 * u[i]
    else:  # Cayley with w = φ/4 = a/2: m - 1 = (-2|w|², 2w) / (1 + |w|²)
        for i in range(m):
            inv = 1.0 / (1.0 + 0.25 * u[i])
            cm[i] = -0.5 * u[i] * inv
            ax[i] *= inv
            ay[i] *= inv
            az[i] *= inv


@nb.njit(cache=True, error_model="numpy")
def _steps(g, lo, hi, h, hstep, scale, kind, ax, ay, az, u, cm):
    """m(φ_k) - 1 of samples lo..hi into the buffers (cm, ax, ay, az), ready for the chain.

    The two passes above, then the rare large exact steps (u >= TAYLOR_LIMIT) recomputed with sin and cos, so
    that the chain's loop has no branch (a branch there made the four interleaved chains of _local4 ten times
    slower).
    """
    _half_angles(g, lo, hi, h, hstep, scale, ax, ay, az, u)
    _steps_minus_one(kind, hi - lo, ax, ay, az, u, cm)
    if kind == KIND_EXACT:
        for i in range(hi - lo):
            if u[i] >= TAYLOR_LIMIT:
                k = lo + i
                f = h[k * hstep] * scale
                cm[i], ax[i], ay[i], az[i] = exp_half_minus_one(g[k, 0] * f, g[k, 1] * f, g[k, 2] * f)


@nb.njit(cache=True, inline="always", error_model="numpy")
def renormalize(mode, w, x, y, z):
    """Scale to unit norm: exactly, or by the division-free series (3 - |q|²)/2 (nabbla part 9)."""
    n2 = w * w + x * x + y * y + z * z
    if mode == NORM_EXACT:
        f = 1.0 / math.sqrt(n2)
    else:
        f = 0.5 * (3.0 - n2)
    return w * f, x * f, y * f, z * f


@nb.njit(cache=True, error_model="numpy")
def _chain(g, h, hstep, scale, kind, lo, hi, w, x, y, z, out, at, columns, norm_mode, norm_every, counter):
    """(w,x,y,z) ⊗ m(φ_lo) ⊗ ... ⊗ m(φ_k) for k in [lo, hi), renormalised every `norm_every` steps, into out.

    Attitude k goes to row k - at of out, shape (rows, 4), or with `columns` to column k - at of out, shape
    (4, columns) (the scan's block scratch, :data:`SCAN_COLS`).  `counter` is the number of steps since the
    last renormalisation; returns the last attitude and the counter.  Per block of samples: the step
    quaternions into buffers (_steps: half angles into columns, a vectorised pass, the rare large exact steps
    with sin and cos), then the chain q + q ⊗ (m - 1).
    """
    ax = np.empty(BLOCK)
    ay = np.empty(BLOCK)
    az = np.empty(BLOCK)
    u = np.empty(BLOCK)
    cm = np.empty(BLOCK)
    c = counter
    for start in range(lo, hi, BLOCK):
        stop = min(start + BLOCK, hi)
        _steps(g, start, stop, h, hstep, scale, kind, ax, ay, az, u, cm)
        for i in range(stop - start):
            k = start + i
            w, x, y, z = advance(w, x, y, z, cm[i], ax[i], ay[i], az[i])
            c += 1
            if norm_mode != NORM_NONE and c >= norm_every:
                w, x, y, z = renormalize(norm_mode, w, x, y, z)
                c = 0
            j = k - at
            if columns:
                out[0, j] = w
                out[1, j] = x
                out[2, j] = y
                out[3, j] = z
            else:
                out[j, 0], out[j, 1], out[j, 2], out[j, 3] = w, x, y, z
    return w, x, y, z, c


@nb.njit(cache=True, nogil=True, error_model="numpy")
def sequential(g, h, hstep, scale, kind, norm_mode, norm_every, counter, q, out):
    """q[b] ← q[b] ⊗ m(φ_k) for k in the chunk, writing each new attitude to out[b, k].

    Normalisation follows the user's schedule literally: every `norm_every` steps (counted across chunks by
    `counter`, the steps since the last one).  Returns the updated counter.
    """
    c_end = counter
    for b in range(g.shape[0]):
        w, x, y, z, c_end = _chain(
            g[b],
            h,
            hstep,
            scale,
            kind,
            0,
            g.shape[1],
            q[b, 0],
            q[b, 1],
            q[b, 2],
            q[b, 3],
            out[b],
            0,
            False,
            norm_mode,
            norm_every,
            counter,
        )
        q[b, 0], q[b, 1], q[b, 2], q[b, 3] = w, x, y, z
    return c_end


# Samples per tile: its output (2 MiB) is still in the caches when phase 3 revisits it.  Smaller tiles ran
# faster on one thread in a scratch A/B (2^14: 17 against 22 ns a sample), but they shorten the blocks, which costs
# accuracy at a steady rate (_scan_offsets), so the tile stays at 2^16.
SCAN_TILE = 1 << 16
SCAN_BLOCKS = 8  # blocks per tile whatever the thread count, so that the arithmetic (the result) is fixed
# Phase 1 writes a block's prefix products as the four columns of a scratch array (SCAN_BLOCKS, 4, SCAN_COLS),
# where phase 3 rotates them in vector registers before storing them as rows of the output: with rows, LLVM
# left the rotation scalar on the znver4 target (scratch A/B on the 2-core EPYC VM, in the caches: 1.5 against
# 4.0 ns a row; 10^7 samples on two threads: 0.109 against 0.121 s, best of 9, the same bits).  The columns are
# longer than a block so that the sixteen store streams of _local4 fall in different L1 sets: at 8193 doubles
# they were 65544 bytes apart, 8 past a multiple of 4096, and phase 1 took 8.7 against 5.4 ns a sample.
SCAN_COLS = SCAN_TILE // SCAN_BLOCKS + 33  # 65800 bytes a column: 264 past a multiple of 4096


@nb.njit(cache=True, error_model="numpy")
def _scan_bounds(start, stop, bounds):
    """Block edges of the tile [start, stop) into bounds; returns the number of blocks (at least 256 samples each)."""
    size = stop - start
    n_blocks = min(SCAN_BLOCKS, max(1, size // 256))
    for blk in range(n_blocks + 1):
        bounds[blk] = start + blk * size // n_blocks
    return n_blocks


@nb.njit(cache=True, inline="always", error_model="numpy")
def _store(out, k, w, x, y, z):
    out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z


@nb.njit(cache=True, inline="always", error_model="numpy")
def _store_column(flat, j, col, w, x, y, z):
    """The components of one attitude at flat[j], flat[j + col], ...: one sample of a block's scratch columns."""
    flat[j] = w
    flat[j + col] = x
    flat[j + np.uint64(2) * col] = y
    flat[j + np.uint64(3) * col] = z


@nb.njit(cache=True, error_model="numpy")
def _local1(g, h, hstep, scale, kind, chain_norm, bounds, blk, cols, ends):
    """Phase 1, one block: its prefix products from the identity into cols[blk], its last one into ends[blk]."""
    lo = bounds[blk]
    w, x, y, z, _ = _chain(
        g, h, hstep, scale, kind, lo, bounds[blk + 1], 1.0, 0.0, 0.0, 0.0, cols[blk], lo, True, chain_norm, 16, 0
    )
    _store(ends, blk, w, x, y, z)


@nb.njit(cache=True, error_model="numpy")
def _local4(g, h, hstep, scale, kind, chain_norm, bounds, blk, cols, ends):
    """Phase 1 for blocks blk..blk+3 at once: four independent chains interleaved in one loop.

    One chain is latency-bound: each step's product waits for the last, while the core could issue the
    products of four chains in that time (measured: 16 % less time per sample in the caches).  Every chain
    does exactly what :func:`_local1` does (the same steps, products and renormalisation counter from 0), so
    the results are bit-identical to it; only the order in which the processor sees independent operations
    changes.  The chains run together over the shortest block's length (block lengths differ by at most one);
    each then finishes alone in _chain.  The attitudes go to the blocks' scratch columns (cols, :data:`SCAN_COLS`),
    indexed as unsigned offsets into the flat array (numba then emits no test for negative indices).
    """
    ax = np.empty((4, BLOCK))
    ay = np.empty((4, BLOCK))
    az = np.empty((4, BLOCK))
    u = np.empty((4, BLOCK))
    cm = np.empty((4, BLOCK))
    w0, x0, y0, z0 = 1.0, 0.0, 0.0, 0.0
    w1, x1, y1, z1 = 1.0, 0.0, 0.0, 0.0
    w2, x2, y2, z2 = 1.0, 0.0, 0.0, 0.0
    w3, x3, y3, z3 = 1.0, 0.0, 0.0, 0.0
    s0, s1, s2, s3, s4 = bounds[blk], bounds[blk + 1], bounds[blk + 2], bounds[blk + 3], bounds[blk + 4]
    common = min(s1 - s0, s2 - s1, s3 - s2, s4 - s3)
    flat = cols.reshape(-1)
    col = np.uint64(SCAN_COLS)
    b0 = np.uint64(blk) * np.uint64(4) * col  # where block blk's w column starts
    b1 = b0 + np.uint64(4) * col
    b2 = b1 + np.uint64(4) * col
    b3 = b2 + np.uint64(4) * col
    c = 0
    for off in range(0, common, BLOCK):
        m = min(BLOCK, common - off)
        for j in range(4):
            lo = bounds[blk + j] + off
            _steps(g, lo, lo + m, h, hstep, scale, kind, ax[j], ay[j], az[j], u[j], cm[j])
        for i in range(m):
            w0, x0, y0, z0 = advance(w0, x0, y0, z0, cm[0, i], ax[0, i], ay[0, i], az[0, i])
            w1, x1, y1, z1 = advance(w1, x1, y1, z1, cm[1, i], ax[1, i], ay[1, i], az[1, i])
            w2, x2, y2, z2 = advance(w2, x2, y2, z2, cm[2, i], ax[2, i], ay[2, i], az[2, i])
            w3, x3, y3, z3 = advance(w3, x3, y3, z3, cm[3, i], ax[3, i], ay[3, i], az[3, i])
            c += 1
            if chain_norm != NORM_NONE and c >= 16:
                w0, x0, y0, z0 = renormalize(chain_norm, w0, x0, y0, z0)
                w1, x1, y1, z1 = renormalize(chain_norm, w1, x1, y1, z1)
                w2, x2, y2, z2 = renormalize(chain_norm, w2, x2, y2, z2)
                w3, x3, y3, z3 = renormalize(chain_norm, w3, x3, y3, z3)
                c = 0
            j = np.uint64(off + i)
            _store_column(flat, b0 + j, col, w0, x0, y0, z0)
            _store_column(flat, b1 + j, col, w1, x1, y1, z1)
            _store_column(flat, b2 + j, col, w2, x2, y2, z2)
            _store_column(flat, b3 + j, col, w3, x3, y3, z3)
    # the last sample of the longer blocks, alone
    c0, c1, c2, c3 = cols[blk], cols[blk + 1], cols[blk + 2], cols[blk + 3]
    w0, x0, y0, z0, _ = _chain(
        g, h, hstep, scale, kind, s0 + common, s1, w0, x0, y0, z0, c0, s0, True, chain_norm, 16, c
    )
    w1, x1, y1, z1, _ = _chain(
        g, h, hstep, scale, kind, s1 + common, s2, w1, x1, y1, z1, c1, s1, True, chain_norm, 16, c
    )
    w2, x2, y2, z2, _ = _chain(
        g, h, hstep, scale, kind, s2 + common, s3, w2, x2, y2, z2, c2, s2, True, chain_norm, 16, c
    )
    w3, x3, y3, z3, _ = _chain(
        g, h, hstep, scale, kind, s3 + common, s4, w3, x3, y3, z3, c3, s3, True, chain_norm, 16, c
    )
    _store(ends, blk, w0, x0, y0, z0)
    _store(ends, blk + 1, w1, x1, y1, z1)
    _store(ends, blk + 2, w2, x2, y2, z2)
    _store(ends, blk + 3, w3, x3, y3, z3)


@nb.njit(cache=True, error_model="numpy")
def _rotate_block(sw, sx, sy, sz, cols, m, out, lo, unit, fix_mode):
    """Phase 3 of one block: out[lo + i] ← s ⊗ (column i of cols), normalised with `unit`, for i < m.

    The product runs on the columns in place, where LLVM vectorises it; a second loop stores them as rows
    (unsigned offsets into the flat output: numba then emits no test for negative indices).
    """
    cw, cx, cy, cz = cols[0], cols[1], cols[2], cols[3]
    for i in range(m):
        rw, rx, ry, rz = qmul(sw, sx, sy, sz, cw[i], cx[i], cy[i], cz[i])
        if unit:
            rw, rx, ry, rz = renormalize(fix_mode, rw, rx, ry, rz)
        cw[i] = rw
        cx[i] = rx
        cy[i] = ry
        cz[i] = rz
    flat = out.reshape(-1)
    one = np.uint64(1)
    j = np.uint64(4) * np.uint64(lo)
    for i in range(np.uint64(m)):
        flat[j] = cw[i]
        flat[j + one] = cx[i]
        flat[j + 2 * one] = cy[i]
        flat[j + 3 * one] = cz[i]
        j += np.uint64(4)


@nb.njit(cache=True, error_model="numpy")
def _scan_part(g, h, hstep, scale, kind, unit, part, n_parts, prev_b, prev, prev_c, cur_b, cur, cur_c, out):
    """One thread's share of one parallel region: phase 3 of the previous tile, then phase 1 of this one.

    Of each tile, part p of n_parts takes the contiguous run of blocks [p·n/n_parts, (p+1)·n/n_parts): the same
    blocks in both phases, so a block's output is still in that core's cache when it is rotated.  (prev_b,
    prev) and (cur_b, cur) are tile records (_tile_record), prev_c and cur_c the tiles' block scratch
    (SCAN_COLS); a record with 0 blocks is skipped.  Phase 1 runs four blocks at a time interleaved (_local4).
    """
    fix_mode, chain_norm = _scan_modes(kind, unit)
    n_prev = prev_b[0]
    if n_prev > 0:
        bounds = prev_b[1:]
        for blk in range(part * n_prev // n_parts, (part + 1) * n_prev // n_parts):
            s = prev[SCAN_BLOCKS + blk]
            lo = bounds[blk]
            _rotate_block(s[0], s[1], s[2], s[3], prev_c[blk], bounds[blk + 1] - lo, out, lo, unit, fix_mode)
    n_cur = cur_b[0]
    if n_cur > 0:
        bounds = cur_b[1:]
        ends = cur[:SCAN_BLOCKS]
        blk = part * n_cur // n_parts
        hi = (part + 1) * n_cur // n_parts
        while hi - blk >= 4:
            _local4(g, h, hstep, scale, kind, chain_norm, bounds, blk, cur_c, ends)
            blk += 4
        while blk < hi:
            _local1(g, h, hstep, scale, kind, chain_norm, bounds, blk, cur_c, ends)
            blk += 1


@nb.njit(cache=True, inline="always", error_model="numpy")
def _start_advance(sw, sx, sy, sz, ew, ex, ey, ez, unit, fix_mode):
    """The start attitude of the next block, s ⊗ e, normalised with `unit` as _rotate_block does (phase 2).

    The same operations as phase 3 on the block's last sample (whose local value is e), so the attitude carried
    to the next tile is that row's output bit for bit.
    """
    w, x, y, z = qmul(sw, sx, sy, sz, ew, ex, ey, ez)
    if unit:
        w, x, y, z = renormalize(fix_mode, w, x, y, z)
    return w, x, y, z


@nb.njit(cache=True, error_model="numpy")
def _scan_offsets(unit, kind, q, rec_b, rec):
    """Phase 2 of one tile, between regions: its blocks' start attitudes from q, q advanced to the tile's end.

    (rec_b, rec) is the tile's record (_tile_record): the block end attitudes are rec[:SCAN_BLOCKS] (phase 1),
    the start attitudes written here rec[SCAN_BLOCKS:].  Block b starts at q ⊗ end_0 ⊗ ... ⊗ end_{b-1}; q
    becomes the tile's last output, so the next tile's start does not wait for phase 3.

    Accuracy: at a constant rate every block's chain makes the same rounding error, and the blocks' errors
    add coherently, so the scan's error grows as n ε / sqrt(block length); a double-double chain here did not
    change it (measured).  Blocks of 8192 samples keep it at 5.7e-13 rad over 10^6 steps (2048: 1.3e-12).
    """
    fix_mode, _ = _scan_modes(kind, unit)
    sw, sx, sy, sz = q[0], q[1], q[2], q[3]
    for blk in range(rec_b[0]):
        _store(rec, SCAN_BLOCKS + blk, sw, sx, sy, sz)
        sw, sx, sy, sz = _start_advance(
            sw, sx, sy, sz, rec[blk, 0], rec[blk, 1], rec[blk, 2], rec[blk, 3], unit, fix_mode
        )
    q[0], q[1], q[2], q[3] = sw, sx, sy, sz


@nb.njit(cache=True, error_model="numpy")
def _tile_record(start, stop, rec_b):
    """The integer part of a tile record for samples [start, stop): number of blocks (0: empty), block edges.

    rec_b[0] is the number of blocks and rec_b[1:] their edges.  The record's float part, (2 SCAN_BLOCKS, 4),
    holds the blocks' end attitudes (phase 1) and then their start attitudes (phase 2).
    """
    if stop <= start:
        rec_b[0] = 0
        return
    rec_b[0] = _scan_bounds(start, stop, rec_b[1:])


@nb.njit(cache=True, inline="always")
def _scan_modes(kind, unit):
    """(normalisation of the outputs, normalisation inside a block's chain) for the scan.

    Norm-preserving steps (exact, cayley) keep a block's products within rounding of unit norm (no rescaling
    inside it, and the division-free series finishes the outputs); first/second-order ones grow the norm by
    |φ|²/8 a step: the running product is rescaled every 16 steps so that long blocks cannot overflow (scaling
    never changes the direction) and the outputs are divided by their norm.
    """
    preserving = kind == KIND_EXACT or kind == KIND_CAYLEY
    fix_mode = NORM_SERIES if preserving else NORM_EXACT
    chain_norm = NORM_EXACT if unit and not preserving else NORM_NONE
    return fix_mode, chain_norm


@nb.njit(cache=True, parallel=True, nogil=True, error_model="numpy")
def scan(g, h, hstep, scale, kind, unit, q, out, n_parts):
    """Parallel prefix product of the step quaternions of one body: out[k] = q ⊗ m(φ_0) ⊗ ... ⊗ m(φ_k).

    The samples are processed tile by tile, so that a tile's output is still in the cores' caches when it is
    visited the second time.  Each tile is cut into SCAN_BLOCKS blocks (fewer for short tiles), which the
    n_parts threads share out: every block's prefix products start from the identity (phase 1); the block end
    attitudes are chained from the attitude at the tile's start (phase 2, on this thread) and each block is
    rotated by the attitude at its start (quaternion products are associative, phase 3).  Phase 3 of a tile
    and phase 1 of the next run in the same parallel region, so a tile costs one wake-up of the threads, not
    two.  The blocks do not depend on the number of threads, so neither does the result: :func:`scan_serial`
    is the same arithmetic on one thread.  With `unit` the outputs are normalised: the direction is the
    sequential loop's, only rounding differs.  Otherwise they are the raw products.  q is the incoming
    attitude and is updated to the last one.
    """
    n = g.shape[0]
    prev_b, cur_b = np.zeros(SCAN_BLOCKS + 2, dtype=np.int64), np.zeros(SCAN_BLOCKS + 2, dtype=np.int64)
    prev, cur = np.zeros((2 * SCAN_BLOCKS, 4)), np.zeros((2 * SCAN_BLOCKS, 4))
    prev_c, cur_c = np.empty((SCAN_BLOCKS, 4, SCAN_COLS)), np.empty((SCAN_BLOCKS, 4, SCAN_COLS))
    for start in range(0, n + SCAN_TILE, SCAN_TILE):  # one region more than tiles: the last one's phase 3
        _tile_record(start, min(start + SCAN_TILE, n), cur_b)
        for part in nb.prange(n_parts):
            _scan_part(g, h, hstep, scale, kind, unit, part, n_parts, prev_b, prev, prev_c, cur_b, cur, cur_c, out)
        if cur_b[0] > 0:
            _scan_offsets(unit, kind, q, cur_b, cur)
        prev_b, cur_b = cur_b, prev_b
        prev, cur = cur, prev
        prev_c, cur_c = cur_c, prev_c


@nb.njit(cache=True, nogil=True, error_model="numpy")
def scan_serial(g, h, hstep, scale, kind, unit, q, out):
    """:func:`scan` on the calling thread alone, bit for bit (the same blocks and arithmetic; no thread pool).

    On one thread nothing waits for other threads, so each group of four blocks is finished (phases 2 and 3)
    right after its phase 1, while its output is still in the core's cache: a tile's whole output would not
    fit (measured 20 against 25 ns a sample, CPU time, 10^7 samples, 2-core machine under load).  The start
    attitudes are the same products in the same order as :func:`_scan_offsets`, so the bits are scan's.
    """
    fix_mode, chain_norm = _scan_modes(kind, unit)
    n = g.shape[0]
    bounds = np.zeros(SCAN_BLOCKS + 1, dtype=np.int64)
    ends = np.zeros((SCAN_BLOCKS, 4))
    cols = np.empty((SCAN_BLOCKS, 4, SCAN_COLS))
    for start in range(0, n, SCAN_TILE):
        n_blocks = _scan_bounds(start, min(start + SCAN_TILE, n), bounds)
        sw, sx, sy, sz = q[0], q[1], q[2], q[3]  # the attitude at the start of the next block
        blk = 0
        while blk < n_blocks:
            size = 4 if n_blocks - blk >= 4 else 1
            if size == 4:
                _local4(g, h, hstep, scale, kind, chain_norm, bounds, blk, cols, ends)
            else:
                _local1(g, h, hstep, scale, kind, chain_norm, bounds, blk, cols, ends)
            for b in range(blk, blk + size):
                lo = bounds[b]
                _rotate_block(sw, sx, sy, sz, cols[b], bounds[b + 1] - lo, out, lo, unit, fix_mode)
                sw, sx, sy, sz = _start_advance(
                    sw, sx, sy, sz, ends[b, 0], ends[b, 1], ends[b, 2], ends[b, 3], unit, fix_mode
                )
            blk += size
        q[0], q[1], q[2], q[3] = sw, sx, sy, sz


@nb.njit(cache=True, inline="always", error_model="numpy")
def _qvec(w, x, y, z, ox, oy, oz):
    """½ q ⊗ (0, ω): the right-hand side of q̇ = ½ q ⊗ ω (Gajda 2.3)."""
    rw, rx, ry, rz = qmul(w, x, y, z, 0.0, ox, oy, oz)
    return 0.5 * rw, 0.5 * rx, 0.5 * ry, 0.5 * rz


@nb.njit(cache=True, inline="always", error_model="numpy")
def _rk4_step(w, x, y, z, a0, a1, a2, a3, h, mid, end, b, k):
    """The attitude after an RK4 step of length h, unnormalised.

    ``a`` is the first stage; ``mid[b, k]`` and ``end[b, k]`` are the rates halfway and at the end.
    """
    mx, my, mz = mid[b, k, 0], mid[b, k, 1], mid[b, k, 2]
    hh = 0.5 * h
    b0, b1, b2, b3 = _qvec(w + hh * a0, x + hh * a1, y + hh * a2, z + hh * a3, mx, my, mz)
    c0, c1, c2, c3 = _qvec(w + hh * b0, x + hh * b1, y + hh * b2, z + hh * b3, mx, my, mz)
    d0, d1, d2, d3 = _qvec(w + h * c0, x + h * c1, y + h * c2, z + h * c3, end[b, k, 0], end[b, k, 1], end[b, k, 2])
    s = h / 6.0
    return (
        w + s * (a0 + 2.0 * (b0 + c0) + d0),
        x + s * (a1 + 2.0 * (b1 + c1) + d1),
        y + s * (a2 + 2.0 * (b2 + c2) + d2),
        z + s * (a3 + 2.0 * (b3 + c3) + d3),
    )


@nb.njit(cache=True, error_model="numpy")
def rk4(w0, wm, w1, wq, wi, h, spans, tm, norm_mode, norm_every, counter, q, out):
    """Classical RK4 on q̇ = ½ q ⊗ ω(t) with the rates at the start, middle and end of each step.

    A step of span 2 covers two sample intervals (its stages fall on three samples, math.md §6.3); the attitude
    at the sample inside it comes from a separate RK4 step to that sample (rates at the start, halfway to it (wq)
    and at the inner sample itself (wi)), which is output but not fed back.
    Renormalised on the user's schedule, counted in steps.  Returns the counter.
    """
    n_bodies = w0.shape[0]
    n = w0.shape[1]
    c_end = counter
    for b in range(n_bodies):
        w, x, y, z = q[b, 0], q[b, 1], q[b, 2], q[b, 3]
        c = counter
        o = 0
        for k in range(n):
            hk = h[k]
            a0, a1, a2, a3 = _qvec(w, x, y, z, w0[b, k, 0], w0[b, k, 1], w0[b, k, 2])
            nw, nx, ny, nz = _rk4_step(w, x, y, z, a0, a1, a2, a3, hk, wm, w1, b, k)
            c += 1
            if norm_mode != NORM_NONE and c >= norm_every:
                nw, nx, ny, nz = renormalize(norm_mode, nw, nx, ny, nz)
                c = 0
            if spans[k] == 2:
                mw, mx, my, mz = _rk4_step(w, x, y, z, a0, a1, a2, a3, tm[k], wq, wi, b, k)
                mw, mx, my, mz = renormalize(NORM_EXACT, mw, mx, my, mz)
                out[b, o, 0], out[b, o, 1], out[b, o, 2], out[b, o, 3] = mw, mx, my, mz
                o += 1
            w, x, y, z = nw, nx, ny, nz
            out[b, o, 0], out[b, o, 1], out[b, o, 2], out[b, o, 3] = w, x, y, z
            o += 1
        q[b, 0], q[b, 1], q[b, 2], q[b, 3] = w, x, y, z
        c_end = c
    return c_end


@nb.njit(cache=True, inline="always", error_model="numpy")
def _cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@nb.njit(cache=True, error_model="numpy")
def coning(inc, coef, c_prev, norm_mode, norm_every, counter, pos, node, alpha, beta, prev, group, out):
    """Multi-sample rotation-vector updates (math.md §6.2) from gyro increments.

    The chain advances once per group of N = coef.shape[0] increments by the group's rotation vector
        φ = Σ Δθ_i + Σ_{i<j} coef[i, j] Δθ_i × Δθ_j + c_prev Δθ_prev × Δθ_1,
    where Δθ_prev is the increment before the group.  Inside a group every sample still gets an attitude:
    node ⊗ exp((α + β)/2) with Savage's two-speed recursion (β += ½ (α + Δθ_prev/6) × Δθ, α += Δθ), fourth
    order in the sample interval; these outputs do not feed the chain.  pos is the position in the current
    group (shared by all bodies); returns (pos, counter).
    """
    n_bodies = inc.shape[0]
    n = inc.shape[1]
    size = coef.shape[0]
    pos_end = pos
    c_end = counter
    for b in range(n_bodies):
        p = pos
        c = counter
        for k in range(n):
            dx, dy, dz = inc[b, k, 0], inc[b, k, 1], inc[b, k, 2]
            group[b, p, 0], group[b, p, 1], group[b, p, 2] = dx, dy, dz
            # Savage partial update (used for outputs inside the group)
            sx = alpha[b, 0] + prev[b, 0] / 6.0
            sy = alpha[b, 1] + prev[b, 1] / 6.0
            sz = alpha[b, 2] + prev[b, 2] / 6.0
            cx, cy, cz = _cross(sx, sy, sz, dx, dy, dz)
            beta[b, 0] += 0.5 * cx
            beta[b, 1] += 0.5 * cy
            beta[b, 2] += 0.5 * cz
            alpha[b, 0] += dx
            alpha[b, 1] += dy
            alpha[b, 2] += dz
            p += 1
            if p == size:
                # the group's rotation vector by the chosen coefficient set
                fx, fy, fz = alpha[b, 0], alpha[b, 1], alpha[b, 2]
                for i in range(size):
                    for j in range(i + 1, size):
                        kij = coef[i, j]
                        if kij != 0.0:
                            cx, cy, cz = _cross(
                                group[b, i, 0],
                                group[b, i, 1],
                                group[b, i, 2],
                                group[b, j, 0],
                                group[b, j, 1],
                                group[b, j, 2],
                            )
                            fx += kij * cx
                            fy += kij * cy
                            fz += kij * cz
                if c_prev != 0.0:
                    # only with groups of one ("one plus previous"): prev is the previous sample's increment
                    cx, cy, cz = _cross(
                        prev[b, 0], prev[b, 1], prev[b, 2], group[b, 0, 0], group[b, 0, 1], group[b, 0, 2]
                    )
                    fx += c_prev * cx
                    fy += c_prev * cy
                    fz += c_prev * cz
                mw, mx, my, mz = exp_half_minus_one(fx, fy, fz)
                w, x, y, z = advance(node[b, 0], node[b, 1], node[b, 2], node[b, 3], mw, mx, my, mz)
                c += 1
                if norm_mode != NORM_NONE and c >= norm_every:
                    w, x, y, z = renormalize(norm_mode, w, x, y, z)
                    c = 0
                node[b, 0], node[b, 1], node[b, 2], node[b, 3] = w, x, y, z
                for i in range(3):
                    alpha[b, i] = 0.0
                    beta[b, i] = 0.0
                p = 0
            else:
                mw, mx, my, mz = exp_half_minus_one(
                    alpha[b, 0] + beta[b, 0], alpha[b, 1] + beta[b, 1], alpha[b, 2] + beta[b, 2]
                )
                w, x, y, z = advance(node[b, 0], node[b, 1], node[b, 2], node[b, 3], mw, mx, my, mz)
            # for a group of one the "previous" increment is this sample's; otherwise the last in the group
            prev[b, 0], prev[b, 1], prev[b, 2] = dx, dy, dz
            out[b, k, 0], out[b, k, 1], out[b, k, 2], out[b, k, 3] = w, x, y, z
        pos_end = p
        c_end = c
    return pos_end, c_end
