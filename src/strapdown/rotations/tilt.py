"""The tilt quaternion: every attitude as a heading about the vertical times a yaw-free tilt (Rowe, US 6,377,906 B1).

Every attitude splits as ``q = q_z(ψ) ⊗ e`` with ``q_z(ψ)`` a rotation about the vertical (heading) and
``e = e0 + e1 i + e2 j`` (no k part) a rotation about a horizontal axis: the patent's "modified" quaternion
(math.md §5.3).  The gravity a body senses depends on e alone, so a tilt sensor yields e without knowing the
heading.  The split is singular only upside down (tilt 180°, ``w² + z² = 0``); there
:func:`tilt_from_quaternion` returns the half turn about the horizontal axis and flags it, never NaN.  The
reference frame is z up (ENU, NWU).  :class:`strapdown.fusion.TiltEstimator` estimates e.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from .euler import from_euler

__all__ = ["tilt_from_pitch_roll", "tilt_from_quaternion", "tilt_from_up", "tilt_rates"]

#: Within this of upside down (w² + z² < tol) the split is taken as the half turn, and flagged.
INVERTED_TOL = 1e-6


def tilt_from_quaternion(q, *, check: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split attitudes ``q = q_z(ψ) ⊗ e`` into heading ψ and tilt quaternion e (math.md §5.3).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Attitudes, sensor to a z-up reference frame (normalised here).

    Returns
    -------
    e : numpy.ndarray, shape (..., 4)
        Tilt quaternions ``(w² + z², wx + yz, wy - xz, 0) / √(w² + z²)`` with e0 ≥ 0.  Within 1e-6 of upside
        down, where the split is singular, the half turn ``(0, x, y, 0)/|(x, y)|`` (or about x when that is 0
        too).
    heading : numpy.ndarray, shape (...)
        ψ = 2 atan2(z, w) in (-π, π]; 0 where inverted.
    inverted : numpy.ndarray of bool, shape (...)
        Where the chart's singularity was met.

    Examples
    --------
    >>> from strapdown import from_euler
    >>> from strapdown.rotations.tilt import tilt_from_quaternion
    >>> e, heading, inverted = tilt_from_quaternion(from_euler([40.0, 10.0, 0.0], "ZYX", degrees=True))
    >>> e.round(6) + 0.0, round(float(heading), 6), bool(inverted)     # e1 is -3e-18: + 0.0 drops the sign
    (array([0.996195, 0.      , 0.087156, 0.      ]), 0.698132, False)
    """
    q = _v.rotations(q, "q", check=check)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = (q[..., i] for i in range(4))
    n = np.sqrt(w * w + z * z)
    inverted = n < INVERTED_TOL
    with np.errstate(invalid="ignore", divide="ignore"):
        e = np.stack([n, (w * x + y * z) / n, (w * y - x * z) / n, np.zeros_like(n)], axis=-1)
        heading = 2 * np.arctan2(z, w)
    if inverted.any():
        h = np.sqrt(x * x + y * y)
        flip = np.stack(
            [
                np.zeros_like(n),
                np.where(h > 0, x / np.where(h > 0, h, 1), 1.0),
                np.where(h > 0, y / np.where(h > 0, h, 1), 0.0),
                np.zeros_like(n),
            ],
            axis=-1,
        )
        e = np.where(inverted[..., None], flip, e)
        heading = np.where(inverted, 0.0, heading)
    # 2 atan2 spans (-2π, 2π] (q and -q): wrap into (-π, π]
    heading = np.pi - np.mod(np.pi - heading, 2 * np.pi)
    return e + 0.0, heading + 0.0, inverted  # + 0.0 turns -0.0 into 0.0


def tilt_from_up(up) -> np.ndarray:
    """Tilt quaternions from the "up" direction sensed in body axes (math.md §5.5).

    The shortest arc taking ``u`` to the vertical z: ``e0 = √((1 + u_z)/2)``, ``e1 = u_y / (2 e0)``,
    ``e2 = -u_x / (2 e0)``; its axis is horizontal automatically.  Straight down gives the half turn about x.

    Parameters
    ----------
    up : array_like, shape (..., 3)
        Up directions in body axes, any length (an accelerometer at rest reads +g along up).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Tilt quaternions (body to a z-up frame), e3 = 0.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.rotations.tilt import tilt_from_up
    >>> tilt_from_up([0.0, 0.0, 9.81])
    array([1., 0., 0., 0.])
    >>> tilt_from_up([0.0, 1.0, 1.0]).round(6)        # 45° of roll
    array([0.92388 , 0.382683, 0.      , 0.      ])
    """
    u = _v.vectors(up, "up")
    # scaled by the largest component first: |up|² overflows from 1e154 (the norm became inf and the tilt
    # quaternion of [1e200, 0, 1e200] had norm 0.707) and underflows below 1e-154
    big = np.max(np.abs(u), axis=-1, keepdims=True)
    if not (big > 0).all():
        raise ValueError(f"up{_v.first_index(~(big[..., 0] > 0))} is a zero vector")
    u = u / big
    u = u / np.linalg.norm(u, axis=-1, keepdims=True)
    e0 = np.sqrt(np.maximum(0.0, 0.5 * (1 + u[..., 2])))
    down = e0 < 1e-9
    safe = np.where(down, 1.0, e0)
    e = np.stack([e0, u[..., 1] / (2 * safe), -u[..., 0] / (2 * safe), np.zeros_like(e0)], axis=-1)
    half_turn = np.array([0.0, 1.0, 0.0, 0.0], dtype=u.dtype)
    return np.where(down[..., None], half_turn, e) + u.dtype.type(0)  # no -0.0; float32 stays float32


def tilt_from_pitch_roll(pitch, roll, degrees: bool = False) -> np.ndarray:
    """Tilt quaternions from inclinometer angles: pitch θ and roll φ of the yaw-pitch-roll (ZYX) convention.

    Parameters
    ----------
    pitch, roll : array_like, shape (...)
        Angles, radians (or degrees).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        The tilt quaternions of ``from_euler([0, θ, φ], "ZYX")``, i.e. with e3 = 0.

    Examples
    --------
    >>> from strapdown.rotations.tilt import tilt_from_pitch_roll
    >>> tilt_from_pitch_roll(10.0, 0.0, degrees=True).round(6)
    array([0.996195, 0.      , 0.087156, 0.      ])
    """
    p = _v.finite(pitch, "pitch")
    r = _v.finite(roll, "roll")
    _v.broadcast(("pitch", p.shape), ("roll", r.shape))
    p, r = np.broadcast_arrays(p, r)
    q = from_euler(np.stack([np.zeros_like(p), p, r], axis=-1), "ZYX", degrees)
    return tilt_from_quaternion(q, check=False)[0]


def tilt_rates(e, omega) -> tuple[np.ndarray, np.ndarray]:
    """The patent's yaw-free kinematics: ė of the tilt quaternion and the discarded heading rate ψ̇ (math.md §5.4).

    ``ė0 = -½(e1 p + e2 q)``, ``ė1 = [(e0² - e2²) p + e1 e2 q + 2 e0 e2 r] / (2 e0)``,
    ``ė2 = [(e0² - e1²) q + e1 e2 p - 2 e0 e1 r] / (2 e0)``, ``ψ̇ = (e0 r + e1 q - e2 p) / e0``, with body rates
    ω = (p, q, r).  Singular at e0 = 0 (upside down).

    Parameters
    ----------
    e : array_like, shape (..., 4)
        Tilt quaternions (e3 = 0).
    omega : array_like, shape (..., 3)
        Body rates, rad/s.

    Returns
    -------
    e_dot : numpy.ndarray, shape (..., 4)
        Rate of the tilt quaternion (its k part is 0).
    heading_rate : numpy.ndarray, shape (...)
        ψ̇, rad/s.

    Examples
    --------
    >>> from strapdown.rotations.tilt import tilt_rates
    >>> e_dot, psi_dot = tilt_rates([1.0, 0.0, 0.0, 0.0], [0.2, 0.0, 0.5])    # level: roll rate and yaw rate
    >>> e_dot, float(psi_dot)
    (array([0. , 0.1, 0. , 0. ]), 0.5)
    """
    e = _v.quaternions(e, "e")
    w = _v.vectors(omega, "omega")
    e0, e1, e2 = e[..., 0], e[..., 1], e[..., 2]
    p, q, r = w[..., 0], w[..., 1], w[..., 2]
    if not (np.abs(e0) > 0).all():
        raise ValueError("e has e0 = 0 (upside down), where the yaw-free kinematics are singular")
    with np.errstate(over="ignore", invalid="ignore"):
        d0 = -0.5 * (e1 * p + e2 * q)
        d1 = ((e0**2 - e2**2) * p + e1 * e2 * q + 2 * e0 * e2 * r) / (2 * e0)
        d2 = ((e0**2 - e1**2) * q + e1 * e2 * p - 2 * e0 * e1 * r) / (2 * e0)
        e_dot = np.stack([d0, d1, d2, np.zeros_like(d0)], axis=-1)
        heading = (e0 * r + e1 * q - e2 * p) / e0
    bad = ~(np.isfinite(e_dot).all(axis=-1) & np.isfinite(heading))
    if bad.any():
        e0_bad = float(np.broadcast_to(e0, bad.shape)[bad][0])
        raise ValueError(
            f"e{_v.first_index(bad)} is too close to upside down (e0 = {e0_bad:.3g}) for these rates: the yaw-free "
            "rates, which divide by e0, overflow"
        )
    return e_dot, heading
