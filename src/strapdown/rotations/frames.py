"""Reference frames (NED, ENU, NWU, ...) and body axes (FRD, FLU, RFU, ...): re-expressing attitudes and vectors.

A frame is named by three letters, the directions of its x, y and z axes:

* reference frames use N, E, S, W, U (up) and D (down): ``"NED"`` (aviation), ``"ENU"`` (robotics, Liu et al.),
  ``"NWU"`` (imufusion's default);
* body axes use F (forward), B (back), R (right), L (left), U and D: ``"FRD"`` (aviation), ``"FLU"`` (ROS),
  ``"RFU"`` (Liu et al.: right-forward-up).

Any right-handed combination is accepted.  A body frame is tied to the reference frames by the usual zero
attitude: level, nose (F) to the North, right (R) to the East.  So the identity attitude in (NED, FRD) is the
identity in (ENU, RFU) and in (NWU, FLU).

An attitude q maps body to reference; re-expressed it is
``q' = q(ref_from → ref_to) ⊗ q ⊗ q(body_to → body_from)`` (:func:`change_frame`).
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["change_frame", "frame_matrix", "frame_quaternion"]

# Directions in a working basis x = North/Forward, y = East/Right, z = Down.
_REFERENCE = {
    "N": (1, 0, 0),
    "S": (-1, 0, 0),
    "E": (0, 1, 0),
    "W": (0, -1, 0),
    "D": (0, 0, 1),
    "U": (0, 0, -1),
}
_BODY = {"F": (1, 0, 0), "B": (-1, 0, 0), "R": (0, 1, 0), "L": (0, -1, 0), "D": (0, 0, 1), "U": (0, 0, -1)}


def _axes(frame: str, name: str) -> tuple[str, np.ndarray]:
    """(kind, rows) of a frame name: kind 'reference' or 'body'; rows are its axes in the working basis."""
    if not isinstance(frame, str) or len(frame) != 3:
        raise ValueError(f"{name} must be three axis letters such as 'NED', 'ENU' or 'FRD'; got {frame!r}")
    letters = frame.upper()
    if set(letters) <= set(_REFERENCE) and set(letters) & set("NESW"):
        kind, table = "reference", _REFERENCE
    elif set(letters) <= set(_BODY) and set(letters) & set("FBRL"):
        kind, table = "body", _BODY
    else:
        raise ValueError(
            f"{name}={frame!r} mixes or misuses axis letters: reference frames use N, E, S, W, U, D and "
            "body frames use F, B, R, L, U, D"
        )
    rows = np.array([table[c] for c in letters], dtype=np.float64)
    det = np.linalg.det(rows)
    if not det > 0.5:
        problem = "repeats a direction" if abs(det) < 0.5 else "is left-handed"
        raise ValueError(f"{name}={frame!r} {problem}; a frame needs three right-handed axes")
    return kind, rows


def check_frame(frame, name: str, kind: str | None = None) -> str:
    """Validate a frame name given as argument ``name`` (of ``kind`` "reference" or "body" when given).

    The errors name the caller's argument, not ``src``/``dst`` of :func:`frame_matrix`.
    """
    got, _ = _axes(frame, name)
    if kind is not None and got != kind:
        raise ValueError(
            f"{name}={frame!r} is a {got} frame; {name} must be a {kind} frame "
            f"({'N, E, S, W, U, D, e.g. NED or ENU' if kind == 'reference' else 'F, B, R, L, U, D, e.g. FRD or FLU'})"
        )
    return frame


def frame_matrix(src: str, dst: str) -> np.ndarray:
    """Matrix M with ``v_dst = M @ v_src``: the coordinates of a vector in frame ``dst`` from those in ``src``.

    Parameters
    ----------
    src, dst : str
        Two reference frames (``"NED"``, ``"ENU"``, ...) or two body frames (``"FRD"``, ``"FLU"``, ...).

    Returns
    -------
    numpy.ndarray, shape (3, 3)
        A signed permutation matrix with determinant +1.

    Examples
    --------
    >>> from strapdown import frame_matrix
    >>> frame_matrix("NED", "ENU") @ [1.0, 2.0, 3.0]     # 1 north, 2 east, 3 down
    array([ 2.,  1., -3.])
    """
    kind_src, a_src = _axes(src, "src")
    kind_dst, a_dst = _axes(dst, "dst")
    if kind_src != kind_dst:
        raise ValueError(
            f"src={src!r} is a {kind_src} frame and dst={dst!r} a {kind_dst} frame; convert between frames of "
            "the same kind (use change_frame to re-express an attitude)"
        )
    return a_dst @ a_src.T


def frame_quaternion(src: str, dst: str) -> np.ndarray:
    """Unit quaternion of :func:`frame_matrix`, so that ``rotate(frame_quaternion(src, dst), v_src) = v_dst``.

    Parameters
    ----------
    src, dst : str
        Two reference frames or two body frames.

    Returns
    -------
    numpy.ndarray, shape (4,)
        Canonical unit quaternion.

    Examples
    --------
    >>> from strapdown import frame_quaternion
    >>> frame_quaternion("ENU", "NED")
    array([0.        , 0.70710678, 0.70710678, 0.        ])
    """
    return _permutation_quaternion(frame_matrix(src, dst))


def _permutation_quaternion(m: np.ndarray) -> np.ndarray:
    """The canonical unit quaternion of a rotation matrix, in closed form (Shepperd's method), in plain numpy.

    Frame rotations are constants that every estimator builds when it is created: the numba kernel of
    ``from_matrix`` would cost a cache load (a quarter of a second for a short command-line call) for one matrix.
    Shepperd (1978) divides by the largest of 4w², 4x², 4y², 4z² (here at least 1 for any signed permutation),
    so the result is exact to rounding; the sign follows :func:`strapdown.rotations.quaternion.canonical`.
    """
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    squares = [1.0 + tr, 1.0 + 2.0 * m[0, 0] - tr, 1.0 + 2.0 * m[1, 1] - tr, 1.0 + 2.0 * m[2, 2] - tr]  # 4w², 4x²...
    k = int(np.argmax(squares))
    r = np.sqrt(squares[k])  # 2 |q_k|
    if k == 0:
        q = [r, (m[2, 1] - m[1, 2]) / r, (m[0, 2] - m[2, 0]) / r, (m[1, 0] - m[0, 1]) / r]
    elif k == 1:
        q = [(m[2, 1] - m[1, 2]) / r, r, (m[0, 1] + m[1, 0]) / r, (m[0, 2] + m[2, 0]) / r]
    elif k == 2:
        q = [(m[0, 2] - m[2, 0]) / r, (m[0, 1] + m[1, 0]) / r, r, (m[1, 2] + m[2, 1]) / r]
    else:
        q = [(m[1, 0] - m[0, 1]) / r, (m[0, 2] + m[2, 0]) / r, (m[1, 2] + m[2, 1]) / r, r]
    q = np.array(q) / 2.0
    nonzero = q[np.abs(q) > 1e-12]
    # the first non-zero component positive: canonical()'s rule (w > 0, on a tie x > 0, ...)
    return (-q if nonzero[0] < 0 else q) + 0.0


def change_frame(
    q,
    *,
    ref_from: str | None = None,
    ref_to: str | None = None,
    body_from: str | None = None,
    body_to: str | None = None,
    check: bool = True,
) -> np.ndarray:
    """Re-express attitude quaternions in other reference and/or body axes.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Attitudes mapping ``body_from`` axes to ``ref_from`` axes.
    ref_from, ref_to : str, optional
        Reference frames before and after (both or neither).
    body_from, body_to : str, optional
        Body axes before and after (both or neither).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``q(ref_from → ref_to) ⊗ q ⊗ q(body_to → body_from)``: the same physical attitude, mapping ``body_to``
        axes to ``ref_to`` axes.

    Examples
    --------
    >>> from strapdown import as_euler, change_frame, from_euler
    >>> q_ned = from_euler([30.0, 10.0, 5.0], "ZYX", degrees=True)    # yaw 30 deg east of north
    >>> q_enu = change_frame(q_ned, ref_from="NED", ref_to="ENU", body_from="FRD", body_to="RFU")
    >>> as_euler(q_enu, "ZXY", degrees=True).round(9)   # Liu: heading counter-clockwise, pitch, roll
    array([-30.,  10.,   5.])
    """
    from .quaternion import multiply

    q = _v.quaternions(q, "q", check=check)
    out = q
    if (ref_from is None) != (ref_to is None):
        raise ValueError("give both ref_from and ref_to, or neither")
    if (body_from is None) != (body_to is None):
        raise ValueError("give both body_from and body_to, or neither")
    # checked here first, so that an error names the argument (frame_quaternion would call it src or dst)
    if ref_from is not None:
        check_frame(ref_from, "ref_from", "reference")
        check_frame(ref_to, "ref_to", "reference")
        out = multiply(frame_quaternion(ref_from, ref_to).astype(q.dtype), out, check=False)
    if body_from is not None:
        check_frame(body_from, "body_from", "body")
        check_frame(body_to, "body_to", "body")
        out = multiply(out, frame_quaternion(body_to, body_from).astype(q.dtype), check=False)
    return out
