"""Small scalar helpers shared by the fusion kernels (private).

The filter kernels (:mod:`._attitude_numba`, :mod:`._tilt_numba`) allow fused multiply-adds
(``fastmath={"contract"}``) and nothing else of fastmath: each is one correctly rounded operation, nothing is
reassociated, so any chunking still gives bit-identical results; it makes the per-sample recursion about a tenth
faster.
"""

from __future__ import annotations

import math

import numba as nb

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ..propagate._integrate_numba import TAYLOR_SHORT, exp_half_minus_one
from ..rotations._quaternion_numba import qmul


@nb.njit(cache=True, inline="always", error_model="numpy")
def unit3(x, y, z):
    """A sensor sample's direction and length: ``(x, y, z) / n, n`` with n = |v|, or ``(x, y, z), 0`` for v = 0."""
    n = math.sqrt(x * x + y * y + z * z)
    if n > 0.0:
        return x / n, y / n, z / n, n
    return x, y, z, n


@nb.njit(cache=True, inline="always", error_model="numpy")
def rotate(w, x, y, z, vx, vy, vz):
    """R(q) v for a unit quaternion, expanded: v + 2w (u×v) + 2 u×(u×v)."""
    tx = 2.0 * (y * vz - z * vy)
    ty = 2.0 * (z * vx - x * vz)
    tz = 2.0 * (x * vy - y * vx)
    return vx + w * tx + (y * tz - z * ty), vy + w * ty + (z * tx - x * tz), vz + w * tz + (x * ty - y * tx)


@nb.njit(cache=True, inline="always", error_model="numpy")
def horizontal_rows(w, x, y, z):
    """The first two rows of R(q) (q = (w, x, y, z), unit): R_0 and R_1, six numbers."""
    return (
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
    )


@nb.njit(cache=True, inline="always", error_model="numpy")
def rotate_back(w, x, y, z, vx, vy, vz):
    """R(q)ᵀ v."""
    return rotate(w, -x, -y, -z, vx, vy, vz)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _stepped(w, x, y, z, px, py, pz, left):
    """The step q ⊗ exp(φ/2) (``left``: exp(φ/2) ⊗ q) as q + q ⊗ (exp(φ/2) - 1), not normalised."""
    dw, dx, dy, dz = exp_half_minus_one(px, py, pz)
    if left:
        ew, ex, ey, ez = qmul(dw, dx, dy, dz, w, x, y, z)
    else:
        ew, ex, ey, ez = qmul(w, x, y, z, dw, dx, dy, dz)
    return w + ew, x + ex, y + ey, z + ez


@nb.njit(cache=True, inline="always", error_model="numpy")
def right_step(w, x, y, z, px, py, pz):
    """Right step q ⊗ exp(φ/2), normalised: the exact body-rate update (the integrator's increment form).

    The step keeps |q| = 1 to rounding, so the series normalisation q (3 - |q|²)/2 (nabbla part 9) is exact to
    rounding and needs no square root; it also pulls any |q| near 1 back quadratically.
    """
    w, x, y, z = _stepped(w, x, y, z, px, py, pz, False)
    f = 1.5 - 0.5 * (w * w + x * x + y * y + z * z)
    return w * f, x * f, y * f, z * f


@nb.njit(cache=True, inline="always", error_model="numpy")
def _exp_minus_one(ax, ay, az):
    """exp(a) - 1 of the half angle a = φ/2: exp_half_minus_one(2a) bit for bit, without its halving.

    For |a| < 0.1 (every filter step at sensor rates) its series, the same lines; beyond, that function itself.
    """
    u = ax * ax + ay * ay + az * az
    if u < TAYLOR_SHORT:
        cm1 = u * (-1.0 / 2.0 + u * (1.0 / 24.0 + u * (-1.0 / 720.0 + u * (1.0 / 40320.0))))
        s = 1.0 + u * (-1.0 / 6.0 + u * (1.0 / 120.0 + u * (-1.0 / 5040.0 + u * (1.0 / 362880.0))))
        return cm1, s * ax, s * ay, s * az
    return exp_half_minus_one(2.0 * ax, 2.0 * ay, 2.0 * az)  # 2a halved is a again, exactly


@nb.njit(cache=True, inline="always", error_model="numpy")
def right_step_raw(w, x, y, z, ax, ay, az):
    """The product q ⊗ exp(a), a = φ/2, not normalised (see renormalised): right_step's update, written out.

    Inlined, it takes the caller's fused multiply-adds (qmul, a function of its own, is compiled without them):
    twelve of the product's sixteen multiplications fused with its twelve additions, one rounding fewer each.
    """
    dw, dx, dy, dz = _exp_minus_one(ax, ay, az)
    return (
        w + (w * dw - x * dx - y * dy - z * dz),
        x + (w * dx + x * dw + y * dz - z * dy),
        y + (w * dy - x * dz + y * dw + z * dx),
        z + (w * dz + x * dy - y * dx + z * dw),
    )


@nb.njit(cache=True, inline="always", error_model="numpy")
def renormalised(w, x, y, z):
    """The series normalisation q (3 - |q|²)/2 of right_step, for a q within rounding of unit norm."""
    f = 1.5 - 0.5 * (w * w + x * x + y * y + z * z)
    return w * f, x * f, y * f, z * f


@nb.njit(cache=True, inline="always", error_model="numpy")
def left_step(w, x, y, z, px, py, pz):
    """exp(φ/2) ⊗ q, normalised: a rotation by φ in the reference frame."""
    w, x, y, z = _stepped(w, x, y, z, px, py, pz, True)
    inv = 1.0 / math.sqrt(w * w + x * x + y * y + z * z)
    return w * inv, x * inv, y * inv, z * inv


@nb.njit(cache=True, inline="always", error_model="numpy")
def _arc_w(vx, vy, vz, s2):
    """|v| + v_z without cancellation when v points down: s2 / (|v| - v_z) there."""
    nv = math.sqrt(s2 + vz * vz)
    return nv + vz if vz >= 0.0 else s2 / (nv - vz)


@nb.njit(cache=True, inline="always", error_model="numpy")
def unit_rotvec(w, x, y, z):
    """Rotation vector of a unit quaternion: 2 asin(s)/s · (x, y, z), s = |(x, y, z)|, sign of w folded in.

    For the small steps of a filter (s < 0.05) the series 2 (1 + s²/6 + 3 s⁴/40 + 5 s⁶/112 + 35 s⁸/1152) needs
    no square root or division (first omitted term < 2e-15 relative); beyond, atan2.
    """
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    s2 = x * x + y * y + z * z
    if s2 < 0.0025:
        k = 2.0 + s2 * (1.0 / 3.0 + s2 * (3.0 / 20.0 + s2 * (5.0 / 56.0 + s2 * (35.0 / 576.0))))
    else:
        s = math.sqrt(s2)
        k = 2.0 * math.atan2(s, w) / s
    return x * k, y * k, z * k


@nb.njit(cache=True, inline="always", error_model="numpy")
def tilt_to_z(vx, vy, vz):
    """The tilt quaternion (e0, e1, e2; e3 = 0) turning the direction v onto +z (math.md §5.5); down: about x."""
    s2 = vx * vx + vy * vy
    if s2 == 0.0:
        return (1.0, 0.0, 0.0) if vz >= 0.0 else (0.0, 1.0, 0.0)
    w = _arc_w(vx, vy, vz, s2)
    inv = 1.0 / math.sqrt(w * w + s2)
    return w * inv, vy * inv, -vx * inv


@nb.njit(cache=True, inline="always", error_model="numpy")
def tilt_to_z_scaled(vx, vy, vz):
    """tilt_to_z as (w, vy, -vx) and the factor 1/|(w, vy, -vx)| that normalises it, w = |v| + v_z.

    A product with the tilt quaternion can then run beside the square root and division of the factor and be
    scaled after.  For v up, |(w, vy, -vx)|² = w² + vx² + vy² = 2|v|w = 2|v|² + 2 v_z |v|: one fused step after
    the root of |v|² instead of two.
    """
    s2 = vx * vx + vy * vy
    if s2 == 0.0:
        return (1.0, 0.0, 0.0, 1.0) if vz >= 0.0 else (0.0, 1.0, 0.0, 1.0)
    n2 = s2 + vz * vz
    nv = math.sqrt(n2)
    if vz >= 0.0:
        w = nv + vz
        y = 2.0 * vz * nv + 2.0 * n2
    else:  # without cancellation (_arc_w)
        w = s2 / (nv - vz)
        y = w * w + s2
    return w, vy, -vx, 1.0 / math.sqrt(y)


@nb.njit(cache=True, inline="always", error_model="numpy")
def tilt_to_vertical(vx, vy, vz):
    """Rotation vector (horizontal) that turns the direction v onto +z: axis v×z, angle atan2(|v×z|, v·z)."""
    s = math.sqrt(vx * vx + vy * vy)
    if s == 0.0:
        if vz >= 0.0:
            return 0.0, 0.0
        return math.pi, 0.0  # straight down: half a turn about x
    angle = math.atan2(s, vz)
    return vy / s * angle, -vx / s * angle


@nb.njit(cache=True, inline="always", error_model="numpy")
def lowpass2(h, tau):
    """Exact step over h seconds of the second-order Butterworth low-pass with cutoff √2/tau rad/s.

    The filter is the ODE y'' + (2/tau) y' + (2/tau²) y = (2/tau²) u, whose poles are (-1 ± i)/tau; with the input
    held over the step (zero-order hold), the deviation d = y - u and the rate v = y' advance by the transition
    matrix exp(A h) = [[c + s, tau s], [-2 s/tau, c - s]], c + i s = exp((-1 + i) h/tau).  The states are the
    output and its rate, so they stay meaningful for any interval: a gap or a change of rate needs no restart
    (a direct-form filter's states belong to the coefficients that made them, and swing when those change).
    For h/tau < 0.05 the exponential is its Taylor series to the sixth power (error < 2e-12): jittered intervals
    then cost no transcendental functions.  Returns the four entries of exp(A h), row by row.
    """
    th = h / tau
    if th < 0.05:
        c = 1.0 - th + th * th * th * (1.0 / 3.0 - th * (1.0 / 6.0 - th * (1.0 / 30.0)))
        s = th * (1.0 - th + th * th * (1.0 / 3.0 - th * th * (1.0 / 30.0 - th * (1.0 / 90.0))))
    else:
        e = math.exp(-th)
        c = e * math.cos(th)
        s = e * math.sin(th)
    return c + s, tau * s, -2.0 * s / tau, c - s


NOMINAL_TAU = 1.0  # s: how fast the nominal sample interval follows a lasting lower rate (gap_step)


@nb.njit(cache=True, inline="always", error_model="numpy")
def gap_step(h, nominal):
    """The weight of the previous gyro sample over an interval of h s, and the nominal interval after it.

    A gyro sample is the rate over (or at the end of) its own sample interval, ``nominal`` (the shortest recent
    interval).  An interval h longer than that holds missing samples: the part h - nominal between the previous
    sample and this one is not covered by either.  Interpolating the rate linearly between the two samples (at
    the centres of their intervals) gives it the mean (ω_prev + ω)/2, so the mean rate over the whole interval is
    ω + w (ω_prev - ω) with w = (h - nominal) / (2h): exact for a rate that changes linearly, and 0 for regular
    samples.  Applying ω alone over a gap errs by about the gap times the change of rate.  The nominal interval
    drops at once to a shorter interval and rises towards a longer one in NOMINAL_TAU, so a lasting lower rate is
    soon regular again.
    """
    if nominal <= 0.0:  # the first interval
        return 0.0, h
    w = 0.0
    if h > nominal:
        w = (h - nominal) / (2.0 * h)
        nominal += (h - nominal) * min(1.0, h / NOMINAL_TAU)
    else:
        nominal = h
    return w, nominal


@nb.njit(cache=True, inline="always", error_model="numpy")
def gap_rate(h, nominal, wx, wy, wz, px, py, pz):
    """The rate to apply over an interval of h s (gap_step), the nominal interval and previous sample after it.

    Returns (rate x, y, z, nominal, previous x, y, z); an interval of 0 (a first sample) changes nothing.
    """
    if h <= 0.0:
        return wx, wy, wz, nominal, px, py, pz
    w, nominal = gap_step(h, nominal)
    return wx + w * (px - wx), wy + w * (py - wy), wz + w * (pz - wz), nominal, wx, wy, wz


@nb.njit(cache=True, inline="always", error_model="numpy")
def lowpass2_step(y, v, u, p00, p01, p10, p11):
    """One step of the low-pass of ``lowpass2`` (its four coefficients) from output y and rate v, input u held."""
    d = y - u
    return u + p00 * d + p01 * v, p10 * d + p11 * v


@nb.njit(cache=True, inline="always", error_model="numpy")
def start_or_lowpass(ix, iy, iz, h, tau, a_init, a_cnt, asx, asy, asz, mx, my, mz, vx, vy, vz, p00, p01, p10, p11):
    """One accelerometer sample in I, h s after the last, into the filter of the estimators (output m, rate v).

    The start: for the first tau seconds (``a_init`` counts them; < 0 once over) the output is the plain mean of
    the samples (VQF starts its filters so).  A low-pass started at the first sample would carry that sample's
    linear acceleration for several tau; the mean lets it average out from the start.  Then the hand-over, in
    steady state at the mean, and the exact step of the low-pass (lowpass2's coefficients p) over each interval:
    no restart is needed after a gap or a change of rate, and jitter changes nothing but the interval.
    Returns (a_init, a_cnt, asx, asy, asz, mx, my, mz, vx, vy, vz).
    """
    if a_init >= 0.0:
        asx += ix
        asy += iy
        asz += iz
        a_cnt += 1.0
        mx, my, mz = asx / a_cnt, asy / a_cnt, asz / a_cnt
        a_init += h
        if a_init >= tau * (1.0 - 1e-9):
            a_init = -1.0
            vx = vy = vz = 0.0
    else:
        mx, vx = lowpass2_step(mx, vx, ix, p00, p01, p10, p11)
        my, vy = lowpass2_step(my, vy, iy, p00, p01, p10, p11)
        mz, vz = lowpass2_step(mz, vz, iz, p00, p01, p10, p11)
    return a_init, a_cnt, asx, asy, asz, mx, my, mz, vx, vy, vz


@nb.njit(cache=True, inline="always", error_model="numpy")
def copy_into(dst, d0, src, s0, n):
    """dst[d0 : d0 + n] = src[s0 : s0 + n] as a loop.

    A slice assignment between arrays makes numba compile its broadcasting check, whose error message pulls in
    numba's whole string formatting: seconds of a cold first call for one line (benchmarks/bench_coldstart.py).
    """
    for i in range(n):
        dst[d0 + i] = src[s0 + i]
