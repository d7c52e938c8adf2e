"""Numba kernel of :mod:`strapdown.fusion.saturation` (private): readings pinned at the range limit."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)


@nb.njit(cache=True, error_model="numpy")
def pinned_at_extremes(v, limit, floor, min_run, out):
    """Whether any component of ``v`` (N, 3) is pinned; with ``out`` of N rows, also which (marked in it).

    ``limit`` > 0: a component with ``|v| >= limit (1 - 1e-3)`` is pinned.  0: a run of ``min_run`` or more
    identical readings at an axis's largest or smallest value over ``v`` (NaN ignored), where that value is
    ``floor`` or more in magnitude.

    The estimators call it on every update with an ``out`` of no rows, and nearly every chunk has nothing pinned,
    so that answer must cost little more than reading ``v`` once: a branch-free pass finds the six extremes (the
    processor runs it at the speed of memory); only where one is large enough to be a range does a second count
    how often it occurs, and only where it occurs ``min_run`` times does a third look for runs.  The mask is
    made by a second call with ``out`` of N rows (the same types: no second compilation).
    """
    n = v.shape[0]
    mark = out.shape[0] == n and n > 0
    if limit > 0.0:
        bound = limit * (1.0 - 1e-3)
        found = False
        for k in range(n):
            for a in range(3):
                if abs(v[k, a]) >= bound:
                    if not mark:
                        return True
                    out[k, a] = True
                    found = True
        return found
    # 1. the extremes (NaN never replaces one)
    t0 = t1 = t2 = -np.inf
    b0 = b1 = b2 = np.inf
    for k in range(n):
        x0, x1, x2 = v[k, 0], v[k, 1], v[k, 2]
        t0 = x0 if x0 > t0 else t0
        t1 = x1 if x1 > t1 else t1
        t2 = x2 if x2 > t2 else t2
        b0 = x0 if x0 < b0 else b0
        b1 = x1 if x1 < b1 else b1
        b2 = x2 if x2 < b2 else b2
    e = np.array([t0, t1, t2, b0, b1, b2])  # axis i % 3
    for i in range(6):
        if not (abs(e[i]) >= floor and math.isfinite(e[i])):
            e[i] = np.nan  # no range: matches nothing below
    if not (e == e).any():
        return False
    # 2. how often each candidate occurs: a run of min_run needs that many
    t0, t1, t2, b0, b1, b2 = e[0], e[1], e[2], e[3], e[4], e[5]
    c0 = c1 = c2 = c3 = c4 = c5 = 0
    for k in range(n):
        x0, x1, x2 = v[k, 0], v[k, 1], v[k, 2]
        c0 += x0 == t0
        c1 += x1 == t1
        c2 += x2 == t2
        c3 += x0 == b0
        c4 += x1 == b1
        c5 += x2 == b2
    counts = (c0, c1, c2, c3, c4, c5)
    found = False
    # 3. the runs
    for i in range(6):
        if counts[i] < min_run:
            continue
        a = i % 3
        extreme = e[i]
        run = 0
        for k in range(n + 1):
            if k < n and v[k, a] == extreme:
                run += 1
                continue
            if run >= min_run:
                found = True
                if not mark:
                    return True
                for j in range(k - run, k):
                    out[j, a] = True
            run = 0
    return found
