"""Rotation groups (the symmetries of regular solids, prisms and pyramids) and reducing attitudes by them.

The finite groups of proper rotations in three dimensions are the cyclic groups C_n (n rotations about one axis),
the dihedral groups D_n (C_n and n half turns about axes perpendicular to it) and the rotation groups of the
Platonic solids: the tetrahedral group T (12), the octahedral group O (24, the cube's) and the icosahedral
group I (60, the dodecahedron's).  They are what scipy's ``Rotation.create_group`` returns, with the same names
and orientations:

* ``"Cn"`` about the ``axis`` (x, y or z), by the angles 2πk/n, k = 0, ..., n - 1;
* ``"Dn"``: C_n, then the half turns about the axes at the angles πk/n in the plane perpendicular to ``axis``,
  measured from the next axis in the cycle x → y → z → x (from x for ``axis="z"``);
* ``"T"``: the rotations of the tetrahedron with vertices (1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1);
  ``"O"`` of the octahedron with vertices ±x, ±y, ±z; ``"I"`` of the icosahedron with vertices at the cyclic
  permutations of (0, ±1, ±φ), φ the golden ratio.  ``axis`` does not apply to them.

The solids' groups are generated here from two rotations each, closed under the product: a half turn about z
and the 120° turn about (1, 1, 1) for T, the quarter turn about z and the same 120° turn for O, the 72° turn
about the vertex (0, 1, φ) and the 120° turn for I (a rotation of order 5 and one of order 3 generate the
icosahedral group, which is simple).  Elements are unit quaternions in canonical sign (w ≥ 0, see
:func:`strapdown.rotations.quaternion.canonical`), the identity first.

:func:`reduce` maps attitudes to the smallest equivalent one under two groups, the symmetries of the object
turned (on the right) and of the frame it is seen in (on the left): crystallography's misorientation.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["create_group", "reduce"]

_AXES = ("x", "y", "z", "X", "Y", "Z")
_PHI = (1 + np.sqrt(5)) / 2
_SOLIDS = {"T": 12, "O": 24, "I": 60}


def _turn(axis, angle: float) -> np.ndarray:
    """The unit quaternion of a turn by ``angle`` about ``axis`` (normalised here)."""
    axis = np.asarray(axis, dtype=np.float64)
    return np.array([np.cos(angle / 2), *(np.sin(angle / 2) * axis / np.linalg.norm(axis))])


def _closure(generators: list[np.ndarray], order: int) -> np.ndarray:
    """Every product of the generators, breadth first from the identity, one canonical quaternion per rotation."""
    from .quaternion import canonical, multiply

    found = [np.array([1.0, 0.0, 0.0, 0.0])]
    keys = {tuple(np.round(found[0], 9))}
    frontier = list(found)
    while frontier:
        new = []
        for q in frontier:
            for g in generators:
                p = multiply(g, q, check=False)
                # a component that is zero but for rounding would let it decide the sign: make it zero
                p = canonical(np.where(np.abs(p) < 1e-12, 0.0, p), check=False)
                key = tuple(np.round(p, 9) + 0.0)
                if key not in keys:
                    keys.add(key)
                    new.append(p)
        found += new
        frontier = new
    if len(found) != order:  # the generators are fixed: this guards the construction itself
        raise AssertionError(f"the group closed with {len(found)} elements, not {order}")
    return np.array(found)


def create_group(group: str, axis: str = "Z") -> np.ndarray:
    """The elements of a rotation group, as unit quaternions (scipy's ``Rotation.create_group``).

    Parameters
    ----------
    group : {"I", "O", "T", "Cn", "Dn"}
        The icosahedral, octahedral or tetrahedral group, or the cyclic or dihedral group of order n ≥ 1
        (``"C4"``, ``"D6"``); orientations in the module notes.
    axis : {"X", "Y", "Z", "x", "y", "z"}
        The main axis of ``"Cn"`` and ``"Dn"`` (default z); not used by the solids' groups.

    Returns
    -------
    numpy.ndarray, shape (m, 4)
        The m distinct rotations of the group (m = 60, 24, 12, n, 2n), canonical sign, the identity first.

    Examples
    --------
    >>> from strapdown.rotations.groups import create_group
    >>> create_group("C4").round(6)                    # 0, 90, 180, 270 deg about z
    array([[ 1.      ,  0.      ,  0.      ,  0.      ],
           [ 0.707107,  0.      ,  0.      ,  0.707107],
           [ 0.      ,  0.      ,  0.      ,  1.      ],
           [ 0.707107,  0.      ,  0.      , -0.707107]])
    >>> len(create_group("I")), len(create_group("D3", axis="x"))
    (60, 6)
    """
    from .quaternion import canonical

    if not isinstance(group, str):
        raise ValueError(f"group must be a string such as 'I', 'O', 'T', 'C4' or 'D6'; got {group!r}")
    if not isinstance(axis, str) or axis not in _AXES:
        raise ValueError(f"axis must be one of {', '.join(_AXES)}; got {axis!r}")
    if group in _SOLIDS:
        diagonal = _turn([1.0, 1.0, 1.0], 2 * np.pi / 3)
        first = {"T": _turn([0.0, 0.0, 1.0], np.pi), "O": _turn([0.0, 0.0, 1.0], np.pi / 2)}
        first["I"] = _turn([0.0, 1.0, _PHI], 2 * np.pi / 5)
        return _closure([first[group], diagonal], _SOLIDS[group])
    if group[:1] not in ("C", "D") or not group[1:].isdigit() or not group[1:].isascii():
        raise ValueError(f"group must be one of 'I', 'O', 'T', 'Dn', 'Cn' (n a positive integer); got {group!r}")
    n = int(group[1:])
    if n < 1:
        raise ValueError(f"group {group!r}: the order n must be positive")
    k = "xyz".index(axis.lower())
    e = np.eye(3)
    half = np.pi * np.arange(n) / n  # half the angles 2πk/n of C_n, and the directions of D_n's half turns
    cyclic = np.zeros((n, 4))
    cyclic[:, 0] = np.cos(half)
    cyclic[:, 1:] = np.sin(half)[:, None] * e[k]
    if group[0] == "C":
        return canonical(cyclic, check=False)
    flips = np.zeros((n, 4))
    flips[:, 1:] = np.cos(half)[:, None] * e[(k + 1) % 3] + np.sin(half)[:, None] * e[(k + 2) % 3]
    return canonical(np.concatenate([cyclic, flips]), check=False)


def _group_rows(value, name: str) -> np.ndarray | None:
    from .quaternion import normalize

    if value is None:
        return None
    arr = normalize(_v.rotations(value, name), check=False)
    if arr.ndim > 2 or arr.shape[:-1] == (0,):
        raise ValueError(f"{name} must be one quaternion or a non-empty (m, 4) stack, got shape {arr.shape}")
    return np.ascontiguousarray(np.atleast_2d(arr), dtype=np.float64)


def reduce(q, left=None, right=None, *, check: bool = True):
    """The smallest rotation ``l ⊗ q ⊗ r`` over ``l`` in ``left`` and ``r`` in ``right`` (scipy's ``reduce``).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions (normalised first).
    left, right : array_like, shape (m, 4) or (4,), optional
        The rotations to try on either side (a group from :func:`create_group`); None stands for the identity.
    check : bool
        Reject NaN, infinities and zero quaternions (default).

    Returns
    -------
    reduced : numpy.ndarray, shape (..., 4)
        ``left[i] ⊗ q ⊗ right[j]`` (normalised) for the pair with the largest ``|w|``, the least angle; the first
        such pair in the order (i, j) when several tie.
    left_index, right_index : numpy.ndarray of int, shape (...), or None
        ``i`` and ``j``; None for a side not given.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_rotvec, from_rotvec
    >>> from strapdown.rotations.groups import create_group, reduce
    >>> q, _, j = reduce(from_rotvec([0.0, 0.0, 1.7]), right=create_group("C4"))   # a square: 1.7 - π/2
    >>> as_rotvec(q).round(6), int(j)
    (array([0.      , 0.      , 0.129204]), 3)
    """
    from ._quaternion_numba import best_reduction_rows
    from .quaternion import multiply, normalize

    qv = normalize(_v.rotations(q, "q", check=check), check=False)
    lv, rv = _group_rows(left, "left"), _group_rows(right, "right")
    if lv is None and rv is None:
        return qv, None, None
    rows = np.ascontiguousarray(qv.reshape(-1, 4), dtype=np.float64)
    identity = np.array([[1.0, 0.0, 0.0, 0.0]])
    i = np.empty(rows.shape[0], dtype=np.intp)
    j = np.empty(rows.shape[0], dtype=np.intp)
    best_reduction_rows(rows, identity if lv is None else lv, identity if rv is None else rv, i, j)
    out = rows
    if lv is not None:
        out = multiply(lv[i], out, check=False)
    if rv is not None:
        out = multiply(out, rv[j], check=False)
    shape = qv.shape[:-1]
    out = normalize(out, check=False).reshape((*shape, 4)).astype(qv.dtype, copy=False)
    return out, None if lv is None else i.reshape(shape), None if rv is None else j.reshape(shape)
