"""Numba kernels for :mod:`strapdown.rotations.euler` (private).

Both kernels work on validated, C-contiguous rows and compute in float64 whatever the storage type;
``as_euler_rows`` releases the GIL (it runs per chunk in the file pipelines, beside the background writer).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ._quaternion_numba import qmul


@nb.njit(cache=True)
def from_euler_rows(angles, axes, cols, out):
    """out[n] = e(axes[0], a[cols[0]]) ⊗ e(axes[1], a[cols[1]]) ⊗ e(axes[2], a[cols[2]]).

    e(axis, angle) is the elementary quaternion [cos(angle/2), sin(angle/2) u_axis].  The caller orders the
    factors: intrinsic sequences left to right, extrinsic ones reversed.
    """
    for n in range(out.shape[0]):
        w, x, y, z = 1.0, 0.0, 0.0, 0.0
        for m in range(3):
            h = 0.5 * float(angles[n, cols[m]])
            c = math.cos(h)
            s = math.sin(h)
            ax = axes[m]
            w, x, y, z = qmul(w, x, y, z, c, s if ax == 0 else 0.0, s if ax == 1 else 0.0, s if ax == 2 else 0.0)
        out[n, 0] = w
        out[n, 1] = x
        out[n, 2] = y
        out[n, 3] = z


@nb.njit(cache=True, inline="always")
def _wrap(a):
    """Wrap an angle in [-2π, 2π] into (-π, π] (selects: a > π and a <= -π exclude each other)."""
    a = a - 2.0 * math.pi if a > math.pi else a
    return a + 2.0 * math.pi if a <= -math.pi else a


@nb.njit(cache=True, inline="always")
def _at(value, target, single):
    """Value == target as the caller will see it (after rounding to float32 when single)."""
    if single:
        return np.float32(value) == np.float32(target)
    return value == target


@nb.njit(cache=True, inline="always")
def _fold(angle, half, full, single):
    """The outer angle as stored: rounded to float32 when `single`, and moved from -half to +half.

    The kernel wraps in radians; the rounding to degrees or to float32 can land exactly on -180°, which the
    output range (-180°, 180°] excludes.  The test and the addition are made in the output's type.
    """
    if single:
        a = np.float32(angle)
        return a + np.float32(full) if a <= np.float32(-half) else a
    return angle + full if angle <= -half else angle


# atan2 in a form LLVM can vectorise (libm's atan2 is a call per element, which is most of as_euler's time):
# Cephes' atan (Moshier, "Methods and Programs for Mathematical Functions", 1989; cephes/cmath/atan.c), whose
# rational approximation on [0, 0.66] has a peak relative error of 1.8e-16, after the octant reduction of atan2
# to t = min(|y|, |x|) / max(|y|, |x|) in [0, 1] (t > 0.66: atan t = π/4 + atan((t - 1)/(t + 1))).  The
# multiples of π/4 carry their low parts (π/4 = PIO4_HI + PIO4_LO) and the sum is formed smallest term first
# with the high part added last, so that atan2(y, ±0), atan2(0, -x), atan2(0, 0) and every result within a few
# ulp of a multiple of π/2 are exactly the doubles libm returns: the gimbal-lock test compares the middle angle
# with its limit exactly.  (Adding the low part after the high one loses the half ulp it should round with:
# 1 row in 6 at pitch ±90° came back 1 ulp below π/2.)  Elsewhere within 2 ulp of libm.  Signed zeros follow
# IEEE 754 atan2.
_P0 = -8.750608600031904122785e-01
_P1 = -1.615753718733365076637e01
_P2 = -7.500855792314704667340e01
_P3 = -1.228866684490136173410e02
_P4 = -6.485021904942025371773e01
_Q0 = 2.485846490142306297962e01
_Q1 = 1.650270098316988542046e02
_Q2 = 4.328810604912902668951e02
_Q3 = 4.853903996359136964868e02
_Q4 = 1.945506571482613964425e02
_PIO4_HI = 0.7853981633974483
_PIO4_LO = 3.061616997868383e-17
_3PIO4_HI = 2.356194490192345
_3PIO4_LO = 9.184850993605148e-17


@nb.njit(cache=True, inline="always", error_model="numpy")
def atan2_vec(y, x):
    """atan2(y, x) within 2 ulp (exact near multiples of π/2), branch-free (selects only), for finite y and x."""
    ax = abs(x)
    ay = abs(y)
    big = ay > ax  # |y| > |x|: reflect about π/4
    mn = ax if big else ay
    mx = ay if big else ax
    t = mn / mx if mx > 0.0 else 0.0
    reduce = t > 0.66
    u = (t - 1.0) / (t + 1.0) if reduce else t
    z = u * u
    p = (((_P0 * z + _P1) * z + _P2) * z + _P3) * z + _P4
    q = ((((z + _Q0) * z + _Q1) * z + _Q2) * z + _Q3) * z + _Q4
    corr = u * z * p / q  # atan u = u + corr
    # R = m π/4 + sgn atan u: first octant m = 0 or 1 (reduced), sgn = +; reflected (|y| > |x|) m = 2 - reduce,
    # sgn = -; x < 0 reflected m = 2 + reduce, sgn = +; x < 0 m = 4 - reduce, sgn = -.
    negative_x = math.copysign(1.0, x) < 0.0
    k = (1.0 if big else 0.0) + (0.0 if big else 2.0) * (1.0 if negative_x else 0.0)
    sgn = -1.0 if big != negative_x else 1.0
    m = 2.0 * k + (sgn if reduce else 0.0)
    # m π/4 as hi + lo: m * PIO4 is exact for m = 0, 1, 2, 4; 3π/4 has its own pair.
    three = m == 3.0
    hi = _3PIO4_HI if three else m * _PIO4_HI
    lo = _3PIO4_LO if three else m * _PIO4_LO
    # Smallest terms first and one rounding at the end (as fdlibm's atan): near a multiple of π/2 the result
    # is then the double nearest to m π/4 + sgn atan u, which the gimbal-lock test compares exactly.
    return math.copysign(hi + ((lo + sgn * corr) + sgn * u), y)


BLOCK = 256  # rows per pass: the column buffers stay in L1


@nb.njit(cache=True, error_model="numpy")
def _complex_pairs(q, lo, hi, i, j, k, proper, sign, a_, b_, c_, d_):
    """The two complex numbers a + ib, c + id of rows lo..hi (see :func:`as_euler_rows`), as columns."""
    for r in range(hi - lo):
        n = lo + r
        # Canonical sign first (w > 0, ties by x, y, z) so that q and -q give bit-identical angles.
        w = float(q[n, 0])
        x = float(q[n, 1])
        y = float(q[n, 2])
        z = float(q[n, 3])
        # bitwise & and | (no short-circuit) and a select: a random sign is a branch the CPU cannot predict
        neg = (w < 0.0) | ((w == 0.0) & ((x < 0.0) | ((x == 0.0) & ((y < 0.0) | ((y == 0.0) & (z < 0.0))))))
        flip = -1.0 if neg else 1.0
        w = flip * w
        qi = flip * float(q[n, 1 + i])
        qj = flip * float(q[n, 1 + j])
        qk = flip * float(q[n, 1 + k]) * sign
        if proper:
            a_[r] = w
            b_[r] = qi
            c_[r] = qj
            d_[r] = qk
        else:
            a_[r] = w - qj
            b_[r] = qi + qk
            c_[r] = qj + w
            d_[r] = qk - qi


@nb.njit(cache=True, error_model="numpy")
def _half_angles(m, a_, b_, c_, d_, middle, half_sum, half_diff):
    """β/2 - low/2 = atan2(|c + id|, |a + ib|), arg(a + ib), arg(c + id) of m rows: a vectorised pass."""
    for r in range(m):
        a = a_[r]
        b = b_[r]
        c = c_[r]
        d = d_[r]
        middle[r] = atan2_vec(math.sqrt(c * c + d * d), math.sqrt(a * a + b * b))
        half_sum[r] = atan2_vec(b, a)
        half_diff[r] = atan2_vec(d, c)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _finish_row(out, n, middle, half_sum, half_diff, low, high, proper, sign, intrinsic, scale, single, half, full):
    """The gimbal-lock rule, the outer angles, wrapping and units of one row (see :func:`as_euler_rows`).

    Written with selects rather than branches: the wrap of a random angle is a branch the CPU cannot predict.
    """
    at_low = _at(middle * scale, low * scale, single)  # only α + γ is defined
    at_high = _at(middle * scale, high * scale, single) & (not at_low)  # only γ - α is defined
    locked = at_low | at_high
    carried = 2.0 * half_sum if at_low else (2.0 * half_diff if intrinsic else -2.0 * half_diff)
    alpha = (0.0 if intrinsic else carried) if locked else half_sum - half_diff
    gamma = (carried if intrinsic else 0.0) if locked else half_sum + half_diff
    middle = low if at_low else (high if at_high else middle)
    if not proper:
        gamma = gamma * sign
    # +0.0 turns a -0.0 (from 0 * -1) into +0.0
    alpha = _fold(_wrap(alpha) * scale + 0.0, half, full, single)
    gamma = _fold(_wrap(gamma) * scale + 0.0, half, full, single)
    middle = middle * scale
    if intrinsic:
        out[n, 0] = gamma
        out[n, 1] = middle
        out[n, 2] = alpha
    else:
        out[n, 0] = alpha
        out[n, 1] = middle
        out[n, 2] = gamma


@nb.njit(cache=True, nogil=True, error_model="numpy")
def as_euler_rows(q, i, j, k, proper, sign, intrinsic, scale, single, half, full, out):
    """Euler angles of the *extrinsic* sequence (i, j, i) or (i, j, k) by the direct half-angle method.

    Derivation (math.md §3.2; Bernardes & Viollet, PLoS ONE 2022).  For the extrinsic proper sequence
    q = e_i(γ) ⊗ e_j(β) ⊗ e_i(α) the components regroup into two complex numbers
        a + i b = cos(β/2) e^{i(α+γ)/2},    c + i d = sin(β/2) e^{i(γ-α)/2},
    with a = w, b = q_i, c = q_j, d = ε q_k (k the remaining axis, ε the parity of (i, j, k)).  A Tait-Bryan
    sequence becomes the same form after a 45° change of variables (a = w - q_j, b = q_i + ε q_k,
    c = w + q_j, d = ε q_k - q_i), with β shifted by -π/2 and γ scaled by ε.  Hence
        β = 2 atan2(|c + i d|, |a + i b|),  (α+γ)/2 = arg(a + i b),  (γ-α)/2 = arg(c + i d).
    Both moduli come from the same quaternion, so the rotation rebuilt from the angles is accurate to a few
    ulp everywhere, including arbitrarily close to gimbal lock: no snapping threshold is needed.

    Gimbal lock is taken only when the middle angle the caller receives (scaled by `scale` to degrees or not,
    rounded to float32 when `single`) is *exactly* at its limit; one half angle is then undefined, the output's
    third angle is set to 0 and the first one carries the whole rotation.

    For an intrinsic sequence the caller passes the reversed axes; the triple is then reversed on output.
    Angles are multiplied by `scale` (1 for radians, 180/π for degrees) on output.  An outer angle that the
    rounding to degrees or float32 puts at -`half` (-180° or -π in the output's type) is moved to +`half`.
    """
    scratch = block_scratch()
    for start in range(0, q.shape[0], BLOCK):
        stop = min(start + BLOCK, q.shape[0])
        block_rows(q, start, stop, i, j, k, proper, sign, intrinsic, scale, single, half, full, scratch, out, start)


@nb.njit(cache=True, inline="always", error_model="numpy")
def block_scratch():
    """The rows one block of :func:`block_rows` works in: a, b, c, d, the middle angle, the half sum and difference."""
    return (
        np.empty(BLOCK),
        np.empty(BLOCK),
        np.empty(BLOCK),
        np.empty(BLOCK),
        np.empty(BLOCK),
        np.empty(BLOCK),
        np.empty(BLOCK),
    )


@nb.njit(cache=True, inline="always", error_model="numpy")
def block_rows(q, start, stop, i, j, k, proper, sign, intrinsic, scale, single, half, full, scratch, out, first):
    """One block of :func:`as_euler_rows`: the angles of rows start..stop-1 of q into rows first... of out.

    Inlined into its callers (as_euler_rows and the file writers' column kernel), so each runs it as its own loop.
    """
    a_, b_, c_, d_, mid_, hs_, hd_ = scratch
    low, high = (0.0, math.pi) if proper else (-0.5 * math.pi, 0.5 * math.pi)
    _complex_pairs(q, start, stop, i, j, k, proper, sign, a_, b_, c_, d_)
    _half_angles(stop - start, a_, b_, c_, d_, mid_, hs_, hd_)
    for r in range(stop - start):
        middle = 2.0 * mid_[r] + low
        _finish_row(
            out, first + r, middle, hs_[r], hd_[r], low, high, proper, sign, intrinsic, scale, single, half, full
        )
