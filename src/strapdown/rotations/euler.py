"""Euler angles: all 12 axis sequences, intrinsic and extrinsic, exact at gimbal lock.

Sequences are named as in scipy: three axis letters, **upper case for intrinsic** rotations (about the axes of
the rotating body, e.g. ``"ZYX"`` = yaw, pitch, roll) and **lower case for extrinsic** rotations (about the fixed
reference axes, e.g. ``"xyz"``).  ``from_euler("ZYX", [ψ, θ, φ])`` is
``q = e_z(ψ) ⊗ e_y(θ) ⊗ e_x(φ)``, Gajda (2.15)-(2.16), and ``from_euler("xyz", [φ, θ, ψ])`` is the same
rotation.

Ranges of :func:`as_euler`
--------------------------
* first and third angle in (-π, π]; Tait-Bryan middle angle (three different axes) in [-π/2, π/2]; proper
  Euler middle angle (first axis = third axis) in [0, π];
* ``yaw_range="positive"`` maps the *outer* angle, the one about a reference-frame axis (the first angle of an
  intrinsic sequence, the third of an extrinsic one), into [0, 2π).  For ``"ZYX"`` this gives Gajda's ranges
  (1.1): yaw in [0°, 360°), pitch in [-90°, 90°], roll in (-180°, 180°].

Gimbal lock
-----------
When the middle angle is exactly at its limit (±90° for Tait-Bryan, 0° or 180° for proper sequences) only the
sum or the difference of the outer angles is defined.  :func:`as_euler` then returns the **third angle as 0** and
lets the first carry the whole rotation (for ``"ZYX"`` at pitch +90°: roll = 0, yaw = ψ - φ).  The test is made
on the number you receive (after degree conversion and float32 rounding) and nowhere else: there is no snapping
threshold, so a middle angle 1e-12 away from the limit keeps both outer angles, and the rotation rebuilt from
the angles is correct to a few ulp everywhere.  The result is never NaN.

A quaternion made from a middle angle of exactly ±90° is in general not exactly at the lock once rounded
(``cos(π/4)`` and ``sin(π/4)`` differ in the last bit): its middle angle then comes back an ulp inside the limit
with both outer angles, and only their defined sum or difference is meaningful.  That is the faithful answer for
the numbers given, and the rotation is the same to a few ulp either way.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["as_euler", "from_euler"]

_AXIS = {"x": 0, "y": 1, "z": 2}
_UNCOMPILED_S_PER_ROW = 2e-5  # the kernels run uncompiled, a first call's (_support/uncompiled.py)


def _parse_seq(seq) -> tuple[bool, tuple[int, int, int]]:
    """(intrinsic, axis indices) of a 3-letter sequence, or a ValueError naming `seq`."""
    if not isinstance(seq, str) or len(seq) != 3:
        raise ValueError(f"seq must be a string of three axis letters such as 'ZYX' or 'xyz'; got {seq!r}")
    if seq.isupper():
        intrinsic = True
    elif seq.islower():
        intrinsic = False
    else:
        raise ValueError(
            f"seq {seq!r} mixes upper and lower case: use upper case for intrinsic rotations ('ZYX') and "
            "lower case for extrinsic ones ('zyx')"
        )
    low = seq.lower()
    if any(c not in _AXIS for c in low):
        raise ValueError(f"seq must use only the axes x, y and z; got {seq!r}")
    if low[0] == low[1] or low[1] == low[2]:
        raise ValueError(f"seq {seq!r} repeats an axis in consecutive places; that is not an Euler sequence")
    return intrinsic, (_AXIS[low[0]], _AXIS[low[1]], _AXIS[low[2]])


def _kernel_args(seq: str, degrees: bool) -> tuple:
    """The arguments ``as_euler_rows`` takes for a sequence and unit (also those of the file writer's kernel).

    Returns (i, j, k, proper, sign, intrinsic, scale, half, full): the extrinsic axes (k the remaining one for a
    proper sequence), the parity sign of (i, j, k), the unit scale, and 180° and 360° (or π and 2π) in float64.
    """
    intrinsic, axes = _parse_seq(seq)
    i, j, k = axes[::-1] if intrinsic else axes
    proper = i == k
    if proper:
        k = 3 - i - j
    sign = 1.0 if (j - i) % 3 == 1 else -1.0  # parity of the permutation (i, j, k)
    scale = 180.0 / np.pi if degrees else 1.0
    full = 360.0 if degrees else 2 * np.pi
    half = 180.0 if degrees else np.pi
    return i, j, k, proper, sign, intrinsic, scale, half, full


def from_euler(angles, seq: str = "ZYX", degrees: bool = False, *, check: bool = True) -> np.ndarray:
    """Attitude quaternions from Euler angles.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        The three angles in the order of ``seq`` (for ``"ZYX"``: yaw ψ, pitch θ, roll φ).  Any real values are
        accepted; they need not lie in the output ranges of :func:`as_euler`.  For a sequence of one or two
        axes, shape (..., 1) or (..., 2), and a single number for one axis (as scipy).
    seq : str
        Axis sequence: ``"ZYX"``, ``"ZXY"``, ``"ZXZ"``, ... (intrinsic) or ``"xyz"``, ... (extrinsic); also
        one or two axes (``"z"``, ``"ZY"``), see :mod:`strapdown.rotations.davenport`.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions ``[w, x, y, z]`` (body to reference), the plain product of the three elementary
        rotations (not sign-normalised; see :func:`strapdown.rotations.quaternion.canonical`).

    Notes
    -----
    For ``"ZYX"`` this is Gajda's initial quaternion (2.16), ``t = q(Ψ, z) ⊗ r(Θ, y) ⊗ s(Φ, x)``; for
    ``"ZXY"`` it is Liu et al.'s (15).

    Examples
    --------
    >>> from strapdown import from_euler
    >>> from_euler([90.0, 0.0, 0.0], "ZYX", degrees=True)     # yaw 90 deg
    array([0.70710678, 0.        , 0.        , 0.70710678])
    >>> from_euler([[0, 0, 30], [0, 30, 0]], "ZYX", degrees=True).round(6)   # roll 30, pitch 30
    array([[0.965926, 0.258819, 0.      , 0.      ],
           [0.965926, 0.      , 0.258819, 0.      ]])
    """
    if isinstance(seq, str) and len(seq) in (1, 2):  # scipy's one- and two-axis sequences
        from .davenport import from_short_euler

        return from_short_euler(angles, seq, degrees, check)
    intrinsic, axes = _parse_seq(seq)
    angles = _v.finite(angles, "angles", check=check)
    _v.check_last_axis(angles, "angles", 3, f"one angle per axis of {seq!r}")
    if degrees:
        angles = np.deg2rad(angles)
    shape = angles.shape[:-1]
    rows = np.ascontiguousarray(angles.reshape(-1, 3))
    if intrinsic:
        order_axes, order_cols = axes, (0, 1, 2)
    else:  # extrinsic: q = e_3(γ) ⊗ e_2(β) ⊗ e_1(α)
        order_axes, order_cols = axes[::-1], (2, 1, 0)
    out = np.empty((rows.shape[0], 4), dtype=angles.dtype)
    from .._support.uncompiled import call
    from ._euler_numba import from_euler_rows

    args = (rows, np.array(order_axes, dtype=np.int64), np.array(order_cols, dtype=np.int64), out)
    call(from_euler_rows, *args, python_seconds=_UNCOMPILED_S_PER_ROW * rows.shape[0])
    return out.reshape((*shape, 4))


def as_euler(
    q,
    seq: str = "ZYX",
    degrees: bool = False,
    yaw_range: str = "signed",
    *,
    check: bool = True,
) -> np.ndarray:
    """Euler angles of attitude quaternions, exact and NaN-free everywhere (see the module notes).

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions ``[w, x, y, z]`` (body to reference); they need not be normalised, and ``q`` and
        ``-q`` give identical angles.
    seq : str
        Axis sequence, upper case intrinsic (``"ZYX"``), lower case extrinsic (``"xyz"``).
    yaw_range : {"signed", "positive"}
        Range of the outer angle (about a reference axis): (-π, π] or, as Gajda (1.1), [0, 2π).

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Angles in the order of ``seq``.

    Notes
    -----
    The direct half-angle method (math.md §3.2, after Bernardes & Viollet 2022) reads each pair of outer
    angles from two complex numbers made of quaternion components; it never takes ``asin`` of a matrix
    element nor Gajda's stage-4 half-angle ``arctan``, whose special case at 180° this removes.

    Examples
    --------
    >>> from strapdown import as_euler, from_euler
    >>> q = from_euler([30.0, 20.0, 10.0], "ZYX", degrees=True)
    >>> as_euler(q, "ZYX", degrees=True).round(9)
    array([30., 20., 10.])
    >>> as_euler(from_euler([-30.0, 90.0, 10.0], "ZYX", degrees=True), degrees=True,
    ...          yaw_range="positive").round(9)    # vertical: roll 0, yaw carries yaw - roll
    array([320.,  90.,   0.])
    """
    _v.choice(yaw_range, "yaw_range", ("signed", "positive"))
    i, j, k, proper, sign, intrinsic, scale, half, full = _kernel_args(seq, degrees)
    q = _v.rotations(q, "q", check=check)
    shape = q.shape[:-1]
    rows = np.ascontiguousarray(q.reshape(-1, 4))
    out = np.empty((rows.shape[0], 3), dtype=q.dtype)
    from .._support.uncompiled import call
    from ._euler_numba import as_euler_rows

    full, half = float(out.dtype.type(full)), float(out.dtype.type(half))  # 2π and π as the output holds them
    # the kernel also folds -180° (from the rounding to degrees or float32) to +180°, in the output's type
    args = (rows, i, j, k, proper, sign, intrinsic, scale, q.dtype == np.float32, half, full, out)
    call(as_euler_rows, *args, python_seconds=_UNCOMPILED_S_PER_ROW * rows.shape[0])
    if yaw_range == "positive":
        angle = out[:, 0 if intrinsic else 2]
        angle[angle < 0] += full
        angle[angle >= full] -= full  # -1e-17 + 2π rounds to 2π, which is not in [0, 2π)
    return out.reshape((*shape, 3))
