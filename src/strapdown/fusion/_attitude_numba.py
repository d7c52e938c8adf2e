"""Numba kernel of :mod:`strapdown.fusion.attitude` (private).

The state is one float64 vector ``s`` (offsets below, named in attitude.py) plus the NX x NX covariance ``P`` of
the Kalman states (gyro bias and scale-factor errors, accelerometer bias, lever arm); both are updated in place,
so any chunking gives the same result.

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
    renormalised,
    right_step_raw,
    rotate,
    start_or_lowpass,
    tilt_to_z_scaled,
    unit_rotvec,
)

# the flag bits are defined once, in estimate.py
from .estimate import FLAG_ACC_REJECTED as FLAG_ACC_MISSING
from .estimate import FLAG_BIAS_AT_LIMIT, FLAG_REST
from .estimate import FLAG_MAG_REJECTED as FLAG_MAG_DISTURBED

# --- layout of s ------------------------------------------------------------------------------------------------
QG = 0  # 4: gyro frame attitude, sensor -> almost-inertial frame I
QC = 4  # 3: correction q_c (a tilt quaternion, k part 0): I -> 6D reference frame
AF = 7  # 3: the accelerometer filter's rate state dy/dt per axis, in I (its output is AFO; lowpass2)
X = 10  # 6: gyro bias (rad/s) and scale-factor errors (dimensionless), sensor axes
REG = 16  # 28: the regressor filter's output and rate for 14 channels (block rate; lowpass2)
V7 = 44  # 7: the magnetometer regressors, first-order low-pass at tau_mag (block rate)
ACC = 51  # 24: block accumulators: 14 acc regressors, 7 mag regressors, 3 field components
TB = 75  # 1: seconds accumulated in the current block
EXS = 76  # 3: the correction q_c at the start of the block (its change over the block is measured)
W2 = 79  # 1: |omega|^2 dt summed over the block
NMAG = 80  # 1: seconds of magnetometer data in the block
RESTG = 81  # 3: gyro mean for rest detection
RESTA = 84  # 3: accelerometer mean for rest detection
REST = 87  # 1: seconds at rest so far
DELTA = 88  # 1: heading offset delta (rad): output = q_z(delta) (x) q_6D
MREF = 89  # 2: reference field norm, dip (rad)
MCUR = 91  # 2: current field norm, dip (fast low-pass)
MOLD = 93  # 2: the field before the last switch of reference (norm < 0: none)
DIST = 95  # 1: seconds the field has been disturbed
UND = 96  # 1: seconds the field has been undisturbed
STARTED = 97  # 1: 1 once the regressor filter has started
TACC = 98  # 1: seconds since the last accelerometer sample
AFO = 99  # 3: the accelerometer filter's output, in I
RESTV = 102  # 1: mean squared deviation of the gyro from its rest mean, (rad/s)²
AINIT = 103  # 1: seconds of accelerometer averaged at the start (< 0: the averaging is over)
ASUM = 104  # 3: the sum of the accelerometer samples in I during that time
ACNT = 107  # 1: how many
MAGN = 108  # 1: undisturbed heading updates so far (-1: waiting for the inclination's restart after a clip)
GPREV = 109  # 3: the last gyro sample, rad/s (gap_step)
NOMDT = 112  # 1: the nominal sample interval, s (0: none yet)
MCONF = 120  # 1: seconds the first field has been consistent (< 0: it is the reference)
ALIN = 113  # 1: seconds of accelerometer samples summed into ARES in the current block
RLP = 114  # 3: the low-pass of the accelerometer's departure from the filtered vector, in I (block rate)
RLV = 117  # 3: its rate
XA = 121  # 3: accelerometer bias, sensor axes, m/s² (Kalman states 6-8)
ALAST = 124  # 3: the last accelerometer sample (rest detection holds it through missing rows)
ARES = 127  # 3: the accelerometer's departure from the filtered vector, in I, times dt, summed over the block
QN = 130  # 1: gyro steps since the gyro frame was last renormalised
XL = 131  # 3: lever arm, sensor axes, m (Kalman states 9-11)
YDD = 134  # 6: the second derivative of the low-passed rows of R at the last block's end (lever arm)
SIZE = 140

# The gyro frame is renormalised every RENORM_STEPS steps, not after each: a step (right_step_raw) keeps |q| to
# its rounding, about 1e-16 (at most 2e-16), so |q| - 1 stays below ~1e-15 in between; the series normalisation
# (renormalised) removes it whatever it is.  Counted in the state (QN), so any chunking gives the same results.
RENORM_STEPS = 8

REST_MEAN_FACTOR = 3.0  # a steady mean rate counts as a bias (rest) up to this many prior spreads
N_REG = 14
NX = 12  # Kalman states: gyro bias (3), gyro scale-factor errors (3), accelerometer bias (3), lever arm (3)
N_SUMS = 36  # block sums: 14 acc regressors (12, 13 formed at the update), 7 mag (20 formed), field, |w|², t_mag,
# the accelerometer's seconds and departure from the filtered vector (26-29)


@nb.njit(cache=True, error_model="numpy")
def kalman(x, P, H, z, R, nm, PHt, K, tmp, lo, hi):
    """In-place Kalman update of the NX-state x, P with nm <= 3 measurements z = H x + noise of variances R.

    Written for speed at the block rate: P is symmetric, so only its upper triangle is formed and mirrored.
    A function of its own, not inlined: it runs once per block, and each inlined copy of its unrolled loops
    lengthened the estimator's first compilation by seconds (benchmarks/bench_coldstart.py).  Callers pass
    ``nm`` as ``np.int64(n)``: a literal would compile one specialisation per count.  Only states lo..hi-1 are
    updated: for a block of P with no covariance with the rest and H zero outside it, that is the whole update
    (the accelerometer bias's and the gyro's, attitude_estimator.py step 3), at a fraction of the work.
    """
    for j in range(nm):
        for i in range(lo, hi):
            d = 0.0
            for c in range(lo, hi):
                d += P[i, c] * H[j, c]
            PHt[i, j] = d
    # S = H P Hᵀ + R, inverted in closed form
    s00 = R[0]
    for c in range(lo, hi):
        s00 += H[0, c] * PHt[c, 0]
    if nm == 1:
        i00 = 1.0 / s00
        for i in range(lo, hi):
            K[i, 0] = PHt[i, 0] * i00
    elif nm == 2:
        s01 = 0.0
        s11 = R[1]
        for c in range(lo, hi):
            s01 += H[0, c] * PHt[c, 1]
            s11 += H[1, c] * PHt[c, 1]
        det = s00 * s11 - s01 * s01
        i00 = s11 / det
        i01 = -s01 / det
        i11 = s00 / det
        for i in range(lo, hi):
            a0 = PHt[i, 0]
            a1 = PHt[i, 1]
            K[i, 0] = a0 * i00 + a1 * i01
            K[i, 1] = a0 * i01 + a1 * i11
    else:
        s01 = s02 = s12 = 0.0
        s11 = R[1]
        s22 = R[2]
        for c in range(lo, hi):
            s01 += H[0, c] * PHt[c, 1]
            s02 += H[0, c] * PHt[c, 2]
            s11 += H[1, c] * PHt[c, 1]
            s12 += H[1, c] * PHt[c, 2]
            s22 += H[2, c] * PHt[c, 2]
        c00 = s11 * s22 - s12 * s12
        c01 = s02 * s12 - s01 * s22
        c02 = s01 * s12 - s02 * s11
        inv_det = 1.0 / (s00 * c00 + s01 * c01 + s02 * c02)
        i00 = c00 * inv_det
        i01 = c01 * inv_det
        i02 = c02 * inv_det
        i11 = (s00 * s22 - s02 * s02) * inv_det
        i12 = (s01 * s02 - s00 * s12) * inv_det
        i22 = (s00 * s11 - s01 * s01) * inv_det
        for i in range(lo, hi):
            a0 = PHt[i, 0]
            a1 = PHt[i, 1]
            a2 = PHt[i, 2]
            K[i, 0] = a0 * i00 + a1 * i01 + a2 * i02
            K[i, 1] = a0 * i01 + a1 * i11 + a2 * i12
            K[i, 2] = a0 * i02 + a1 * i12 + a2 * i22
    for j in range(nm):
        d = z[j]
        for c in range(lo, hi):
            d -= H[j, c] * x[c]
        tmp[j] = d
    for i in range(lo, hi):
        d = 0.0
        for j in range(nm):
            d += K[i, j] * tmp[j]
        x[i] += d
    # P -= K (H P) = K PHtᵀ, upper triangle then mirrored
    for i in range(lo, hi):
        for c in range(i, hi):
            d = 0.0
            for j in range(nm):
                d += K[i, j] * PHt[c, j]
            v = P[i, c] - d
            P[i, c] = v
            P[c, i] = v


@nb.njit(cache=True, error_model="numpy", inline="always")
def in_use(x, P, j, k2):
    """The accelerometer bias subtracted on axis j: x_j - k2 P_jj / x_j, zero while x_j² <= k2 P_jj.

    A positive-part shrinkage, continuous at the threshold (attitude_estimator.py, step 3).
    """
    v = x[j]
    if k2 <= 0.0:
        return v
    if v * v <= k2 * P[j, j]:
        return 0.0
    return v - k2 * P[j, j] / v


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def run(gyro, acc, mag, use_mag, dts, p, s, P, out, seg_end, seg_val, flags, squares):
    """The AttitudeEstimator over a chunk (module notes of attitude.py); s and P are updated in place.

    dts: the sample intervals; sample k's is ``dts[min(k, len(dts) - 1)]``, so a constant interval may come as
    two entries (the first sample's and every later one's: Estimator.compact_intervals).

    p: tau_acc, tau_mag, bias forgetting variance rate, scale variance rate, motion noise density², kappa²,
    rest noise density², mag noise density², rest gyro threshold², rest acc threshold², rest time, rest filter
    tau, bias prior spread (rad/s), field norm threshold (relative), dip threshold (rad), reference tau, current
    tau, new-field time, block length (s), linear-acceleration factor², start time (s), accelerometer-bias random
    walk (0: not modelled), the accelerometer bias's own linear-acceleration factor², its significance² (the
    shrinkage of the bias in use: in_use), the lever arm's random walk² (m²/s), the significance² of the bias the
    gyro's update takes as known.

    Bias and its standard deviation change at block updates only, so they are not written per sample: segment
    i (``seg_end[i-1]`` to ``seg_end[i]``, from 0) holds the bias (``seg_val[0, i]``) and its standard deviations
    (``seg_val[1, i]``: each part contiguous, handed on without a copy); the arrays need room for every block
    that ends in the chunk and the unfinished one (attitude.py sizes them; more blocks than they hold stop the
    kernel); returns how many were written.
    ``squares`` gets the sums of squares of gyro, acc and (9D) mag added, for the input checks
    (Estimator.checks_in_kernel).

    Speed: over each block, one loop integrates the gyro frame and writes it to ``out``, a second runs the
    accelerometer filter and the correction on it and overwrites it with the 6D attitude (split so, each keeps its
    recursion's state in registers: a tenth faster than one loop over both, same operations, same results);
    simple loops then form the block's regressor sums from them, detect rest and, in 9D, turn them into the 9D
    output.  Small loops run faster than one large one.
    """
    tau_acc = p[0]
    rest_time, rest_tau, prior, t_block = p[10], p[11], p[12], p[18]
    last = dts.shape[0] - 1  # sample k's interval is dts[min(k, last)]: a constant one may come as two entries
    at_limit = FLAG_BIAS_AT_LIMIT if max(abs(s[X]), abs(s[X + 1]), abs(s[X + 2])) > prior else 0
    gw, gx, gy, gz = s[QG], s[QG + 1], s[QG + 2], s[QG + 3]
    # the correction q_c = (cw, c1, c2, 0) as (rw, r1, r2) times rinv (tilt_to_z_scaled); from the state, normalised
    rw, r1, r2, rinv = s[QC], s[QC + 1], s[QC + 2], 1.0
    vx, vy, vz = s[AF], s[AF + 1], s[AF + 2]
    mx, my, mz = s[AFO], s[AFO + 1], s[AFO + 2]
    a_init, a_cnt = s[AINIT], s[ACNT]
    asx, asy, asz = s[ASUM], s[ASUM + 1], s[ASUM + 2]
    x = np.empty(NX)
    copy_into(x, 0, s, X, 6)
    copy_into(x, 6, s, XA, 3)
    copy_into(x, 9, s, XL, 3)
    gpx, gpy, gpz, nominal = s[GPREV], s[GPREV + 1], s[GPREV + 2], s[NOMDT]
    # a count out of range (a hand-made state) renormalises at the first step
    n_raw = int(s[QN]) if 0.0 <= s[QN] < RENORM_STEPS else RENORM_STEPS - 1
    sums = np.zeros(N_SUMS)
    copy_into(sums, 0, s, ACC, 24)
    sums[24] = s[W2]
    sums[25] = s[NMAG]
    # the accelerometer's departure from the filtered vector (sums 26-29), summed in registers over a block
    lin_t, lin_x, lin_y, lin_z = s[ALIN], s[ARES], s[ARES + 1], s[ARES + 2]
    tb = s[TB]
    sw, s1, s2 = s[EXS], s[EXS + 1], s[EXS + 2]
    # the rest detector's state: gyro mean, accelerometer mean, seconds at rest, gyro scatter, last accelerometer
    # sample, and its last coefficient (index 11) for the interval of index 12
    rs = np.empty(13)
    copy_into(rs, 0, s, RESTG, 3)
    copy_into(rs, 3, s, RESTA, 3)
    rs[6] = s[REST]
    rs[7] = s[RESTV]
    copy_into(rs, 8, s, ALAST, 3)
    rs[11] = 0.0
    rs[12] = -1.0
    rest = rs[6]
    H = np.zeros((3, NX))
    z = np.zeros(3)
    R = np.zeros(3)
    PHt = np.zeros((NX, 3))
    K = np.zeros((NX, 3))
    tmp = np.zeros(3)
    # regressor outputs; cached block coefficients: T, 4 of lowpass2, bias decay, kmag, kcur, kref; changes of the 6
    # row channels
    work = np.zeros(N_REG + 21)
    hs = np.zeros((2, NX))  # the block's regressor rows, kept while H is reused (_block)
    work[N_REG] = -1.0
    last_t_acc = -1.0
    t_acc = s[TACC]
    p00 = p01 = p10 = p11 = rr = f_dt = 0.0
    sg0 = math.sqrt(P[0, 0])
    sg1 = math.sqrt(P[1, 1])
    sg2 = math.sqrt(P[2, 2])
    bx, by, bz, sx, sy, sz = x[0], x[1], x[2], x[3], x[4], x[5]
    bax, bay, baz = in_use(x, P, 6, p[23]), in_use(x, P, 7, p[23]), in_use(x, P, 8, p[23])
    # the gyro's scale and bias correction times half the interval c_dt: φ/2 = ω (1 - s) dt/2 - b dt/2, formed
    # anew when the interval or the bias changes
    c_dt = -1.0
    kx = ky = kz = ex = ey = ez = 0.0
    # first sample of the current block in this chunk; typed int64, not Literal[int](0), which would compile
    # _sums, _sums9 and _rest a second time for the literal
    start = np.int64(0)
    n_seg = 0
    n = gyro.shape[0]
    thr = t_block * (1.0 - 1e-9)  # tolerant of rounding in summed intervals
    k0 = 0
    while k0 < n:
        # 1. gyro frame with the bias and scale factor of the last block update, into out, up to the block's end
        # (where its intervals reach its length, or the chunk's); over an interval that holds missing samples,
        # the rate interpolated across the gap (gap_step).  A loop of its own, then the accelerometer's: each
        # recursion keeps its state in registers, where one loop over both spilt them.
        k1 = n
        ended = False
        for k in range(k0, n):
            dt = dts[min(k, last)]
            wx = gyro[k, 0]
            wy = gyro[k, 1]
            wz = gyro[k, 2]
            if 0.0 < dt <= nominal:  # regular: gap_rate's rate is the sample's own (weight 0 for the previous one)
                nominal = dt
                ox, oy, oz = wx, wy, wz
            else:  # the previous sample (the state's for the first) is read only here
                px, py, pz = gpx, gpy, gpz
                if k > 0:
                    px, py, pz = gyro[k - 1, 0], gyro[k - 1, 1], gyro[k - 1, 2]
                ox, oy, oz, nominal, _, _, _ = gap_rate(dt, nominal, wx, wy, wz, px, py, pz)
            if dt != c_dt:
                c_dt = dt
                h = 0.5 * dt
                kx, ky, kz = (1.0 - sx) * h, (1.0 - sy) * h, (1.0 - sz) * h
                ex, ey, ez = bx * h, by * h, bz * h
            gw, gx, gy, gz = right_step_raw(gw, gx, gy, gz, ox * kx - ex, oy * ky - ey, oz * kz - ez)
            n_raw += 1
            if n_raw >= RENORM_STEPS:
                gw, gx, gy, gz = renormalised(gw, gx, gy, gz)
                n_raw = 0
            out[k, 0], out[k, 1], out[k, 2], out[k, 3] = gw, gx, gy, gz
            tb += dt
            if tb >= thr:
                k1 = k + 1
                ended = True
                break
        for k in range(k0, k1):
            dt = dts[min(k, last)]
            flag = 0
            qw, qx, qy, qz = out[k, 0], out[k, 1], out[k, 2], out[k, 3]
            # 2. accelerometer in I, Butterworth low-pass; a missing sample (NaN row) holds the filter
            ax_ = acc[k, 0]
            t_acc += dt
            if ax_ == ax_:
                if t_acc != last_t_acc:  # the filter steps over the time since the last accelerometer sample
                    p00, p01, p10, p11 = lowpass2(t_acc, tau_acc)
                    last_t_acc = t_acc
                f_dt = t_acc
                t_acc = 0.0
                ix, iy, iz = rotate(qw, qx, qy, qz, ax_ - bax, acc[k, 1] - bay, acc[k, 2] - baz)
                # the start's plain mean, then the low-pass stepped exactly over the interval (start_or_lowpass)
                a_init, a_cnt, asx, asy, asz, mx, my, mz, vx, vy, vz = start_or_lowpass(
                    ix, iy, iz, f_dt, tau_acc, a_init, a_cnt, asx, asy, asz, mx, my, mz, vx, vy, vz, p00, p01, p10, p11
                )
                # the linear acceleration the filter is averaging out (the sample's departure from the filtered
                # vector), whose residual after the low-pass moves the correction as a bias error would
                if a_init < 0.0:  # low-passed at the block update (its cutoff is far below the block rate)
                    lin_t += f_dt
                    lin_x += (ix - mx) * f_dt
                    lin_y += (iy - my) * f_dt
                    lin_z += (iz - mz) * f_dt
                # 3. the correction: the tilt quaternion that turns the filtered vector vertical
                rw, r1, r2, rinv = tilt_to_z_scaled(mx, my, mz)
            else:  # held, normalised as the state holds it (so that any chunking gives the same results)
                flag |= FLAG_ACC_MISSING
                rw, r1, r2, rinv = rw * rinv, r1 * rinv, r2 * rinv, 1.0
            # the 6D attitude q_c ⊗ q_g (the k part of q_c is 0), scaled after the product
            out[k, 0] = (rw * qw - r1 * qx - r2 * qy) * rinv
            out[k, 1] = (rw * qx + r1 * qw + r2 * qz) * rinv
            out[k, 2] = (rw * qy - r1 * qz + r2 * qw) * rinv
            out[k, 3] = (rw * qz + r1 * qy - r2 * qx) * rinv
            flags[k] = flag | at_limit
        k0 = k1
        if ended:
            k = k1 - 1
            sums[26], sums[27], sums[28], sums[29] = lin_t, lin_x, lin_y, lin_z
            _samples(out, gyro, acc, mag, use_mag, dts, start, k + 1, p, s, sums, squares, flags, rs)
            # never with the sizes _run gives (no writes out of bounds)
            if n_seg >= seg_end.shape[0] - 1 or n_seg >= seg_val.shape[1] - 1:
                raise ValueError("AttitudeEstimator: more blocks than the segment buffers hold")
            n_seg = _segment(seg_end, seg_val, n_seg, k + 1, bx, by, bz, sg0, sg1, sg2)
            rest, rr = rs[6], rs[11]
            start = k + 1
            # the correction's rotation over the block, q_c ⊗ q_c,start*: the rate the bias regression explains
            cw, c1, c2 = rw * rinv, r1 * rinv, r2 * rinv
            ex_sum, ey_sum, _ = unit_rotvec(
                cw * sw + c1 * s1 + c2 * s2, c1 * sw - cw * s1, c2 * sw - cw * s2, c2 * s1 - c1 * s2
            )
            sw, s1, s2 = cw, c1, c2
            # Variance of the rest mean as a bias measurement, per axis: the gyro's own scatter through the
            # exponential mean (factor rr/(2-rr)), times the number of block updates that share one mean's
            # memory (2 rest_tau / T), which the filter would otherwise count as independent.
            rest_var = rs[7] / 3.0 * rr / (2.0 - rr) * max(1.0, 2.0 * rest_tau / tb)
            s[AFO], s[AFO + 1], s[AFO + 2] = mx, my, mz  # the filtered vector now (g for the noise of step 3)
            _block(
                s,
                P,
                x,
                sums,
                tb,
                ex_sum,
                ey_sum,
                rest >= rest_time,
                a_init >= 0.0,
                rs[0],
                rs[1],
                rs[2],
                rest_var,
                use_mag,
                p,
                H,
                z,
                R,
                PHt,
                K,
                tmp,
                work,
                hs,
            )
            sg0 = math.sqrt(P[0, 0])
            sg1 = math.sqrt(P[1, 1])
            sg2 = math.sqrt(P[2, 2])
            bx, by, bz, sx, sy, sz = x[0], x[1], x[2], x[3], x[4], x[5]
            bax, bay, baz = in_use(x, P, 6, p[23]), in_use(x, P, 7, p[23]), in_use(x, P, 8, p[23])
            at_limit = FLAG_BIAS_AT_LIMIT if max(abs(bx), abs(by), abs(bz)) > prior else 0
            c_dt = -1.0
            tb = 0.0
            for i in range(N_SUMS):
                sums[i] = 0.0
            lin_t = lin_x = lin_y = lin_z = 0.0
    # the unfinished block: its sums so far are kept in the state
    sums[26], sums[27], sums[28], sums[29] = lin_t, lin_x, lin_y, lin_z
    _samples(out, gyro, acc, mag, use_mag, dts, start, n, p, s, sums, squares, flags, rs)
    if start < n:
        n_seg = _segment(seg_end, seg_val, n_seg, n, bx, by, bz, sg0, sg1, sg2)
    s[QG], s[QG + 1], s[QG + 2], s[QG + 3] = gw, gx, gy, gz
    s[QC], s[QC + 1], s[QC + 2] = rw * rinv, r1 * rinv, r2 * rinv
    s[AF], s[AF + 1], s[AF + 2] = vx, vy, vz
    s[AFO], s[AFO + 1], s[AFO + 2] = mx, my, mz
    s[AINIT], s[ACNT] = a_init, a_cnt
    s[ASUM], s[ASUM + 1], s[ASUM + 2] = asx, asy, asz
    copy_into(s, X, x, 0, 6)
    copy_into(s, XA, x, 6, 3)
    copy_into(s, XL, x, 9, 3)
    copy_into(s, ACC, sums, 0, 24)
    s[W2] = sums[24]
    s[ALIN] = sums[26]
    s[ARES], s[ARES + 1], s[ARES + 2] = sums[27], sums[28], sums[29]
    s[NMAG] = sums[25]
    s[TB] = tb
    s[EXS], s[EXS + 1], s[EXS + 2] = sw, s1, s2
    copy_into(s, RESTG, rs, 0, 3)
    copy_into(s, RESTA, rs, 3, 3)
    s[REST] = rs[6]
    s[RESTV] = rs[7]
    copy_into(s, ALAST, rs, 8, 3)
    s[TACC] = t_acc
    if n and dts[min(n - 1, last)] > 0.0:  # the last sample with an interval (gap_rate)
        gpx, gpy, gpz = gyro[n - 1, 0], gyro[n - 1, 1], gyro[n - 1, 2]
    s[GPREV], s[GPREV + 1], s[GPREV + 2], s[NOMDT] = gpx, gpy, gpz, nominal
    s[QN] = n_raw
    return n_seg


@nb.njit(cache=True, inline="always", error_model="numpy")
def _samples(out, gyro, acc, mag, use_mag, dts, j0, j1, p, s, sums, squares, flags, rs):
    """The loops over samples j0..j1-1 of a block (or of its part in this chunk): its sums, rest detection."""
    if use_mag:
        _sums9(out, gyro, mag, dts, j0, j1, sums, squares, flags, s[DELTA], s[DIST] > 0.0)
    else:
        _sums(out, gyro, dts, j0, j1, sums, squares)
    _rest(gyro, acc, dts, j0, j1, p, rs, flags, squares)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _segment(seg_end, seg_val, n_seg, end, bx, by, bz, sg0, sg1, sg2):
    """Write segment n_seg (samples up to ``end``: its bias and their standard deviations); returns n_seg + 1."""
    seg_end[n_seg] = end
    seg_val[0, n_seg, 0], seg_val[0, n_seg, 1], seg_val[0, n_seg, 2] = bx, by, bz
    seg_val[1, n_seg, 0], seg_val[1, n_seg, 1], seg_val[1, n_seg, 2] = sg0, sg1, sg2
    return n_seg + 1


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def _rest(gyro, acc, dts, j0, j1, p, rs, flags, squares):
    """Rest detection over samples j0..j1-1 (module notes, step 4), and their rest flag.

    Gyro and accelerometer close to their 0.5 s means for rest_time, the mean rate plausible as a bias.  Nothing
    in the per-sample recursion depends on it (the bias changes at block updates only), so it runs here, a loop
    of its own the processor can pipeline, rather than lengthening the recursion's.
    """
    rest_gyr2, rest_acc2, rest_time, rest_tau = p[8], p[9], p[10], p[11]
    last = np.uintp(dts.shape[0] - 1)  # unsigned indices: no wrap-around code for negative ones
    rest_mean_max = REST_MEAN_FACTOR * p[12]
    rgx, rgy, rgz, rax, ray, raz = rs[0], rs[1], rs[2], rs[3], rs[4], rs[5]
    rest, rv, ax, ay, az, rr, last_dt = rs[6], rs[7], rs[8], rs[9], rs[10], rs[11], rs[12]
    acc2 = squares[1]
    # A sample's departure from the mean after it is (1 - rr) times its departure from the mean before it (the
    # exponential mean's step), so the squared departures come from the differences the means are stepped with.
    keep2 = (1.0 - rr) * (1.0 - rr)
    for j in range(np.uintp(j0), np.uintp(j1)):
        dt = dts[min(j, last)]
        if dt != last_dt:  # the coefficient changes only with the interval
            rr = 1.0 - math.exp(-dt / rest_tau)
            keep2 = (1.0 - rr) * (1.0 - rr)
            last_dt = dt
        wx, wy, wz = gyro[j, 0], gyro[j, 1], gyro[j, 2]
        a0, a1, a2 = acc[j, 0], acc[j, 1], acc[j, 2]
        acc2 += a0 * a0 + a1 * a1 + a2 * a2  # NaN for a missing sample: the input checks then look closer
        if a0 == a0:  # a missing sample holds the last one
            ax, ay, az = a0, a1, a2
        ex, ey, ez = wx - rgx, wy - rgy, wz - rgz
        fx, fy, fz = ax - rax, ay - ray, az - raz
        rgx, rgy, rgz = rgx + rr * ex, rgy + rr * ey, rgz + rr * ez
        rax, ray, raz = rax + rr * fx, ray + rr * fy, raz + rr * fz
        dg = keep2 * (ex * ex + ey * ey + ez * ez)
        da = keep2 * (fx * fx + fy * fy + fz * fz)
        rv += rr * (dg - rv)
        # steady is not still: a turntable or a steady turn keeps the gyro near its mean too, so the mean itself
        # must also be plausible as a bias under the prior (VQF tests it against its bias clip)
        if dg < rest_gyr2 and da < rest_acc2 and max(abs(rgx), abs(rgy), abs(rgz)) < rest_mean_max:
            rest += dt
        else:
            rest = 0.0
        if rest >= rest_time:
            flags[j] |= FLAG_REST
    rs[0], rs[1], rs[2], rs[3], rs[4], rs[5] = rgx, rgy, rgz, rax, ray, raz
    rs[6], rs[7], rs[8], rs[9], rs[10], rs[11], rs[12] = rest, rv, ax, ay, az, rr, last_dt
    squares[1] = acc2


@nb.njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _add6(out, gyro, j, dt, u):
    """Sample j's terms of the 6D block sums (_sums, _sums9), added to ``u`` = (u0 ... u11, w2, gyr2).

    The horizontal rows of R(q) for the 6D attitude in ``out``, time-weighted, the same times diag(omega),
    |omega|² dt and |omega|².  Returns the new sums, then what _sums9 goes on with: the attitude, the rate, 2 dt
    and the rows.
    """
    u0, u1, u2, u3, u4, u5, u6, u7, u8, u9, u10, u11, w2, gyr2 = u
    qw, qx, qy, qz = out[j, 0], out[j, 1], out[j, 2], out[j, 3]
    wx, wy, wz = gyro[j, 0], gyro[j, 1], gyro[j, 2]
    t2 = 2.0 * dt  # (2 a) dt = a (2 dt) exactly: a product fewer per entry
    r00 = (1.0 - 2.0 * (qy * qy + qz * qz)) * dt
    r01 = (qx * qy - qw * qz) * t2
    r02 = (qx * qz + qw * qy) * t2
    r10 = (qx * qy + qw * qz) * t2
    r11 = (1.0 - 2.0 * (qx * qx + qz * qz)) * dt
    r12 = (qy * qz - qw * qx) * t2
    u0 += r00
    u1 += r01
    u2 += r02
    u3 += r10
    u4 += r11
    u5 += r12
    u6 += r00 * wx
    u7 += r01 * wy
    u8 += r02 * wz
    u9 += r10 * wx
    u10 += r11 * wy
    u11 += r12 * wz
    w = wx * wx + wy * wy + wz * wz
    w2 += w * dt
    gyr2 += w
    u = (u0, u1, u2, u3, u4, u5, u6, u7, u8, u9, u10, u11, w2, gyr2)
    return u, qw, qx, qy, qz, wx, wy, wz, t2, r00, r01, r02, r10, r11, r12


@nb.njit(cache=True, inline="always", error_model="numpy")
def _rows_into(qw, qx, qy, qz, sums):
    sums[30], sums[31], sums[32], sums[33], sums[34], sums[35] = horizontal_rows(qw, qx, qy, qz)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _last_rows(out, j, sums):
    """The horizontal rows of R(q) at sample j (the block's last): the lever arm's regressor (_block)."""
    _rows_into(out[j, 0], out[j, 1], out[j, 2], out[j, 3], sums)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _last_rows_turned(out, j, sums, cd, sd):
    """_last_rows for a 9D attitude q_z(delta) ⊗ q_6D in out: q_6D = q_z(-delta) ⊗ q."""
    qw, qx, qy, qz = out[j, 0], out[j, 1], out[j, 2], out[j, 3]
    _rows_into(cd * qw + sd * qz, cd * qx + sd * qy, cd * qy - sd * qx, cd * qz - sd * qw, sums)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _sums6(sums, squares):
    """The running 6D sums of a block as _add6 continues them (in order: any chunking gives the same sums)."""
    u0, u1, u2, u3, u4, u5, u6, u7 = sums[0], sums[1], sums[2], sums[3], sums[4], sums[5], sums[6], sums[7]
    return u0, u1, u2, u3, u4, u5, u6, u7, sums[8], sums[9], sums[10], sums[11], sums[24], squares[0]


@nb.njit(cache=True, inline="always", error_model="numpy")
def _store6(sums, squares, u):
    """Put _add6's sums back (the inverse of _sums6)."""
    sums[0], sums[1], sums[2], sums[3], sums[4], sums[5] = u[0], u[1], u[2], u[3], u[4], u[5]
    sums[6], sums[7], sums[8], sums[9], sums[10], sums[11] = u[6], u[7], u[8], u[9], u[10], u[11]
    sums[24], squares[0] = u[12], u[13]


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def _sums(out, gyro, dts, j0, j1, sums, squares):
    """Add samples j0..j1-1 to the block sums, time-weighted (6D; 9D: _sums9): _add6 for each.

    The rows times the bias-and-scale correction are formed at the block update from these.
    """
    last = np.uintp(dts.shape[0] - 1)  # unsigned indices: no wrap-around code for negative ones
    u = _sums6(sums, squares)
    for j in range(np.uintp(j0), np.uintp(j1)):
        u = _add6(out, gyro, j, dts[min(j, last)], u)[0]
    _store6(sums, squares, u)
    if j1 > j0:
        _last_rows(out, j1 - 1, sums)


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def _sums9(out, gyro, mag, dts, j0, j1, sums, squares, flags, delta, disturbed):
    """_sums in 9D, one loop: also the vertical row of R(q), the same times diag(omega), and the field.

    For the samples with a field, the field in the 6D frame, R(q) m, is formed from the rows already at hand
    (cheaper than a rotation by q).  A sample without a field counts with weight 0 (selects, not a branch, so
    the loop stays one straight run).  Then the 6D attitude in ``out`` becomes the 9D one, turned by the heading
    offset: q = q_z(delta) ⊗ q_6D, flagged while the field is disturbed.

    The 6D part is _sums's _add6: one loop with the 9D part behind a ``use_mag`` branch measured 3 % slower in 6D
    (and changes 9D's rounding), so each mode has its straight loop.
    """
    last = np.uintp(dts.shape[0] - 1)  # unsigned indices: no wrap-around code for negative ones
    cd = math.cos(0.5 * delta)
    sd = math.sin(0.5 * delta)
    u = _sums6(sums, squares)
    v0, v1, v2, v3, v4, v5 = sums[14], sums[15], sums[16], sums[17], sums[18], sums[19]
    h0, h1, h2, tm = sums[21], sums[22], sums[23], sums[25]
    mag2 = squares[2]
    for j in range(np.uintp(j0), np.uintp(j1)):
        dt = dts[min(j, last)]
        u, qw, qx, qy, qz, wx, wy, wz, t2, r00, r01, r02, r10, r11, r12 = _add6(out, gyro, j, dt, u)
        mx, my, mz = mag[j, 0], mag[j, 1], mag[j, 2]
        mag2 += mx * mx + my * my + mz * mz  # NaN for a missing sample, as acc in _rest
        present = mx == mx
        dm = dt if present else 0.0
        mx = mx if present else 0.0
        my = my if present else 0.0
        mz = mz if present else 0.0
        r20 = (qx * qz - qw * qy) * (t2 if present else 0.0)
        r21 = (qy * qz + qw * qx) * (t2 if present else 0.0)
        r22 = (1.0 - 2.0 * (qx * qx + qy * qy)) * dm
        v0 += r20
        v1 += r21
        v2 += r22
        v3 += r20 * wx
        v4 += r21 * wy
        v5 += r22 * wz
        h0 += r00 * mx + r01 * my + r02 * mz  # (R m) dt, its rows times dt at hand; 0 without a field
        h1 += r10 * mx + r11 * my + r12 * mz
        h2 += r20 * mx + r21 * my + r22 * mz
        tm += dm
        out[j, 0] = cd * qw - sd * qz
        out[j, 1] = cd * qx - sd * qy
        out[j, 2] = cd * qy + sd * qx
        out[j, 3] = cd * qz + sd * qw
        if disturbed:
            flags[j] |= FLAG_MAG_DISTURBED
    _store6(sums, squares, u)
    sums[14], sums[15], sums[16], sums[17], sums[18], sums[19] = v0, v1, v2, v3, v4, v5
    sums[21], sums[22], sums[23], sums[25] = h0, h1, h2, tm
    squares[2] = mag2
    if j1 > j0:  # the rows of the 6D attitude: undo the heading turn just written
        _last_rows_turned(out, j1 - 1, sums, cd, sd)


@nb.njit(cache=True, inline="always", error_model="numpy", fastmath={"contract"})
def _pht6(P, H, PHt, lo):
    """P Hᵀ for the block's two measurements and the six states from lo (the first half of _update6)."""
    for i in range(6):
        a0 = 0.0
        a1 = 0.0
        for c in range(6):
            pc = P[lo + i, lo + c]
            a0 += pc * H[0, lo + c]
            a1 += pc * H[1, lo + c]
        PHt[lo + i, 0] = a0
        PHt[lo + i, 1] = a1


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def _update6(x, P, H, z, R, PHt, K, lo):
    """kalman() for the block's two measurements and the six states from lo, given their P Hᵀ (_pht6).

    The six are the gyro's, or the accelerometer bias's and the lever arm's (attitude_estimator.py, step 3).
    Fixed trip counts, so the loops unroll: the general form's runtime bounds cost a tenth of the estimator's time
    at 100 Hz.

    Returns the mean over the two rows of h P hᵀ after the update, the uncertainty the states still leave in
    the measurement: from the 2x2 A = H P Hᵀ before it, A - A S⁻¹ A (S = A + R), without another pass over P.
    """
    a00 = 0.0
    a01 = 0.0
    a11 = 0.0
    for c in range(6):
        a00 += H[0, lo + c] * PHt[lo + c, 0]
        a01 += H[0, lo + c] * PHt[lo + c, 1]
        a11 += H[1, lo + c] * PHt[lo + c, 1]
    s00 = a00 + R[0]
    s11 = a11 + R[1]
    det = s00 * s11 - a01 * a01
    i00 = s11 / det
    i01 = -a01 / det
    i11 = s00 / det
    e0 = z[0]
    e1 = z[1]
    for c in range(6):
        e0 -= H[0, lo + c] * x[lo + c]
        e1 -= H[1, lo + c] * x[lo + c]
    for i in range(6):
        p0 = PHt[lo + i, 0]
        p1 = PHt[lo + i, 1]
        k0 = p0 * i00 + p1 * i01
        k1 = p0 * i01 + p1 * i11
        K[lo + i, 0] = k0
        K[lo + i, 1] = k1
        x[lo + i] += k0 * e0 + k1 * e1
    for i in range(6):
        for c in range(i, 6):
            v = P[lo + i, lo + c] - (K[lo + i, 0] * PHt[lo + c, 0] + K[lo + i, 1] * PHt[lo + c, 1])
            P[lo + i, lo + c] = v
            P[lo + c, lo + i] = v
    b00 = a00 * (i00 * a00 + i01 * a01) + a01 * (i01 * a00 + i11 * a01)
    b11 = a01 * (i00 * a01 + i01 * a11) + a11 * (i01 * a01 + i11 * a11)
    return 0.5 * ((a00 - b00) + (a11 - b11))


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def _block(
    s,
    P,
    x,
    accu,
    T,
    ex_sum,
    ey_sum,
    at_rest,
    starting,
    rgx,
    rgy,
    rgz,
    rest_var,
    use_mag,
    p,
    H,
    z,
    R,
    PHt,
    K,
    tmp,
    work,
    hs,
):
    """The block-rate part: regressor filter, Kalman updates of bias and scale, magnetometer heading."""
    tau_acc, tau_mag, q_bias, q_scale = p[0], p[1], p[2], p[3]
    r_motion, kappa2, r_rest, r_mag, prior = p[4], p[5], p[6], p[7], p[12]
    norm_th, dip_th, ref_tau, cur_tau, new_time = p[13], p[14], p[15], p[16], p[17]
    acc_factor, start_time, q_acc, acc_bias_factor = p[19], p[20], p[21], p[22]
    w2_sum = accu[24]
    t_mag = accu[25]
    c = N_REG
    # Blocks have the same length unless the sample intervals change.  Recomputed on any change, however small:
    # reused across a change below rounding, they would depend on where a chunk started (each chunk computes them
    # afresh), and chunked results would differ from whole ones at rounding level.
    if T != work[c]:
        work[c] = T
        work[c + 1], work[c + 2], work[c + 3], work[c + 4] = lowpass2(T, tau_acc)
        work[c + 6] = 1.0 - math.exp(-T / tau_mag)
        work[c + 7] = 1.0 - math.exp(-T / cur_tau)
        work[c + 8] = 1.0 - math.exp(-T / ref_tau)
        # the bias's Gauss-Markov decay over the block (below)
        work[c + 5] = math.exp(-T * q_bias / (2.0 * prior * prior))
    p00, p01, p10, p11 = work[c + 1], work[c + 2], work[c + 3], work[c + 4]
    u0, u1, u2 = in_use(x, P, 6, p[23]), in_use(x, P, 7, p[23]), in_use(x, P, 8, p[23])
    kmag, kcur, kref, phi = work[c + 6], work[c + 7], work[c + 8], work[c + 5]
    # The bias is a first-order Gauss-Markov process: stationary spread `prior` (the prior, instead of a clip),
    # and a correlation time that makes it wander as fast as the forgetting rate says while far inside the prior
    # (dP/dt = 2 prior² / t_c = q_bias).  It pulls the estimate towards zero only at the rate 1/t_c (an hour for
    # the defaults), so a large bias the data show is learnt, not clipped; one beyond `prior` is flagged.
    for i in range(3):
        x[i] *= phi
        for j in range(6):  # the gyro's block: the accelerometer's has no covariance with it (step 3)
            P[i, j] *= phi
            P[j, i] *= phi
        P[i, i] += prior * prior * (1.0 - phi * phi)
        P[3 + i, 3 + i] += q_scale * T
        P[6 + i, 6 + i] += q_acc * T
        if P[9 + i, 9 + i] > 0.0:
            P[9 + i, 9 + i] += p[24] * T
    # the regressors through the same low-pass as the accelerometer (box mean of the block, then Butterworth at
    # the block rate): the correction rate responds to a bias error through that filter (math: attitude.py)
    # rows of R times the bias-and-scale correction, constant over the block: linear in the other sums
    accu[12] = accu[0] * x[0] + accu[1] * x[1] + accu[2] * x[2] + accu[6] * x[3] + accu[7] * x[4] + accu[8] * x[5]
    accu[13] = accu[3] * x[0] + accu[4] * x[1] + accu[5] * x[2] + accu[9] * x[3] + accu[10] * x[4] + accu[11] * x[5]
    accu[20] = accu[14] * x[0] + accu[15] * x[1] + accu[16] * x[2] + accu[17] * x[3] + accu[18] * x[4] + accu[19] * x[5]
    start = s[STARTED] == 0.0
    two_tau2 = 2.0 / (tau_acc * tau_acc)
    lp = work
    inv_t = 1.0 / T
    for i in range(N_REG):
        v = accu[i] * inv_t
        j = REG + 2 * i
        if start:  # steady state at the first block's value
            s[j] = v
            s[j + 1] = 0.0
        # the block mean held over the block: exact for the continuous filter (lowpass2)
        y0 = s[j]
        r0 = s[j + 1]
        y, r = lowpass2_step(y0, r0, v, p00, p01, p10, p11)
        s[j] = y
        s[j + 1] = r
        if i < 6:  # the rows of R: their low-passed change over the block (accelerometer bias)
            work[N_REG + 9 + i] = y - y0
            # the lever arm r: the sensor's offset R r from a fixed point accelerates at d²(R r)/dt², which the
            # low-pass passes as y'' r, y'' = 2 (u - y - tau y') / tau² (lowpass2's ODE) at the block's end
            ydd = (accu[30 + i] - y - tau_acc * r) * two_tau2
            work[N_REG + 15 + i] = 0.0 if start else ydd - s[YDD + i]
            s[YDD + i] = ydd
        # the measurement is the correction's mean rate over the block, so the regressor is the filter output's
        # mean over the block too, not its end value (half a block later): integrating the filter's ODE
        # (tau²/2) y'' + tau y' + y = u over the block gives mean(y) = u - (tau Δy + tau²/2 Δy') / T exactly
        lp[i] = v - (tau_acc * (y - y0) + 0.5 * tau_acc * tau_acc * (r - r0)) * inv_t
    s[STARTED] = 1.0
    w2 = w2_sum / T
    # Linear acceleration a moves the filtered vector by LP[a]/g, whose horizontal rate the regression would
    # read as a bias error; correlated over about tau_acc, it is a noise of density² mean(|d LP[a]/dt|²) tau/g²
    # The departure a - LP[a], passed through the same low-pass, estimates LP[a]; its mean rate over the block
    # is its change over T (the block mean held, lowpass2); horizontal: less its part along the filtered vector.
    g2 = s[AFO] ** 2 + s[AFO + 1] ** 2 + s[AFO + 2] ** 2
    r_acc = 0.0
    if accu[26] > 0.0 and g2 > 0.0:
        ra = tmp  # free until the Kalman updates below (no allocation per block)
        for i in range(3):
            v = accu[27 + i] / accu[26]
            y, s[RLV + i] = lowpass2_step(s[RLP + i], s[RLV + i], v, p00, p01, p10, p11)
            ra[i] = (y - s[RLP + i]) / T
            s[RLP + i] = y
        along = ra[0] * s[AFO] + ra[1] * s[AFO + 1] + ra[2] * s[AFO + 2]
        r_acc = (ra[0] ** 2 + ra[1] ** 2 + ra[2] ** 2 - along * along / g2) * tau_acc / g2
    rm = (r_motion + kappa2 * w2 + acc_factor * r_acc) / T
    for j in range(3):
        H[0, j] = lp[j]
        H[1, j] = lp[3 + j]
        H[0, 3 + j] = lp[6 + j]
        H[1, 3 + j] = lp[9 + j]
    z[0] = lp[12] - ex_sum / T
    z[1] = lp[13] - ey_sum / T
    # An accelerometer bias b_a (sensor axes) leaves LP[R b_a] in the filtered vector, and the correction tilts
    # by (δ_y, -δ_x)/g with it: over the block it turns by (ΔLP[R_1] b_a, -ΔLP[R_0] b_a)/g, R_i the rows of R.
    # The estimate in use is subtracted from the accelerometer, so only the rest is measured.
    inv_gt = 1.0 / (math.sqrt(g2) * T) if g2 > 0.0 else 0.0
    d0 = work[N_REG + 9 :]
    for j in range(3):
        H[0, 6 + j] = -d0[3 + j] * inv_gt
        H[1, 6 + j] = d0[j] * inv_gt
        H[0, 9 + j] = -d0[9 + j] * inv_gt
        H[1, 9 + j] = d0[6 + j] * inv_gt
    z[0] += H[0, 6] * u0 + H[0, 7] * u1 + H[0, 8] * u2
    z[1] += H[1, 6] * u0 + H[1, 7] * u1 + H[1, 8] * u2
    R[0] = rm
    R[1] = rm
    if starting:  # while the start averages, the correction does not follow the low-pass the regression models
        pass
    elif P[6, 6] <= 0.0 and P[7, 7] <= 0.0 and P[8, 8] <= 0.0 and P[9, 9] <= 0.0:  # neither modelled
        _pht6(P, H, PHt, 0)
        _update6(x, P, H, z, R, PHt, K, 0)
    else:
        # The accelerometer's states and the gyro's are learnt one after the other (attitude_estimator.py, step
        # 3), each taking the other's estimate as known and its uncertainty h P hᵀ as noise.  First the
        # accelerometer bias and the lever arm, from what the gyro's estimate leaves of the block.
        for a in range(2):
            for j in range(NX):
                hs[a, j] = H[a, j]
        z0, z1 = z[0], z[1]
        # the gyro's P Hᵀ, for its uncertainty here and its own update below (the accelerometer's update leaves
        # the gyro's block of P as it is)
        _pht6(P, H, PHt, 0)
        v_gyro = 0.5 * (H[0, 0] * PHt[0, 0] + H[0, 1] * PHt[1, 0] + H[0, 2] * PHt[2, 0])
        v_gyro += 0.5 * (H[0, 3] * PHt[3, 0] + H[0, 4] * PHt[4, 0] + H[0, 5] * PHt[5, 0])
        v_gyro += 0.5 * (H[1, 0] * PHt[0, 1] + H[1, 1] * PHt[1, 1] + H[1, 2] * PHt[2, 1])
        v_gyro += 0.5 * (H[1, 3] * PHt[3, 1] + H[1, 4] * PHt[4, 1] + H[1, 5] * PHt[5, 1])
        for a in range(2):
            d = z0 if a == 0 else z1
            for j in range(6):
                d -= hs[a, j] * x[j]
                H[a, j] = 0.0
            z[a] = d
        R[0] = (r_motion + kappa2 * w2 + acc_bias_factor * r_acc + v_gyro * tau_acc) / T
        R[1] = R[0]
        _pht6(P, H, PHt, 6)
        v_acc = _update6(x, P, H, z, R, PHt, K, 6)
        # Then the gyro's errors from what the accelerometer bias and the lever arm leave (z holds the raw
        # measurement: the bias in use was added back above); what they may still be wrong by moves the correction
        # as the linear acceleration does, so their uncertainty counts as a rate correlated over tau_acc.  The
        # bias taken as known is the estimate shrunk by its own significance (p[25], less than the readings'
        # p[23]): with the readings' shrinkage, the part of a real bias not yet subtracted is left for the gyro's
        # states, and a motion that cannot tell the two apart (a steady turn) hands it over to them block by block.
        g0, g1, g2 = in_use(x, P, 6, p[25]), in_use(x, P, 7, p[25]), in_use(x, P, 8, p[25])
        R[0] = rm + v_acc * tau_acc / T
        R[1] = R[0]
        for a in range(2):
            d = (z0 if a == 0 else z1) - (hs[a, 6] * g0 + hs[a, 7] * g1 + hs[a, 8] * g2)
            for j in range(9, NX):
                d -= hs[a, j] * x[j]
            z[a] = d
            for j in range(NX):
                H[a, j] = hs[a, j] if j < 6 else 0.0
        _update6(x, P, H, z, R, PHt, K, 0)
    if at_rest:
        for a in range(3):
            for j in range(NX):
                H[a, j] = 0.0
            H[a, a] = 1.0
            R[a] = max(r_rest / T, rest_var)
        z[0] = rgx
        z[1] = rgy
        z[2] = rgz
        # the gyro's states only: the accelerometer's have no covariance with them (step 3)
        kalman(x, P, H, z, R, np.int64(3), PHt, K, tmp, np.int64(0), np.int64(6))
    if not use_mag or t_mag <= 0.0:
        return
    # magnetometer: the field in the 6D frame, its norm and dip against a learned reference, the heading offset
    hx = accu[21] / t_mag
    hy = accu[22] / t_mag
    hz = accu[23] / t_mag
    nrm = math.sqrt(hx * hx + hy * hy + hz * hz)
    dip = math.atan2(-hz, math.sqrt(hx * hx + hy * hy))
    if s[MREF] <= 0.0:  # first field: it is the reference (a candidate until it has stayed consistent)
        s[MREF], s[MREF + 1], s[MCUR], s[MCUR + 1] = nrm, dip, nrm, dip
        for i in range(7):
            s[V7 + i] = accu[14 + i] / t_mag
    s[MCUR] += kcur * (nrm - s[MCUR])
    s[MCUR + 1] += kcur * (dip - s[MCUR + 1])
    cn, cdp = s[MCUR], s[MCUR + 1]
    disturbed = abs(cn - s[MREF]) > norm_th * s[MREF] or abs(cdp - s[MREF + 1]) > dip_th
    if s[MCONF] >= 0.0:
        # The start: the first field is only a candidate until it has stayed consistent for mag_start_time (a
        # phone's magnetometer may read a transient field for its first second).  A different field replaces it
        # and restarts the heading mean, so that its first update sets the heading at once.
        if disturbed:
            s[MREF], s[MREF + 1] = cn, cdp
            s[MCONF] = 0.0
            s[MAGN] = 0.0
            s[UND] = 0.0
            disturbed = False
        else:
            s[MCONF] += T
            if s[MCONF] >= start_time:
                s[MCONF] = -1.0
    if disturbed and s[MOLD] > 0.0 and abs(cn - s[MOLD]) <= norm_th * s[MOLD] and abs(cdp - s[MOLD + 1]) <= dip_th:
        # the field is back to the one before the last change of reference (a disturbance that ended)
        s[MREF], s[MOLD] = s[MOLD], s[MREF]
        s[MREF + 1], s[MOLD + 1] = s[MOLD + 1], s[MREF + 1]
        disturbed = False
    if disturbed:
        s[DIST] += T
        s[UND] = 0.0
        if s[DIST] > new_time:  # a new environment, not a passing disturbance: accept it
            s[MOLD], s[MOLD + 1] = s[MREF], s[MREF + 1]
            s[MREF], s[MREF + 1] = cn, cdp
            s[DIST] = 0.0
    else:
        s[DIST] = 0.0
        s[UND] += T
        s[MREF] += kref * (cn - s[MREF])
        s[MREF + 1] += kref * (cdp - s[MREF + 1])
    for i in range(7):
        s[V7 + i] += kmag * (accu[14 + i] / t_mag - s[V7 + i])
    delta = s[DELTA]
    d_prev = delta
    if not disturbed:
        err = math.atan2(hx, hy) - delta  # the offset that turns the horizontal field to north (+y of ENU)
        err = (err + math.pi) % (2.0 * math.pi) - math.pi
        # the mean of the updates so far until it averages longer than tau_mag (VQF's fast start): the first
        # field sets the heading at once, also when the estimate started before the magnetometer's first sample
        # After a clipped gyro (attitude.py, step 7; count -1) the heading waits for the inclination's restart to
        # end, and then its mean restarts: while the inclination restarts from a few samples in motion, a
        # heading from it carries its error times tan(dip).
        m = s[MAGN]
        if m < 0.0 and starting:
            gain = 0.0
        else:
            m = 1.0 if starting or m < 0.0 else m + 1.0
            gain = max(kmag, 1.0 / m)
        s[MAGN] = m
        delta += gain * err
        delta = (delta + math.pi) % (2.0 * math.pi) - math.pi
        s[DELTA] = delta
    # the vertical bias from the heading offset's rate, once the offset has settled after a disturbance
    if r_mag > 0.0 and s[UND] > tau_mag:
        step = delta - d_prev
        step = (step + math.pi) % (2.0 * math.pi) - math.pi
        for j in range(6):
            H[0, j] = s[V7 + j]
        for j in range(6, NX):
            H[0, j] = 0.0
        z[0] = s[V7 + 6] - step / T
        R[0] = (r_mag + kappa2 * w2) / T
        kalman(x, P, H, z, R, np.int64(1), PHt, K, tmp, np.int64(0), np.int64(6))


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def smooth_directions(v, w, dts, tau):
    """Zero-phase weighted local-linear smoothing of direction vectors (rows of v), time constant tau.

    At each sample, the straight line a + b (s - t) fitted to the rows by weighted least squares with weights
    ``w exp(-|s - t| / tau)`` gives a (unnormalised; samples of weight 0 are bridged by their neighbours).
    Where data lie evenly on both sides this is the two-sided exponential mean; at the ends of the record and
    at the edges of long gaps it follows a ramp instead of lagging it by tau times its slope.  The sums run
    forward and backward in O(n).
    """
    n, d = v.shape
    fs = np.zeros((n, 3))  # forward sums of w, w τ, w τ² (τ = s - t ≤ 0)
    fy = np.zeros((n, 2 * d))  # forward sums of w v, w τ v
    s0 = s1 = s2 = 0.0
    y = np.zeros(2 * d)
    for i in range(n):
        if i > 0:
            h = dts[i]
            keep = math.exp(-h / tau)
            s2 = keep * (s2 - 2.0 * h * s1 + h * h * s0)
            s1 = keep * (s1 - h * s0)
            s0 = keep * s0
            for j in range(d):
                y[d + j] = keep * (y[d + j] - h * y[j])
                y[j] = keep * y[j]
        s0 += w[i]
        for j in range(d):
            y[j] += w[i] * v[i, j]
        fs[i, 0], fs[i, 1], fs[i, 2] = s0, s1, s2
        for j in range(2 * d):
            fy[i, j] = y[j]
    out = np.zeros((n, d))
    s0 = s1 = s2 = 0.0
    for j in range(2 * d):
        y[j] = 0.0
    for i in range(n - 1, -1, -1):
        if i < n - 1:
            h = dts[i + 1]
            keep = math.exp(-h / tau)
            s2 = keep * (s2 + 2.0 * h * s1 + h * h * s0)
            s1 = keep * (s1 + h * s0)
            s0 = keep * s0
            for j in range(d):
                y[d + j] = keep * (y[d + j] + h * y[j])
                y[j] = keep * y[j]
        # both passes, sample i (at τ = 0) counted once: it is in the forward sums already
        t0 = fs[i, 0] + s0
        t1 = fs[i, 1] + s1
        t2 = fs[i, 2] + s2
        det = t0 * t2 - t1 * t1
        for j in range(d):
            a0 = fy[i, j] + y[j]
            a1 = fy[i, d + j] + y[d + j]
            if det > 1e-12 * t0 * t2 and t0 > 0.0:
                out[i, j] = (t2 * a0 - t1 * a1) / det
            else:
                out[i, j] = a0 / t0 if t0 > 0.0 else 0.0
        s0 += w[i]
        for j in range(d):
            y[j] += w[i] * v[i, j]
    return out
