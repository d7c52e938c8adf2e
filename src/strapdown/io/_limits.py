"""Magnitudes no sensor reads in any unit (:data:`LIMITS`), and the overflow-free norms that judge them.

Public through :mod:`strapdown.io.plausibility`.
"""

from __future__ import annotations

import math

import numpy as np

from .units import UNITS, scale

#: Magnitudes (SI; µT for the magnetometer) that no sensor reads, in any unit: a reading past them is a broken
#: row, not a unit to declare, and no estimator can use it (``--no-unit-check`` does not switch this check off).
LIMITS = {
    # 1e4 rad/s is 1.6 kHz of spin (95,000 rpm): six times a spinning artillery shell (~250 rev/s), the fastest
    # body that carries an IMU, and twenty times the widest gyro ranges (tens of thousands of °/s, ~500 rad/s)
    "gyro": 1e4,
    # 1e7 m/s² is a million g: five times the largest rated shock accelerometers (200,000 g), ~1e5 times the
    # ±16 g of consumer parts; raw 16-bit counts declared as m/s² (<= 32768) stay below it for the unit check
    "acc": 1e7,
    # 1e7 µT is 10 T: past an MRI scanner (1.5-7 T) and ten times a neodymium magnet's surface field (~1 T);
    # the Earth's field in nT declared as µT (~5e4) and raw counts stay below it for the unit check
    "mag": 1e7,
}


_SI_UNIT = {"gyro": "rad/s", "acc": "m/s2", "mag": "uT"}


_NAME = {"gyro": "gyro", "acc": "accelerometer", "mag": "magnetometer"}


_WHY = {"gyro": "1.6 kHz of spin", "acc": "a million g", "mag": "10 T, past an MRI scanner"}


def row_norms(v) -> np.ndarray:
    """Euclidean norms of the rows of ``v``, without overflow or underflow on the way.

    Each row is divided by its largest ``|component|`` before squaring, so ``[1e300, 0, 0]`` has norm 1e300 (the
    plain sum of squares overflows to inf past 1e154) and ``[1e-300, 0, 0]`` norm 1e-300, not 0.  Rows with NaN
    give NaN, rows with inf give inf, and a norm past the largest float is inf; none of them warns.

    Parameters
    ----------
    v : array_like, shape (..., k)
        Vectors along the last axis.

    Returns
    -------
    numpy.ndarray, shape (...)
        Their norms.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.plausibility import row_norms
    >>> row_norms(np.array([[3e300, 4e300, 0.0], [0.0, 0.0, 0.0]]))
    array([5.e+300, 0.e+000])
    """
    v = np.asarray(v, dtype=np.float64)
    m = np.abs(v).max(axis=-1)
    s = np.where((m > 0) & np.isfinite(m), m, 1.0)  # 0, NaN and inf rows are divided by 1: no 0/0 or inf/inf
    u = v / s[..., None]
    with np.errstate(over="ignore"):  # only a norm past 1.8e308 can overflow here, and inf is its value
        return s * np.sqrt(np.einsum("...i,...i->...", u, u))


def check_magnitude(
    kind: str, values: np.ndarray, unit: str, *, rate_hz: float | None = None, converted: bool = False
) -> tuple[int, int, str] | None:
    """The first row whose magnitude no sensor reads (:data:`LIMITS`), its largest component and what is wrong.

    One pass of ``abs`` and ``max`` over the rows (cheap enough for every chunk of a file); only rows past the
    limit over √3 get an exact, overflow-free norm.  Rows with NaN or infinite values are left to the finite
    check.  The message says the value in the declared unit and in SI, and whether another unit of ``kind``
    would make it plausible (deg/s read as rad/s) or none does (a broken row).

    Parameters
    ----------
    kind : {"gyro", "acc", "mag"}
        The quantity.
    values : numpy.ndarray, shape (N, 3)
        The readings: as in the file (in ``unit``), or in SI when ``converted``.
    unit : str
        The declared unit (canonical name); for gyro increments "rad/s" means rad and "deg/s" deg.
    rate_hz : float, optional
        Sample rate, for gyro increments: they are judged as the rates increment × rate.
    converted : bool
        ``values`` are in SI already (converted with ``unit``).

    Returns
    -------
    (int, int, str) or None
        Row and component (0-based) of the first reading past the limit, and the message, without a location.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.plausibility import check_magnitude
    >>> gyro = np.zeros((5, 3))
    >>> check_magnitude("gyro", gyro, "rad/s") is None
    True
    >>> gyro[3, 1] = 1e300
    >>> row, component, message = check_magnitude("gyro", gyro, "rad/s")
    >>> row, component, message[:55]
    (3, 1, 'the gyro reads 1e+300 rad/s (|gyro| 1e+300 rad/s), beyo')
    """
    values = np.asarray(values, dtype=np.float64)
    if values.size == 0:
        return None
    base = 1.0 if converted else scale(kind, unit)  # SI per value
    per = rate_hz or 1.0
    # the SI magnitude limit in the units of ``values``: no product of a huge value is ever formed
    limit = LIMITS[kind] / (base * per)
    # every component under limit/√3 (the usual case): no row can be past the limit.  Two whole-array
    # reductions cost a tenth of the per-row abs-max below (numpy's axis=1 reduction over 3 is slow); NaN or
    # inf anywhere falls through to the per-row pass, which leaves those rows to the finite check
    bound = max(float(values.max()), -float(values.min()))
    if bound <= limit / math.sqrt(3.0):
        return None
    top = np.abs(values).max(axis=1)
    near = np.flatnonzero(np.isfinite(top) & (top > limit / math.sqrt(3.0)))
    if near.size == 0:
        return None
    norms = row_norms(values[near])
    over = np.flatnonzero(norms > limit)
    if over.size == 0:
        return None
    i = int(near[over[0]])
    j = int(np.argmax(np.abs(values[i])))
    norm = float(norms[over[0]])  # Python floats: a product past 1.8e308 is inf, without a warning
    value = float(values[i, j]) / (scale(kind, unit) if converted else 1.0)
    si = _SI_UNIT[kind]
    if rate_hz:
        own = {"rad/s": "rad", "deg/s": "deg"}.get(unit, unit)
        what = f"the gyro increment reads {value:.4g} {own}, at {rate_hz:g} Hz a rate of {norm * base * per:.4g} {si}"
    else:
        what = f"the {_NAME[kind]} reads {value:.4g} {unit} (|{kind}| {norm * base:.4g} {si})"
    what += f", beyond {LIMITS[kind]:.0e} {si} ({_WHY[kind]})"
    # another unit of the quantity would take the file's numbers to a plausible size: smaller units only
    declared = scale(kind, unit)
    as_unit = {u: norm * base / declared * f * per for u, f in UNITS[kind].items() if f < declared}
    fits = [u for u, x in as_unit.items() if x <= LIMITS[kind]]
    if fits:
        advice = (
            f"as {fits[0]} it would be {as_unit[fits[0]]:.3g} {si}.  Pass --{kind}-unit {fits[0]} if that is the "
            "unit, else fix or remove that row"
        )
    else:
        advice = (
            f"not plausible in any unit ({', '.join(UNITS[kind])}).  Fix or remove that row (--no-unit-check does "
            "not skip this: no estimator can use such a reading)"
        )
    return i, j, f"{what}: {advice}"


def _impossible(hit: tuple[int, int, str], what: str) -> str:
    """A :func:`check_magnitude` finding as a check's message, located in the array given to the check."""
    i, j, message = hit
    return f"{message} (row {i}, component {'xyz'[j] if j < 3 else j} of {what})"
