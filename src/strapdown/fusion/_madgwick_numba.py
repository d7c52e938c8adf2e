"""Numba kernel of :mod:`strapdown.fusion.madgwick` (private)."""

from __future__ import annotations

import math

import numba as nb

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ._kernels_numba import unit3


@nb.njit(cache=True, error_model="numpy")
def run(gyro, acc, mag, use_mag, dts, beta, slip, q, out):
    """Madgwick's gradient-descent filter, sample by sample, in his NWU earth frame; q is updated in place.

    qdot = ½ q ⊗ ω - β ∇f/|∇f|, q += qdot dt, normalise.  f stacks the accelerometer residual
    f_g = Rᵀ(0, 0, 1) - â and, in 9D, the magnetometer residual f_b = Rᵀ(b_x, 0, b_z) - m̂ with (b_x, 0, b_z)
    the measured field turned into the earth frame and made horizontal-north.  ∇f = Jᵀ f (Madgwick 2010, eqs.
    (25)-(34)); kx, kz below are 2 b_x and 2 b_z, except with `slip`, which keeps the original C code's
    assignment of b_x and b_z to the variables named _2bx and _2bz (its predicted field is half the length it
    should be): that reproduces the published BROAD reference.
    """
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    for k in range(gyro.shape[0]):
        gx = gyro[k, 0]
        gy = gyro[k, 1]
        gz = gyro[k, 2]
        d0 = 0.5 * (-q1 * gx - q2 * gy - q3 * gz)
        d1 = 0.5 * (q0 * gx + q2 * gz - q3 * gy)
        d2 = 0.5 * (q0 * gy - q1 * gz + q3 * gx)
        d3 = 0.5 * (q0 * gz + q1 * gy - q2 * gx)
        ax, ay, az, an = unit3(acc[k, 0], acc[k, 1], acc[k, 2])
        if an > 0.0:
            f1 = 2.0 * (q1 * q3 - q0 * q2) - ax
            f2 = 2.0 * (q0 * q1 + q2 * q3) - ay
            f3 = 2.0 * (0.5 - q1 * q1 - q2 * q2) - az
            s0 = -2.0 * q2 * f1 + 2.0 * q1 * f2
            s1 = 2.0 * q3 * f1 + 2.0 * q0 * f2 - 4.0 * q1 * f3
            s2 = -2.0 * q0 * f1 + 2.0 * q3 * f2 - 4.0 * q2 * f3
            s3 = 2.0 * q1 * f1 + 2.0 * q2 * f2
            if use_mag:
                mx, my, mz, mn = unit3(mag[k, 0], mag[k, 1], mag[k, 2])
                if mn > 0.0:  # a zero field (sensor dropout) falls back to 6D, as the original code does
                    # h = R(q) m: the measured field in the earth frame
                    hx = mx * (q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3) + 2.0 * my * (q1 * q2 - q0 * q3)
                    hx += 2.0 * mz * (q1 * q3 + q0 * q2)
                    hy = 2.0 * mx * (q1 * q2 + q0 * q3) + my * (q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3)
                    hy += 2.0 * mz * (q2 * q3 - q0 * q1)
                    hz = 2.0 * mx * (q1 * q3 - q0 * q2) + 2.0 * my * (q2 * q3 + q0 * q1)
                    hz += mz * (q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3)
                    bx = math.sqrt(hx * hx + hy * hy)
                    kx = bx if slip else 2.0 * bx
                    kz = hz if slip else 2.0 * hz
                    f4 = kx * (0.5 - q2 * q2 - q3 * q3) + kz * (q1 * q3 - q0 * q2) - mx
                    f5 = kx * (q1 * q2 - q0 * q3) + kz * (q0 * q1 + q2 * q3) - my
                    f6 = kx * (q0 * q2 + q1 * q3) + kz * (0.5 - q1 * q1 - q2 * q2) - mz
                    s0 += -kz * q2 * f4 + (-kx * q3 + kz * q1) * f5 + kx * q2 * f6
                    s1 += kz * q3 * f4 + (kx * q2 + kz * q0) * f5 + (kx * q3 - 2.0 * kz * q1) * f6
                    s2 += (-2.0 * kx * q2 - kz * q0) * f4 + (kx * q1 + kz * q3) * f5 + (kx * q0 - 2.0 * kz * q2) * f6
                    s3 += (-2.0 * kx * q3 + kz * q1) * f4 + (-kx * q0 + kz * q2) * f5 + kx * q1 * f6
            sn = math.sqrt(s0 * s0 + s1 * s1 + s2 * s2 + s3 * s3)
            if sn > 0.0:
                d0 -= beta * s0 / sn
                d1 -= beta * s1 / sn
                d2 -= beta * s2 / sn
                d3 -= beta * s3 / sn
        dt = dts[k]
        q0 += d0 * dt
        q1 += d1 * dt
        q2 += d2 * dt
        q3 += d3 * dt
        inv = 1.0 / math.sqrt(q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
        q0 *= inv
        q1 *= inv
        q2 *= inv
        q3 *= inv
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = q0, q1, q2, q3
    q[0] = q0
    q[1] = q1
    q[2] = q2
    q[3] = q3
