"""Allan analysis of a sensor at rest: angle random walk, bias instability and rate random walk.

IEEE Std 952-1997 (Annex C) ties each noise of a gyro to a slope of the Allan deviation σ(τ):

* angle random walk N (rate PSD N², two-sided): ``σ² = N²/τ``, slope -1/2, read at τ = 1 s;
* bias instability B (rate PSD ``B²/(2π f)``, flicker): ``σ² = (2 ln 2/π) B²``, slope 0, the floor ``0.664 B``;
* rate random walk K (rate PSD ``(K/2π)²/f²``): ``σ² = K² τ/3``, slope +1/2, read at τ = 3 s.

Their Allan variances add, so instead of reading each off a hand-drawn line the three are fitted together:
``σ²(τ) = N²/τ + (2 ln 2/π) B² + K² τ/3`` is linear in (N², B², K²) and is solved by weighted least squares
over octave-spaced τ with every coefficient non-negative (the best of the 7 subsets of terms).  The weight of
a point is the inverse variance of its Allan-variance estimate, ``2 σ⁴ / ν`` with ν the equivalent degrees of
freedom of the overlapping estimator for the noises present there (the fewest, NIST SP 1065 §5.3), iterated with the
fitted curve.  The points share data, so the 95 % confidence intervals (±1.96 standard errors on N², B², K²)
use an error no smaller than that of the single point telling the coefficient best.  Units
are the signal's: for a gyro in rad/s, N in rad/√s (= rad/s/√Hz), B in rad/s, K in rad/s/√s.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from .._support import validate as _v
from ..simulate.models import ImuModel, TriadModel
from ._calibration import Calibration, sensor_name

__all__ = ["AllanAnalysis", "allan"]

_FLICKER = 2 * np.log(2) / np.pi  # σ² of bias instability per B² (IEEE Std 952 Table C.1)
_Z95 = 1.959963984540054
# The octave-spaced points are estimated from the same data, so errors that take them as independent are too
# small: 1.5 brings the 95 % intervals to 95-100 % coverage in the Monte Carlo of benchmarks/bench_calibrate.py
# (white, flicker and random walk together at two levels; without it the rate random walk's was 88 %).
_CORRELATION = 1.5


@dataclass(frozen=True, eq=False)
class AllanAnalysis:
    """The Allan curve of a signal at rest and the noise terms read off it (per axis).

    Attributes
    ----------
    taus : numpy.ndarray, shape (T,)
        Averaging times, s (octaves of the sample period).
    adev : numpy.ndarray, shape (T, c)
        Allan deviation, units of the signal.
    arw, bias_instability, rate_random_walk : numpy.ndarray, shape (c,)
        N (units·√s), B (units), K (units/√s); 0 where a term is not seen.
    arw_interval, bias_instability_interval, rate_random_walk_interval : numpy.ndarray, shape (c, 2)
        95 % confidence intervals.
    fitted : numpy.ndarray, shape (T, c)
        The Allan deviation of the fitted model.
    mean : numpy.ndarray, shape (c,)
        Mean of the signal (a gyro's bias at rest).
    fs : float
        Sample rate, Hz.
    units : str
        Units of the signal.
    n : int
        Number of samples.
    """

    taus: np.ndarray
    adev: np.ndarray
    arw: np.ndarray
    bias_instability: np.ndarray
    rate_random_walk: np.ndarray
    arw_interval: np.ndarray
    bias_instability_interval: np.ndarray
    rate_random_walk_interval: np.ndarray
    fitted: np.ndarray
    mean: np.ndarray
    fs: float
    units: str
    n: int = 0

    def triad_model(self, *, bias: bool = True):
        """A :class:`strapdown.simulate.TriadModel` with this sensor's white noise and rate random walk.

        The model has one figure per term for all axes, the root mean square over the axes.  Flicker noise
        is not simulated: the bias instability is left out (it shows in ``bias_instability``).

        Parameters
        ----------
        bias : bool
            Use the mean of the signal as the constant bias.
        """
        return TriadModel(
            bias=self.mean if bias else np.zeros(3),
            noise_density=float(np.sqrt(np.mean(self.arw**2))),
            bias_random_walk=float(np.sqrt(np.mean(self.rate_random_walk**2))),
        )

    def imu_model(self, *, sensor: str = "gyro", bias: bool = True):
        """A :class:`strapdown.simulate.ImuModel` whose ``sensor`` ("gyro", "acc" or "mag") is :meth:`triad_model`."""
        sensor = "acc" if sensor == "accel" else sensor_name(sensor)  # the names of release 0.1 too
        _v.choice(sensor, "sensor", ("gyro", "acc", "mag"))
        return ImuModel(**{sensor: self.triad_model(bias=bias)})

    def estimator_params(self) -> dict:
        """Noise parameters of :class:`strapdown.fusion.AttitudeParams` measured on this gyro (rad/s·√s).

        ``bias_noise_rest`` is the noise density of a bias read at rest: the gyro's white noise N, since a mean
        over T seconds scatters by N/√T.  Use as ``AttitudeParams(**analysis.estimator_params())``.
        """
        return {"bias_noise_rest": float(np.sqrt(np.mean(self.arw**2)))}

    @property
    def duration(self) -> float:
        """Length of the record, s (the longest τ is a quarter of it by default)."""
        return float(self.n / self.fs)

    def calibration(self, *, sensor: str = "gyro", frame: str = "sensor"):
        """The mean at rest as a bias-only :class:`~strapdown.calibrate.Calibration`.

        Its sigma is the white-noise level ``N/√T`` of a mean over the record's T seconds, as for
        :func:`~strapdown.calibrate.gyroscope`'s bias from rests; a wandering bias (B, K) moves the mean of
        another record by more, about the Allan deviation at that record's length.
        """
        t = self.duration
        sigma = self.arw / np.sqrt(t)
        if self.mean.shape != (3,):
            raise ValueError(f"a calibration needs three axes; this analysis has {self.mean.shape[0]}")
        quality = {"duration_s": t, "arw": self.arw, "bias_instability": self.bias_instability}
        quality["rate_random_walk"] = self.rate_random_walk
        return Calibration(
            sensor,
            offset=self.mean,
            matrix=np.eye(3),
            frame=frame,
            offset_sigma=sigma,
            matrix_sigma=np.zeros((3, 3)),
            quality=quality,
            method="mean at rest (Allan analysis)",
        )

    def apply(self, readings) -> np.ndarray:
        """Readings with the mean at rest (the bias) removed: ``self.calibration().apply(readings)``."""
        return self.calibration().apply(readings)

    def table(self) -> str:
        """The three terms per axis with their 95 % intervals, as text."""
        rows = [f"{'axis':<5} {'ARW N':>30} {'bias instability B':>30} {'rate random walk K':>30}"]
        for i in range(self.arw.shape[0]):
            cells = []
            for value, interval in (
                (self.arw, self.arw_interval),
                (self.bias_instability, self.bias_instability_interval),
                (self.rate_random_walk, self.rate_random_walk_interval),
            ):
                cells.append(f"{value[i]:.3e} [{interval[i, 0]:.2e}, {interval[i, 1]:.2e}]")
            rows.append(f"{i:<5} " + " ".join(f"{c:>30}" for c in cells))
        return "\n".join(rows) + f"\n(units: N {self.units}·√s, B {self.units}, K {self.units}/√s)"


def _edf(n: int, m: np.ndarray) -> np.ndarray:
    """Equivalent degrees of freedom of the overlapping Allan variance for white, flicker and random-walk FM.

    Howe, Allan & Barnes 1981, as tabulated in NIST SP 1065 (Riley 2008) §5.3, with n = N + 1 phase points.
    """
    m = m.astype(np.float64)
    n = float(n + 1)
    white = (3 * (n - 1) / (2 * m) - 2 * (n - 2) / n) * 4 * m**2 / (4 * m**2 + 5)
    flicker = np.where(m == 1, 2 * (n - 2) ** 2 / (2.3 * n - 4.9), 5 * n**2 / (4 * m * (n + 3 * m)))
    walk = (n - 2) / m * ((n - 1) ** 2 - 3 * m * (n - 1) + 4 * m**2) / (n - 3) ** 2
    return np.maximum(np.column_stack([white, flicker, walk]), 1.0)


def _fit_axis(taus, avar, edf_by_type):
    """Non-negative weighted least squares of avar = N²/τ + (2 ln 2/π) B² + K² τ/3.

    Returns the coefficients (N², B², K²), their standard errors and the fitted curve.  Each point's weight
    is ν/(2σ⁴) with ν the fewest degrees of freedom among the noises that make at least a tenth of the fitted
    curve there.  The points
    share data, so the fit's standard errors are too small: they are taken as no smaller than from the single
    point that tells the coefficient best (all other terms known), and widened by ``_CORRELATION``.
    """
    design = np.column_stack([1 / taus, np.full_like(taus, _FLICKER), taus / 3])  # columns: N², B², K²
    var = avar.copy()
    edf = edf_by_type[:, 0]
    best = None
    for _ in range(4):  # weights from the fitted curve, not from the noisy points themselves
        weight = edf / (2 * np.maximum(var, 1e-300) ** 2)
        best = None
        for size in (3, 2, 1):
            for cols in combinations(range(3), size):
                x = design[:, cols]
                info = x.T @ (x * weight[:, None])
                try:
                    coef = np.linalg.solve(info, x.T @ (weight * avar))
                except np.linalg.LinAlgError:
                    continue
                if np.any(coef < 0):
                    continue
                chi2 = float(np.sum(weight * (avar - x @ coef) ** 2))
                if best is None or chi2 < best[0]:
                    full = np.zeros(3)
                    full[list(cols)] = coef
                    cov = np.zeros((3, 3))
                    cov[np.ix_(cols, cols)] = np.linalg.inv(info)
                    best = (chi2, full, cov)
            if best is not None and size == 3:
                break  # all three terms non-negative: that is the least-squares answer
        terms = design * best[1]
        var = np.maximum(terms.sum(axis=1), 1e-300)
        # the fewest degrees of freedom among the noises that make a tenth or more of the variance there
        present = terms >= 0.1 * var[:, None]
        edf = np.where(present, edf_by_type, np.inf).min(axis=1)
        edf = np.where(np.isfinite(edf), edf, edf_by_type[:, 0])
    # Standard errors from the unconstrained three-term fit (a term fitted to zero still has an upper bound)
    info = design.T @ (design * weight[:, None])
    full = np.linalg.lstsq(info, design.T @ (weight * avar), rcond=None)[0]
    fit_sigma = np.sqrt(np.maximum(np.diag(np.linalg.pinv(info)), 0.0))
    # error of each coefficient from each point alone, with the larger of the fitted and the measured variance
    # and the fewest degrees of freedom of any noise type there: a term fitted to zero may still be present
    single = np.sqrt(2 * np.maximum(var, avar) ** 2 / edf_by_type.min(axis=1))[:, None] / design
    sigma = _CORRELATION * np.maximum(fit_sigma, single.min(axis=0))
    return best[1], sigma, var, np.maximum(full, 0.0)


def _chi2_quantile(p_z: float, nu: np.ndarray) -> np.ndarray:
    """Quantile of χ²(ν) at the standard-normal quantile z (Wilson & Hilferty 1931; no scipy at run time)."""
    h = 2.0 / (9.0 * nu)
    return nu * np.maximum(1.0 - h + p_z * np.sqrt(h), 0.0) ** 3


def _interval(value2, sigma2, unconstrained2):
    """A 95 % interval on a square root from an estimate of the square and its standard error.

    A term seen at more than 1.96 σ is treated as a scaled χ² with ν = 2 (value/σ)² > 7.7 degrees of freedom
    (Satterthwaite 1946), so the interval is asymmetric where few clusters tell it (the rate random walk at
    the longest τ) and ±1.96 σ for many.  A term not seen that clearly reaches down to 0:
    [0, √(max(value, u) + 1.96 σ)], u the unconstrained least-squares estimate.
    """
    seen = value2 > _Z95 * sigma2
    nu = np.where(seen, 2.0 * (value2 / np.maximum(sigma2, 1e-300)) ** 2, 8.0)
    lo = np.where(seen, nu * value2 / _chi2_quantile(_Z95, nu), 0.0)
    hi_seen = nu * value2 / np.maximum(_chi2_quantile(-_Z95, nu), 1e-300)
    hi = np.where(seen, hi_seen, np.maximum(value2, unconstrained2) + _Z95 * sigma2)
    return np.stack([np.sqrt(lo), np.sqrt(hi)], axis=-1)


def allan(x, fs: float, *, units: str = "rad/s", max_cluster_fraction: float = 0.25) -> AllanAnalysis:
    """Read angle random walk, bias instability and rate random walk off the Allan curve of a signal at rest.

    Parameters
    ----------
    x : array_like, shape (N,) or (N, c)
        Samples at rest, one column per axis (a single signal counts as one axis): a gyro in rad/s, an
        accelerometer in m/s², ..., uniformly at ``fs``; hours of data
        are needed to see the rate random walk of a good sensor.
    fs : float
        Sample rate, Hz.
    units : str
        Units of x, for the report.
    max_cluster_fraction : float
        Largest averaging time as a fraction of the record (default 1/4: at least 3 cluster pairs).

    Returns
    -------
    AllanAnalysis
        The curve, N, B and K per axis with 95 % confidence intervals; ``imu_model()`` and
        ``estimator_params()`` hand them to the simulator and the estimators.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import allan
    >>> rng = np.random.default_rng(0)
    >>> gyro = 1e-3 * np.sqrt(100.0) * rng.standard_normal((200_000, 3))     # white noise, N = 1e-3 rad/√s
    >>> result = allan(gyro, fs=100.0)
    >>> np.round(result.arw, 5)
    array([0.001, 0.001, 0.001])
    >>> bool(np.all((result.arw_interval[:, 0] < 1e-3) & (1e-3 < result.arw_interval[:, 1])))
    True
    """
    arr = _v.as_float_array(x, "x", dtype=np.float64)
    if arr.ndim not in (1, 2):
        raise ValueError(f"x must have shape (N,) or (N, c), got shape {arr.shape}")
    _v.check_finite(arr, "x")
    arr = arr[:, None] if arr.ndim == 1 else arr  # one signal: one axis
    n = arr.shape[0]
    if n < 64:
        raise ValueError(f"x has {n} samples; the Allan analysis needs at least 64 (hours for the slow terms)")
    fs = float(_v.finite(fs, "fs", dtype=np.float64))
    if not fs > 0:
        raise ValueError(f"fs is {fs}; it must be positive (Hz)")
    if not 0 < max_cluster_fraction <= 0.5:
        raise ValueError(f"max_cluster_fraction is {max_cluster_fraction}; it must be in (0, 0.5]")
    sizes = 2 ** np.arange(int(np.floor(np.log2(max(n * max_cluster_fraction, 1)))) + 1)
    taus, adev = allan_deviation(arr, fs, sizes / fs)
    edf = _edf(n, sizes)
    c = arr.shape[1]
    coef = np.zeros((c, 3))
    sig = np.zeros((c, 3))
    free = np.zeros((c, 3))
    fitted = np.zeros_like(adev)
    for i in range(c):
        coef[i], sig[i], var, free[i] = _fit_axis(taus, adev[:, i] ** 2, edf)
        fitted[:, i] = np.sqrt(var)
    intervals = [_interval(coef[:, k], sig[:, k], free[:, k]) for k in range(3)]
    values = np.sqrt(coef)
    return AllanAnalysis(
        taus=taus,
        adev=adev,
        arw=values[:, 0],
        bias_instability=values[:, 1],
        rate_random_walk=values[:, 2],
        arw_interval=intervals[0],
        bias_instability_interval=intervals[1],
        rate_random_walk_interval=intervals[2],
        fitted=fitted,
        mean=arr.mean(axis=0),
        fs=fs,
        units=units,
        n=n,
    )


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
    >>> from strapdown.calibrate import allan_deviation
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
    # The deviation is linear in x, so each signal is scaled by a power of two (exact) to a peak in [0.5, 1):
    # the squares below cannot overflow (x ~ 1e200 gave inf) or underflow.  In sample units (θ without the 1/fs,
    # τ = m) fs cancels from d²/τ², so it cannot under- or overflow them either.
    _, e = np.frexp(np.max(np.abs(arr), axis=0))
    scaled = np.ldexp(arr, -e)
    centred = scaled - scaled.mean(axis=0)
    theta = np.zeros((n + 1, *arr.shape[1:]))
    np.cumsum(centred, axis=0, out=theta[1:])
    adev = np.empty((sizes.shape[0], *arr.shape[1:]))
    for i, m in enumerate(sizes):
        stride = 1 if overlapping else m
        d = theta[2 * m :: stride] - 2 * theta[m : n + 1 - m : stride] + theta[: n + 1 - 2 * m : stride]
        adev[i] = np.sqrt(np.mean(d**2, axis=0) / (2.0 * m * m))
    with np.errstate(over="ignore"):
        adev = np.ldexp(adev, e)
    if not np.isfinite(adev).all():
        raise ValueError(f"the Allan deviation of x exceeds the largest float64: x reaches {np.abs(arr).max():.3g}")
    return sizes / fs, adev
