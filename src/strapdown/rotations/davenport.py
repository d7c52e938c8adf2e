"""Davenport angles: rotations about any sequence of one to three axes, and Euler sequences of one or two axes.

Davenport (1973) generalised the Euler angles to any axes n1, n2, n3 with n2 perpendicular to n1 and to n3
(Shuster and Markley, *Generalization of the Euler angles*, J. Astronaut. Sci. 51(2), 2003).  Names and
arguments are scipy's ``Rotation.from_davenport(axes, order, angles)`` and ``as_davenport(axes, order)``:

* ``order="extrinsic"`` (or ``"e"``): the rotations are about the fixed reference axes, the first one first,
  ``q = e(n3, γ) ⊗ e(n2, β) ⊗ e(n1, α)``;
* ``order="intrinsic"`` (or ``"i"``): about the axes of the turning body, ``q = e(n1, α) ⊗ e(n2, β) ⊗ e(n3, γ)``,

with ``e(n, a) = [cos(a/2), sin(a/2) n]`` and q mapping body to reference as everywhere in strapdown.  With the
basis axes these are the Euler angles of :func:`strapdown.from_euler` (``"ZYX"`` is intrinsic z, y, x).

Ranges of :func:`as_davenport`: first and third angle in (-π, π]; the middle angle in ``[-λ, π - λ]``, where λ in
[0, π] is the angle from n1 to n3 about n2 (λ = 0 for proper Euler sequences, π/2 for Tait-Bryan ones: then
[-π/2, π/2]).  Gimbal lock is handled as in :mod:`strapdown.rotations.euler`: no threshold; only at the lock
exactly is the third angle 0.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["as_davenport", "from_davenport"]

_ORDERS = {"e": True, "extrinsic": True, "i": False, "intrinsic": False}
_BASIS = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
_ORTHOGONAL = 1e-7  # |cos| between consecutive unit axes that counts as perpendicular (scipy's tolerance)


def _extrinsic(order) -> bool:
    if order not in _ORDERS:
        raise ValueError(f"order must be 'extrinsic' ('e') or 'intrinsic' ('i'); got {order!r}")
    return _ORDERS[order]


def _axes(axes, most: int = 3) -> np.ndarray:
    """Unit axes (..., k, 3) in float64, consecutive ones perpendicular, or a ValueError naming ``axes``.

    Shape (3,) is one axis, (k, 3) one set of k axes for every rotation, (..., k, 3) a set per rotation.
    """
    arr = _v.as_float_array(axes, "axes", dtype=np.float64)
    if arr.ndim == 1:
        arr = arr[None]
    if arr.ndim < 2 or arr.shape[-1] != 3 or not 1 <= arr.shape[-2] <= most:
        raise ValueError(
            f"axes must have shape (3,), (k, 3) or (..., k, 3) with 1 ≤ k ≤ {most} axes; got shape {arr.shape}"
        )
    _v.check_finite(arr, "axes")
    length = np.linalg.norm(arr, axis=-1)
    if not (length > 0).all():
        raise ValueError(f"axes{_v.first_index(~(length > 0))} is a zero vector; an axis needs a direction")
    unit = arr / length[..., None]
    for i in range(unit.shape[-2] - 1):
        cos = np.einsum("...i,...i->...", unit[..., i, :], unit[..., i + 1, :])
        bad = np.abs(cos) > _ORTHOGONAL
        if bad.any():
            at = _v.first_index(bad)[1:-1] if bad.ndim else ""
            lead = f"{at}, " if at else ""
            raise ValueError(
                f"axes[{lead}{i}] and axes[{lead}{i + 1}] are not perpendicular (cos = {float(cos[bad].flat[0]):.3g}); "
                "consecutive Davenport axes must be perpendicular"
            )
    return np.ascontiguousarray(unit)


def _axis_rows(arr: np.ndarray, lead: tuple, tail: tuple) -> np.ndarray:
    """C-contiguous rows (N or 1, *tail) of an array broadcast to (*lead, *tail): one row when it is shared."""
    own = arr.shape[: arr.ndim - len(tail)]
    if own != lead and int(np.prod(own)) != 1:
        arr = np.broadcast_to(arr, (*lead, *tail))
    return np.ascontiguousarray(arr.reshape((-1, *tail)))


def _lead(name: str, shape: tuple, unit: np.ndarray) -> tuple:
    try:
        return np.broadcast_shapes(shape, unit.shape[:-2])
    except ValueError:
        raise ValueError(
            f"the leading shapes of {name} {shape} and of axes {unit.shape[:-2]} (one set of axes per rotation) do "
            "not broadcast"
        ) from None


def _from_unit_axes(unit: np.ndarray, extrinsic: bool, angles, degrees: bool, check: bool) -> np.ndarray:
    k = unit.shape[-2]
    a = _v.finite(angles, "angles", check=False)
    if a.ndim == 0 and k == 1:
        a = a[None]
    if a.ndim == 0 or a.shape[-1] != k:
        raise ValueError(
            f"angles must have shape (..., {k}), one angle per axis (a single number only for one axis); "
            f"got shape {a.shape}"
        )
    if degrees:
        a = np.deg2rad(a)
    lead = _lead("angles", a.shape[:-1], unit)
    rows = _axis_rows(a, lead, (k,))
    out = np.empty((int(np.prod(lead)), 4), dtype=a.dtype)
    from ._mrp_davenport_numba import from_axes_rows

    if from_axes_rows(rows, _axis_rows(unit, lead, (k, 3)), extrinsic, out) >= 0 and check:  # checked as it goes
        _v.finite(a, "angles")
    return out.reshape((*lead, 4))


def from_davenport(axes, order: str, angles, degrees: bool = False, *, check: bool = True) -> np.ndarray:
    """Attitude quaternions from Davenport angles about one, two or three axes.

    Parameters
    ----------
    axes : array_like, shape (3,), (k, 3) or (..., k, 3), k = 1, 2, 3
        The rotation axes in order; they are normalised, and consecutive ones must be perpendicular.  Leading
        axes give a set of axes per rotation, broadcast against those of ``angles``.
    order : {"extrinsic", "e", "intrinsic", "i"}
        Fixed reference axes or turning body axes (module notes).
    angles : array_like, shape (..., k), or a number for one axis
        One angle per axis (radians, or degrees with ``degrees=True``).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions (body to reference), the plain product of the elementary rotations.

    Examples
    --------
    >>> from strapdown import from_davenport
    >>> from_davenport([0, 0, 1], "e", 90, degrees=True)
    array([0.70710678, 0.        , 0.        , 0.70710678])
    >>> from_davenport([[2, 0, 0], [0, 1, 0], [1, 0, 1]], "extrinsic", [90, 45, 30], degrees=True).round(6)
    array([ 0.560986,  0.701057,  0.430459, -0.092296])
    """
    return _from_unit_axes(_axes(axes), _extrinsic(order), angles, degrees, check)


def as_davenport(q, axes, order: str, degrees: bool = False, *, check: bool = True) -> np.ndarray:
    """Davenport angles of attitude quaternions about three axes (consecutive ones perpendicular).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions (body to reference); ``q`` and ``-q`` give the same angles.
    axes : array_like, shape (3, 3) or (..., 3, 3)
        The three axes, normalised here; ``axes[1]`` must be perpendicular to the other two.  Leading axes give
        a set of axes per rotation, broadcast against those of ``q``.
    order : {"extrinsic", "e", "intrinsic", "i"}
        Fixed reference axes or turning body axes.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Angles; ranges in the module notes (scipy's, with the outer angles in (-π, π]).

    Notes
    -----
    Shuster and Markley (2003) in the direct half-angle form of Bernardes and Viollet (2022), as scipy computes
    it (details in ``_rotations_numba.as_davenport_rows``), in float64 whatever the input dtype.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_davenport, from_rotvec
    >>> ex, ey, ez = np.eye(3)
    >>> as_davenport(from_rotvec([0, 0, np.pi / 2]), [ez, ex, ey], "extrinsic", degrees=True).round(9)
    array([90.,  0.,  0.])
    """
    extrinsic = _extrinsic(order)
    unit = _three_axes(axes)
    q = _v.quaternions(q, "q", check=False)
    lead = _lead("q", q.shape[:-1], unit)
    (n1, n2, n3), lam, flip = _extrinsic_axes(unit, extrinsic)
    sets = np.stack([n1, n2, n3, np.cross(n1, n2)], axis=-2)  # (..., 4, 3): the axes and n1 × n2
    consts = np.stack([lam, np.cos(0.5 * lam), np.sin(0.5 * lam), flip.astype(np.float64)], axis=-1)
    out = np.empty((int(np.prod(lead)), 3), dtype=q.dtype)
    from ._mrp_davenport_numba import as_davenport_rows

    scale = 180.0 / np.pi if degrees else 1.0
    rows = _axis_rows(q, lead, (4,))
    bad = as_davenport_rows(rows, _axis_rows(sets, lead, (4, 3)), _axis_rows(consts, lead, (4,)), extrinsic, scale, out)
    if bad >= 0 and check:
        _v.quaternions(q, "q")  # checked as it goes (see the kernel); the usual message from here
    return out.reshape((*lead, 3))


def _three_axes(axes) -> np.ndarray:
    unit = _axes(axes)
    if unit.shape[-2] != 3:
        raise ValueError(f"as_davenport needs three axes, shape (3, 3) or (..., 3, 3); got {unit.shape[-2]}")
    return unit


def _extrinsic_axes(unit: np.ndarray, extrinsic: bool):
    """(n1, n2, n3) of the extrinsic sequence, λ ≥ 0 (the angle from n1 to n3 about n2) and whether n2 was turned.

    The algorithm is for extrinsic sequences: an intrinsic one is the extrinsic sequence of its axes reversed.
    Where λ < 0, n2 is turned round (λ then ≥ 0), which gives the other set of angles, that of as_euler.
    """
    n1, n2, n3 = (unit[..., m, :] for m in ((0, 1, 2) if extrinsic else (2, 1, 0)))
    lam = np.arctan2(np.einsum("...i,...i->...", n3, np.cross(n1, n2)), np.einsum("...i,...i->...", n3, n1))
    flip = lam < 0
    return (n1, np.where(flip[..., None], -n2, n2), n3), np.abs(lam), flip


def _warn_gimbal_lock(middle: np.ndarray, axes, order: str, eps: float = 1e-7) -> None:
    """A UserWarning where the middle angle (rad) of :func:`as_davenport` lies within ``eps`` of gimbal lock.

    The kernel's half-angle β of the middle turn is in [0, π] and the sequence locks at its ends, where n1,
    turned by the middle rotation, lies along n3 and only the sum or difference of the outer angles is defined;
    β is λ plus the middle angle (minus it when n2 was turned round).  ``eps`` is scipy's threshold.
    """
    _, lam, flip = _extrinsic_axes(_three_axes(axes), _extrinsic(order))
    beta = lam + np.where(flip, -middle, middle)
    locked = (beta <= eps) | (beta >= np.pi - eps)
    if locked.any():
        import warnings

        warnings.warn(
            f"Gimbal lock: rotation{_v.first_index(locked)} is within {eps:g} rad of it ({int(locked.sum())} of "
            f"{locked.size}), where only the sum or difference of the first and third angles is determined "
            "(the angles returned are exact; at the lock itself the third is 0)",
            UserWarning,
            stacklevel=3,
        )


def from_short_euler(angles, seq: str, degrees: bool, check: bool) -> np.ndarray:
    """:func:`strapdown.from_euler` for sequences of one or two axes ("z", "ZY", "xy", ...), as scipy allows."""
    if seq.isupper():
        extrinsic = False
    elif seq.islower():
        extrinsic = True
    else:
        raise ValueError(f"seq {seq!r} mixes upper and lower case: upper case is intrinsic, lower case extrinsic")
    low = seq.lower()
    if any(c not in _BASIS for c in low):
        raise ValueError(f"seq must use only the axes x, y and z; got {seq!r}")
    if len(low) == 2 and low[0] == low[1]:
        raise ValueError(f"seq {seq!r} repeats an axis in consecutive places; that is not an Euler sequence")
    unit = np.array([_BASIS[c] for c in low])
    return _from_unit_axes(unit, extrinsic, angles, degrees, check)
