"""A sensor's noise model measured on the recording itself, and the estimator parameters it sets.

Where the sensor is still, its readings are bias plus noise: the scatter of the gyro there is its white noise
(noise density N, rad/s/√Hz = rad/√s, the angle random walk), the accelerometer's its own (m/s²/√Hz).  Per rest,
the first differences x_k+1 - x_k of a white noise of per-sample deviation σ have deviation σ√2, and a slow
wander of the bias or a slow tilt between two samples hardly adds to them, so σ = std(Δx)/√2 and
N = σ / √fs (quantisation adds its LSB²/12, which the filter sees as noise too).  A still stretch of
``allan_time`` seconds or more also gives the Allan analysis (:func:`strapdown.calibrate.allan`): the bias
instability B and the rate random walk K of the gyro.  A calibration file of ``strapdown calibrate allan`` or
``calibrate gyro`` gives the same figures measured on a still recording (:meth:`NoiseModel.from_calibration`).

:meth:`NoiseModel.estimator_params` turns them into parameters by physical rules (its notes).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._support import validate as _v
from ._rests import find_rests

__all__ = ["NoiseModel", "noise_model"]

_DEG = np.pi / 180.0
# The rest detectors compare a sample's squared departure from the 0.5 s mean, summed over the three axes, with
# the threshold²: for white noise of deviation σ per axis that sum is σ² χ²(3), beyond (6σ)² once in 10⁷ samples.
_REST_SIGMAS = 6.0
# The defaults the rules start from (AttitudeParams, TiltParams): a noisier sensor raises the thresholds, never
# lowers them (below them, a hand's tremor would count as rest).
_REST_GYRO, _REST_ACC = 2.0 * _DEG, 0.5
_BIAS_SIGMA_INIT, _FORGETTING = 0.5 * _DEG, 100.0


@dataclass(frozen=True)
class NoiseModel:
    """Noise figures of a gyro (and accelerometer), with where they came from.

    Attributes
    ----------
    gyro_noise_density : float
        White noise N of the gyro, rad/s/√Hz (rms over the axes).
    acc_noise_density : float or None
        White noise of the accelerometer, m/s²/√Hz (None: not measured).
    gyro_bias_instability : float or None
        B, rad/s (Allan analysis of a still stretch; None: not measured).
    gyro_rate_random_walk : float or None
        K, rad/s/√s (likewise).
    fs : float or None
        Sample rate the figures were measured at, Hz.
    seconds : float
        Seconds of still data they come from.
    source : str
        ``"rests"`` (this recording), ``"allan"`` (its longest rest too) or ``"calibration"`` (a file).
    """

    gyro_noise_density: float
    acc_noise_density: float | None = None
    gyro_bias_instability: float | None = None
    gyro_rate_random_walk: float | None = None
    fs: float | None = None
    seconds: float = 0.0
    source: str = "rests"

    def estimator_params(self, estimator: str = "attitude", fs: float | None = None) -> dict:
        """Parameters of the AttitudeEstimator (``"attitude"``) or the TiltEstimator (``"tilt"``) from the noise.

        The rules (``fs``: the rate of the data the estimator runs on, by default the one measured at):

        * ``bias_noise_rest`` = N: a mean over T s at rest tells the bias to N/√T (AttitudeEstimator);
        * ``rest_gyro`` = max(2°/s, 6 N √fs) and ``rest_acc`` = max(0.5 m/s², 6 σ_a √fs): the rest detectors
          compare each sample's departure from its 0.5 s mean with these, and a still sensor's departures are
          its per-sample noise, so a noisier sensor (or a higher rate) would never be found at rest under
          the defaults; the defaults stay the floor;
        * ``bias_forgetting_time`` = min(100 s, (0.5°/s)² / K²): the bias must be allowed to wander at least as
          fast as its measured rate random walk (dP/dt = K²); the default wander, far above a good sensor's,
          stays the floor (it also covers what the model lacks: temperature, scale errors).

        The time constants (``tau_acc``, ``tau_mag``) are not set from the noise: on moving bodies their balance
        is with the linear acceleration and the magnetic disturbances, which a rest cannot show (the white
        noises alone would give tau_acc = σ_a / (g N), about 1 s for a consumer part, shorter than the 3.5 s that
        BROAD's motion needs).

        Examples
        --------
        >>> import numpy as np
        >>> from strapdown.calibrate import NoiseModel
        >>> noisy = NoiseModel(gyro_noise_density=np.radians(0.05), acc_noise_density=0.01, fs=400.0)
        >>> p = noisy.estimator_params()
        >>> round(float(np.degrees(p["rest_gyro"])), 3), round(p["rest_acc"], 3)
        (6.0, 1.2)
        """
        _v.choice(estimator, "estimator", ("attitude", "tilt"))
        rate = self.fs if fs is None else float(fs)
        out = {}
        if estimator == "attitude" and self.gyro_noise_density > 0:
            out["bias_noise_rest"] = float(self.gyro_noise_density)
        if rate:
            out["rest_gyro"] = max(_REST_GYRO, _REST_SIGMAS * self.gyro_noise_density * np.sqrt(rate))
            if self.acc_noise_density:
                out["rest_acc"] = max(_REST_ACC, _REST_SIGMAS * self.acc_noise_density * np.sqrt(rate))
        k = self.gyro_rate_random_walk
        if estimator == "attitude" and k:
            out["bias_forgetting_time"] = min(_FORGETTING, _BIAS_SIGMA_INIT**2 / k**2)
        return {name: float(v) for name, v in out.items()}

    def metadata(self) -> dict:
        """The figures as text, for an output file's metadata (keys ``noise_*``)."""
        items = {
            "noise_source": self.source,
            "noise_seconds": f"{self.seconds:.6g}",
            "noise_gyro_density_rad_s_sqrt_hz": f"{self.gyro_noise_density:.6g}",
            "noise_acc_density_m_s2_sqrt_hz": self.acc_noise_density,
            "noise_gyro_bias_instability_rad_s": self.gyro_bias_instability,
            "noise_gyro_rate_random_walk_rad_s_sqrt_s": self.gyro_rate_random_walk,
            "noise_fs_hz": self.fs,
        }
        return {k: (v if isinstance(v, str) else f"{v:.6g}") for k, v in items.items() if v is not None}

    @classmethod
    def from_calibration(cls, calibration, fs: float | None = None) -> NoiseModel:
        """The noise model a gyro calibration file holds: ``calibrate allan`` or ``calibrate gyro``'s.

        Allan's (its ``quality`` has ``arw``, ``bias_instability``, ``rate_random_walk`` per axis: rms over the
        axes) or the bias from rests (``noise``, the per-sample deviation at rest, over the ``fs`` it was
        measured at: N = σ / √fs).  ``fs`` is the rate of the data it is used on (the rest thresholds).

        Raises
        ------
        ValueError
            If the calibration holds no noise figures, naming what it has.
        """
        q = calibration.quality
        rms = lambda key: float(np.sqrt(np.mean(np.square(np.asarray(q[key], dtype=np.float64)))))  # noqa: E731
        seconds = float(q.get("duration_s", 0.0) or 0.0)
        if "arw" in q:
            bi, rrw = rms("bias_instability"), rms("rate_random_walk")
            return cls(rms("arw"), None, bi or None, rrw or None, fs, seconds, "calibration")
        if "noise" in q and q.get("fs"):
            n = rms("noise") / np.sqrt(float(q["fs"]))
            return cls(n, None, None, None, fs, float(q.get("samples", 0)) / float(q["fs"]), "calibration")
        raise ValueError(
            f"the {calibration.sensor} calibration ({calibration.method or 'no method'}) holds no noise figures "
            f"(its quality has {', '.join(sorted(q)) or 'nothing'}): take one of `strapdown calibrate allan` or "
            "`calibrate gyro` on a still recording"
        )


def noise_model(gyro, acc=None, *, fs: float, rests=None, allan_time: float = 60.0) -> NoiseModel | None:
    """The noise of a gyro (and accelerometer) measured where the recording is still.

    Parameters
    ----------
    gyro : array_like, shape (N, 3)
        Angular rate, rad/s.
    acc : array_like, shape (N, 3), optional
        Specific force, m/s² (its noise, and a better rest detection).
    fs : float
        Sample rate, Hz.
    rests : array_like of shape (K, 2), optional
        ``[start, stop)`` of the still intervals; by default :func:`strapdown.calibrate.find_rests`.
    allan_time : float
        A rest this long or longer also gets the Allan analysis (bias instability, rate random walk).

    Returns
    -------
    NoiseModel or None
        None when the recording has no rest.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import noise_model
    >>> rng = np.random.default_rng(1)
    >>> fs, density = 100.0, np.radians(0.01)           # 0.01°/s/√Hz
    >>> gyro = density * np.sqrt(fs) * rng.standard_normal((6000, 3))
    >>> acc = [0.0, 0.0, 9.81] + 0.002 * np.sqrt(fs) * rng.standard_normal((6000, 3))
    >>> model = noise_model(gyro, acc, fs=fs, allan_time=np.inf)
    >>> round(float(np.degrees(model.gyro_noise_density)), 4), round(model.acc_noise_density, 4)
    (0.01, 0.002)
    """
    g = _v.vectors(gyro, "gyro", dtype=np.float64)
    a = None if acc is None else _v.vectors(acc, "acc", check=False, dtype=np.float64)
    fs = float(_v.finite(fs, "fs", dtype=np.float64))
    if not fs > 0:
        raise ValueError(f"fs is {fs}; it must be positive (Hz)")
    if rests is None:
        usable = a is None or np.isfinite(a).all()
        rests = find_rests(a if usable else None, g, fs=fs)
    rests = np.asarray(rests, dtype=np.int64).reshape(-1, 2)
    rests = rests[rests[:, 1] - rests[:, 0] >= 3]
    if not len(rests):
        return None
    n_gyro, n_acc, count = 0.0, 0.0, 0
    for start, stop in rests:
        n_gyro += np.sum(np.diff(g[start:stop], axis=0) ** 2) / 2.0
        if a is not None:
            n_acc += np.nansum(np.diff(a[start:stop], axis=0) ** 2) / 2.0
        count += stop - start - 1
    sigma_g = np.sqrt(n_gyro / (3 * count))
    sigma_a = np.sqrt(n_acc / (3 * count)) if a is not None else None
    seconds = float(np.sum(rests[:, 1] - rests[:, 0]) / fs)
    longest = rests[np.argmax(rests[:, 1] - rests[:, 0])]
    bi = rrw = None
    source = "rests"
    if (longest[1] - longest[0]) / fs >= allan_time:
        from ._allan import allan

        analysis = allan(g[longest[0] : longest[1]], fs)
        bi = float(np.sqrt(np.mean(analysis.bias_instability**2))) or None
        rrw = float(np.sqrt(np.mean(analysis.rate_random_walk**2))) or None
        source = "allan"
    return NoiseModel(
        float(sigma_g / np.sqrt(fs)),
        None if sigma_a is None else float(sigma_a / np.sqrt(fs)),
        bi,
        rrw,
        fs,
        seconds,
        source,
    )
