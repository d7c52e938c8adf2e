"""Averages of attitudes, their consistency check, and distances between attitudes (math.md §4.2; nabbla 15, 15½).

* :func:`average_two`: the midpoint of two attitudes, ``normalize(p + sgn(p·q) q)``, which is ``slerp(p, q, ½)``.
* :func:`mean`: the weighted mean of many (Markley, Cheng, Crassidis and Oshman, JGCD 30(4), 2007): the unit
  quaternion that minimises ``Σ w_i ‖R(q̄) - R(q_i)‖²_F``, the top eigenvector of ``M = Σ w_i q_i q_iᵀ``; it does
  not depend on the signs of the inputs, and ``return_outliers=True`` flags the attitudes that are inconsistent
  with it.
* :func:`chordal_distance` (the Frobenius norm of the difference of the rotation matrices) and
  :func:`geodesic_distance` (the rotation angle between two attitudes).

All functions accept non-unit quaternions and use the rotation of ``q / |q|``; every result is sign-invariant in
each input quaternion.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from .quaternion import _norm3, angle_between, canonical, conjugate, multiply

__all__ = ["average_two", "chordal_distance", "geodesic_distance", "mean"]

# Consistency rule: d > _K_MEDIAN · median(d).  The distance to the mean is the absolute deviation of an attitude
# in 3-D, so median(d) is the 3-D median absolute deviation.  For isotropic Gaussian attitude noise of σ per axis,
# d is σ times a chi variable with 3 degrees of freedom (median 1.538), the threshold is 4.61 σ and an inlier is
# flagged with probability 9e-5.
_K_MEDIAN = 3.0
_ROUNDING = 1e-12  # rad: distances at rounding level are never flagged
_ROUNDS = 20  # at most this many rounds of flag / average the rest


def _unit(q: np.ndarray) -> np.ndarray:
    """Validated quaternions scaled to unit norm, in float64."""
    q64 = q.astype(np.float64, copy=False)
    return q64 / np.sqrt(np.einsum("...i,...i->...", q64, q64))[..., None]


def average_two(p, q, *, check: bool = True) -> np.ndarray:
    """Midpoint of two attitudes: ``normalize(p + sgn(p·q) q)``, equal to ``slerp(p, q, ½)`` (nabbla part 15).

    Parameters
    ----------
    p, q : array_like, shape (..., 4)
        Non-zero quaternions (normalised first).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions in the hemisphere of ``p``: the rotation halfway along the shorter arc from p to q, and
        the mean of the two (:func:`mean`).  When the two differ by exactly 180° (``p·q = 0``) every point of a
        circle is a midpoint; ``sgn(0) = +1`` picks ``normalize(p + q)``, as
        :func:`strapdown.rotations.quaternion.slerp` does.

    Notes
    -----
    For unit p and q aligned so that ``p·q = cos φ ≥ 0``, ``|p + q| = 2 cos(φ/2)`` and ``(p + q)/|p + q|`` is the
    point of the great circle through p and q at φ/2 from both, which is ``slerp(p, q, ½)``; it is never zero.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.rotations.average import average_two
    >>> q90z = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]
    >>> average_two([1.0, 0, 0, 0], q90z)                   # 45 deg about z
    array([0.92387953, 0.        , 0.        , 0.38268343])
    >>> average_two([1.0, 0, 0, 0], -np.array(q90z))        # the sign of q does not matter
    array([0.92387953, 0.        , 0.        , 0.38268343])
    """
    p = _v.rotations(p, "p", check=check)
    q = _v.rotations(q, "q", check=check)
    dtype = _v.result_dtype(p, q)
    if check:
        _v.broadcast(("p", p.shape[:-1]), ("q", q.shape[:-1]))
    p1 = _unit(p)
    q1 = _unit(q)
    sign = np.where(np.einsum("...i,...i->...", p1, q1) < 0, -1.0, 1.0)
    s = p1 + sign[..., None] * q1
    return (s / np.sqrt(np.einsum("...i,...i->...", s, s))[..., None]).astype(dtype, copy=False)


def _reduced_axes(axis, ndim: int) -> tuple[int, ...]:
    """Leading axes to average over, as non-negative indices of q (the last axis holds the components)."""
    if axis is None:
        return tuple(range(ndim - 1))
    axes = (axis,) if np.isscalar(axis) else tuple(axis)
    out = []
    for a in axes:
        if not isinstance(a, (int, np.integer)) or isinstance(a, bool):
            raise ValueError(f"axis must be None, an int or a tuple of ints; got {axis!r}")
        if not -ndim <= a < ndim:
            raise ValueError(f"axis {a} is out of range for q of shape (..., 4) with {ndim} dimensions")
        a = int(a) % ndim
        if a == ndim - 1:
            raise ValueError(f"axis {axis!r} includes the last axis of q, which holds the quaternion components")
        out.append(a)
    if len(set(out)) != len(out):
        raise ValueError(f"axis {axis!r} repeats an axis")
    return tuple(sorted(out))


def mean(q, weights=None, *, axis=None, return_outliers: bool = False, threshold=None, check: bool = True):
    """Weighted mean attitude (Markley et al. 2007), optionally with a consistency check that flags outliers.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions (normalised first; signs do not matter).
    weights : array_like, optional
        Non-negative weights broadcastable to ``q.shape[:-1]``, with a positive sum over the averaged axes
        (default: all 1).
    axis : None, int or tuple of int
        Axes of ``q`` to average over, numbered as in ``q`` itself (so ``-2`` is its last leading axis; the last
        axis, the components, cannot be averaged).  None (default): all leading axes, one mean.
    return_outliers : bool
        Also return a boolean mask, the shape of ``q.shape[:-1]``, of the attitudes inconsistent with the others,
        and return the mean of the consistent ones (see Notes).
    threshold : float, optional
        Outlier threshold: an attitude is flagged when its rotation angle d to the mean exceeds this many
        radians.  None (default): the robust rule ``d > 3 median(d)`` over the averaged group.  The distance to
        the mean is an attitude's absolute deviation, so ``median(d)`` is the 3-D median absolute deviation; for
        isotropic Gaussian attitude noise of σ per axis the rule flags beyond 4.6 σ, about 9 inliers in 10⁵.  It
        needs a handful of attitudes (five or more) to mean anything.  Distances below 1e-12 rad are never
        flagged, and weights do not enter the rule.
    check : bool
        Reject NaN, infinities, zero quaternions and invalid weights (default).

    Returns
    -------
    mean : numpy.ndarray, shape (..., 4)
        Unit quaternions, canonical sign (w ≥ 0); the averaged axes removed.
    outliers : numpy.ndarray of bool, shape ``q.shape[:-1]``
        Only with ``return_outliers=True``: the attitudes farther from the returned mean than the threshold.

    Raises
    ------
    ValueError
        For invalid input (naming the argument and the first bad index), an invalid ``axis`` or an empty group.

    Notes
    -----
    For unit quaternions ``‖R(p) - R(q)‖²_F = 8 sin²(θ/2) = 8 (1 - (p·q)²)``, so ``Σ w_i ‖R(q̄) - R(q_i)‖²_F`` is
    least where ``q̄ᵀ M q̄`` is largest: the eigenvector of the largest eigenvalue of ``M = Σ w_i q_i q_iᵀ``
    (math.md §4.2, part 15½), found with ``numpy.linalg.eigh``.  ``q q ᵀ`` does not change with the sign of q, so
    neither does the mean.  It is the same as scipy's ``Rotation.mean``.  Where the top eigenvalue is repeated
    (attitudes spread evenly, e.g. two at 180° from each other) the mean is not unique and one of them is
    returned.  Distances to the mean are :func:`geodesic_distance`.

    The consistency check (``return_outliers=True``) alternates two steps from the mean of all attitudes: flag
    the attitudes beyond the threshold from the current mean, then average the others, until the flags no longer
    change (a few rounds; at most 20).  So the returned mean is the weighted mean of the unflagged attitudes, and
    the flags are relative to it: a gross outlier cannot drag the mean towards itself and hide, or push good
    attitudes over the threshold.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_rotvec
    >>> from strapdown.rotations.average import mean
    >>> q = from_rotvec([[0.0, 0, 0.1], [0, 0, -0.1], [0, 0, 0.2], [0, 0, -0.2], [0, 0, 2.0]])
    >>> m, outliers = mean(q, return_outliers=True)
    >>> outliers
    array([False, False, False, False,  True])
    >>> m.round(12)                              # the mean of the other four
    array([1., 0., 0., 0.])
    >>> mean(q[:2], weights=[3.0, 1.0])          # pulled towards the first: 0.0501 rad about z
    array([0.99968595, 0.        , 0.        , 0.02506003])
    """
    qv = _v.rotations(q, "q", check=check)
    dtype = qv.dtype
    if threshold is not None:
        limit = _v.finite(threshold, "threshold", check=check, dtype=np.float64)
        if limit.ndim != 0 or not limit >= 0:
            raise ValueError(f"threshold must be one non-negative angle in radians; got {threshold!r}")
        if not return_outliers:
            raise ValueError("threshold is the outlier threshold: give it with return_outliers=True")
    q1 = _unit(qv)
    axes = _reduced_axes(axis, q1.ndim)
    lead = q1.shape[:-1]
    if weights is None:
        w = np.ones(lead)
    else:
        w = _v.finite(weights, "weights", check=check, dtype=np.float64)
        try:
            w = np.broadcast_to(w, lead)
        except ValueError:
            raise ValueError(
                f"weights of shape {w.shape} do not broadcast to the attitudes' shape {lead} (q.shape[:-1])"
            ) from None
        if check and (w < 0).any():
            raise ValueError(f"weights{_v.first_index(w < 0)} is negative; weights must be ≥ 0")
    keep = tuple(a for a in range(len(lead)) if a not in axes)
    order = keep + axes
    keep_shape = tuple(lead[a] for a in keep)
    n = int(np.prod([lead[a] for a in axes]))
    if n == 0:
        raise ValueError(f"q has no attitudes to average over axis {axis!r} (shape {qv.shape})")
    qs = np.transpose(q1, (*order, len(lead))).reshape((*keep_shape, n, 4))
    ws = np.transpose(w, order).reshape((*keep_shape, n))
    total = ws.sum(axis=-1)
    if check and not (total > 0).all():
        where = f" for the mean at index {_v.first_index(~(total > 0))}" if keep_shape else ""
        raise ValueError(f"weights sum to zero{where}; a mean needs a positive total weight")
    mu = _eigen_mean(qs, ws)
    if not return_outliers:
        return mu.astype(dtype, copy=False)
    flags = np.zeros(ws.shape, dtype=bool)
    for _ in range(_ROUNDS):
        d = angle_between(mu[..., None, :], qs, check=False)
        if threshold is None:
            limit = _K_MEDIAN * np.median(d, axis=-1, keepdims=True)
        new = (d > limit) & (d > _ROUNDING)
        if (new == flags).all():
            break
        flags = new
        kept = np.where(flags, 0.0, ws)
        # a group whose consistent attitudes all have zero weight keeps the mean of all
        kept = np.where((kept.sum(axis=-1) > 0)[..., None], kept, ws)
        mu = _eigen_mean(qs, kept)
    # back to the layout of q.shape[:-1]
    flags = flags.reshape(keep_shape + tuple(lead[a] for a in axes))
    flags = np.transpose(flags, np.argsort(order))
    return mu.astype(dtype, copy=False), flags


def _eigen_mean(qs: np.ndarray, ws: np.ndarray) -> np.ndarray:
    """Top eigenvector of M = Σ w q qᵀ / Σ w over the second-last axis, canonical sign."""
    m = np.einsum("...n,...ni,...nj->...ij", ws / ws.sum(axis=-1, keepdims=True), qs, qs)
    _, vecs = np.linalg.eigh(m)
    return canonical(vecs[..., :, -1], check=False)


def chordal_distance(p, q, *, check: bool = True) -> np.ndarray:
    """Chordal distance ``‖R(p) - R(q)‖_F = 2√2 sin(θ/2)``: the Frobenius norm of the difference of the matrices.

    Parameters
    ----------
    p, q : array_like, shape (..., 4)
        Non-zero quaternions of any finite norm.

    Returns
    -------
    numpy.ndarray, shape (...)
        Distances (float32 for float32 input) in [0, 2√2], with θ in [0, π] the rotation angle between the
        attitudes.  This is the distance :func:`mean` minimises (squared).  It is not the quaternion chord
        ``min(|p - q|, |p + q|) = 2 sin(θ/4)``.

    Notes
    -----
    Computed as ``2√2 |vec(p* ⊗ q)|`` of the normalised p and q, accurate for tiny angles and sign-invariant.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.rotations.average import chordal_distance
    >>> q90z = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]
    >>> float(chordal_distance([1.0, 0, 0, 0], q90z))      # 2√2 sin 45° = 2
    2.0
    """
    p = _v.rotations(p, "p", check=check)
    q = _v.rotations(q, "q", check=check)
    dtype = _v.result_dtype(p, q)
    if check:
        _v.broadcast(("p", p.shape[:-1]), ("q", q.shape[:-1]))
    # normalised first: |p|²|q|² over- or underflows far from unit norm (float32 at 5e9 gave 0, at 1e-12 inf)
    p1, q1 = _unit(p), _unit(q)
    r = multiply(conjugate(p1, check=False), q1, check=False)
    return (2 * np.sqrt(2) * _norm3(r[..., 1:])).astype(dtype, copy=False)


def geodesic_distance(p, q, *, check: bool = True) -> np.ndarray:
    """Geodesic distance: the rotation angle θ in [0, π] between two attitudes (= quaternion.angle_between).

    Parameters
    ----------
    p, q : array_like, shape (..., 4)
        The two attitudes, as for :func:`~strapdown.rotations.quaternion.angle_between`.

    Returns
    -------
    numpy.ndarray, shape (...)
        Angles in radians, ``2 atan2(|vec r|, |scal r|)`` with ``r = p* ⊗ q`` (math.md §4.2): accurate for tiny
        angles, unlike ``2 acos|p·q|``, and sign-invariant.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.rotations.average import geodesic_distance
    >>> q90z = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]
    >>> round(float(np.degrees(geodesic_distance([1.0, 0, 0, 0], q90z))), 9)
    90.0
    """
    return angle_between(p, q, check=check)
