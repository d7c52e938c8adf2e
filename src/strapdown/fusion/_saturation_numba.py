"""Numba kernel of :mod:`strapdown.fusion.saturation` (private): readings pinned at an axis's extreme."""

from __future__ import annotations

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)


@nb.njit(cache=True)
def pinned_at_extremes(v, floor, min_run, out):
    """Mark the pinned runs in ``out`` (N, 3); returns whether there are any.

    A run: ``min_run`` or more identical readings at an axis's largest or smallest value over ``v`` (NaN
    ignored), where that value is ``floor`` or more in magnitude.

    One pass finds the extremes (numpy's reductions along the short axis cost more than the filters), a second
    runs only where an extreme is large enough to be a range.
    """
    n = v.shape[0]
    top = np.full(3, -np.inf)
    bottom = np.full(3, np.inf)
    for k in range(n):
        for a in range(3):
            x = v[k, a]
            if x > top[a]:
                top[a] = x
            if x < bottom[a]:
                bottom[a] = x
    found = False
    for a in range(3):
        for extreme in (top[a], bottom[a]):
            if not abs(extreme) >= floor or not np.isfinite(extreme):
                continue
            run = 0
            for k in range(n + 1):
                if k < n and v[k, a] == extreme:
                    run += 1
                    continue
                if run >= min_run:
                    found = True
                    for j in range(k - run, k):
                        out[j, a] = True
                run = 0
    return found
