"""Closed-form motions with exact attitude, body rate and gyro increments, independent of strapdown.

* coning (math.md §6.1): q(t) = [cos(α/2), 0, sin(α/2) cos Ωt, sin(α/2) sin Ωt];
* a generic smooth motion: yaw, pitch, roll (ZYX) given as smooth functions of time, the body rate from the
  Euler-angle kinematics, the attitude from scipy; |pitch| stays below 60°.

Increments are exact for coning and from 8-point Gauss-Legendre quadrature per step (error far below 1e-16 for
these steps) for the generic motion.
"""

import numpy as np
from scipy.spatial.transform import Rotation


def coning_q(t, alpha, omega):
    s = np.sin(alpha / 2)
    return np.stack(
        [np.full_like(t, np.cos(alpha / 2)), np.zeros_like(t), s * np.cos(omega * t), s * np.sin(omega * t)], axis=-1
    )


def coning_rate(t, alpha, omega):
    return np.stack(
        [
            np.full_like(t, -2 * omega * np.sin(alpha / 2) ** 2),
            -omega * np.sin(alpha) * np.sin(omega * t),
            omega * np.sin(alpha) * np.cos(omega * t),
        ],
        axis=-1,
    )


def coning_increments(t, alpha, omega):
    """Exact ∫ω over [t_k, t_{k+1}] for the N + 1 times t."""
    t1, t2 = t[:-1], t[1:]
    return np.stack(
        [
            -2 * omega * np.sin(alpha / 2) ** 2 * (t2 - t1),
            np.sin(alpha) * (np.cos(omega * t2) - np.cos(omega * t1)),
            np.sin(alpha) * (np.sin(omega * t2) - np.sin(omega * t1)),
        ],
        axis=-1,
    )


# generic motion: ψ(t), θ(t), φ(t) with their derivatives
_A = [(0.7, 0.9, 0.3), (0.4, 2.3, 1.1), (0.5, 1.7, -0.4)]  # (amplitude, angular frequency, phase) per angle
_DRIFT = (0.35, -0.2, 0.5)  # a steady rate per angle, so the motion is not periodic


def generic_angles(t):
    ang = np.empty((*t.shape, 3))
    rate = np.empty((*t.shape, 3))
    for i, ((a, w, p), d) in enumerate(zip(_A, _DRIFT, strict=True)):
        ang[..., i] = d * t + a * np.sin(w * t + p) * (0.6 if i == 1 else 1.0)
        rate[..., i] = d + a * w * np.cos(w * t + p) * (0.6 if i == 1 else 1.0)
    return ang, rate


def generic_q(t):
    ang, _ = generic_angles(np.asarray(t, dtype=float))
    return Rotation.from_euler("ZYX", ang.reshape(-1, 3)).as_quat(scalar_first=True).reshape((*ang.shape[:-1], 4))


def generic_rate(t):
    """Body rate of ZYX angles: ω = [φ' - ψ' sin θ, θ' cos φ + ψ' cos θ sin φ, -θ' sin φ + ψ' cos θ cos φ]."""
    (_psi, th, ph), (dpsi, dth, dph) = (np.moveaxis(a, -1, 0) for a in generic_angles(np.asarray(t, dtype=float)))
    return np.stack(
        [
            dph - dpsi * np.sin(th),
            dth * np.cos(ph) + dpsi * np.cos(th) * np.sin(ph),
            -dth * np.sin(ph) + dpsi * np.cos(th) * np.cos(ph),
        ],
        axis=-1,
    )


_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)


def generic_increments(t):
    """∫ω over [t_k, t_{k+1}] by 8-point Gauss-Legendre per step."""
    t = np.asarray(t, dtype=float)
    mid = 0.5 * (t[1:] + t[:-1])
    half = 0.5 * (t[1:] - t[:-1])
    nodes = mid[:, None] + half[:, None] * _GL_X[None, :]
    return np.einsum("kn,knc->kc", half[:, None] * _GL_W[None, :], generic_rate(nodes))
