"""scipy's ``Rotation.align_vectors`` on strapdown's arrays (exported by :mod:`strapdown.wahba`).

Three cases, as scipy (its docstring and test_rotation.py's ``test_align_vectors_*`` cases):

* one vector pair: the minimal rotation turning b onto a (:func:`strapdown.decompose.shortest_arc`);
* one infinite weight (the primary pair): the minimal rotation of the primary b onto the primary a, then the
  rotation about a that best aligns the other (secondary) pairs, ``φ = atan2(Σ w (c × a)·â_p, Σ w (c·a -
  (c·â_p)(a·â_p)))`` with c the secondary b after the first rotation ("align-constrain"; the limit of Wahba's
  solution as that weight grows).  If the secondary vectors carry no direction about the primary axis (all
  parallel to it) the result is the primary rotation alone;
* otherwise Wahba's problem on the raw vectors (their lengths weigh, as in scipy's Kabsch solution), by
  :func:`strapdown.wahba.davenport` with ``normalize=False``.
"""

from __future__ import annotations

import numpy as np

from . import _validate as _v

__all__ = ["align_vectors"]

# |Σ w (sin, cos)| below this fraction of Σ w |c⊥| |a⊥|-scale terms: the secondaries fix no angle about the primary
_PARALLEL = 64 * np.finfo(np.float64).eps


def align_vectors(a, b, weights=None, *, check: bool = True):
    """The attitude that best turns the vectors ``b`` onto ``a``: scipy's ``Rotation.align_vectors(a, b, weights)``.

    Parameters
    ----------
    a : array_like, shape (..., m, 3) or (3,)
        Vectors in the reference frame (scipy's frame A).
    b : array_like, shape (..., m, 3) or (3,)
        The same vectors in the body frame (frame B); the same shape as ``a``.
    weights : array_like, shape (m,), optional
        Non-negative weights (default all 1); at most one may be ``inf``, making its pair a constraint met
        exactly.  Vector lengths weigh too (scipy's loss ``½ Σ w |a - C b|²``).
    check : bool
        Reject NaN, zero vectors, negative weights and more than one infinite weight (default).

    Returns
    -------
    q : numpy.ndarray, shape (..., 4)
        Unit quaternions, body to reference: ``a ≈ rotate(q, b)``.
    rssd : numpy.ndarray, shape (...)
        ``√(Σ w |a - C b|²)`` over the pairs of finite weight (scipy's "root sum squared distance").

    Examples
    --------
    >>> from strapdown.wahba import align_vectors
    >>> q, rssd = align_vectors([1.0, 0, 0], [0.0, 1, 0])      # one pair: the minimal rotation, -90° about z
    >>> q.round(12), float(rssd)
    (array([ 0.70710678,  0.        ,  0.        , -0.70710678]), 0.0)
    >>> q, _ = align_vectors([[1.0, 0, 0], [0, 1, 0]], [[0.0, 1, 0], [0, 1, 0]], weights=[np.inf, 1])
    >>> q.round(12)                                            # the secondary is parallel: primary only
    array([ 0.70710678,  0.        ,  0.        , -0.70710678])
    """
    from .decompose import shortest_arc
    from .quaternion import multiply, rotate
    from .rotvec import from_axis_angle
    from .wahba import davenport

    av = _v.vectors(a, "a", check=check)
    bv = _v.vectors(b, "b", check=check)
    if av.shape != bv.shape:
        raise ValueError(f"a and b must have the same shape, got {av.shape} and {bv.shape}")
    dtype = _v.result_dtype(av, bv)
    a2 = np.atleast_2d(av).astype(np.float64)
    b2 = np.atleast_2d(bv).astype(np.float64)
    m = a2.shape[-2]
    if weights is None:
        w = np.ones(m)
    else:
        w = _v.as_float_array(weights, "weights", dtype=np.float64)
        if w.shape != (m,):
            raise ValueError(f"weights must have shape ({m},), one per vector pair; got shape {w.shape}")
        if check and (np.isnan(w).any() or (w < 0).any()):
            raise ValueError(f"weights{_v.first_index(~(w >= 0))} is negative or NaN; weights must be ≥ 0")
    infinite = np.isposinf(w)
    if infinite.sum() > 1:
        raise ValueError(f"only one weight may be infinite; weights {np.flatnonzero(infinite).tolist()} are")
    if m == 1 or infinite.any():
        p = 0 if m == 1 else int(np.flatnonzero(infinite)[0])
        a_p, b_p = a2[..., p, :], b2[..., p, :]
        for vec, name in ((a_p, "a"), (b_p, "b")):
            if check and not (np.linalg.norm(vec, axis=-1) > 0).all():
                raise ValueError(f"the primary vector {name}[..., {p}, :] is zero; it has no direction to align")
        q = shortest_arc(b_p, a_p, check=False)
        if m > 1:
            others = np.arange(m) != p
            a_s, w_s = a2[..., others, :], w[others]
            c_s = rotate(q[..., None, :], b2[..., others, :], check=False)
            axis = a_p / np.linalg.norm(a_p, axis=-1, keepdims=True)
            along_c = np.einsum("...ni,...i->...n", c_s, axis)
            along_a = np.einsum("...ni,...i->...n", a_s, axis)
            sin = np.einsum("n,...n->...", w_s, np.einsum("...ni,...i->...n", np.cross(c_s, a_s), axis))
            cos = np.einsum("n,...n->...", w_s, np.einsum("...ni,...ni->...n", c_s, a_s) - along_c * along_a)
            scale = np.einsum("n,...n->...", w_s, np.linalg.norm(c_s, axis=-1) * np.linalg.norm(a_s, axis=-1))
            phi = np.where(np.hypot(sin, cos) > _PARALLEL * scale, np.arctan2(sin, cos), 0.0)
            q = multiply(from_axis_angle(axis, phi, check=False), q, check=False)
    else:
        q = davenport(b2, a2, w, normalize=False, check=check)
    finite = np.where(infinite, 0.0, w)  # the primary pair is met exactly: it adds nothing (not inf · 0)
    residual = a2 - rotate(q[..., None, :], b2, check=False)
    rssd = np.sqrt(np.einsum("n,...n->...", finite, np.einsum("...ni,...ni->...n", residual, residual)))
    shape = av.shape[:-2] if av.ndim >= 2 else ()
    return q.reshape((*shape, 4)).astype(dtype, copy=False), rssd.reshape(shape).astype(dtype, copy=False)
