"""Modified Rodrigues parameters (MRPs), the attitude coordinates of spacecraft control.

``p = n tan(χ/4)`` for a rotation by χ about the unit axis n (Shuster, *A survey of attitude representations*,
J. Astronaut. Sci. 41(4), 1993, §8), from a unit quaternion ``p = v / (1 + w)``.  Every rotation has two sets:
the short one, ``|p| ≤ 1`` (χ in [0°, 180°]), and its shadow ``-p / |p|²`` (the same rotation the long way
round, ``|p| ≥ 1``), which is ``v / (w - 1)`` (Schaub and Junkins).  :func:`as_mrp` returns the short set, as
scipy's ``Rotation.as_mrp`` does, and :func:`from_mrp` accepts either: MRPs are finite for every rotation but
the full turn, χ = 360°, which only the shadow of the identity (|p| → ∞) would describe.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["as_mrp", "from_mrp", "shadow_mrp"]


def _rows(kernel: str, arr: np.ndarray, width: int, recheck, check: bool) -> np.ndarray:
    """The rows of ``arr`` converted by ``kernel`` of :mod:`._mrp_davenport_numba` into shape (..., width).

    The kernel checks its input as it goes and returns the first bad row, or -1; with ``check``, ``recheck(arr)``
    then raises the usual message for that input.
    """
    from . import _mrp_davenport_numba

    rows = arr.reshape(-1, arr.shape[-1])
    out = np.empty((rows.shape[0], width), dtype=arr.dtype)
    if getattr(_mrp_davenport_numba, kernel)(rows, out) >= 0 and check:
        recheck(arr)
    return out.reshape((*arr.shape[:-1], width))


def from_mrp(mrp, *, check: bool = True) -> np.ndarray:
    """Unit quaternions from modified Rodrigues parameters.

    Parameters
    ----------
    mrp : array_like, shape (..., 3)
        MRPs ``n tan(χ/4)``, short (|p| ≤ 1) or shadow (|p| ≥ 1) set.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``[1 - |p|², 2 p] / (1 + |p|²)`` (Shuster 1993, (253)); w < 0 for a shadow set.

    Examples
    --------
    >>> from strapdown import from_mrp
    >>> from_mrp([0.0, 0.0, 1.0])              # tan(45°): 180° about z
    array([0., 0., 0., 1.])
    >>> from_mrp([0.0, 0.0, 0.41421356237309503]).round(12)   # tan(22.5°): 90° about z
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    return _rows("from_mrp_rows", _v.vectors(mrp, "mrp", check=False), 4, lambda p: _v.vectors(p, "mrp"), check)


def as_mrp(q, *, check: bool = True) -> np.ndarray:
    """Modified Rodrigues parameters of attitude quaternions, the short set (|p| ≤ 1).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions (need not be normalised); ``q`` and ``-q`` give the same result.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        ``sgn(w) v / (|q| + |w|)``, of length ``tan(χ/4)`` with χ in [0, π].  At χ = 180° both sets have
        length 1; the sign rule of :func:`strapdown.rotations.quaternion.canonical` picks one.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_mrp
    >>> as_mrp([0.0, 0.0, 0.0, 1.0])                           # 180° about z
    array([0., 0., 1.])
    >>> as_mrp([-np.cos(np.pi / 4), 0.0, 0.0, -np.sin(np.pi / 4)]).round(12)   # 90° about z, sign flipped
    array([0.        , 0.        , 0.41421356])
    """
    return _rows("as_mrp_rows", _v.quaternions(q, "q", check=False), 3, lambda q: _v.quaternions(q, "q"), check)


def shadow_mrp(mrp, *, check: bool = True) -> np.ndarray:
    """The other MRP set of the same rotation, ``-p / |p|²``.

    Parameters
    ----------
    mrp : array_like, shape (..., 3)
        Non-zero MRPs (the identity, p = 0, has its shadow at infinity).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Shadow parameters; ``from_mrp`` of both is the same rotation.

    Examples
    --------
    >>> from strapdown.rotations.mrp import shadow_mrp
    >>> shadow_mrp([0.0, 0.0, 0.5]) + 0.0       # + 0.0 turns -0.0 into 0.0
    array([ 0.,  0., -2.])
    """
    p = _v.vectors(mrp, "mrp", check=check)
    n2 = np.einsum("...i,...i->...", p, p)
    if check and not (n2 > 0).all():
        raise ValueError(f"mrp{_v.first_index(~(n2 > 0))} is zero (the identity): its shadow set is at infinity")
    return -p / n2[..., None]
