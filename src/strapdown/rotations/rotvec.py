"""Axis-angle, rotation vectors and Gibbs vectors.

* axis-angle ``(n, χ)``: unit axis n and angle χ, Gajda (2.12): ``q = [cos(χ/2), n sin(χ/2)]``;
* rotation vector ``θ = χ n`` (Gajda's Θ, (2.5)-(2.8); scipy's rotvec), ``q = exp(θ/2)``;
* Gibbs vector: Gajda's finite-rotation vector (1.4) ``θ = 2 n tan(χ/2)`` by default, or the classical
  Gibbs vector / Rodrigues parameters ``g = n tan(χ/2)`` (Shuster 1993) with ``convention="rodrigues"``.  It
  is infinite at χ = 180°.

``as_*`` functions take quaternions of any non-zero norm (the rotation of ``q / |q|``) and return angles in
[0, π] (the shorter way round), so ``q`` and ``-q`` give the same result.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from .quaternion import _half_angle, _norm3, _sinc, canonical

__all__ = ["as_axis_angle", "as_gibbs", "as_rotvec", "from_axis_angle", "from_gibbs", "from_rotvec"]

_GIBBS_FACTOR = {"gajda": 2.0, "rodrigues": 1.0}


def from_rotvec(rotvec, degrees: bool = False, *, check: bool = True) -> np.ndarray:
    """Unit quaternions ``exp(θ/2)`` of rotation vectors θ (angle times unit axis).

    Parameters
    ----------
    rotvec : array_like, shape (..., 3)
        Rotation vectors; their length is the angle, in radians (or degrees with ``degrees=True``).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``[cos(|θ|/2), θ sin(|θ|/2)/|θ|]``.  This is Gajda's stage 2, the exact rotation of a constant rate ω
        over Δt for ``θ = ω Δt``; θ = 0 gives the identity without a division, and a series replaces
        ``sin(x)/x`` for tiny angles.  Angles beyond π give w < 0 (the exponential is not sign-normalised).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_rotvec
    >>> from_rotvec([0.0, 0.0, np.pi / 2])
    array([0.70710678, 0.        , 0.        , 0.70710678])
    >>> from_rotvec([0.0, 0.0, 0.0])
    array([1., 0., 0., 0.])
    """
    v = _v.vectors(rotvec, "rotvec", check=check)
    if degrees:
        v = np.deg2rad(v)
    half = 0.5 * _norm3(v)
    out = np.empty((*v.shape[:-1], 4), dtype=v.dtype)
    out[..., 0] = np.cos(half)
    out[..., 1:] = (0.5 * _sinc(half))[..., None] * v
    return out


def as_rotvec(q, degrees: bool = False, *, check: bool = True) -> np.ndarray:
    """Rotation vectors (angle in [0, π] times unit axis) of attitude quaternions.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Attitudes.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Rotation vectors ``2 log(±q)`` with the sign that makes the angle at most π; at exactly π the sign
        rule of :func:`strapdown.rotations.quaternion.canonical` picks the axis, so ``q`` and ``-q`` agree.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_rotvec
    >>> as_rotvec([0.0, 0.0, 0.0, -1.0], degrees=True)    # 180 deg about z
    array([  0.,   0., 180.])
    >>> as_rotvec([np.cos(0.05), 0.0, np.sin(0.05), 0.0]).round(12)    # 0.1 rad about y
    array([0. , 0.1, 0. ])
    """
    q = canonical(_v.rotations(q, "q", check=check), check=False)
    _, half, unit = _half_angle(q)
    out = (2 * half)[..., None] * unit
    return np.rad2deg(out) if degrees else out


def from_axis_angle(axis, angle, degrees: bool = False, *, check: bool = True) -> np.ndarray:
    """Unit quaternions of rotations by ``angle`` about ``axis`` (Gajda 2.12).

    Parameters
    ----------
    axis : array_like, shape (..., 3)
        Rotation axes; they are normalised, and must not be zero.
    angle : array_like, shape (...)
        Angles (right-handed about the axis), broadcast against the leading axes of ``axis``.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``[cos(χ/2), n sin(χ/2)]``.

    Examples
    --------
    >>> from strapdown import from_axis_angle
    >>> from_axis_angle([0, 0, 2], 90, degrees=True)
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    axis_arr = _v.vectors(axis, "axis", check=check)
    angle_arr = _v.finite(angle, "angle", check=check)
    if _v.weak(angle):  # a Python float keeps float32 axes float32
        angle_arr = angle_arr.astype(axis_arr.dtype)
    axis, angle = _v.promote(axis_arr, angle_arr)
    if check:
        _v.broadcast(("axis", axis.shape[:-1]), ("angle", angle.shape))
    length = _norm3(axis)
    if check and not (length > 0).all():
        raise ValueError(f"axis{_v.first_index(~(length > 0))} is a zero vector; a rotation axis must be non-zero")
    if degrees:
        angle = np.deg2rad(angle)
    half = 0.5 * angle
    unit = axis / length[..., None]
    unit, half = np.broadcast_arrays(unit, half[..., None])
    out = np.empty((*unit.shape[:-1], 4), dtype=axis.dtype)
    out[..., 0] = np.cos(half[..., 0])
    out[..., 1:] = np.sin(half) * unit
    return out


def as_axis_angle(q, degrees: bool = False, *, check: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Unit axes and angles in [0, π] of attitude quaternions.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        As for :func:`as_rotvec`.

    Returns
    -------
    axis : numpy.ndarray, shape (..., 3)
        Unit axes; for the identity rotation, where every axis is valid, ``[1, 0, 0]``.
    angle : numpy.ndarray, shape (...)
        Angles.

    Examples
    --------
    >>> from strapdown import as_axis_angle
    >>> axis, angle = as_axis_angle([0.5, 0.5, 0.5, 0.5], degrees=True)
    >>> axis.round(6), round(float(angle), 9)
    (array([0.57735, 0.57735, 0.57735]), 120.0)
    """
    q = canonical(_v.rotations(q, "q", check=check), check=False)
    s, half, axis = _half_angle(q)
    axis[s == 0] = (1, 0, 0)
    angle = 2 * half
    return axis, (np.rad2deg(angle) if degrees else angle)


def from_gibbs(gibbs, convention: str = "gajda", *, check: bool = True) -> np.ndarray:
    """Unit quaternions from Gibbs vectors.

    Parameters
    ----------
    gibbs : array_like, shape (..., 3)
        ``θ = 2 n tan(χ/2)`` (Gajda 1.4, ``convention="gajda"``) or ``g = n tan(χ/2)``
        (``convention="rodrigues"``).  Must be finite: a 180° rotation has no Gibbs vector.
    convention : {"gajda", "rodrigues"}
        Which of the two scalings.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``[1, g] / √(1 + |g|²)`` with ``g = θ / 2``; w > 0 always.

    Examples
    --------
    >>> from strapdown import from_gibbs
    >>> from_gibbs([0.0, 0.0, 2.0])       # 2 tan(45 deg): 90 deg about z
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    _v.choice(convention, "convention", tuple(_GIBBS_FACTOR))
    g = _v.vectors(gibbs, "gibbs", check=check) / _GIBBS_FACTOR[convention]
    out = np.empty((*g.shape[:-1], 4), dtype=g.dtype)
    # [1, g] scaled by its largest entry first: |g|² overflows from |g| ~ 1e154 (1e19 in float32), which would
    # give a zero "quaternion" for a rotation close to 180°
    big = np.maximum(1, np.max(np.abs(g), axis=-1))
    out[..., 0] = 1 / big
    out[..., 1:] = g / big[..., None]
    out /= np.sqrt(np.einsum("...i,...i->...", out, out))[..., None]
    return out


def as_gibbs(q, convention: str = "gajda", *, check: bool = True) -> np.ndarray:
    """Gibbs vectors of attitude quaternions: ``vec(q) / w`` times 2 (Gajda) or 1 (Rodrigues).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions with ``w ≠ 0`` (rotation angle below 180°).
    convention : {"gajda", "rodrigues"}
        ``"gajda"``: Gajda's finite-rotation vector (1.4) ``θ = 2 n tan(χ/2)``; ``"rodrigues"``: the classical
        Gibbs vector ``g = n tan(χ/2)``.
    check : bool
        Reject NaN, infinities, zero quaternions and 180° rotations (default).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Gibbs vectors; sign-invariant in ``q``.

    Raises
    ------
    ValueError
        For a rotation of exactly 180° (w = 0), where the Gibbs vector is infinite.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_gibbs
    >>> q = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]      # 90 deg about z
    >>> as_gibbs(q).round(12), as_gibbs(q, "rodrigues").round(12)
    (array([0., 0., 2.]), array([0., 0., 1.]))
    """
    _v.choice(convention, "convention", tuple(_GIBBS_FACTOR))
    q = _v.rotations(q, "q", check=check)
    w = q[..., 0]
    if check and (w == 0).any():
        raise ValueError(
            f"q{_v.first_index(w == 0)} is a 180° rotation (w = 0): its Gibbs vector is infinite; "
            "use as_rotvec or as_axis_angle instead"
        )
    with np.errstate(over="ignore", invalid="ignore"):
        out = (_GIBBS_FACTOR[convention] / w)[..., None] * q[..., 1:]
    if check and not np.isfinite(out).all():
        bad = ~np.isfinite(out).all(axis=-1)
        raise ValueError(
            f"q{_v.first_index(bad)} is too close to a 180° rotation (w = {float(w[bad][0]):.3g} against a vector part "
            f"of {float(_norm3(q[..., 1:])[bad][0]):.3g}): its Gibbs vector overflows {out.dtype}; use as_rotvec"
        )
    return out
