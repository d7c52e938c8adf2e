"""Numba kernel of :func:`strapdown.fusion.attitude_offline`'s inclination step (private).

The accelerometer, taken into the gyro frame I, is low-passed forward and then backward in time by the online
filter's second-order Butterworth (``lowpass2``): a zero-phase filter whose gain is the square of the online
one's.  Linear acceleration above the cutoff is attenuated as (ω tau)⁻⁴ rather than (ω tau)⁻², and there is
no lag to cancel.  (The mean of a forward and a backward pass, which this replaces, has the gain Re H(ω): its
lags cancel, but its attenuation stays that of one pass.)
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ._kernels_numba import gap_rate, lowpass2, lowpass2_step, right_step, rotate, tilt_to_z


@nb.njit(cache=True, inline="always", error_model="numpy")
def _coefficients(h, tau, last_h, c):
    """The four coefficients of lowpass2 over h s, recomputed only when h changes (c holds the last ones)."""
    if h != last_h:
        c[0], c[1], c[2], c[3] = lowpass2(h, tau)
    return h


@nb.njit(cache=True, error_model="numpy", fastmath={"contract"})
def zero_phase_6d(gyro, acc, dts, q0, tau, out):
    """6D attitudes: the gyro frame from q0, corrected by the zero-phase low-passed accelerometer in it.

    gyro: rates with bias and scale already removed; acc: NaN rows are missing samples (the filter holds); dts:
    the interval ending at each sample (dts[0] = 0: q0 is the attitude at the first sample).  The forward pass
    starts at the mean of the first tau seconds of accelerometer samples in I, in steady state; the backward
    pass starts at the forward pass's last output.  Writes q = q_c ⊗ q_g into out (n, 4).
    """
    n = gyro.shape[0]
    ai = np.empty((n, 3))
    gw, gx, gy, gz = q0[0], q0[1], q0[2], q0[3]
    gpx, gpy, gpz = gyro[0, 0], gyro[0, 1], gyro[0, 2]
    nominal = 0.0
    sx = sy = sz = 0.0
    cnt = 0.0
    elapsed = 0.0
    for k in range(n):
        dt = dts[k]
        # the gyro frame as the online estimator integrates it (rate interpolated across lost rows: gap_rate)
        ox, oy, oz, nominal, gpx, gpy, gpz = gap_rate(dt, nominal, gyro[k, 0], gyro[k, 1], gyro[k, 2], gpx, gpy, gpz)
        gw, gx, gy, gz = right_step(gw, gx, gy, gz, ox * dt, oy * dt, oz * dt)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = gw, gx, gy, gz
        elapsed += dt
        if acc[k, 0] == acc[k, 0]:
            ix, iy, iz = rotate(gw, gx, gy, gz, acc[k, 0], acc[k, 1], acc[k, 2])
            ai[k, 0], ai[k, 1], ai[k, 2] = ix, iy, iz
            if elapsed <= tau or cnt == 0.0:
                sx += ix
                sy += iy
                sz += iz
                cnt += 1.0
        else:
            ai[k, 0] = np.nan
    if cnt == 0.0:  # no accelerometer sample at all: the gyro frame alone
        return
    # forward pass, from the start's mean in steady state
    y = np.empty((n, 3))
    c = np.empty(4)
    mx, my, mz = sx / cnt, sy / cnt, sz / cnt
    vx = vy = vz = 0.0
    h = 0.0
    last_h = -1.0
    for k in range(n):
        h += dts[k]
        if ai[k, 0] == ai[k, 0]:
            if h > 0.0:
                last_h = _coefficients(h, tau, last_h, c)
                mx, vx = lowpass2_step(mx, vx, ai[k, 0], c[0], c[1], c[2], c[3])
                my, vy = lowpass2_step(my, vy, ai[k, 1], c[0], c[1], c[2], c[3])
                mz, vz = lowpass2_step(mz, vz, ai[k, 2], c[0], c[1], c[2], c[3])
            h = 0.0
        y[k, 0], y[k, 1], y[k, 2] = mx, my, mz
    # backward pass over the forward output, the step into sample k over the interval (k, k+1)
    vx = vy = vz = 0.0
    for k in range(n - 1, -1, -1):
        if k < n - 1:
            last_h = _coefficients(dts[k + 1], tau, last_h, c)
            mx, vx = lowpass2_step(mx, vx, y[k, 0], c[0], c[1], c[2], c[3])
            my, vy = lowpass2_step(my, vy, y[k, 1], c[0], c[1], c[2], c[3])
            mz, vz = lowpass2_step(mz, vz, y[k, 2], c[0], c[1], c[2], c[3])
        cw, c1, c2 = tilt_to_z(mx, my, mz)
        gw, gx, gy, gz = out[k, 0], out[k, 1], out[k, 2], out[k, 3]
        out[k, 0] = cw * gw - c1 * gx - c2 * gy  # q_c ⊗ q_g, the k part of q_c being 0 (as online)
        out[k, 1] = cw * gx + c1 * gw + c2 * gz
        out[k, 2] = cw * gy - c1 * gz + c2 * gw
        out[k, 3] = cw * gz + c1 * gy - c2 * gx
