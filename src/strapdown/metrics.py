"""Error metrics and signal statistics (attitude errors, sensor noise characterisation).

Conventions: signals are float arrays with time on the first axis, sampled uniformly at ``fs`` Hz; times and
averaging intervals τ are in seconds; results are float64.  Invalid input raises a ``ValueError`` naming the
argument.
"""

from __future__ import annotations

import numpy as np

from . import _validate as _v

__all__ = ["allan_deviation"]


def _cluster_sizes(n: int, fs: float, taus) -> np.ndarray:
    """Cluster sizes m (samples per averaging interval) for `taus`, or the default log-spaced set."""
    if taus is None:
        top = max(1, n // 10)
        return np.unique(np.round(np.logspace(0, np.log10(top), 30)).astype(np.int64))
    tau = _v.finite(taus, "taus", dtype=np.float64)
    if tau.ndim > 1:
        raise ValueError(f"taus must be a scalar or have shape (T,), got shape {tau.shape}")
    tau = np.atleast_1d(tau)
    m = np.round(tau * fs).astype(np.int64)
    bad = (m < 1) | (m > n // 2)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"taus[{i}] is {tau[i]} s; averaging times must lie between 1/fs = {1 / fs} s and "
            f"(N // 2)/fs = {(n // 2) / fs} s for N = {n} samples"
        )
    return m


def allan_deviation(x, fs: float, taus=None, *, overlapping: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Allan deviation of a rate signal (a gyro's deg/s, an accelerometer's m/s², any sampled quantity).

    Parameters
    ----------
    x : array_like, shape (N,) or (N, c)
        N samples at ``fs`` Hz of one signal or of c signals (for example the three axes of a gyro).
    fs : float
        Sample rate (Hz).
    taus : array_like, shape (T,), optional
        Averaging times (s), each rounded to a whole number m of samples with ``1 <= m <= N // 2``.  By default
        about 30 log-spaced cluster sizes from 1 sample to N/10 samples (fewer when N is small, as sizes are
        whole numbers and repeats are dropped).
    overlapping : bool
        Use every start sample (the overlapping estimator, the default and the more efficient one); otherwise
        only the non-overlapping clusters starting at multiples of m.

    Returns
    -------
    taus : numpy.ndarray, shape (T,)
        The averaging times used, ``m / fs``.
    adev : numpy.ndarray, shape (T,) or (T, c)
        Allan deviation, in the units of x.  With θ the running integral of x (θ_0 = 0, θ_k the sum of the first
        k samples over fs) and τ = m/fs::

            adev(τ)² = Σ_k (θ_{k+2m} - 2θ_{k+m} + θ_k)² / (2 τ² K)

        over the K = N + 1 - 2m starts k = 0, 1, ..., N - 2m (overlapping) or the K = N // m - 1 starts
        k = 0, m, 2m, ... (non-overlapping).  Each term is the difference of the means of two adjacent
        clusters of m samples.  Reading the curve: white noise of density D gives D/√τ (slope -1/2, the value
        at τ = 1 s is D), a rate random walk K gives K √(τ/3) (slope +1/2), a constant bias gives nothing.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.metrics import allan_deviation
    >>> x = np.array([1.0, -1.0] * 50)                       # alternating: the two-sample pairs cancel
    >>> taus, adev = allan_deviation(x, fs=10.0, taus=[0.1, 0.2])
    >>> taus, adev
    (array([0.1, 0.2]), array([1.41421356, 0.        ]))
    >>> rng = np.random.default_rng(0)
    >>> taus, adev = allan_deviation(rng.standard_normal((100_000, 3)), fs=100.0)
    >>> taus.shape, adev.shape, float(taus[0]), float(taus[-1])
    ((29,), (29, 3), 0.01, 100.0)
    """
    arr = _v.as_float_array(x, "x", dtype=np.float64)
    if arr.ndim not in (1, 2):
        raise ValueError(f"x must have shape (N,) or (N, c), got shape {arr.shape}")
    _v.check_finite(arr, "x")
    n = arr.shape[0]
    if n < 2:
        raise ValueError(f"x has {n} sample(s); the Allan deviation needs at least 2")
    fs_arr = _v.finite(fs, "fs", dtype=np.float64)
    if fs_arr.ndim != 0 or not fs_arr > 0:
        raise ValueError(f"fs must be a positive scalar (Hz), got {fs_arr}")
    fs = float(fs_arr)
    sizes = _cluster_sizes(n, fs, taus)

    # The Allan variance ignores a constant offset (the second difference of a line is zero); removing the mean
    # first keeps the running sum small, so the differences of its far-apart values lose no digits.
    centred = arr - arr.mean(axis=0)
    theta = np.zeros((n + 1, *arr.shape[1:]))
    np.cumsum(centred, axis=0, out=theta[1:])
    theta /= fs
    adev = np.empty((sizes.shape[0], *arr.shape[1:]))
    for i, m in enumerate(sizes):
        stride = 1 if overlapping else m
        d = theta[2 * m :: stride] - 2 * theta[m : n + 1 - m : stride] + theta[: n + 1 - 2 * m : stride]
        tau = m / fs
        adev[i] = np.sqrt(np.mean(d**2, axis=0) / (2 * tau**2))
    return sizes / fs, adev
