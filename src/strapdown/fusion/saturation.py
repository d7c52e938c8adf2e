"""Sensor saturation: readings pinned at the range limit, found in the readings themselves.

A MEMS gyro or accelerometer reports at most its full-scale range: beyond it the reading stays at the limit, the
same number sample after sample, while the true rate or force goes on.  Integrated, a clipped gyro turns the
estimate by less than the body turned, an error no later sample reveals; a clipped accelerometer reads neither
gravity nor the specific force.  :func:`saturated` finds such samples: components at ``limit`` in magnitude when
the range is known, or, when it is not, runs of at least ``min_run`` identical readings at an axis's extreme value
over the chunk (a reading that is a quantised number far beyond the noise stays exactly equal only when pinned).
Extremes below ``floor`` are never taken as a range: no sensor's full scale is that small (2 rad/s, 115°/s, is
below the smallest gyro range on offer, 125°/s; 1.5 g below the smallest accelerometer range, 2 g), so a body
resting or turning slowly on a coarse sensor is not mistaken for a clipped one.

The estimators flag such samples (``FLAG_SATURATED``) and do not take the clipped gyro reading for the rate:
:func:`bridged` replaces a clipped run by the cubic that continues the readings on either side (the top of the
peak the range cut off), and after a run too long to bridge (:data:`LONG_CLIP`) the
:class:`~strapdown.fusion.AttitudeEstimator` restarts its inclination and heading, so that gravity and the field
pull the attitude back within seconds (its module notes, step 7; :func:`restarts`).  Measured on simulated
handheld motion with a gyro clipping at 400°/s (tests/fusion/test_saturation.py): 5 s after the flicks, bridging
leaves the error within 1.5 times the unclipped run's, where restarting after every short run cost more than it
gave (the restarted mean begins inside the flick's 2 g jolt) and ignoring the clip left 1.3 times the bridged error
in 9D.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ACC_FLOOR", "GYRO_FLOOR", "saturated"]

GYRO_FLOOR = 2.0  # rad/s: an extreme below this is not a gyro's range (the smallest on offer is 125°/s)

ACC_FLOOR = 1.5 * 9.80665  # m/s²: an extreme below this is not an accelerometer's range (the smallest is 2 g)


def saturated(values, limit: float = 0.0, *, floor: float = GYRO_FLOOR, min_run: int = 3) -> np.ndarray:
    """Which samples have a component pinned at the sensor's range limit.

    Parameters
    ----------
    values : array_like, shape (N, 3)
        Readings (NaN rows, no sample, are never saturated).
    limit : float
        The full-scale range in the units of ``values`` when known: a component with ``|v| >= limit (1 - 1e-3)``
        is clipped (within a thousandth: a quantised range stops an LSB or so short).  0 (the default): found
        from the readings, runs of ``min_run`` or more consecutive identical
        readings at an axis's largest or smallest value over ``values``, when that value is ``floor`` or more in
        magnitude.  ``inf``: never.
    floor : float
        The smallest magnitude taken as a range when ``limit`` is 0 (:data:`GYRO_FLOOR`, :data:`ACC_FLOOR`).
    min_run : int
        The shortest run of identical readings at the extreme taken as clipped when ``limit`` is 0.

    Returns
    -------
    numpy.ndarray of bool, shape (N,)
        True where some component is clipped.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion.saturation import saturated
    >>> w = np.zeros((8, 3))
    >>> w[2:6, 0] = 7.15            # pinned for four samples
    >>> w[7, 1] = 3.0               # a single large reading is not a run
    >>> saturated(w).astype(int)
    array([0, 0, 1, 1, 1, 1, 0, 0])
    >>> saturated(w, limit=np.radians(2000)).any()
    np.False_
    """
    return pinned(values, limit, floor=floor, min_run=min_run).any(axis=-1)


def pinned(values, limit: float = 0.0, *, floor: float = GYRO_FLOOR, min_run: int = 3) -> np.ndarray:
    """Which components are pinned at the range limit, shape (N, 3): :func:`saturated` per component."""
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 2 or v.shape[-1] != 3:
        raise ValueError(f"values must have shape (N, 3), got {v.shape}")
    found = clipped_components(v, limit, floor, min_run)
    return np.zeros(v.shape, dtype=bool) if found is None else found


def clipped_components(v: np.ndarray, limit: float, floor: float, min_run: int = 3) -> np.ndarray | None:
    """:func:`pinned` of an (N, 3) float64 array, or None when nothing is (the estimators' fast path)."""
    if not limit >= 0:
        raise ValueError(f"limit must be a range >= 0 (0: found from the readings, inf: never), got {limit!r}")
    n = v.shape[0]
    if n == 0 or limit == np.inf or (limit == 0 and n < min_run):
        return None
    from .._support.uncompiled import call
    from ._saturation_numba import pinned_at_extremes

    v = np.ascontiguousarray(v)
    args = (v, float(limit), float(floor), int(min_run))
    # a pass that only answers whether anything is pinned: no mask unless something is (nearly never)
    seconds = 3e-6 * n  # uncompiled, a first call's (_support/uncompiled.py)
    if not call(pinned_at_extremes, *args, _NO_MASK, python_seconds=seconds):
        return None
    out = np.zeros((n, 3), dtype=bool)
    call(pinned_at_extremes, *args, out, python_seconds=seconds)
    return out


_NO_MASK = np.zeros((0, 3), dtype=bool)


def bridged(values, clipped: np.ndarray) -> np.ndarray:
    """Clipped components replaced by the cubic that continues the readings on either side (C¹ across the run).

    A clipped run of a smooth rate is the top of a peak: the cubic Hermite curve through the last reading before
    the run and the first after, with their slopes (differences of two readings), overshoots the range as the
    peak did (a parabola's exactly: slope times run length over 4), so the lost turn is mostly given back.
    A run at either end of the array is held at the limit.  The samples are taken as evenly spaced.
    """
    v = np.array(values, dtype=np.float64)
    n = v.shape[0]
    for axis in range(3):
        at = clipped[:, axis]
        if not at.any():
            continue
        edges = np.diff(np.concatenate([[0], at.view(np.int8), [0]]))
        for b, e in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1), strict=True):
            if b < 2 or e + 1 >= n:
                continue
            y0, y1 = v[b - 1, axis], v[e, axis]
            s0, s1 = v[b - 1, axis] - v[b - 2, axis], v[e + 1, axis] - v[e, axis]
            length = e - b + 1  # intervals from sample b - 1 to sample e
            u = np.arange(1, length) / length
            h00, h10, h01, h11 = 2 * u**3 - 3 * u**2 + 1, u**3 - 2 * u**2 + u, -2 * u**3 + 3 * u**2, u**3 - u**2
            fill = h00 * y0 + h10 * s0 * length + h01 * y1 + h11 * s1 * length
            # never below the limit in magnitude: a reading there was at least that
            v[b:e, axis] = np.where(np.abs(fill) > np.abs(v[b:e, axis]), fill, v[b:e, axis])
    return v


LONG_CLIP = 0.5  # s: a clipped run this long is past bridging; the estimators restart their inclination and heading


def restarts(clipped: np.ndarray, dts: np.ndarray, carried: float) -> tuple[np.ndarray, float]:
    """Where an estimator restarts after long clipped runs: (sample indices, seconds of the run at the end).

    A run restarts the inclination and heading where it has lasted :data:`LONG_CLIP` and again at its first
    unclipped sample.  ``dts``: each sample's interval (compact: the first's, then every later one's);
    ``carried``: seconds of a run under way at the start (0 for none), as the last call returned.
    """
    n = clipped.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.int64), carried
    h = dts if len(dts) == n else np.r_[dts[:1], np.full(n - 1, dts[-1])]
    edges = np.diff(np.concatenate([[0], clipped.view(np.int8), [0]]))
    starts, ends = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    cuts = []
    if carried >= LONG_CLIP and not clipped[0]:
        cuts.append(0)
    last = 0.0
    for b, e in zip(starts, ends, strict=True):
        before = carried if b == 0 else 0.0
        seconds = before + np.cumsum(h[b:e])
        if seconds[-1] >= LONG_CLIP:
            if before < LONG_CLIP:
                cuts.append(b + int(np.searchsorted(seconds, LONG_CLIP * (1.0 - 1e-9))))
            if e < n:
                cuts.append(e)
        last = seconds[-1] if e == n else 0.0
    return np.asarray(cuts, dtype=np.int64), float(last)
