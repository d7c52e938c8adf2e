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
    """Unit axes (k, 3) in float64, consecutive ones perpendicular, or a ValueError naming ``axes``."""
    arr = _v.as_float_array(axes, "axes", dtype=np.float64)
    if arr.ndim == 1:
        arr = arr[None]
    if arr.ndim != 2 or arr.shape[-1] != 3 or not 1 <= arr.shape[0] <= most:
        raise ValueError(f"axes must have shape (3,) or (k, 3) with 1 ≤ k ≤ {most} axes; got shape {arr.shape}")
    _v.check_finite(arr, "axes")
    length = np.linalg.norm(arr, axis=-1)
    if not (length > 0).all():
        raise ValueError(f"axes[{int(np.flatnonzero(~(length > 0))[0])}] is a zero vector; an axis needs a direction")
    unit = arr / length[:, None]
    for i in range(unit.shape[0] - 1):
        cos = float(unit[i] @ unit[i + 1])
        if abs(cos) > _ORTHOGONAL:
            raise ValueError(
                f"axes[{i}] and axes[{i + 1}] are not perpendicular (cos = {cos:.3g}); consecutive Davenport axes "
                "must be perpendicular"
            )
    return np.ascontiguousarray(unit)


def _from_unit_axes(unit: np.ndarray, extrinsic: bool, angles, degrees: bool, check: bool) -> np.ndarray:
    k = unit.shape[0]
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
    rows = a.reshape(-1, k)
    out = np.empty((rows.shape[0], 4), dtype=a.dtype)
    from ._mrp_davenport_numba import from_axes_rows

    if from_axes_rows(rows, unit, extrinsic, out) >= 0 and check:  # checked as it goes (see the kernel)
        _v.finite(a, "angles")
    return out.reshape((*a.shape[:-1], 4))


def from_davenport(axes, order: str, angles, degrees: bool = False, *, check: bool = True) -> np.ndarray:
    """Attitude quaternions from Davenport angles about one, two or three axes.

    Parameters
    ----------
    axes : array_like, shape (3,) or (k, 3), k = 1, 2, 3
        The rotation axes in order; they are normalised, and consecutive ones must be perpendicular.
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
    axes : array_like, shape (3, 3)
        The three axes, normalised here; ``axes[1]`` must be perpendicular to the other two.
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
    unit = _axes(axes)
    if unit.shape[0] != 3:
        raise ValueError(f"as_davenport needs three axes, shape (3, 3); got {unit.shape[0]}")
    q = _v.quaternions(q, "q", check=False)
    n1, n2, n3 = unit if extrinsic else unit[::-1]  # the algorithm is for extrinsic sequences
    lam = float(np.arctan2(n3 @ np.cross(n1, n2), n3 @ n1))
    flip = lam < 0
    if flip:  # the other set of angles, that of as_euler: turn n2 round so that λ ≥ 0
        n2 = -n2
        lam = -lam
    rows = q.reshape(-1, 4)
    out = np.empty((rows.shape[0], 3), dtype=q.dtype)
    from ._mrp_davenport_numba import as_davenport_rows

    n1, n2, n3 = (np.ascontiguousarray(n) for n in (n1, n2, n3))
    scale = 180.0 / np.pi if degrees else 1.0
    if as_davenport_rows(rows, n1, n2, n3, lam, flip, extrinsic, scale, out) >= 0 and check:
        _v.quaternions(q, "q")  # checked as it goes (see the kernel); the usual message from here
    return out.reshape((*q.shape[:-1], 3))


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
