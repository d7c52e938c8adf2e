"""The attitude columns of output tables, and the representations as table columns.

Each representation of :data:`REPRESENTATIONS` is a fixed number of real columns, converted by the library's
``from_*`` / ``as_*`` functions: ``quat`` (qw, qx, qy, qz), ``euler`` (any of the 24 sequences; yaw, pitch and
roll for ``"ZYX"``), ``matrix`` (c11 ... c33, row by row), ``rotvec``, ``axis_angle`` (axis and angle), ``gibbs``
(Gajda's or Rodrigues'), ``cayley_klein`` (real and imaginary parts of u11, u12, u21, u22) and ``compressed``
(Liu et al.'s unique angles).  Angles are in degrees or radians, and the names say which (``yaw_deg``).

:func:`attitude_columns` builds the output table of the ``integrate`` and ``estimate`` commands: time,
quaternion, Euler angles in the chosen sequence and range, and the bias and flags of an estimator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._support import validate as _v
from ..rotations.euler import _kernel_args
from ..rotations.values import REPRESENTATIONS, Angles, column_names, from_values, to_values

__all__ = [
    "FLAG_COLUMNS",
    "REPRESENTATIONS",
    "Angles",
    "OutputSpec",
    "attitude_columns",
    "column_names",
    "flag_bits",
    "from_values",
    "to_values",
]


@dataclass(frozen=True)
class OutputSpec:
    """What the ``integrate`` and ``estimate`` commands write besides time and quaternion.

    Attributes
    ----------
    euler : bool
        Write Euler angles (sequence, unit and range from ``angles``).
    angles : Angles
        How angles are written; the bias follows ``angles.degrees`` (deg/s or rad/s).
    bias, flags : bool
        Write the estimator's gyro bias and flags when it has them.
    format : str, optional
        ``"csv"``, ``"parquet"``, ``"hdf5"`` or ``"mat"``; by default from the output's suffix.
    float32 : bool
        Write quaternions, angles and bias as float32 (half the bytes; each value is the float64 result rounded
        to the nearest float32, a relative error of at most 6e-8).  The time stays float64: float32 would round
        a time of 10^5 s to 8 ms.
    """

    euler: bool = True
    angles: Angles = Angles()
    bias: bool = True
    flags: bool = True
    format: str | None = None
    float32: bool = False


#: The named boolean columns written beside ``flags``: column name -> name of its bit in :mod:`strapdown.fusion`.
FLAG_COLUMNS = {
    "rest": "FLAG_REST",
    "acc_rejected": "FLAG_ACC_REJECTED",
    "mag_rejected": "FLAG_MAG_REJECTED",
    "inverted": "FLAG_INVERTED",
    "bias_at_limit": "FLAG_BIAS_AT_LIMIT",
    "saturated": "FLAG_SATURATED",
}
# The bias-at-limit bit when the estimators do not define one: the next free bit after FLAG_INVERTED (8).
_BIAS_AT_LIMIT = 16


def flag_bits() -> dict[str, int]:
    """The bit of each named flag column (:data:`FLAG_COLUMNS`), as the estimators define them.

    Returns
    -------
    dict of str to int
        Column name -> bit value in the ``flags`` bit mask.

    Examples
    --------
    >>> from strapdown.io.tables import flag_bits
    >>> flag_bits()
    {'rest': 1, 'acc_rejected': 2, 'mag_rejected': 4, 'inverted': 8, 'bias_at_limit': 16, 'saturated': 32}
    """
    from .. import fusion

    return {name: int(getattr(fusion, bit, _BIAS_AT_LIMIT)) for name, bit in FLAG_COLUMNS.items()}


def attitude_columns(
    t, q, spec: OutputSpec = OutputSpec(), bias=None, flags=None, bias_at_limit=None, *, check: bool = True
) -> dict:
    """The output table of attitudes: ``t``, ``qw..qz``, Euler angles, ``bias_*``, ``flags`` and one column per flag.

    Parameters
    ----------
    t : numpy.ndarray, shape (N,)
        Times, s.
    q : numpy.ndarray, shape (N, 4)
        Attitudes.
    spec : OutputSpec
        Which columns.
    bias : numpy.ndarray of shape (N, 3), optional
        Gyro bias, rad/s.
    flags : numpy.ndarray of shape (N,), optional
        Estimator flags: a bit mask of the bits of :func:`flag_bits`.  Written as the integer ``flags`` and as one
        boolean column per bit (``rest``, ``acc_rejected``, ``mag_rejected``, ``inverted``, ``bias_at_limit``).
    bias_at_limit : numpy.ndarray of bool, shape (N,), optional
        Rows whose bias sits at the estimator's ``bias_limit`` on some axis, when the estimator does not flag it
        itself: its bit is set in ``flags``.
    check : bool
        Validate ``q`` before the Euler angles (default); False for the library's own unit quaternions.

    Returns
    -------
    dict of str to numpy.ndarray
        Columns in order: each a new contiguous array that shares memory with no argument (a writer may keep
        it without a copy).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.tables import attitude_columns
    >>> cols = attitude_columns(np.array([0.0]), np.array([[1.0, 0.0, 0.0, 0.0]]))
    >>> list(cols)
    ['t', 'qw', 'qx', 'qy', 'qz', 'yaw_deg', 'pitch_deg', 'roll_deg']
    >>> cols = attitude_columns([0.0, 0.1], np.eye(4)[[0, 0]], flags=np.array([0, 5]))
    >>> list(cols)[-7:]
    ['flags', 'rest', 'acc_rejected', 'mag_rejected', 'inverted', 'bias_at_limit', 'saturated']
    >>> cols["rest"], cols["acc_rejected"], cols["mag_rejected"]
    (array([False,  True]), array([False, False]), array([False,  True]))
    """
    return _attitude_columns(t, q, spec, bias, flags, bias_at_limit, check=check)


def _attitude_columns(t, q, spec, bias=None, flags=None, bias_at_limit=None, *, check=True, t0=0.0):
    """:func:`attitude_columns` of the times ``t - t0`` (the file pipelines' relative time, without a second copy)."""
    dtype = np.float32 if spec.float32 else np.float64
    cols = {"t": np.subtract(np.asarray(t, dtype=np.float64), t0)}
    names = column_names("quat") + (column_names("euler", spec.angles) if spec.euler else [])
    cols.update(zip(names, _attitude_block(q, spec, check, dtype), strict=True))
    if spec.bias and bias is not None:
        unit = "deg_s" if spec.angles.degrees else "rad_s"
        b = np.degrees(bias) if spec.angles.degrees else np.asarray(bias, dtype=np.float64)
        cols.update(zip([f"bias_{a}_{unit}" for a in "xyz"], _columns(b, dtype), strict=True))
    if spec.flags and flags is not None:
        bits = flag_bits()
        f = np.array(flags, dtype=np.uint8)
        if bias_at_limit is not None:
            f = f | np.where(bias_at_limit, bits["bias_at_limit"], 0).astype(np.uint8)
        cols["flags"] = f
        cols.update({name: (f & bit) != 0 for name, bit in bits.items()})
    return cols


_UNCOMPILED_S_PER_ROW = 2.5e-5  # the columns' kernel run uncompiled (_support/uncompiled.py), measured


def _attitude_block(q, spec: OutputSpec, check: bool, dtype, new=np.empty) -> np.ndarray:
    """Quaternion and (with ``spec.euler``) Euler columns as the rows of a C-ordered (4 or 7, N) array from ``new``.

    One kernel pass (``_columns_numba``) reads each quaternion once, instead of ``as_euler`` and two transposing
    copies: the same values (the angles bit for bit as ``to_values("euler", q, spec.angles)``), rounded to
    ``dtype`` only on the store.
    """
    q = np.ascontiguousarray(q, dtype=np.float64)
    qe = _v.rotations(q, "q", check=check)  # what as_euler would convert (after its check, rescaled rows)
    out = new((7 if spec.euler else 4, len(q)), dtype)
    if len(q):
        from .._support.uncompiled import call
        from ._columns_numba import quat_euler_columns

        i, j, k, proper, sign, intrinsic, scale, half, full = _kernel_args(spec.angles.seq, spec.angles.degrees)
        positive = spec.angles.range == "positive"
        qe = np.ascontiguousarray(qe)
        args = (q, qe, spec.euler, i, j, k, proper, sign, intrinsic, scale, half, full, positive, out)
        call(quat_euler_columns, *args, python_seconds=_UNCOMPILED_S_PER_ROW * len(q))
    return out


def _columns(values: np.ndarray, dtype) -> np.ndarray:
    """The columns of an (N, k) array as the rows of a new C-ordered (k, N) array of ``dtype``.

    One transposing pass (and cast) for all k columns: the writer needs contiguous columns, and copying k
    strided ones apart costs twice as much.
    """
    return np.array(values.T, dtype=dtype, order="C")
