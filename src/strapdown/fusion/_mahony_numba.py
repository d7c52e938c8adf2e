"""Numba kernel of :mod:`strapdown.fusion.mahony` (private)."""

from __future__ import annotations

import math

import numba as nb

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ._kernels_numba import right_step, rotate, rotate_back, unit3


@nb.njit(cache=True, error_model="numpy")
def run(gyro, acc, mag, use_mag, dts, kp, ki, q, b, out, bias_out):
    """Mahony's explicit complementary filter with integral bias, in ENU; q and b updated in place.

    e = â × v̂ (+ m̂ × ŵ in 9D), with v̂ = Rᵀ z the predicted up and ŵ = Rᵀ(0, |h_xy|, h_z) the predicted field,
    h = R m̂; b ← b - ki e dt; ω = gyro - b + kp e; q ← q ⊗ exp(ω dt/2) (exact, unlike the original first-order
    step).  Mahony, Hamel & Pflimlin, IEEE TAC 53(5), 2008.
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    b0, b1, b2 = b[0], b[1], b[2]
    for k in range(gyro.shape[0]):
        ex = 0.0
        ey = 0.0
        ez = 0.0
        ax, ay, az, an = unit3(acc[k, 0], acc[k, 1], acc[k, 2])
        if an > 0.0:
            vx, vy, vz = rotate_back(w, x, y, z, 0.0, 0.0, 1.0)
            ex = ay * vz - az * vy
            ey = az * vx - ax * vz
            ez = ax * vy - ay * vx
        if use_mag:
            mx, my, mz, mn = unit3(mag[k, 0], mag[k, 1], mag[k, 2])
            if mn > 0.0:
                hx, hy, hz = rotate(w, x, y, z, mx, my, mz)
                wx, wy, wz = rotate_back(w, x, y, z, 0.0, math.sqrt(hx * hx + hy * hy), hz)
                ex += my * wz - mz * wy
                ey += mz * wx - mx * wz
                ez += mx * wy - my * wx
        dt = dts[k]
        if ki > 0.0:
            b0 -= ki * ex * dt
            b1 -= ki * ey * dt
            b2 -= ki * ez * dt
        gx = gyro[k, 0] - b0 + kp * ex
        gy = gyro[k, 1] - b1 + kp * ey
        gz = gyro[k, 2] - b2 + kp * ez
        w, x, y, z = right_step(w, x, y, z, gx * dt, gy * dt, gz * dt)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z
        bias_out[k, 0], bias_out[k, 1], bias_out[k, 2] = b0, b1, b2
    q[0] = w
    q[1] = x
    q[2] = y
    q[3] = z
    b[0] = b0
    b[1] = b1
    b[2] = b2
