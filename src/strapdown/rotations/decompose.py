"""Splitting rotations: swing-twist, the shortest arc between two vectors, and the attitude error for control.

* :func:`swing_twist` (math.md §4.2, nabbla part 16): a rotation as a twist about a given axis and a swing about an
  axis perpendicular to it.
* :func:`shortest_arc` (nabbla part 6): the smallest rotation that turns one vector onto another.
* :func:`attitude_error`: the error rotation between an attitude and its set point, with the sign chosen so that
  a controller never turns the long way round (the unwinding problem).

All functions accept non-unit quaternions (they use the rotation of ``q / |q|``) and return unit quaternions; every
function broadcasts over leading axes and keeps float32 as float32.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from .quaternion import _norm3, canonical, conjugate, multiply
from .rotvec import as_rotvec

__all__ = ["attitude_error", "shortest_arc", "swing_twist"]


def _unit_quaternions(q: np.ndarray) -> np.ndarray:
    return q / np.sqrt(np.einsum("...i,...i->...", q, q))[..., None]


def _broadcast(*named: tuple[str, np.ndarray]) -> tuple[int, ...]:
    """Common leading shape of several (..., k) arrays, or a ValueError naming them."""
    try:
        return np.broadcast_shapes(*(arr.shape[:-1] for _, arr in named))
    except ValueError:
        shapes = ", ".join(f"{name} {arr.shape}" for name, arr in named)
        raise ValueError(f"the leading axes of {shapes} do not broadcast") from None


def _unit_vectors(v, name: str, check: bool) -> np.ndarray:
    """Validated non-zero 3-vectors scaled to unit length (by their largest component first, so tiny vectors work)."""
    v = _v.vectors(v, name, check=check)
    big = np.max(np.abs(v), axis=-1)
    if check and not (big > 0).all():
        raise ValueError(f"{name}{_v.first_index(~(big > 0))} is a zero vector; it has no direction")
    with np.errstate(invalid="ignore", divide="ignore"):
        scaled = v / big[..., None]
        return scaled / _norm3(scaled)[..., None]


def swing_twist(q, axis, *, frame: str = "body", check: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Split attitudes into a twist about ``axis`` and a swing about an axis perpendicular to it.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero attitude quaternions (body to reference).
    axis : array_like, shape (..., 3)
        The twist axis n (any non-zero length).
    frame : {"body", "reference"}
        Frame in which ``axis`` is given, which also fixes the order of the factors.  ``"body"`` (default):
        ``q = swing ⊗ twist``, the twist turns the body about its own axis n first (for n = forward, the roll
        about the nose), then the swing tilts n to where it points.  ``"reference"``: ``q = twist ⊗ swing``, the
        swing comes first and the twist turns about the reference axis n last (for n = the vertical, the twist is
        the heading and the swing the tilt, as in Rowe's tilt quaternion, math.md §5).
    check : bool
        Reject NaN, infinities, zero quaternions and zero axes (default).

    Returns
    -------
    swing : numpy.ndarray, shape (..., 4)
        Unit quaternions of rotations about axes perpendicular to n.
    twist : numpy.ndarray, shape (..., 4)
        Unit quaternions of rotations about n, ``normalize(w, (v·n) n)`` with q = (w, v) normalised.  The
        product (in the order above) is ``q / |q|`` itself, sign included.

    Notes
    -----
    math.md §4.2: with ``q = (w, v)`` and unit n, ``twist = (w, (v·n) n) / √(w² + (v·n)²)`` and
    ``swing = q ⊗ twist*`` (``twist* ⊗ q`` for ``frame="reference"``; the twist is the same quaternion in both
    cases).  The swing's vector part is perpendicular to n.  With ``frame="body"`` the swing is the shortest arc
    taking n to ``rotate(q, n)``.  Degenerate case: where ``w = 0`` and ``v·n = 0`` (q is a 180° rotation about an
    axis perpendicular to n) the twist is undefined; the identity twist is returned and the swing is q.  Near that
    case the split is ill-conditioned, as it must be.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_euler
    >>> from strapdown.rotations.decompose import swing_twist
    >>> q = from_euler([0.0, 30.0, 40.0], "ZYX", degrees=True)     # pitch 30 deg, then roll 40 deg
    >>> swing, twist = swing_twist(q, [1.0, 0.0, 0.0])              # twist about the body x axis: the roll
    >>> twist.round(8)
    array([0.93969262, 0.34202014, 0.        , 0.        ])
    >>> swing.round(8)
    array([0.96592583, 0.        , 0.25881905, 0.        ])
    """
    _v.choice(frame, "frame", ("body", "reference"))
    qv = _v.rotations(q, "q", check=check)
    n = _unit_vectors(axis, "axis", check)
    dtype = _v.result_dtype(qv, _v.vectors(axis, "axis", check=False))
    lead = _broadcast(("q", qv), ("axis", n))
    q1 = np.broadcast_to(_unit_quaternions(qv.astype(np.float64, copy=False)), (*lead, 4))
    n = np.broadcast_to(n.astype(np.float64, copy=False), (*lead, 3))
    w = q1[..., 0]
    p = np.einsum("...i,...i->...", q1[..., 1:], n)
    length = np.hypot(w, p)
    undefined = length == 0
    with np.errstate(invalid="ignore", divide="ignore"):
        tw = np.where(undefined, 1.0, w / length)
        tp = np.where(undefined, 0.0, p / length)
    twist = np.empty(q1.shape)
    twist[..., 0] = tw
    twist[..., 1:] = tp[..., None] * n
    if frame == "body":
        swing = multiply(q1, conjugate(twist, check=False), check=False)
    else:
        swing = multiply(conjugate(twist, check=False), q1, check=False)
    return swing.astype(dtype, copy=False), twist.astype(dtype, copy=False)


def shortest_arc(u, v, *, check: bool = True) -> np.ndarray:
    """Unit quaternion of the smallest rotation that turns the direction of ``u`` onto that of ``v``.

    Parameters
    ----------
    u, v : array_like, shape (..., 3)
        Non-zero vectors (only their directions matter).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        q with ``rotate(q, û) = v̂``, of angle ``θ = atan2(|û × v̂|, û·v̂)`` in [0, π] about the axis
        ``û × v̂ / |û × v̂|`` (perpendicular to both), w ≥ 0.  If u is a body vector and v its direction in the
        reference frame, q is the attitude with the least rotation that explains the observation (for instance
        the tilt from an accelerometer, with no heading).

    Notes
    -----
    The angle comes from atan2 and the axis from the normalised cross product, made exactly perpendicular to u,
    which keeps full accuracy near 0° and near 180°, unlike ``normalize(1 + û·v̂, û × v̂)``, whose scalar part
    cancels near 180°.  Any rotation
    of 180° about an axis perpendicular to u turns u onto -u; the axis is then chosen as ``û × e_k``, normalised,
    with e_k the coordinate axis least aligned with u (ties: the first).  For exactly parallel vectors the result
    is the identity.  The result is never NaN.

    Examples
    --------
    >>> from strapdown.rotations.decompose import shortest_arc
    >>> shortest_arc([1.0, 0, 0], [0, 2.0, 0])        # 90 deg about z
    array([0.70710678, 0.        , 0.        , 0.70710678])
    >>> shortest_arc([1.0, 0, 0], [-1.0, 0, 0])       # 180 deg about an axis perpendicular to x
    array([0., 0., 0., 1.])
    """
    uv = _v.vectors(u, "u", check=False)
    vv = _v.vectors(v, "v", check=False)
    dtype = _v.result_dtype(uv, vv)
    a = _unit_vectors(u, "u", check).astype(np.float64, copy=False)
    b = _unit_vectors(v, "v", check).astype(np.float64, copy=False)
    lead = _broadcast(("u", a), ("v", b))
    a = np.broadcast_to(a, (*lead, 3))
    b = np.broadcast_to(b, (*lead, 3))
    c = np.cross(a, b)
    s = _norm3(c)
    d = np.einsum("...i,...i->...", a, b)
    half = 0.5 * np.arctan2(s, d)
    big = np.max(np.abs(c), axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        axis = c / big[..., None]
        # Near 180° the rounding of û × v̂ (of order ε against a length of order θ - π) tilts the axis out of the
        # plane perpendicular to u, and a half turn about a tilted axis misses -u.  Projecting it back keeps
        # rotate(q, û) = v̂ to rounding for every angle.
        axis = axis - np.einsum("...i,...i->...", axis, a)[..., None] * a
        axis = axis / _norm3(axis)[..., None]
    flat = ~(big > 0)
    if flat.any():
        # parallel (half = 0: any axis) or antiparallel (half = π/2): a unit axis perpendicular to u
        least = np.argmin(np.abs(a[flat]), axis=-1)
        e = np.zeros_like(a[flat])
        e[np.arange(len(least)), least] = 1.0
        perp = np.cross(a[flat], e)
        axis[flat] = perp / _norm3(perp)[..., None]
    out = np.empty((*a.shape[:-1], 4))
    out[..., 0] = np.cos(half)
    out[..., 1:] = np.sin(half)[..., None] * axis
    return out.astype(dtype, copy=False)


def attitude_error(q, q_ref, *, frame: str = "body", rotvec: bool = False, check: bool = True) -> np.ndarray:
    """Attitude error for a controller, with the sign chosen so that the error angle is in [0, π].

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Actual attitudes (body to reference), non-zero.
    q_ref : array_like, shape (..., 4)
        Desired attitudes (the set points), non-zero.
    frame : {"body", "reference"}
        ``"body"`` (default): ``e = q_ref* ⊗ q``, so ``q = q_ref ⊗ e``: the rotation from the desired to the
        actual attitude, expressed in the desired body axes (what a body-rate or torque loop feeds back).
        ``"reference"``: ``e = q ⊗ q_ref*``, so ``q = e ⊗ q_ref``: the same rotation in reference axes.
    rotvec : bool
        Return the error as a rotation vector (angle in [0, π] times unit axis, rad) instead of a quaternion.

    Returns
    -------
    numpy.ndarray, shape (..., 4) or (..., 3)
        Unit error quaternions with w ≥ 0 (canonical sign, :func:`strapdown.rotations.quaternion.canonical`), or
        rotation vectors.  Identical for ``±q`` and ``±q_ref``.

    Notes
    -----
    q and -q are the same attitude, and an integrated or filtered quaternion drifts between the two hemispheres.
    A feedback ``u = -k vec(q_ref* ⊗ q)`` taken as it comes then drives the body towards ``-q_ref`` half of the
    time: the long way round, up to a full turn for an error near zero (the unwinding problem, which
    motivates sign-free representations such as Liu et al.'s compressed quaternion, math.md §3).  Taking
    ``w ≥ 0`` makes the error the shorter rotation, of angle ``2 atan2(|v|, w)`` in [0, π], and
    ``-k vec(e)`` a torque towards the set point along the shorter way.  At exactly 180° both ways are equally
    short and the canonical rule picks one; a controller that must not chatter there needs hysteresis (Mayhew,
    Sanfelice and Teel, IEEE TAC 56(11), 2011), which is beyond a memoryless function.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.rotations.decompose import attitude_error
    >>> q_ref = [1.0, 0, 0, 0]
    >>> q = -np.array([np.cos(0.05), 0, 0, np.sin(0.05)])      # 0.1 rad about z, in the other hemisphere
    >>> attitude_error(q, q_ref)
    array([0.99875026, 0.        , 0.        , 0.04997917])
    >>> attitude_error(q, q_ref, rotvec=True)
    array([0. , 0. , 0.1])
    """
    _v.choice(frame, "frame", ("body", "reference"))
    qv = _v.rotations(q, "q", check=check)
    rv = _v.rotations(q_ref, "q_ref", check=check)
    dtype = _v.result_dtype(qv, rv)
    _broadcast(("q", qv), ("q_ref", rv))
    q1 = _unit_quaternions(qv.astype(np.float64, copy=False))
    r1 = _unit_quaternions(rv.astype(np.float64, copy=False))
    if frame == "body":
        e = multiply(conjugate(r1, check=False), q1, check=False)
    else:
        e = multiply(q1, conjugate(r1, check=False), check=False)
    e = canonical(e, check=False)
    if rotvec:
        return as_rotvec(e, check=False).astype(dtype, copy=False)
    return e.astype(dtype, copy=False)
