"""Numba kernel of :mod:`strapdown.fusion.tilt` (private).

The kernels allow fused multiply-adds (``fastmath={"contract"}``) and nothing else of fastmath: each is one
correctly rounded operation, nothing is reassociated, so any chunking still gives bit-identical results; it makes
the per-sample recursion about a tenth faster.
"""

from __future__ import annotations

import math

import numba as nb

from ._base import FLAG_ACC_REJECTED, FLAG_BIAS_AT_LIMIT, FLAG_INVERTED, FLAG_REST
from ._kernels_numba import gap_rate, lowpass2, lowpass2_step, right_step, rotate, rotate_back, tilt_to_z, unit_rotvec

# state vector layout (one float64 array, so that get/set and chunking are trivial)
QG = 0  # 4: gyro frame attitude, sensor -> almost-inertial frame I
QC = 4  # 4: tilt correction, I -> reference (yaw-free; its k part is 0)
QCP = 8  # 4: the correction one sample earlier (for the drift loop's pending update)
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
SIZE = 40

REST_MEAN_FACTOR = 3.0  # a steady mean rate is a bias (rest) up to this many bias_limit (as in the AttitudeEstimator)
PRIOR_TIME = 36000.0  # s: the bias prior's pull towards zero (a Gauss-Markov correlation time, no clip); it leaves
# a learnt bias short by tau_bias / PRIOR_TIME of itself (0.3 % for the default 100 s)

REST_FILTER = 0.5  # s: time constant of the rest detector's low-pass filters


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def run(
    gyr,
    up,
    dts,
    tau_acc,
    rest_gyro,
    rest_acc,
    rest_time,
    tau_rest_bias,
    tau_bias,
    bias_limit,
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
    g times the up direction given by an inclinometer.  Flag 8 marks an output attitude ``to_out ⊗ q`` within
    ``inverted_tol`` of upside down, where the tilt chart of its frame is singular.

    Speed: one sample's work is a long chain of dependent operations (gyro step, rotation into I, filter, tilt,
    drift loop), too long for the processor to overlap consecutive samples by itself.  The drift loop therefore
    runs one sample late: sample k first applies the update owed by sample k-1, which depends on nothing of
    sample k, so it executes alongside sample k's chain.  A delay of one sample (1/fs) in a loop of time
    constant tau_bias changes nothing measurable; it makes the filter 1.6 times faster.  The state lives in
    local variables (registers) inside the loop and goes back to s at the end.
    """
    gw, gx, gy, gz = s[QG], s[QG + 1], s[QG + 2], s[QG + 3]  # q_g
    cw, c1, c2 = s[QC], s[QC + 1], s[QC + 2]  # q_c
    pw, p1, p2 = s[QCP], s[QCP + 1], s[QCP + 2]  # q_c one sample earlier
    qw, qx, qy, qz = s[Q], s[Q + 1], s[Q + 2], s[Q + 3]
    b0, b1, b2 = s[BIAS], s[BIAS + 1], s[BIAS + 2]
    l0, l1, l2 = s[LP1], s[LP1 + 1], s[LP1 + 2]
    m0, m1, m2 = s[LP2], s[LP2 + 1], s[LP2 + 2]
    r0, r1, r2 = s[GLP], s[GLP + 1], s[GLP + 2]  # gyro mean (rest detection)
    u0, u1, u2 = s[ALP], s[ALP + 1], s[ALP + 2]  # tilt-sensor mean (rest detection)
    rest = s[REST]
    inv_tau_bias = 1.0 / tau_bias if tau_bias > 0.0 else 0.0
    fw, fx, fy, fz = to_out[0], to_out[1], to_out[2], to_out[3]
    tol2 = inverted_tol * inverted_tol
    gated = acc_gate < math.inf
    gpx, gpy, gpz, nominal = s[GPREV], s[GPREV + 1], s[GPREV + 2], s[NOMDT]
    rest_mean_max = REST_MEAN_FACTOR * bias_limit
    t_acc, hx, hy, hz = s[ATIME], s[ALAST], s[ALAST + 1], s[ALAST + 2]
    last_dt = last_t_acc = -1.0
    p00 = p01 = p10 = p11 = r = f = keep = 0.0
    for k in range(gyr.shape[0]):
        dt = dts[k]
        if dt != last_dt:  # the coefficients change only with the interval
            r = 1.0 - math.exp(-dt / REST_FILTER)
            f = 1.0 - math.exp(-dt / tau_rest_bias)
            keep = math.exp(-dt / PRIOR_TIME)
            last_dt = dt
        flag = 0
        wx = gyr[k, 0]
        wy = gyr[k, 1]
        wz = gyr[k, 2]
        ax = up[k, 0]
        ay = up[k, 1]
        az = up[k, 2]
        # 1. gyro frame: the bias-corrected rate, exact step; over an interval that holds missing samples, the
        # rate interpolated across the gap (gap_step in _kernels_numba.py)
        ox, oy, oz, nominal, gpx, gpy, gpz = gap_rate(dt, nominal, wx, wy, wz, gpx, gpy, gpz)
        gw, gx, gy, gz = right_step(gw, gx, gy, gz, (ox - b0) * dt, (oy - b1) * dt, (oz - b2) * dt)
        # 4. (of sample k-1) bias in motion, the patent's drift loop: in steady state the correction turns at the
        # rate of the bias error, so its last increment q_c ⊗ q_c,previous* (horizontal in the reference frame),
        # taken to body axes, is fed back with time constant tau_bias
        if tau_bias > 0.0:
            hw = cw * pw + c1 * p1 + c2 * p2  # q_c ⊗ q_c,previous*, both tilt quaternions
            h1 = c1 * pw - cw * p1
            h2 = c2 * pw - cw * p2
            h3 = c2 * p1 - c1 * p2
            ex, ey, _ = unit_rotvec(hw, h1, h2, h3)
            bx, by, bz = rotate_back(qw, qx, qy, qz, ex, ey, 0.0)
            b0 -= bx * inv_tau_bias
            b1 -= by * inv_tau_bias
            b2 -= bz * inv_tau_bias
        pw, p1, p2 = cw, c1, c2
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
            t_acc = 0.0
            ix, iy, iz = rotate(gw, gx, gy, gz, ax, ay, az)
            m0, l0 = lowpass2_step(m0, l0, ix, p00, p01, p10, p11)
            m1, l1 = lowpass2_step(m1, l1, iy, p00, p01, p10, p11)
            m2, l2 = lowpass2_step(m2, l2, iz, p00, p01, p10, p11)
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
        # 5. bias at rest: the low-passed gyro, once gyro and tilt sensor have been steady for rest_time
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
        if rest >= rest_time:
            flag |= FLAG_REST
            b0 += f * (r0 - b0)
            b1 += f * (r1 - b1)
            b2 += f * (r2 - b2)
        # the bias prior instead of a clip: a pull towards zero over PRIOR_TIME (a Gauss-Markov bias), far slower
        # than either way of learning it, so a large bias the data show is learnt; beyond bias_limit it is flagged
        b0 *= keep
        b1 *= keep
        b2 *= keep
        if max(abs(b0), abs(b1), abs(b2)) > bias_limit:
            flag |= FLAG_BIAS_AT_LIMIT
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
