"""Interpolating attitude time series: piecewise slerp, Shoemake's squad, and resampling to new timestamps.

Conventions: times ``t`` of shape (n,) are strictly increasing, in any unit (seconds usually); the attitudes ``q``
have time on the first axis, shape (n, ..., 4), so several series sampled at the same times interpolate at once.
New times ``t_new`` of any shape must lie in ``[t[0], t[-1]]`` (no extrapolation); results have shape
``t_new.shape + q.shape[1:]``.  Before interpolating, the series is made continuous in sign (each sample is
flipped if needed so that ``q[i]·q[i-1] ≥ 0``): every segment then takes the shorter arc, and the results are
continuous in sign too.  At a sample time the result is that sample, possibly with its sign flipped.
Computations are in float64; results keep float32 as float32.  ``check`` (default True) rejects NaN, infinities,
zero quaternions, non-increasing ``t`` and ``t_new`` outside the range with a ``ValueError`` that names the
argument and the first bad index.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from ..rotations.quaternion import conjugate, exp, log, multiply, power, slerp
from ._series import attitude_series
from .spline import RotationSpline

__all__ = ["RotationSpline", "resample", "slerp_series", "squad_series"]

METHODS = ("slerp", "squad")


def _segments(tv: np.ndarray, tn: np.ndarray, extra: int):
    """Segment index i (t[i] ≤ t_new ≤ t[i+1]) and fraction s in [0, 1], s shaped to broadcast with q[1:-1]."""
    i = np.clip(np.searchsorted(tv, tn, side="right") - 1, 0, tv.shape[0] - 2)
    s = (tn - tv[i]) / (tv[i + 1] - tv[i])
    return i, s.reshape(s.shape + (1,) * extra)


def _pure(v: np.ndarray) -> np.ndarray:
    """Pure quaternions (0, v)."""
    out = np.zeros((*v.shape[:-1], 4))
    out[..., 1:] = v
    return out


def _arc(p: np.ndarray, q: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Shoemake's slerp along the given arc, ``p ⊗ (p* ⊗ q)^s`` (no shorter-arc sign flip)."""
    return multiply(p, power(multiply(conjugate(p, check=False), q, check=False), s, check=False), check=False)


def _log_vec(q: np.ndarray) -> np.ndarray:
    """Vector part of log(q) for unit q: half angle in [0, π] times the unit axis (no sign is chosen)."""
    return log(q, check=False)[..., 1:]


def _finish(out: np.ndarray, q_end: np.ndarray, s: np.ndarray, dtype) -> np.ndarray:
    """Return the sample itself where s = 1 (the end of a segment), so the curve passes exactly through it."""
    return np.where(s[..., None] == 1, q_end, out).astype(dtype, copy=False)


def slerp_series(t, q, t_new, *, check: bool = True) -> np.ndarray:
    """Piecewise spherical linear interpolation of an attitude series (constant rate between samples).

    Parameters
    ----------
    t, q, t_new : array_like
        Sample times (n ≥ 2), the attitudes at those times (normalised first) and the times at which to
        interpolate (module conventions).

    Returns
    -------
    numpy.ndarray, shape ``t_new.shape + q.shape[1:]``
        Unit quaternions.  In segment ``[t_i, t_{i+1}]``, with ``s = (t_new - t_i)/(t_{i+1} - t_i)``,
        ``q_i ⊗ (q_i* ⊗ q_{i+1})^s``: a rotation about a fixed body axis at a constant rate, the shorter way.
        Continuous, with a jump of the angular rate at each sample.  The same rotations as scipy's
        ``Slerp(t, Rotation)``.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.propagate.interpolate import slerp_series
    >>> q = [[1.0, 0, 0, 0], [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]]     # 0 and 90 deg about z
    >>> slerp_series([0.0, 2.0], q, [0.0, 1.0])
    array([[1.        , 0.        , 0.        , 0.        ],
           [0.92387953, 0.        , 0.        , 0.38268343]])
    """
    tv, q1, tn, dtype = attitude_series(t, q, t_new, check)
    i, s = _segments(tv, tn, q1.ndim - 2)
    p1 = q1[i + 1]
    return _finish(slerp(q1[i], p1, s, check=False), p1, s, dtype)


def squad_series(t, q, t_new, *, check: bool = True) -> np.ndarray:
    """Shoemake's spherical quadrangle interpolation (squad): a C¹ attitude curve through the samples.

    Parameters
    ----------
    t, q, t_new : array_like
        As for :func:`slerp_series`; the times need not be uniform.

    Returns
    -------
    numpy.ndarray, shape ``t_new.shape + q.shape[1:]``
        Unit quaternions through every sample, with an angular rate continuous at the samples.

    Notes
    -----
    In segment i, with ``s = (t_new - t_i)/h_i`` and ``h_i = t_{i+1} - t_i`` (Shoemake 1987)::

        squad = slerp(slerp(q_i, q_{i+1}, s), slerp(a_i, a_{i+1}, s), 2s(1 - s)),   a_i = q_i ⊗ exp(T_i)

    with slerps that follow the given arcs (``p ⊗ exp(s log(p* ⊗ q))``, no sign flip).  Writing
    ``v_i = log(q_i* ⊗ q_{i+1})``, the body-frame rate of the curve leaves sample i at ``(v_i + 2 T_i)/h_i`` and
    arrives at it at ``(v_{i-1} - 2 T_i)/h_{i-1}``.  Equating the two gives the control points::

        T_i = (h_i v_{i-1} - h_{i-1} v_i) / (2 (h_{i-1} + h_i)),   and then   ω_i = 2 (v_{i-1} + v_i)/(h_{i-1} + h_i)

    (ω in rad per time unit), the central difference of the samples.  For uniform times this is Shoemake's
    ``a_i = q_i ⊗ exp(-(log(q_i* ⊗ q_{i+1}) + log(q_i* ⊗ q_{i-1}))/4)``; for non-uniform times the standard
    points would leave a jump in the rate, these do not.  The end points take ``a_0 = q_0`` and
    ``a_{n-1} = q_{n-1}``, so with two samples squad is slerp.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_rotvec
    >>> from strapdown.propagate.interpolate import squad_series
    >>> q = from_rotvec([[0.0, 0, 0], [0, 0, 0.5], [0, 0, 1.0], [0, 0, 1.5]])      # a steady turn about z
    >>> squad_series([0.0, 1.0, 2.0, 3.0], q, [1.5]).round(8)                         # 0.75 rad: on the arc
    array([[0.93050762, 0.        , 0.        , 0.36627253]])
    """
    tv, q1, tn, dtype = attitude_series(t, q, t_new, check)
    extra = q1.ndim - 2
    v = _log_vec(multiply(conjugate(q1[:-1], check=False), q1[1:], check=False))  # (n - 1, ..., 3)
    h = np.diff(tv).reshape((-1,) + (1,) * (extra + 1))
    tangent = np.zeros((*q1.shape[:-1], 3))
    tangent[1:-1] = (h[1:] * v[:-1] - h[:-1] * v[1:]) / (2 * (h[:-1] + h[1:]))
    a = multiply(q1, exp(_pure(tangent), check=False), check=False)
    i, s = _segments(tv, tn, extra)
    p1 = q1[i + 1]
    out = _arc(_arc(q1[i], p1, s), _arc(a[i], a[i + 1], s), 2 * s * (1 - s))
    return _finish(out, p1, s, dtype)


def resample(t, q, t_new, method: str = "slerp", *, check: bool = True) -> np.ndarray:
    """Resample an attitude series to new timestamps by :func:`slerp_series` or :func:`squad_series`.

    Parameters
    ----------
    t, q, t_new : array_like
        As for :func:`slerp_series`.
    method : {"slerp", "squad"}
        Piecewise slerp (constant rate in each interval; the default) or squad (rate continuous at the samples).

    Returns
    -------
    numpy.ndarray, shape ``t_new.shape + q.shape[1:]``
        Unit quaternions at ``t_new``.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_rotvec, from_rotvec
    >>> from strapdown.propagate.interpolate import resample
    >>> t = np.array([0.0, 0.1, 0.3])                                  # irregular samples
    >>> q = from_rotvec([[0.0, 0, 0], [0, 0, 0.1], [0, 0, 0.3]])      # 1 rad/s about z
    >>> as_rotvec(resample(t, q, [0.05, 0.2], method="squad")).round(12)
    array([[0.  , 0.  , 0.05],
           [0.  , 0.  , 0.2 ]])
    """
    _v.choice(method, "method", METHODS)
    if method == "squad":
        return squad_series(t, q, t_new, check=check)
    return slerp_series(t, q, t_new, check=check)
