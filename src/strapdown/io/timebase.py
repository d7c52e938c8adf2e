"""The unit of a time column, inferred from its steps and checked, and the instant its t = 0 stands for.

A wrong time unit is a silent wrong answer (epoch nanoseconds read as seconds gave t up to 2e11 s), so an integer
time column gets its unit from the median step between samples: the unit in which that step is a sample period
of an IMU (10 µs to 10 s), preferring rates near 100 Hz, and the epoch's unit when the first value is a date
between 1973 and 2100 in it.  Any time column, float or integer, whose median step makes a period outside
10 µs..10 s in its unit is refused, with the column, the step and what each unit would make of it.
"""

from __future__ import annotations

import math

import numpy as np

from .source import TimeOrigin

__all__ = ["PERIOD_RANGE", "check_period", "infer_time_unit", "origin_of"]

#: Plausible sample periods of an IMU, s.
PERIOD_RANGE = (1e-5, 10.0)
_PER_S = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}
_EPOCH_S = (1e8, 4.1e9)  # 1973 .. 2100


def _rates(step: float) -> str:
    return ", ".join(f"{u}: {_hz(step * f)}" for u, f in _PER_S.items())


def _hz(period: float) -> str:
    return f"{1 / period:.3g} Hz" if period > 0 else "no step"


def infer_time_unit(step: float, first: float, column: str, where: str) -> tuple[str, str]:
    """The unit of an integer time column from its median ``step`` and ``first`` value, and why.

    Parameters
    ----------
    step : float
        Median difference of consecutive values.
    first : float
        The first value (absolute), to recognise epoch times.
    column : str
        The column, for messages.
    where : str
        The file, for messages.

    Returns
    -------
    unit : {"ns", "us", "ms", "s"}
        The unit.
    reason : str
        How it was told ("epoch ns", "period 4 ms").

    Raises
    ------
    ValueError
        When no unit makes the step a plausible sample period.

    Examples
    --------
    >>> from strapdown.io.timebase import infer_time_unit
    >>> infer_time_unit(10_000_000, 1.7e18, "time", "a.csv")[0], infer_time_unit(4000, 2e7, "timestamp", "b")[0]
    ('ns', 'us')
    >>> infer_time_unit(10, 1.7e12, "t", "c")[0]
    'ms'
    """
    lo, hi = PERIOD_RANGE
    fits = [u for u, f in _PER_S.items() if lo <= step * f <= hi]
    if not fits:
        raise ValueError(
            f"{where}: the integer time column {column!r} steps by {step:g} (median), a sample period outside "
            f"{lo:g}..{hi:g} s in every unit ({_rates(step)}); give its unit with --time-unit, or --rate"
        )
    for u in fits:
        if _EPOCH_S[0] <= abs(first) * _PER_S[u] <= _EPOCH_S[1]:
            return u, f"epoch {u} (first value {np.datetime64(int(abs(first) * _PER_S[u]), 's')})"
    # nearest to 100 Hz in log scale; a tie goes to the finer unit (fast IMUs are commoner than 1 Hz ones)
    best = min(fits, key=lambda u: (round(abs(math.log10(step * _PER_S[u]) + 2), 9), _PER_S[u]))
    return best, f"median step {step:g} {best} = {_hz(step * _PER_S[best])}"


def check_period(step: float, unit: str, column: str, where: str) -> None:
    """A ValueError when a median ``step`` in ``unit`` is no IMU's sample period (outside 10 µs..10 s).

    Parameters
    ----------
    step : float
        Median difference of consecutive times, in ``unit``.
    unit : str
        The unit taken.
    column, where : str
        The column and the file, for messages.

    Returns
    -------
    None

    Examples
    --------
    >>> from strapdown.io.timebase import check_period
    >>> check_period(0.01, "s", "t", "a.csv")
    >>> check_period(4000.0, "s", "timestamp", "log.csv")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ValueError: log.csv: time column 'timestamp' taken in s steps by 4000 s (median), ... it looks like us (250 Hz)...
    """
    lo, hi = PERIOD_RANGE
    period = step * _PER_S[unit]
    if lo <= period <= hi:
        return
    fits = [u for u, f in _PER_S.items() if lo <= step * f <= hi]
    guess = min(fits, key=lambda u: abs(math.log10(step * _PER_S[u]) + 2)) if fits else None
    hint = f"it looks like {guess} ({_hz(step * _PER_S[guess])})" if guess else f"in other units: {_rates(step)}"
    raise ValueError(
        f"{where}: time column {column!r} taken in {unit} steps by {period:.6g} s (median), {_hz(period)}: "
        f"no IMU samples so; {hint}. Give its unit with --time-unit"
    )


def origin_of(first, unit: str) -> TimeOrigin:
    """The :class:`TimeOrigin` of a time column whose first value is ``first`` in ``unit``.

    Parameters
    ----------
    first : int or float
        The first value.
    unit : str
        Its unit.

    Returns
    -------
    TimeOrigin
        Kind ``"epoch"`` when the value is a date between 1973 and 2100, else ``"file"``.

    Examples
    --------
    >>> from strapdown.io.timebase import origin_of
    >>> str(origin_of(1718030736872695300, "ns"))
    '1718030736872695300 ns since the epoch (1970-01-01 UTC)'
    """
    seconds = abs(float(first)) * _PER_S[unit]
    kind = "epoch" if _EPOCH_S[0] <= seconds <= _EPOCH_S[1] else "file"
    value = int(first) if float(first).is_integer() else float(first)
    return TimeOrigin(value, unit, kind)
