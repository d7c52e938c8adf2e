"""The checks an IMU file's chunks pass before anything uses them: finite rows, magnitudes, units, time (private).

Each names the file, the line (or row) and the column of what it refuses, and says what the numbers look like.
"""

from __future__ import annotations

import numpy as np

from .units import check_magnitude, check_plausible


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
    rows = np.flatnonzero(bad)
    shown = ", ".join(imu.where(row + int(i)).split()[-1] for i in rows[:5])
    unit = imu.where(row).split()[0] + ("s" if rows.size > 1 else "")
    more = f" (and {rows.size - 5} more in rows {row}-{row + n - 1})" if rows.size > 5 else ""
    first = culprit[min(culprit)]
    what = "NaN or empty values" if np.isnan(np.asarray(cols[first])[rows[0]]).any() else "infinite values"
    raise ValueError(
        f"{imu.path}: {what} at {unit} {shown}{more}, first in column {first!r}; remove or fill "
        "those rows (their readings are unknown, and every later attitude depends on them)"
    )


def check_magnitudes(imu, kind: str, raw: np.ndarray, row: int, period: float | None) -> None:
    """A ValueError at the first reading past :data:`~strapdown.io.units.LIMITS`: file, line, column, value.

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
        raise ValueError(f"{imu.path}: {imu.where(row + i)}, column {column!r}: {problem}")


def check_units(imu, kind: str, raw: np.ndarray, row: int, period: float | None) -> None:
    rate = 1.0 / period if (imu.increments and kind == "gyro" and period) else None
    if kind == "gyro" and imu.increments and not rate:
        return
    if kind in imu.sparse:
        raw = raw[np.isfinite(raw).all(axis=1)]
    problem = check_plausible(kind, raw, imu.units[kind], rate_hz=rate)
    if problem:
        raise ValueError(f"{imu.path}: {problem} (columns {imu.picks[kind].label}, from {imu.where(row)})")


def _around(imu, t: np.ndarray, prev: float, row: int, i: int) -> tuple[str, float, float]:
    """Where row i of a chunk starting at ``row`` is, the time before it (``prev`` for the first) and its own."""
    return imu.where(row + i), float(prev if i == 0 else t[i - 1]), float(t[i])


class TimeCheck:
    """Strictly increasing time and no gap longer than ``max_gap`` nominal periods, across chunks."""

    def __init__(self, imu):
        self.imu = imu
        self.last: float | None = None
        self.period: float | None = None if imu.rate is None else 1.0 / imu.rate

    def __call__(self, t: np.ndarray, row: int) -> None:
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
                f"{imu.path}: time ({imu.time.label}) does not increase at {where}: {before!r} -> {at!r}; sort the "
                "rows, or drop the repeated ones"
            )
        if self.period is None:
            inner = d[np.isfinite(d)]
            if inner.size:
                self.period = float(np.median(inner))
        limit = imu.spec.max_gap
        if limit and self.period:
            over = np.flatnonzero(np.isfinite(d) & (d > limit * self.period))
            if over.size:
                i = int(over[0])
                where, before, at = _around(imu, t, prev, row, i)
                raise ValueError(
                    f"{imu.path}: a gap of {d[i]:.6g} s ({d[i] / self.period:.1f} sample periods of "
                    f"{self.period:.6g} s) before {where} (time {before!r} -> {at!r}); "
                    f"at most --max-gap {limit:g} periods are allowed.  Split the file there, or raise --max-gap "
                    "(0: no check)"
                )
        self.last = float(t[-1])
