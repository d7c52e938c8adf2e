"""Numba kernel of :mod:`strapdown.fusion.complementary` (private)."""

from __future__ import annotations

import math

import numba as nb

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ._kernels_numba import left_step, right_step, rotate, tilt_to_vertical, unit3


@nb.njit(cache=True, error_model="numpy")
def run(gyro, acc, mag, use_mag, dts, tau_acc, tau_mag, gravity, acc_gate, q, out, flags):
    """Quaternion complementary filter in ENU; q updated in place.

    Gyro step q ← q ⊗ exp(ω dt/2); then, in the reference frame, a fraction 1 - exp(-dt/τ_acc) of the tilt
    that turns the measured up R â onto z (an axis in the horizontal plane: the heading is untouched), and in
    9D a fraction 1 - exp(-dt/τ_mag) of the heading that turns the horizontal field onto north (+y), about z.
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    for k in range(gyro.shape[0]):
        dt = dts[k]
        w, x, y, z = right_step(w, x, y, z, gyro[k, 0] * dt, gyro[k, 1] * dt, gyro[k, 2] * dt)
        flag = 0
        ax, ay, az, an = unit3(acc[k, 0], acc[k, 1], acc[k, 2])
        if an > 0.0 and abs(an - gravity) <= acc_gate:
            ux, uy, uz = rotate(w, x, y, z, ax, ay, az)
            cx, cy = tilt_to_vertical(ux, uy, uz)
            g = 1.0 - math.exp(-dt / tau_acc) if tau_acc > 0.0 else 1.0
            w, x, y, z = left_step(w, x, y, z, g * cx, g * cy, 0.0)
        else:
            flag |= 2
        if use_mag:
            mx, my, _ = rotate(w, x, y, z, mag[k, 0], mag[k, 1], mag[k, 2])
            if mx * mx + my * my > 0.0:
                heading_error = math.atan2(mx, my)  # angle of the horizontal field east of north
                g = 1.0 - math.exp(-dt / tau_mag) if tau_mag > 0.0 else 1.0
                w, x, y, z = left_step(w, x, y, z, 0.0, 0.0, g * heading_error)
        out[k, 0], out[k, 1], out[k, 2], out[k, 3] = w, x, y, z
        flags[k] = flag
    q[0] = w
    q[1] = x
    q[2] = y
    q[3] = z
