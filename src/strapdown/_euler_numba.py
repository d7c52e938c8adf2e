"""Numba kernels for :mod:`strapdown.euler` (private).

Both kernels work on validated, C-contiguous rows and compute in float64 whatever the storage type.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

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


@nb.njit(cache=True)
def _wrap(a):
    """Wrap an angle in [-2π, 2π] into (-π, π]."""
    if a > math.pi:
        return a - 2.0 * math.pi
    if a <= -math.pi:
        return a + 2.0 * math.pi
    return a


@nb.njit(cache=True)
def _at(value, target, single):
    """Value == target as the caller will see it (after rounding to float32 when single)."""
    if single:
        return np.float32(value) == np.float32(target)
    return value == target


@nb.njit(cache=True)
def as_euler_rows(q, i, j, k, proper, sign, intrinsic, scale, single, out):
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
    Angles are multiplied by `scale` (1 for radians, 180/π for degrees) on output.
    """
    if proper:
        low = 0.0
        high = math.pi
    else:
        low = -0.5 * math.pi
        high = 0.5 * math.pi
    for n in range(q.shape[0]):
        # Canonical sign first (w > 0, ties by x, y, z) so that q and -q give bit-identical angles.
        w = float(q[n, 0])
        x = float(q[n, 1])
        y = float(q[n, 2])
        z = float(q[n, 3])
        flip = 1.0
        if w < 0.0 or (w == 0.0 and (x < 0.0 or (x == 0.0 and (y < 0.0 or (y == 0.0 and z < 0.0))))):
            flip = -1.0
        w = flip * w
        qi = flip * float(q[n, 1 + i])
        qj = flip * float(q[n, 1 + j])
        qk = flip * float(q[n, 1 + k]) * sign
        if proper:
            a = w
            b = qi
            c = qj
            d = qk
        else:
            a = w - qj
            b = qi + qk
            c = qj + w
            d = qk - qi
        middle = 2.0 * math.atan2(math.sqrt(c * c + d * d), math.sqrt(a * a + b * b)) + low
        half_sum = math.atan2(b, a)
        half_diff = math.atan2(d, c)
        if _at(middle * scale, low * scale, single):  # only α + γ is defined
            if intrinsic:
                alpha = 0.0
                gamma = 2.0 * half_sum
            else:
                alpha = 2.0 * half_sum
                gamma = 0.0
            middle = low
        elif _at(middle * scale, high * scale, single):  # only γ - α is defined
            if intrinsic:
                alpha = 0.0
                gamma = 2.0 * half_diff
            else:
                alpha = -2.0 * half_diff
                gamma = 0.0
            middle = high
        else:
            alpha = half_sum - half_diff
            gamma = half_sum + half_diff
        if not proper:
            gamma = gamma * sign
        # +0.0 turns a -0.0 (from 0 * -1) into +0.0
        alpha = _wrap(alpha) * scale + 0.0
        gamma = _wrap(gamma) * scale + 0.0
        middle = middle * scale
        if intrinsic:
            out[n, 0] = gamma
            out[n, 1] = middle
            out[n, 2] = alpha
        else:
            out[n, 0] = alpha
            out[n, 1] = middle
            out[n, 2] = gamma
