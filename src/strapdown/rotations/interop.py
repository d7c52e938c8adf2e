"""Interoperability with :class:`scipy.spatial.transform.Rotation` (scipy is an optional extra).

scipy stores quaternions scalar last by default; these helpers keep strapdown's scalar-first layout on our side
and pass ``scalar_first=True`` on scipy's, so no component order can slip.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["as_scipy", "from_scipy", "to_scipy"]


def _rotation_class():
    try:
        from scipy.spatial.transform import Rotation
    except ImportError:  # pragma: no cover - exercised only without scipy
        raise ImportError(
            "as_scipy/from_scipy need scipy: pip install 'strapdown[test]' or pip install scipy"
        ) from None
    return Rotation


def as_scipy(q, *, check: bool = True):
    """A scipy ``Rotation`` holding the attitudes ``q`` (body to reference, so ``rot.apply(v_body)`` = v_ref).

    Parameters
    ----------
    q : array_like, shape (4,) or (n, 4)
        Non-zero quaternions ``[w, x, y, z]`` (scipy normalises them).

    Returns
    -------
    scipy.spatial.transform.Rotation
        A single rotation for shape (4,), a stack for (n, 4).

    Examples
    --------
    >>> from strapdown import as_scipy
    >>> as_scipy([0.0, 0.0, 0.0, 1.0]).as_rotvec().round(12)    # 180 deg about z
    array([0.        , 0.        , 3.14159265])
    """
    q = _v.quaternions(q, "q", check=check)
    return _rotation_class().from_quat(q, scalar_first=True)


#: :func:`as_scipy` by its name of release 0.1 (the library's pairs are ``from_*`` / ``as_*``).
to_scipy = as_scipy


def from_scipy(rot) -> np.ndarray:
    """Scalar-first quaternions ``[w, x, y, z]`` of a scipy ``Rotation``.

    Parameters
    ----------
    rot : scipy.spatial.transform.Rotation
        One rotation or a stack.

    Returns
    -------
    numpy.ndarray, shape (4,) or (n, 4)
        Unit quaternions as scipy stores them (its sign).

    Examples
    --------
    >>> from scipy.spatial.transform import Rotation
    >>> from strapdown import from_scipy
    >>> from_scipy(Rotation.from_euler("z", 90, degrees=True))
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    rotation = _rotation_class()
    if not isinstance(rot, rotation):
        raise ValueError(f"rot must be a scipy.spatial.transform.Rotation, got {type(rot).__name__}")
    return np.asarray(rot.as_quat(scalar_first=True))
