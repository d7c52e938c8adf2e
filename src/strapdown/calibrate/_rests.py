"""Finding the still intervals of a recording (rest detection).

A sample is at rest when, over a window centred on it, every accelerometer axis and every gyro axis scatters
less than a threshold, and the gyro's mean is small (so that a steady turn on a turntable, whose readings do
not scatter either, is not taken for rest).  Runs of rest samples at least ``min_duration`` long are the
rests.  The defaults suit MEMS sensors held by hand and then set down: BROAD's breaks are found with them
(``tests/calibrate/test_calibrate_accelerometer.py``).
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from .._support.renamed import renamed

__all__ = ["find_rests"]


def _moving(x: np.ndarray, w: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation (per column) over the window of w samples centred on each sample."""
    n = len(x)
    centred = x - x.mean(axis=0)  # keeps the running sums small: no digits lost in their differences
    c1 = np.zeros((n + 1, x.shape[1]))
    c2 = np.zeros((n + 1, x.shape[1]))
    np.cumsum(centred, axis=0, out=c1[1:])
    np.cumsum(centred**2, axis=0, out=c2[1:])
    lo = np.clip(np.arange(n) - w // 2, 0, n)
    hi = np.clip(lo + w, 0, n)
    lo = np.maximum(hi - w, 0)
    count = (hi - lo)[:, None]
    mean = (c1[hi] - c1[lo]) / count
    var = np.maximum((c2[hi] - c2[lo]) / count - mean**2, 0.0)
    return mean + x.mean(axis=0), np.sqrt(var)


def _triad(x, name: str) -> np.ndarray | None:
    if x is None:
        return None
    arr = _v.as_float_array(x, name, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name} must have shape (N, 3) (one 3-vector per sample), got shape {arr.shape}")
    _v.check_finite(arr, name)
    return arr


@renamed(gyr="gyro")
def find_rests(
    acc=None,
    gyro=None,
    *,
    fs: float,
    window: float = 0.5,
    min_duration: float = 1.0,
    acc_threshold: float = 0.25,
    gyro_threshold: float = 0.02,
    gyro_limit: float = 0.1,
) -> np.ndarray:
    """The still intervals of a recording, from the accelerometer, the gyro or both.

    Parameters
    ----------
    acc : array_like, shape (N, 3), optional
        Specific force, m/s².
    gyro : array_like, shape (N, 3), optional
        Angular rate, rad/s.
    fs : float
        Sample rate, Hz.
    window : float
        Length of the moving window, s.
    min_duration : float
        Shortest rest, s.
    acc_threshold : float
        Largest standard deviation of an accelerometer axis over the window, m/s².
    gyro_threshold : float
        Largest standard deviation of a gyro axis over the window, rad/s (default about 1.1°/s).
    gyro_limit : float
        Largest magnitude of the gyro's mean over the window, rad/s (default about 5.7°/s, above any MEMS
        bias): a steady turn is no rest.

    Returns
    -------
    numpy.ndarray of int, shape (K, 2)
        ``[start, stop)`` sample indices of each rest, in time order.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import find_rests
    >>> rng = np.random.default_rng(0)
    >>> acc = np.tile([0.0, 0.0, 9.81], (600, 1)) + 0.02 * rng.standard_normal((600, 3))
    >>> acc[200:300] += 3 * np.sin(np.linspace(0, 6 * np.pi, 100))[:, None]    # one second of shaking
    >>> find_rests(acc, fs=100.0)
    array([[  0, 179],
           [322, 600]])
    """
    a = _triad(acc, "acc")
    g = _triad(gyro, "gyro")
    if a is None and g is None:
        raise ValueError("find_rests needs acc, gyro or both")
    if a is not None and g is not None and len(a) != len(g):
        raise ValueError(f"acc has {len(a)} samples and gyro {len(g)}; they must be sampled together")
    fs = float(_v.finite(fs, "fs", dtype=np.float64))
    if not fs > 0:
        raise ValueError(f"fs is {fs}; it must be positive (Hz)")
    for name, value in (("window", window), ("min_duration", min_duration)):
        if not float(value) > 0:
            raise ValueError(f"{name} is {value}; it must be positive (s)")
    n = len(a if a is not None else g)
    w = max(2, round(window * fs))
    still = np.ones(n, dtype=bool)
    if a is not None:
        still &= _moving(a, w)[1].max(axis=1) < acc_threshold
    if g is not None:
        mean, std = _moving(g, w)
        still &= (std.max(axis=1) < gyro_threshold) & (np.linalg.norm(mean, axis=1) < gyro_limit)
    edges = np.diff(np.concatenate([[0], still.astype(np.int8), [0]]))
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    keep = (stops - starts) >= min_duration * fs
    return np.column_stack([starts[keep], stops[keep]]).astype(np.int64).reshape(-1, 2)
