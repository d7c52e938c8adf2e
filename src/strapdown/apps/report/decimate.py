"""Long signals thinned for display with their peaks kept: min-max decimation over equal time buckets.

A browser draws a few thousand points per line at interactive speed; a one-hour log at 1 kHz has 3.6 million.
Taking every k-th sample would drop the spikes a person looks for (a shock on the accelerometer, a magnetic
disturbance), so each line keeps, in each of ``buckets`` equal spans of time, the sample where it is lowest and
the one where it is highest: the minimum and maximum of every bucket survive exactly, and with them every peak
wider than nothing.  This is the min-max half of M4 (Jugel et al., *M4: A Visualization-Oriented Time Series
Data Aggregation*, PVLDB 7(10), 2014), which draws the same pixels as the full line when there are as many
buckets as pixel columns; the first and last sample are kept too, so the line spans the same time.
"""

from __future__ import annotations

import numpy as np

__all__ = ["break_lines", "minmax_indices"]


def minmax_indices(t, values, buckets: int) -> np.ndarray:
    """The rows of ``values`` that min-max decimation keeps: each bucket's lowest and highest sample, per column.

    Parameters
    ----------
    t : array_like, shape (n,)
        Times, non-decreasing.
    values : array_like, shape (n,) or (n, c)
        One or more signals on those times; NaN samples (no reading) are never chosen.
    buckets : int
        Equal spans of time between ``t[0]`` and ``t[-1]``; at most ``2 * buckets * c + 2`` rows are kept.

    Returns
    -------
    numpy.ndarray of intp
        Sorted row indices, the same for every column (so one table serves a whole figure); all rows when
        there are no more than twice as many as buckets.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.apps.report.decimate import minmax_indices
    >>> t = np.arange(1000.0)
    >>> y = np.zeros(1000); y[637] = 5.0; y[200] = -3.0          # two one-sample spikes
    >>> keep = minmax_indices(t, y, 10)
    >>> bool(637 in keep and 200 in keep), len(keep) <= 22
    (True, True)
    """
    t = np.asarray(t, dtype=np.float64)
    v = np.asarray(values, dtype=np.float64)
    v = v[:, None] if v.ndim == 1 else v
    if v.shape[0] != t.shape[0]:
        raise ValueError(f"values have {v.shape[0]} rows for {t.shape[0]} times")
    if not (isinstance(buckets, int | np.integer) and buckets >= 1):
        raise ValueError(f"buckets must be a positive integer, got {buckets!r}")
    n = t.shape[0]
    if n <= 2 * buckets:
        return np.arange(n)
    span = t[-1] - t[0]
    k = np.zeros(n, dtype=np.int64) if span <= 0 else np.minimum((t - t[0]) / span * buckets, buckets - 1)
    k = k.astype(np.int64)
    starts = np.flatnonzero(np.diff(k, prepend=-1))  # times sorted: each bucket is one run of rows
    owner = np.repeat(np.arange(starts.size), np.diff(np.append(starts, n)))
    keep = [np.array([0, n - 1])]
    for column in v.T:
        finite = np.isfinite(column)
        for sign in (1.0, -1.0):  # the maximum of +v and of -v: the highest and the lowest sample
            x = np.where(finite, sign * column, -np.inf)
            best = np.maximum.reduceat(x, starts)
            hit = np.flatnonzero((x == best[owner]) & finite)
            # the first row of each bucket that reaches its extreme
            _, first = np.unique(owner[hit], return_index=True)
            keep.append(hit[first])
    return np.unique(np.concatenate(keep))


def break_lines(keep: np.ndarray, labels) -> np.ndarray:
    """Kept rows with a break (index -1) wherever the label changes: a line is not drawn over a gap.

    Parameters
    ----------
    keep : numpy.ndarray of int
        Sorted rows, from :func:`minmax_indices`.
    labels : array_like of int, shape of ``keep``
        A label per kept row (its segment; a new one after each gap or wrap of an angle).

    Returns
    -------
    numpy.ndarray of intp
        ``keep`` with -1 inserted before each row whose label differs from the previous one; the caller
        writes NaN there.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.apps.report.decimate import break_lines
    >>> break_lines(np.array([0, 2, 3, 5]), np.array([0, 0, 1, 1])).tolist()
    [0, 2, -1, 3, 5]
    """
    labels = np.asarray(labels)
    cuts = np.flatnonzero(np.diff(labels)) + 1
    return np.insert(np.asarray(keep, dtype=np.intp), cuts, -1)
