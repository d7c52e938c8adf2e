"""Sensors at different rates on one time line: the gyro's rows drive, the others are placed on them.

The gyro is never resampled: every gyro sample is one row.  An accelerometer or magnetometer sample goes to the
gyro row nearest to it in time (a tie goes to the later row, whose gyro step ends at the sample); when several
land on one row the nearest is kept; samples more than one gyro period outside the gyro's time span are dropped.
Rows that get no sample are NaN rows, which the estimators with ``missing_samples`` (``AttitudeEstimator``) take
as "no sample of that sensor then" (:mod:`strapdown.fusion`): a slow magnetometer costs nothing.  Placed this way
a sample is at most half a gyro period from its row; the estimators take it as read at the end of the row's step.
"""

from __future__ import annotations

import numpy as np

__all__ = ["place_on_rows"]


def place_on_rows(t_rows, t_samples, values, period: float | None = None, *, index: bool = False):
    """Put samples taken at ``t_samples`` on the rows timed ``t_rows`` (nearest row), NaN rows elsewhere.

    Parameters
    ----------
    t_rows : array_like, shape (n,)
        The gyro's times, strictly increasing (any unit; integers are compared exactly).
    t_samples : array_like, shape (m,)
        The other sensor's times, increasing, in the same unit.
    values : array_like, shape (m, k)
        Its samples.
    period : float, optional
        The gyro's period, beyond which a sample is dropped; by default the median step of ``t_rows`` (given when
        the rows are one chunk of a longer log, whose period is the whole log's).
    index : bool
        Also return which sample each row got.

    Returns
    -------
    numpy.ndarray, shape (n, k)
        float64; a row without a sample is all NaN.
    numpy.ndarray of int, shape (n,)
        With ``index``: the sample on each row, -1 for none.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.merge import place_on_rows
    >>> place_on_rows([0, 10, 20, 30], [9, 26], np.array([[1.0], [2.0]]))[:, 0]
    array([nan,  1., nan,  2.])
    """
    t_rows = np.asarray(t_rows)
    t_samples = np.asarray(t_samples)
    values = np.asarray(values, dtype=np.float64)
    if values.ndim != 2:  # (n,) or (n, k): an empty (0, k) block keeps its k, which reshape cannot infer
        values = values.reshape(t_samples.shape[0], -1)
    out = np.full((t_rows.shape[0], values.shape[1]), np.nan)
    which = np.full(t_rows.shape[0], -1, dtype=np.int64)
    if t_rows.size == 0 or t_samples.size == 0:
        return (out, which) if index else out
    if t_rows.dtype.kind in "iu" and t_samples.dtype.kind in "iu":
        t_rows, t_samples = t_rows.astype(np.int64), t_samples.astype(np.int64)
    else:
        t_rows, t_samples = t_rows.astype(np.float64), t_samples.astype(np.float64)
    after = np.clip(np.searchsorted(t_rows, t_samples, side="left"), 0, t_rows.size - 1)
    before = np.clip(after - 1, 0, t_rows.size - 1)
    d_after = np.abs(t_rows[after] - t_samples)
    d_before = np.abs(t_samples - t_rows[before])
    row = np.where(d_before < d_after, before, after)  # a tie goes to the later row
    dist = np.minimum(d_before, d_after)
    if period is None:
        period = np.median(np.diff(t_rows)) if t_rows.size > 1 else np.inf
    inside = dist <= period
    sample = np.flatnonzero(inside)
    row, dist, values = row[inside], dist[inside], values[inside]
    # nearest first, so that the first occurrence of each row is the sample kept
    order = np.lexsort((dist, row))
    row, values, sample = row[order], values[order], sample[order]
    first = np.ones(row.size, dtype=bool)
    first[1:] = row[1:] != row[:-1]
    out[row[first]] = values[first]
    which[row[first]] = sample[first]
    return (out, which) if index else out
