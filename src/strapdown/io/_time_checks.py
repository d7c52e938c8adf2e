"""The time checks of a file's chunks: time that increases, and gaps over ``max_gap`` sample periods.

:func:`strapdown.io.plausibility.check_chunk` runs :meth:`TimeCheck.increasing` before the checks of the readings
and :meth:`TimeCheck.gaps` after them.
"""

from __future__ import annotations

import numpy as np


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
                f"{imu.file_of('time')}: time ({imu.time.label}) does not increase at {where}: {before!r} -> "
                f"{at!r}; sort the rows, or drop the repeated ones"
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
