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

import numpy as np

from ._gravity_checks import check_gravity_sign, check_gyro_at_rest, check_gyro_tilt, flipped_body
from ._limits import _SI_UNIT, LIMITS, _impossible, check_magnitude, row_norms
from ._time_checks import TimeCheck
from .units import GRAVITY, UNITS, scale

__all__ = [
    "LIMITS",
    "ZEROED_RUN",
    "TimeCheck",
    "check_chunk",
    "check_gravity_sign",
    "check_gyro_at_rest",
    "check_gyro_tilt",
    "check_magnitude",
    "check_plausible",
    "flipped_body",
    "gravity_warning",
    "probe",
    "row_norms",
    "zeroed_rows",
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
    "mG": (150.0, 800.0),
    "nT": (15e3, 80e3),
    "mT": (0.015, 0.08),
    "normalised": (0.5, 2.0),
}


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

    The gyro against the accelerometer at rest (:func:`check_gyro_at_rest`) or in motion (:func:`check_gyro_tilt`).

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
        if not problem:  # in motion: the gyro's tilt against the accelerometer's (rows timed by the median step)
            t = np.flatnonzero(both) * imu.period
            problem = check_gyro_tilt(gyro[both], acc[both], t, imu.units["gyro"])
        if problem:
            files = dict.fromkeys(map(str, (imu.file_of("gyro"), imu.file_of("acc"))))
            raise ValueError(
                f"{' and '.join(files)}: {problem} (columns {imu.picks['gyro'].label} and {imu.picks['acc'].label})"
            )


def gravity_warning(imu, body: str, declared: str) -> str | None:
    """A warning when the first readings put gravity downward in the axes a run reads them in, else None.

    A format whose vehicles start upright refuses such a file already (:func:`probe`); any other file may start
    upside down (a phone face down), so this only warns, with the ``--body`` that would read it upright
    (:func:`flipped_body`): FRD data read in the default FLU axes comes out upside down (roll 180°) otherwise.

    Parameters
    ----------
    imu : ImuFile
        The input (its first accelerometer rows).
    body : str
        The axes its readings are taken in (``"FLU"``).
    declared : str
        Where they came from (``"assumed"``, ``"--body"``, ``"preset of ulog"``), for the message.
    """
    if "acc" not in imu.picks or getattr(imu.source, "upright", False) or not imu.spec.unit_check:
        return None
    acc = imu.head("acc")
    problem = check_gravity_sign(acc[np.isfinite(acc).all(axis=1)], body)
    if problem is None:
        return None
    how = "assumed, not declared" if declared == "assumed" else declared
    return (
        f"warning: {imu.file_of('acc')}: {problem.split(': it looks like')[0]} (axes {body}: {how}).  If the "
        f"sensor starts upright, its axes are {flipped_body(body)}: pass --body {flipped_body(body)}, else the "
        "attitudes start upside down (roll 180°)"
    )


#: Consecutive rows of exact zeros on one axis that are taken as a zeroed block rather than readings.
ZEROED_RUN = 64


def zeroed_rows(raws: dict, min_run: int = ZEROED_RUN) -> np.ndarray:
    """Rows inside a run of ``min_run`` or more exact zeros on an axis of the accelerometer or magnetometer.

    No such sensor reads exactly 0.0 for dozens of samples in a row while it reads otherwise elsewhere (its noise
    is about a count; free fall is never exact to the bit, the Earth's field never zero), but a zeroed block of
    a damaged file does: 4 KiB of a MAT or HDF5 file is 512 float64 values of one column, or 170 rows of an
    (n, 3) array.  An axis that is zero on every row of the chunk (a simulated level (0, 0, 9.81)) is taken as
    it is, and so is the gyro, which a simulated or quantised sensor at rest may read as 0 for long stretches.

    Parameters
    ----------
    raws : dict
        ``{kind: (n, 3) array}`` of one chunk, as read.
    min_run : int
        Shortest run of zeros flagged.

    Returns
    -------
    ndarray of bool, shape (n,)

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.plausibility import zeroed_rows
    >>> acc = np.tile([0.1, -0.2, 9.8], (200, 1))
    >>> acc[50:150, 0] = 0.0  # a zeroed stretch of one column
    >>> hit = zeroed_rows({"gyro": np.zeros((200, 3)), "acc": acc})
    >>> int(hit.sum()), int(np.argmax(hit))
    (100, 50)
    """
    n = len(next(iter(raws.values()))) if raws else 0
    hit = np.zeros(n, dtype=bool)
    for values in (raws.get(k) for k in ("acc", "mag")):
        if values is None or n < min_run:
            continue
        for axis in np.atleast_2d(values.T):
            zero = axis == 0
            if zero.all() or np.count_nonzero(zero) < min_run:
                continue
            edges = np.flatnonzero(np.diff(np.concatenate(([0], zero.view(np.int8), [0]))))
            for a, b in zip(edges[::2], edges[1::2], strict=True):
                if b - a >= min_run:
                    hit[a:b] = True
    return hit
