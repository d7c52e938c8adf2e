"""Numba kernel of :mod:`strapdown.fusion.tilt` (private).

Fused multiply-adds only, as :mod:`._kernels_numba` explains.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ._kernels_numba import (
    copy_into,
    gap_rate,
    horizontal_rows,
    lowpass2,
    lowpass2_step,
    right_step,
    rotate,
    start_or_lowpass,
    tilt_to_z,
    unit_rotvec,
)
from .estimate import FLAG_ACC_REJECTED, FLAG_BIAS_AT_LIMIT, FLAG_INVERTED, FLAG_REST

# state vector layout (one float64 array, so that get/set and chunking are trivial)
QG = 0  # 4: gyro frame attitude, sensor -> almost-inertial frame I
QC = 4  # 4: tilt correction, I -> reference (yaw-free; its k part is 0)
QCP = 8  # 4: the correction at the start of the drift loop's block
Q = 12  # 4: the estimate q_c ⊗ q_g of the last sample
BIAS = 16  # 3: gyro bias estimate, sensor axes, rad/s
LP1 = 19  # 3: the low-pass filter's rate (lowpass2) for the tilt-sensor vector in I
LP2 = 22  # 3: its output
GLP = 25  # 3: low-passed gyro (rest detection), sensor axes
ALP = 28  # 3: low-passed tilt-sensor vector (rest detection), sensor axes
REST = 31  # 1: seconds at rest so far
GPREV = 32  # 3: the last gyro sample, rad/s (gap_step)
NOMDT = 35  # 1: the nominal sample interval, s (0: none yet)
ATIME = 36  # 1: seconds since the last tilt-sensor sample the filter took (missing and gated rows add up)
ALAST = 37  # 3: the last tilt-sensor sample present (the rest detector holds it through missing rows)
NX = 6  # the drift loop's Kalman states: gyro bias (3, rad/s) and scale-factor errors (3)
COV = 40  # NX²: their covariance, row by row
ND = 14  # the drift loop's low-passed channels: R's horizontal rows (6), the same times diag ω (6), R (b + s ω) (2)
DRIFT = COV + NX * NX  # 2 ND: their rates, then their outputs
BLOCK = DRIFT + 2 * ND  # 1: seconds into the drift loop's block
START = BLOCK + 1  # 5: the start's plain mean: seconds so far (-1: over), sum of the samples in I (3), count
SCALE = START + 5  # 3: the gyro scale-factor errors (the gyro reads (1 + s) ω + b)
SIZE = SCALE + 3

REST_MEAN_FACTOR = 3.0  # a steady mean rate is a bias (rest) up to this many bias_limit (as in the AttitudeEstimator)
PRIOR_TIME = 36000.0  # s: the bias prior's pull towards zero (a Gauss-Markov correlation time, no clip); it leaves
# a learnt bias short by tau_bias / PRIOR_TIME of itself (0.3 % for the default 100 s)

REST_FILTER = 0.5  # s: time constant of the rest detector's low-pass filters
BLOCK_TIME = 0.1  # s: the drift loop's update interval; its low-pass (tau_acc ~ 3 s) is far slower.  0.05 s
# gives the same accuracy (BROAD, test-bed) and costs about a quarter of the speed: the 6-state update is ~400 flops


@nb.njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def kalman(p, x, h, y, w, clip, u):
    """Kalman update of the state x (covariance p, both in place) by one scalar measurement y = h·x + noise.

    The noise has variance w, the innovation is clipped to ±clip; u is scratch of x's size.  Several
    measurements with independent noise, taken one after the other (each against the updated x), are the same
    as one update by all of them.
    """
    n = x.shape[0]
    s = w
    e = y
    for i in range(n):
        ui = 0.0
        for j in range(n):
            ui += p[i, j] * h[j]
        u[i] = ui
        s += h[i] * ui
        e -= h[i] * x[i]
    g = 1.0 / s
    e = min(max(e, -clip), clip) * g
    for i in range(n):
        x[i] += u[i] * e
        ug = u[i] * g
        for j in range(n):
            p[i, j] -= ug * u[j]


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def run(
    gyro,
    up,
    dts,
    tau_acc,
    rest_gyro,
    rest_acc,
    rest_time,
    tau_rest_bias,
    tau_bias,
    bias_limit,
    bias_noise,
    scale_noise,
    acc_bias_sigma,
    gravity,
    acc_gate,
    to_out,
    inverted_tol,
    s,
    out,
    bias_out,
    flags,
):
    """The TiltEstimator, sample by sample (module notes of tilt.py); s is the state vector, updated in place.

    up[k] is the tilt-sensor vector in sensor axes: the accelerometer minus any known kinematic acceleration, or
    g times the up direction given by an inclinometer (NaN: no sample).  Flag 8 marks an output attitude
    ``to_out ⊗ q`` within ``inverted_tol`` of upside down, where the tilt chart of its frame is singular.

    Speed: the bias and scale change only at the drift loop's block updates (every BLOCK_TIME s), so the
    per-sample chain (gyro step, rotation into I, filter, tilt) carries no Kalman arithmetic.  The state lives
    in local variables (registers) inside the loop and goes back to s at the end.
    """
    gw, gx, gy, gz = s[QG], s[QG + 1], s[QG + 2], s[QG + 3]  # q_g
    cw, c1, c2 = s[QC], s[QC + 1], s[QC + 2]  # q_c
    pw, p1, p2 = s[QCP], s[QCP + 1], s[QCP + 2]  # q_c at the block's start
    qw, qx, qy, qz = s[Q], s[Q + 1], s[Q + 2], s[Q + 3]
    b0, b1, b2 = s[BIAS], s[BIAS + 1], s[BIAS + 2]
    k0, k1, k2 = s[SCALE], s[SCALE + 1], s[SCALE + 2]
    l0, l1, l2 = s[LP1], s[LP1 + 1], s[LP1 + 2]
    m0, m1, m2 = s[LP2], s[LP2 + 1], s[LP2 + 2]
    r0, r1, r2 = s[GLP], s[GLP + 1], s[GLP + 2]  # gyro mean (rest detection)
    u0, u1, u2 = s[ALP], s[ALP + 1], s[ALP + 2]  # tilt-sensor mean (rest detection)
    rest = s[REST]
    kp = np.empty((NX, NX))  # filled and stored by loops (copy_into's note)
    for i in range(NX):
        copy_into(kp[i], 0, s, COV + i * NX, NX)
    kx = np.empty(NX)
    kh = np.zeros(NX)
    ku = np.empty(NX)
    # rates 0..ND-1, then outputs: R00 R01 R02 R10 R11 R12, the same times diag ω, R (b + s ω) x and y
    d = s[DRIFT : DRIFT + 2 * ND].copy()
    xs = np.empty(ND)
    blk = s[BLOCK]
    a_init, asx, asy, asz, a_cnt = s[START], s[START + 1], s[START + 2], s[START + 3], s[START + 4]
    fw, fx, fy, fz = to_out[0], to_out[1], to_out[2], to_out[3]
    tol2 = inverted_tol * inverted_tol
    gated = acc_gate < math.inf
    gpx, gpy, gpz, nominal = s[GPREV], s[GPREV + 1], s[GPREV + 2], s[NOMDT]
    rest_mean_max = REST_MEAN_FACTOR * bias_limit
    t_acc, hx, hy, hz = s[ATIME], s[ALAST], s[ALAST + 1], s[ALAST + 2]
    q_noise = bias_noise * bias_noise  # (rad/s)²/s: the bias random walk
    s_noise = scale_noise * scale_noise  # 1/s: the scale factors' random walk
    motion_density = (tau_bias * bias_noise) ** 2  # (rad/s)² s: steady-state time constant tau_bias in motion
    rest_density = (tau_rest_bias * bias_noise) ** 2  # likewise tau_rest_bias at rest
    acc_bias_density = tau_acc * (acc_bias_sigma / gravity) ** 2  # s: times |dLP[R]/dt|² (module notes, 4)
    last_dt = last_t_acc = last_blk = -1.0
    at_limit = FLAG_BIAS_AT_LIMIT if max(abs(b0), abs(b1), abs(b2)) > bias_limit else 0
    p00 = p01 = p10 = p11 = r = 0.0
    d00 = d01 = d10 = d11 = keep = 0.0
    for k in range(gyro.shape[0]):
        dt = dts[k]
        if dt != last_dt:  # the coefficient changes only with the interval
            r = 1.0 - math.exp(-dt / REST_FILTER)
            last_dt = dt
        flag = 0
        wx = gyro[k, 0]
        wy = gyro[k, 1]
        wz = gyro[k, 2]
        ax = up[k, 0]
        ay = up[k, 1]
        az = up[k, 2]
        # 1. gyro frame: the bias-corrected rate, exact step; over an interval that holds missing samples, the
        # rate interpolated across the gap (gap_step in _kernels_numba.py)
        ox, oy, oz, nominal, gpx, gpy, gpz = gap_rate(dt, nominal, wx, wy, wz, gpx, gpy, gpz)
        gw, gx, gy, gz = right_step(
            gw, gx, gy, gz, (ox - b0 - k0 * ox) * dt, (oy - b1 - k1 * oy) * dt, (oz - b2 - k2 * oz) * dt
        )
        # 2. the tilt sensor in the almost-inertial frame, low-passed over tau_acc (second-order Butterworth,
        # stepped exactly over the time since the last sample it took: lowpass2).  A missing sample (NaN row) or
        # one the gate rejects holds the filter; the next one steps it over the whole time since, so a gap
        # needs no restart.  (NaN fails a2 > 0.)
        t_acc += dt
        a2 = ax * ax + ay * ay + az * az
        if a2 > 0.0 and (not gated or abs(math.sqrt(a2) - gravity) <= acc_gate):
            if t_acc != last_t_acc:
                p00, p01, p10, p11 = lowpass2(t_acc, tau_acc)
                last_t_acc = t_acc
            ix, iy, iz = rotate(gw, gx, gy, gz, ax, ay, az)
            # the start's plain mean, then the low-pass stepped exactly over the interval (start_or_lowpass)
            a_init, a_cnt, asx, asy, asz, m0, m1, m2, l0, l1, l2 = start_or_lowpass(
                ix, iy, iz, t_acc, tau_acc, a_init, a_cnt, asx, asy, asz, m0, m1, m2, l0, l1, l2, p00, p01, p10, p11
            )
            t_acc = 0.0
        else:
            flag |= FLAG_ACC_REJECTED
        if ax == ax:
            hx, hy, hz = ax, ay, az
        # 3. the correction q_c is the tilt quaternion that turns the filtered vector vertical (math.md §5.5): a
        # function of the filter state, not a recursion; the estimate is q_c ⊗ q_g
        cw, c1, c2 = tilt_to_z(m0, m1, m2)
        qw = cw * gw - c1 * gx - c2 * gy  # q_c ⊗ q_g with the k part of q_c zero
        qx = cw * gx + c1 * gw + c2 * gz
        qy = cw * gy - c1 * gz + c2 * gw
        qz = cw * gz + c1 * gy - c2 * gx
        # 5. rest: gyro and tilt sensor close to their 0.5 s means for rest_time
        r0 += r * (wx - r0)
        r1 += r * (wy - r1)
        r2 += r * (wz - r2)
        u0 += r * (hx - u0)  # the last sample present
        u1 += r * (hy - u1)
        u2 += r * (hz - u2)
        dg = (wx - r0) ** 2 + (wy - r1) ** 2 + (wz - r2) ** 2
        da = (hx - u0) ** 2 + (hy - u1) ** 2 + (hz - u2) ** 2
        # a steady mean rate is a bias if the prior finds it plausible (within three bias_limit per axis)
        gm = max(abs(r0), abs(r1), abs(r2))
        if dg < rest_gyro * rest_gyro and da < rest_acc * rest_acc and gm < rest_mean_max:
            rest += dt
        else:
            rest = 0.0
        at_rest = rest >= rest_time
        if at_rest:
            flag |= FLAG_REST
        # 4. the drift loop, a Kalman filter of the bias updated every BLOCK_TIME (module notes, 4)
        blk += dt
        if blk >= BLOCK_TIME:
            if blk != last_blk:
                d00, d01, d10, d11 = lowpass2(blk, tau_acc)
                keep = math.exp(-blk / PRIOR_TIME)
                last_blk = blk
            # the bias prior instead of a clip: a Gauss-Markov bias, pulled towards zero over PRIOR_TIME
            b0 *= keep
            b1 *= keep
            b2 *= keep
            for i in range(NX):
                for j in range(NX):
                    kp[i, j] *= (keep if i < 3 else 1.0) * (keep if j < 3 else 1.0)  # the bias rows and columns
            for i in range(3):
                kp[i, i] += q_noise * blk
                kp[3 + i, 3 + i] += s_noise * blk
            # the horizontal rows of R(q), the same times diag ω, and R (b + s ω), through the tilt sensor's
            # low-pass (so lagged alike)
            xs[0], xs[1], xs[2], xs[3], xs[4], xs[5] = horizontal_rows(qw, qx, qy, qz)
            xs[6], xs[7], xs[8] = xs[0] * ox, xs[1] * oy, xs[2] * oz
            xs[9], xs[10], xs[11] = xs[3] * ox, xs[4] * oy, xs[5] * oz
            xs[12] = xs[0] * b0 + xs[1] * b1 + xs[2] * b2 + xs[6] * k0 + xs[7] * k1 + xs[8] * k2
            xs[13] = xs[3] * b0 + xs[4] * b1 + xs[5] * b2 + xs[9] * k0 + xs[10] * k1 + xs[11] * k2
            if a_init >= 0.0:
                # during the start the tilt sensor's filter is a plain mean, so is this one (time-weighted over
                # the blocks so far); it hands over in steady state, as that one does
                wm = blk / max(a_init, blk)
                for j in range(ND):
                    d[ND + j] += wm * (xs[j] - d[ND + j])
                    d[j] = 0.0
            else:
                for j in range(ND):
                    d[ND + j], d[j] = lowpass2_step(d[ND + j], d[j], xs[j], d00, d01, d10, d11)
            kx[0], kx[1], kx[2], kx[3], kx[4], kx[5] = b0, b1, b2, k0, k1, k2
            if at_rest:
                # the 0.5 s gyro mean measures the bias on every axis
                w = rest_density / blk
                for i in range(3):
                    kh[:] = 0.0
                    kh[i] = 1.0
                    y = r0 if i == 0 else (r1 if i == 1 else r2)
                    kalman(kp, kx, kh, y, w, math.inf, ku)
            elif tau_bias > 0.0:
                # in motion, the patent's drift loop: a bias or scale error turns the almost-inertial frame at
                # R (δb + δs ω), and the correction turns with it, lagged by the filter: its mean rate over the
                # block (reference frame, horizontal) is -LP[R (δb + δs ω)], so y = -rate + LP[R (b̂ + ŝ ω)]
                # measures LP[R] b + LP[R diag ω] s (VQF's regression for the bias, the AttitudeEstimator's)
                hw = cw * pw + c1 * p1 + c2 * p2  # q_c ⊗ q_c,start*, both tilt quaternions
                h1 = c1 * pw - cw * p1
                h2 = c2 * pw - cw * p2
                h3 = c2 * p1 - c1 * p2
                ex, ey, _ = unit_rotvec(hw, h1, h2, h3)
                # noise: a base density (tau_bias) and the correction an accelerometer bias makes while the
                # body turns, |dLP[R]/dt| acc_bias_sigma / g, coloured over tau_acc (module notes, 4)
                rr = d[0] ** 2 + d[1] ** 2 + d[2] ** 2 + d[3] ** 2 + d[4] ** 2 + d[5] ** 2
                w = (motion_density + acc_bias_density * rr) / blk
                # the correction's rate is the block's mean, so the regressor is taken at its middle: the
                # low-pass output half a block back along its rate
                hb = 0.5 * blk
                for i in range(2):
                    for j in range(3):
                        c = 3 * i + j
                        kh[j] = d[ND + c] - hb * d[c]
                        kh[3 + j] = d[ND + 6 + c] - hb * d[6 + c]
                    c = 12 + i
                    kalman(kp, kx, kh, d[ND + c] - hb * d[c] - (ex if i == 0 else ey) / blk, w, bias_limit, ku)
            b0, b1, b2, k0, k1, k2 = kx[0], kx[1], kx[2], kx[3], kx[4], kx[5]
            pw, p1, p2 = cw, c1, c2
            blk = 0.0
            at_limit = FLAG_BIAS_AT_LIMIT if max(abs(b0), abs(b1), abs(b2)) > bias_limit else 0
        flag |= at_limit  # the bias changes only here
        out[k, 0] = qw
        out[k, 1] = qx
        out[k, 2] = qy
        out[k, 3] = qz
        bias_out[k, 0] = b0
        bias_out[k, 1] = b1
        bias_out[k, 2] = b2
        ow = fw * qw - fx * qx - fy * qy - fz * qz  # scalar and k parts of to_out ⊗ q
        oz = fw * qz + fx * qy - fy * qx + fz * qw
        if ow * ow + oz * oz < tol2:
            flag |= FLAG_INVERTED
        flags[k] = flag
    s[QG], s[QG + 1], s[QG + 2], s[QG + 3] = gw, gx, gy, gz
    s[QC], s[QC + 1], s[QC + 2], s[QC + 3] = cw, c1, c2, 0.0
    s[QCP], s[QCP + 1], s[QCP + 2], s[QCP + 3] = pw, p1, p2, 0.0
    s[Q], s[Q + 1], s[Q + 2], s[Q + 3] = qw, qx, qy, qz
    s[BIAS], s[BIAS + 1], s[BIAS + 2] = b0, b1, b2
    s[LP1], s[LP1 + 1], s[LP1 + 2] = l0, l1, l2
    s[LP2], s[LP2 + 1], s[LP2 + 2] = m0, m1, m2
    s[GLP], s[GLP + 1], s[GLP + 2] = r0, r1, r2
    s[ALP], s[ALP + 1], s[ALP + 2] = u0, u1, u2
    s[REST] = rest
    s[GPREV], s[GPREV + 1], s[GPREV + 2], s[NOMDT] = gpx, gpy, gpz, nominal
    s[ATIME], s[ALAST], s[ALAST + 1], s[ALAST + 2] = t_acc, hx, hy, hz
    for i in range(NX):
        copy_into(s, COV + i * NX, kp[i], 0, NX)
    copy_into(s, DRIFT, d, 0, 2 * ND)
    s[SCALE], s[SCALE + 1], s[SCALE + 2] = k0, k1, k2
    s[BLOCK] = blk
    s[START], s[START + 1], s[START + 2], s[START + 3], s[START + 4] = a_init, asx, asy, asz, a_cnt
