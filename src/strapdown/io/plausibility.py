"""Readings no sensor makes, and units the readings contradict: every check a file's readings pass, in one place.

Two kinds of check, both naming the file, the line (or row) and the column of what they refuse, and saying what
the numbers look like:

* magnitudes no sensor reads in any unit (:data:`LIMITS`): a broken row, refused whatever is declared;
* declarations the data contradict: a gyro in "rad/s" turning faster than any MEMS gyro can measure, an
  accelerometer in "m/s2" reading 1 at rest, gravity pointing up in axes whose z points down, a gyro turning
  while the accelerometer says the body is still.  Silently integrating degrees as radians gives nonsense that
  looks fine, so each is an error with the fix in the message.  The ``check_*`` functions that judge a whole
  stream return that message (what looks wrong and how to say otherwise, ``--no-unit-check`` among the fixes),
  or None when nothing does.

:class:`~strapdown.io.ImuFile` runs :func:`probe` on a file's first rows and :func:`check_chunk` on every chunk.
"""

from __future__ import annotations

import math

import numpy as np

from .units import GRAVITY, UNITS, scale

__all__ = [
    "LIMITS",
    "TimeCheck",
    "check_chunk",
    "check_gravity_sign",
    "check_gyro_at_rest",
    "check_magnitude",
    "check_plausible",
    "probe",
    "row_norms",
]


# A MEMS gyro's largest range is about ±2000°/s (35 rad/s); human and vehicle motion stays well below it.
_GYRO_MAX = 35.0


# Typical ranges of |value| in each declared unit, to say which unit a wrong declaration probably is.
# Past ±16 g (the largest range of consumer accelerometers) a median |a| is no accelerometer in that unit.
_ACC_MAX = 16 * GRAVITY


_ACC_AT_REST = {"m/s2": (6.0, 14.0), "g": (0.6, 1.4), "mg": (600.0, 1400.0)}


_EARTH_FIELD = {
    "uT": (15.0, 80.0),
    "gauss": (0.15, 0.8),
    "nT": (15e3, 80e3),
    "mT": (0.015, 0.08),
    "normalised": (0.5, 2.0),
}


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


def check_plausible(kind: str, raw: np.ndarray, unit: str, *, rate_hz: float | None = None) -> str | None:
    """A message when the magnitudes of ``raw`` (the file's values) contradict the declared ``unit``, else None.

    The gyro check flags rates beyond any MEMS gyro's range (±2000°/s) declared as rad/s; for increments
    give ``rate_hz`` and the increments are turned into rates.  The accelerometer and magnetometer checks
    compare the median magnitude with gravity and the Earth's field (15-80 µT) and name the unit it fits.
    A reading past :data:`LIMITS` is named first (row and component, :func:`check_magnitude`): no unit
    explains it, so it is no hint of one.

    Parameters
    ----------
    kind : {"gyro", "acc", "mag"}
        The quantity.
    raw : numpy.ndarray, shape (N, 3)
        Values as read (before conversion), finite.
    unit : str
        The declared unit (canonical name).
    rate_hz : float, optional
        Sample rate, for gyro increments.

    Returns
    -------
    str or None
        The message: the unit the values look like, or raw counts, or gravity missing from ``acc``.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.plausibility import check_plausible
    >>> check_plausible("acc", np.array([[0.0, 0.0, 1.0]] * 10), "m/s2")[:46]
    '|acc| is about 1 m/s2 (median), gravity is 9.8'
    >>> check_plausible("acc", np.array([[0.0, 0.0, 9.81]] * 10), "m/s2") is None
    True
    """
    if raw.shape[0] == 0:
        return None
    # a reading no unit explains is no hint of a unit (1e300 is not deg/s either): say so, wherever it is
    hit = check_magnitude(kind, raw, unit, rate_hz=rate_hz)
    if hit:
        return _impossible(hit, "the values checked")
    sub = raw[:: max(1, raw.shape[0] // 4096)]  # a few thousand rows tell the unit; the whole chunk costs more
    mags = row_norms(sub)
    if kind == "gyro":
        if unit != "rad/s":
            return None
        rates = mags * rate_hz if rate_hz else mags
        high = float(np.percentile(rates, 99))
        if high > _GYRO_MAX:
            return (
                f"gyro magnitudes reach {high:.4g} rad/s, beyond the ±2000°/s range of any MEMS gyro: they look "
                "like deg/s.  Pass --gyro-unit deg/s, or --no-unit-check if they really are rad/s"
            )
        return None
    median = float(np.median(mags))
    table = _ACC_AT_REST if kind == "acc" else _EARTH_FIELD
    lo, hi = table[unit]
    if lo <= median <= hi:
        return None
    fits = [u for u, (a, b) in table.items() if u != unit and a <= median <= b]
    option = "--acc-unit" if kind == "acc" else "--mag-unit"
    if kind == "acc":
        si = median * UNITS["acc"][unit]
        # gravity keeps a fixed direction while the body moves little, so the mean vector is about as long as the
        # samples; with gravity removed the samples swing about zero and their mean vector is short
        steady = float(np.linalg.norm(sub.mean(axis=0))) / median if median > 0 else 0.0
        if fits and steady > 0.5:
            return (
                f"|acc| is about {median:.3g} {unit} (median), gravity is 9.81 m/s2: the values look like "
                f"{fits[0]}.  Pass {option} {fits[0]}, or --no-unit-check if {unit} is right"
            )
        if si < 0.5 * GRAVITY:
            return (
                f"|acc| is about {si:.3g} m/s2 (median) with a mean vector of {steady * si:.3g} m/s2, where an "
                "accelerometer reads gravity (9.81 m/s2) plus motion: this looks like a gravity-free 'linear "
                "acceleration' stream (phyphox's Linear Accelerometer, Sensor Logger's Accelerometer.csv), not the "
                "specific force the estimators need.  Use the file with gravity (phyphox Accelerometer, Sensor "
                "Logger TotalAcceleration.csv), or --no-unit-check"
            )
        if si < _ACC_MAX:
            return None  # sustained high g (aerobatics, a centrifuge): possible, and no unit fits better
        return (
            f"|acc| is about {median:.4g} {unit} (median) = {si:.4g} m/s2, far from gravity (9.81 m/s2) at any "
            f"unit ({', '.join(_ACC_AT_REST)}): raw sensor counts?  Scale them to a unit, or --no-unit-check"
        )
    if not fits:
        return None  # raw counts or an unusual field: the estimators use its direction only, so no complaint
    what = "the Earth's field is 25-65 uT"
    return (
        f"|{kind}| is about {median:.3g} {unit} (median), {what}: the values look like {fits[0]}.  "
        f"Pass {option} {fits[0]}, or --no-unit-check if {unit} is right"
    )


def check_gravity_sign(acc, body: str) -> str | None:
    """A message when an upright body's accelerometer reads gravity downwards at rest (a sign error), else None.

    At rest an accelerometer reads the specific force, +g along the body's up (``-z`` for FRD, ``+z`` for FLU
    or RFU).  A vehicle that starts upright (a drone on the ground) whose mean first reading points within 30°
    of the body's *down* is reporting acceleration with the opposite sign (or has its z axis flipped).

    Parameters
    ----------
    acc : numpy.ndarray, shape (N, 3)
        The first readings, m/s², finite.
    body : str
        The sensor axes (``"FRD"``, ``"FLU"``, ...).

    Returns
    -------
    str or None
        The message: the reading's direction and sign, in ``body`` axes.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.plausibility import check_gravity_sign
    >>> check_gravity_sign(np.tile([0.0, 0.0, -9.8], (50, 1)), "FRD") is None   # FRD at rest: up is -z
    True
    >>> check_gravity_sign(np.tile([0.0, 0.0, 9.8], (50, 1)), "FRD")[:40]
    'the accelerometer reads gravity downward'
    """
    if acc.shape[0] == 0 or body[2] not in "UD":
        return None
    mean = acc.mean(axis=0)
    norm = float(np.linalg.norm(mean))
    if not 0.5 * GRAVITY < norm < 1.5 * GRAVITY:
        return None  # moving, or a unit problem that check_plausible names
    up = np.array([0.0, 0.0, 1.0 if body[2] == "U" else -1.0])
    if float(mean @ up) / norm < -math.cos(math.radians(30)):
        return (
            f"the accelerometer reads gravity downward at the start ({np.round(mean, 2).tolist()} m/s2 in {body} "
            f"axes), where a body at rest reads +9.81 m/s2 upward: it looks like acceleration with the sign "
            f"flipped, or the log starts upside down.  Negate it, or pass --no-unit-check if it really is inverted"
        )
    return None


# A gyro that says the body tilts this fast while gravity stays put in the body contradicts the accelerometer:
# 0.2 rad/s (11°/s) is far past any MEMS gyro's bias (a few °/s at worst, uncalibrated).
_TILT_RATE_AT_REST = 0.2


def check_gyro_at_rest(gyro, acc, seconds: float, unit: str) -> str | None:
    """A message when the gyro turns the body about a horizontal axis while the accelerometer says it does not.

    At rest, or turning about the vertical only (a turntable), gravity keeps its direction in the body.  A mean
    rate of more than 0.2 rad/s about an axis perpendicular to gravity would turn that direction by 11° a
    second; if the accelerometer's direction stays within 3° over the window instead, the gyro's numbers are not
    rates in ``unit`` (deg/s values declared as rad/s read a 0.5°/s bias as 29°/s), or the two sensors' axes
    differ.  A gyro reading past :data:`LIMITS` is named instead (row and component, :func:`check_magnitude`).

    Parameters
    ----------
    gyro, acc : numpy.ndarray, shape (N, 3)
        Rates (rad/s, converted with the declared unit) and specific force (m/s²) of the same rows, finite.
    seconds : float
        The span of the rows, s.
    unit : str
        The gyro's declared unit, for the message.

    Returns
    -------
    str or None
        The message: the rate across gravity against the accelerometer's drift, or a reading past the limits.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.plausibility import check_gyro_at_rest
    >>> acc = np.tile([0.0, 0.0, 9.81], (500, 1))
    >>> check_gyro_at_rest(np.tile([0.0, 0.0, 1.0], (500, 1)), acc, 5.0, "rad/s") is None   # a turntable
    True
    >>> check_gyro_at_rest(np.tile([0.5, -0.3, 0.2], (500, 1)), acc, 5.0, "rad/s")[:38]
    'the gyro turns the body at 0.583 rad/s'
    """
    n = acc.shape[0]
    if n < 20 or seconds < 1.0:
        return None
    # a rate no unit explains is not "deg/s declared as rad/s": name it (and keep it out of the sums below)
    hit = check_magnitude("gyro", gyro, unit, converted=True)
    if hit:
        return _impossible(hit, "the gyro rows checked")
    # the accelerometer only by direction, scaled by its largest reading: no sum or square can overflow
    size = float(np.abs(acc).max())
    if not 0.0 < size < math.inf:
        return None
    k = max(1, n // 10)
    blocks = (acc / size)[: n - n % k].reshape(-1, k, 3).mean(axis=1)  # means of k rows: the noise out
    lengths = row_norms(blocks)
    ref = blocks[0]
    g = float(lengths[0]) * size
    if not 0.8 * GRAVITY < g < 1.2 * GRAVITY:
        return None
    up = ref / lengths[0]
    cos = blocks @ up / np.where(lengths > 0, lengths, 1.0)  # a zero block: cos 0, a drift of 90°
    drift = float(np.degrees(np.arccos(np.clip(cos.min(), -1.0, 1.0))))
    w = gyro.mean(axis=0)
    across = float(np.linalg.norm(w - (w @ up) * up))
    if drift > 3.0 or across < _TILT_RATE_AT_REST:
        return None
    guess = "  The values look like deg/s: pass --gyro-unit deg/s" if unit == "rad/s" else ""
    return (
        f"the gyro turns the body at {across:.3g} rad/s about a horizontal axis ({np.degrees(across * seconds):.0f}° "
        f"in {seconds:.3g} s), but gravity stays within {drift:.1f}° in the accelerometer's axes: the gyro's numbers "
        f"are not rates in {unit}, or the two sensors' axes differ.{guess} (or --no-unit-check)"
    )


def check_finite_rows(imu, cols: dict, row: int, n: int) -> None:
    # the usual case, every value finite, in one pass without temporaries: a NaN or inf anywhere makes a
    # column's sum NaN or inf (a sum of finite values that overflows only sends it the long way below)
    if all(np.isfinite(np.sum(v)) for v in cols.values()):
        return
    bad = np.zeros(n, dtype=bool)
    culprit = {}
    # a slower sensor's rows are all NaN where it has no sample: those are not bad, partly NaN rows are
    absent = {}
    for kind in imu.sparse:
        fields = imu.picks[kind].fields
        none = np.all(
            [np.isnan(cols[f]).all(axis=1) if cols[f].ndim == 2 else np.isnan(cols[f]) for f in fields], axis=0
        )
        absent.update(dict.fromkeys(fields, none))
    for name, values in cols.items():
        b = ~np.isfinite(values)
        if name in absent:
            b = b & ~(absent[name][:, None] if b.ndim == 2 else absent[name])
        if b.ndim == 2:
            b = b.any(axis=1)
        if b.any():
            culprit.setdefault(int(np.argmax(b)), name)
            bad |= b
    if not bad.any():
        return
    first = culprit[min(culprit)]
    # the rows of the culprit's own column, in its own file (a merged recording's sensors each have theirs)
    own = np.flatnonzero(~np.isfinite(cols[first]).reshape(n, -1).all(axis=1) & bad)
    rows = own if own.size else np.flatnonzero(bad)
    path, at = imu.locate(first, row + int(rows[0]))
    shown = ", ".join(imu.locate(first, row + int(i))[1].split()[-1] for i in rows[:5])
    unit = at.split()[0] + ("s" if rows.size > 1 else "")
    more = f" (and {rows.size - 5} more in rows {row}-{row + n - 1})" if rows.size > 5 else ""
    what = "NaN or empty values" if np.isnan(np.asarray(cols[first])[rows[0]]).any() else "infinite values"
    raise ValueError(
        f"{path}: {what} at {unit} {shown}{more}, first in column {first!r}; remove or fill "
        "those rows (their readings are unknown, and every later attitude depends on them)"
    )


def check_magnitudes(imu, kind: str, raw: np.ndarray, row: int, period: float | None) -> None:
    """A ValueError at the first reading past :data:`~strapdown.io.plausibility.LIMITS`: file, line, column, value.

    Not switched off by ``unit_check``: such a reading is a broken row in any unit, and the estimators would
    only lose the attitude on it later, with no line to look at.
    """
    if kind == "gyro" and imu.increments:
        if not period:
            return  # no rate to turn increments into rates yet (a first chunk of one row)
        hit = check_magnitude(kind, raw, imu.units[kind], rate_hz=1.0 / period)
    else:
        hit = check_magnitude(kind, raw, imu.units[kind])
    if hit:
        i, j, problem = hit
        pick = imu.picks[kind]
        column = pick.fields[j] if len(pick.fields) > 1 else f"{pick.fields[0]}[{j}]"
        path, where = imu.locate(pick.fields[min(j, len(pick.fields) - 1)], row + i)
        raise ValueError(f"{path}: {where}, column {column!r}: {problem}")


def check_units(imu, kind: str, raw: np.ndarray, row: int, period: float | None) -> None:
    rate = 1.0 / period if (imu.increments and kind == "gyro" and period) else None
    if kind == "gyro" and imu.increments and not rate:
        return
    if kind in imu.sparse:
        raw = raw[np.isfinite(raw).all(axis=1)]
    problem = check_plausible(kind, raw, imu.units[kind], rate_hz=rate)
    if problem:
        path, where = imu.locate(imu.picks[kind].fields[0], row)
        raise ValueError(f"{path}: {problem} (columns {imu.picks[kind].label}, from {where})")


def _around(imu, t: np.ndarray, prev: float, row: int, i: int) -> tuple[str, float, float]:
    """Where row i of a chunk starting at ``row`` is, the time before it (``prev`` for the first) and its own."""
    return imu.locate(imu.time.fields[0], row + i)[1], float(prev if i == 0 else t[i - 1]), float(t[i])


class TimeCheck:
    """Strictly increasing time and no gap longer than ``max_gap`` nominal periods, across chunks.

    Calling it runs both checks; :func:`check_chunk` runs :meth:`increasing` first and :meth:`gaps` after every
    check of the readings, so that a file that is wrong in another way is told so before it is told of its gaps.
    """

    def __init__(self, imu):
        self.imu = imu
        self.last: float | None = None
        self.period: float | None = None if imu.rate is None else 1.0 / imu.rate
        self._steps: np.ndarray | None = None
        self._prev = None

    def __call__(self, t: np.ndarray, row: int) -> None:
        """Check the times ``t`` (s) of the chunk that starts at ``row``, after the chunks before it."""
        self.increasing(t, row)
        self.gaps(t, row)

    def increasing(self, t: np.ndarray, row: int) -> None:
        """Refuse time that does not increase; learn the period from the first chunk."""
        if t.size == 0:
            return
        imu = self.imu
        prev = t[0] if self.last is None else self.last
        d = np.diff(t, prepend=prev)
        if self.last is None:
            d[0] = np.inf
        bad = np.flatnonzero(~(d > 0))
        if bad.size:
            where, before, at = _around(imu, t, prev, row, int(bad[0]))
            raise ValueError(
                f"{imu.file_of('time')}: time ({imu.time.label}) does not increase at {where}: {before!r} -> {at!r}; sort the "
                "rows, or drop the repeated ones"
            )
        if self.period is None:
            inner = d[np.isfinite(d)]
            if inner.size:
                self.period = float(np.median(inner))
        self._steps, self._prev = d, prev
        self.last = float(t[-1])

    def gaps(self, t: np.ndarray, row: int) -> None:
        """Refuse a step over ``max_gap`` periods in the chunk :meth:`increasing` has just seen."""
        imu, d = self.imu, self._steps
        limit = imu.spec.max_gap
        if d is None or t.size == 0 or not (limit and self.period):
            return
        over = np.flatnonzero(np.isfinite(d) & (d > limit * self.period))
        if over.size:
            i = int(over[0])
            where, before, at = _around(imu, t, self._prev, row, i)
            raise ValueError(
                f"{imu.file_of('time')}: a gap of {d[i]:.6g} s ({d[i] / self.period:.1f} sample periods of "
                f"{self.period:.6g} s) before {where} (time {before!r} -> {at!r}); at most --max-gap {limit:g} "
                "periods are allowed with --on-gap error.  Leave --on-gap out to bridge short gaps and restart "
                "after long ones, or give --on-gap bridge (carry the attitude across every gap), restart (start "
                "afresh after each), split (a file per segment); or raise --max-gap (0: no check)"
            )


def check_chunk(imu, cols: dict, raws: dict, t: np.ndarray, row: int, times: TimeCheck | None) -> TimeCheck:
    """Every check of one chunk of a file, in the order that names the first fault: values, time, magnitudes, units.

    ``cols`` are the chunk's fields as read, ``raws`` the readings of each sensor in the file's units, ``t`` the
    times in seconds and ``times`` the file's running time check (None for the first chunk), which is returned.
    The gaps come last: every check of the readings runs whatever the gap policy, and before a gap stops a run.
    """
    times = TimeCheck(imu) if times is None else times
    n = t.shape[0]
    check_finite_rows(imu, cols, row, n)
    times.increasing(t, row)
    for kind, raw in raws.items():
        if kind in _SI_UNIT:
            check_magnitudes(imu, kind, raw, row, times.period)
            if imu.spec.unit_check:
                check_units(imu, kind, raw, row, times.period)
    times.gaps(t, row)
    return times


def probe(imu, heads: dict) -> None:
    """Checks on the first rows: a normalised magnetometer, gravity's sign, a gyro the accelerometer contradicts.

    ``heads`` holds the first rows of each sensor in the file's units.  A magnetometer of about unit norm is
    taken as normalised (``imu.units["mag"]``, with a note); the others raise a ValueError naming the columns.
    """
    # the checks below read magnitudes: a broken row among these first ones is named by line and column
    for kind, raw in heads.items():
        check_magnitudes(imu, kind, raw, 0, imu.period)
    if "mag" in heads and imu.spec.mag_unit is None and imu.picks["mag"].unit_hint is None:
        raw = heads["mag"][np.isfinite(heads["mag"]).all(axis=1)]
        norms = row_norms(raw)
        if norms.size and 0.8 <= np.median(norms) <= 1.25 and imu.units["mag"] == "uT":
            imu.units["mag"] = "normalised"
            imu.notes.append(f"mag normalised (|m| median {np.median(norms):.3g}): used for its direction")
    if "acc" not in heads:
        return
    acc = heads["acc"] * scale("acc", imu.units["acc"])
    if imu.source.upright and imu.body:
        problem = check_gravity_sign(acc[np.isfinite(acc).all(axis=1)], imu.body)
        if problem:
            raise ValueError(f"{imu.file_of('acc')}: {problem} (columns {imu.picks['acc'].label})")
    if not imu.increments and imu.period:
        gyro = heads["gyro"] * scale("gyro", imu.units["gyro"])
        both = np.isfinite(acc).all(axis=1) & np.isfinite(gyro).all(axis=1)
        problem = check_gyro_at_rest(gyro[both], acc[both], gyro.shape[0] * imu.period, imu.units["gyro"])
        if problem:
            files = dict.fromkeys(map(str, (imu.file_of("gyro"), imu.file_of("acc"))))
            raise ValueError(
                f"{' and '.join(files)}: {problem} (columns {imu.picks['gyro'].label} and {imu.picks['acc'].label})"
            )
