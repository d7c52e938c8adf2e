"""Arrays handed out again once nothing else refers to them: the file pipelines' per-chunk memory (private).

A file command makes a few large arrays per chunk of 2^18 rows (2-15 MB each: the output columns, the row
times, the gyro samples of a step).  Each fresh one comes from the kernel as new pages, zeroed on first touch,
and goes back when it is freed: on the 2-core machine the columns kernel took 11.3 ms per chunk into fresh
blocks against 5.0 ms into one reused block (``/tmp`` micro-benchmark, noted in ``notes/h-io3.md``).

An array is reused only when the pool holds the only reference to it (CPython's reference count, which views
raise through their base): a background writer still encoding a chunk, a view a caller kept, a MATLAB writer
gathering its parts, all keep their arrays out of reach, and the pool then makes a new one.
"""

from __future__ import annotations

import sys

import numpy as np


def _references_when_free() -> int:
    """``sys.getrefcount`` of a pooled array nobody else holds, seen from the loop in :meth:`Blocks.take`."""
    probe = [np.empty(0)]
    for array in probe:
        return sys.getrefcount(array)
    raise AssertionError("unreachable")


_FREE = _references_when_free()


class Blocks:
    """A pool of arrays: :meth:`take` returns one of the shape and type asked for that nobody else refers to.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io._blocks import Blocks
    >>> pool = Blocks()
    >>> a = pool.take((2, 3), np.float64)
    >>> pool.take((2, 3), np.float64) is a        # still held here: a new one
    False
    >>> del a
    >>> pool.take((2, 3), np.float64).shape       # one of the two, now free
    (2, 3)
    """

    def __init__(self, limit: int = 12):
        self._arrays: list[np.ndarray] = []
        self.limit = limit

    def take(self, shape: tuple, dtype) -> np.ndarray:
        """An uninitialised array of ``shape`` and ``dtype``: a free pooled one, else a new one (pooled if room)."""
        dtype = np.dtype(dtype)
        for array in self._arrays:
            if sys.getrefcount(array) <= _FREE and array.shape == shape and array.dtype == dtype:
                return array
        array = np.empty(shape, dtype)
        if len(self._arrays) >= self.limit:  # make room: drop a free array (of another shape), if there is one
            for i, old in enumerate(self._arrays):
                if sys.getrefcount(old) <= _FREE:
                    del self._arrays[i], old
                    break
        if len(self._arrays) < self.limit:
            self._arrays.append(array)
        return array
