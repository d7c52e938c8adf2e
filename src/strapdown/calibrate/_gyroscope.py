"""Gyroscope bias from rests; scale factors and cross-axis coupling from a reference.

The model is that of :class:`strapdown.simulate.TriadModel`: ``r = A ω + b`` with ``A = I + diag(s) + M``.

* **Bias only** (no reference): the mean of the readings over the rests (:func:`find_rests`), where ω is
  the Earth's rotation (15°/h, below the bias of MEMS gyros; it is not removed).
* **Reference** (a turntable's known rates, or a reference attitude from optical tracking or a better IMU
  turned into mean rates over each sample): ``r = A ω_ref + b`` by linear least squares, one axis at a time,
  for all 12 numbers.  Every axis must be turned about for its scale and coupling to be seen.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from .._support.renamed import renamed
from ..rotations.quaternion import canonical, conjugate, log, multiply
from . import _ellipsoid as _e
from . import _linear
from ._calibration import Calibration
from ._magnetometer import InsufficientMotionError
from ._rests import find_rests

__all__ = ["gyroscope", "rates_from_attitude"]

_MIN_RATE = np.radians(10.0)  # rms reference rate needed about every axis, rad/s


def rates_from_attitude(q, fs: float) -> np.ndarray:
    """Mean body rates over each step of a sampled attitude (what an ``"average"`` gyro reads).

    Parameters
    ----------
    q : array_like, shape (N + 1, 4)
        Attitudes (sensor to reference) at the step boundaries, sampled uniformly at ``fs``.
    fs : float
        Sample rate, Hz.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``2 log(q_k* ⊗ q_{k+1}) fs``: the rotation vector of each step over its duration, rad/s.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import rates_from_attitude
    >>> a = np.linspace(0.0, 0.1, 3)                                # 0.05 rad per step about z
    >>> q = np.column_stack([np.cos(a / 2), 0 * a, 0 * a, np.sin(a / 2)])
    >>> rates_from_attitude(q, fs=10.0)
    array([[0. , 0. , 0.5],
           [0. , 0. , 0.5]])
    """
    q = _v.quaternions(q, "reference_attitude", dtype=np.float64)
    if q.ndim != 2 or len(q) < 2:
        raise ValueError(f"reference_attitude must have shape (N + 1, 4) with N >= 1, got shape {q.shape}")
    step = canonical(multiply(conjugate(q[:-1]), q[1:]))
    return 2.0 * log(step)[:, 1:] * float(fs)


@renamed(gyr="gyro")
def gyroscope(
    gyro,
    *,
    fs: float | None = None,
    acc=None,
    rests=None,
    reference_rate=None,
    reference_attitude=None,
    frame: str = "sensor",
    **rest_options,
) -> Calibration:
    """Fit a gyro's bias (from rests) or its bias, scale factors and cross-axis coupling (from a reference).

    Parameters
    ----------
    gyro : array_like, shape (N, 3)
        Angular rate, rad/s, sensor axes ``frame``.
    fs : float, optional
        Sample rate, Hz (to find rests, or to turn ``reference_attitude`` into rates).
    acc : array_like, shape (N, 3), optional
        Accelerometer readings, m/s², to find the rests more surely.
    rests : array_like of int, shape (K, 2), optional
        ``[start, stop)`` of the rests, instead of finding them.
    reference_rate : array_like, shape (N, 3), optional
        True body rates, rad/s (a turntable's), aligned with ``gyro``.
    reference_attitude : array_like, shape (N + 1, 4), optional
        True attitudes at the sample boundaries: gyro sample k is the mean rate from attitude k to k + 1.
    frame : str
        Name of the sensor axes, stored with the calibration.
    **rest_options
        Passed to :func:`find_rests`.

    Returns
    -------
    Calibration
        ``calibrated = matrix @ (gyro - offset)`` with one-sigma uncertainties (white-noise level).  Quality:
        ``noise`` (per-sample scatter, rad/s, per axis) and ``samples``; from rests also ``rests`` and
        ``bias_spread`` (standard deviation of the rests' means about the bias, rad/s: much above
        ``offset_sigma`` means the bias wanders); from a reference also ``scale_factor``, ``misalignment``,
        their sigmas and ``excitation`` (rms reference rate about the principal axes, rad/s).

    Raises
    ------
    InsufficientMotionError
        Without a rest (bias), or when the reference hardly turns about some axis (the message names it).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import gyroscope
    >>> rng = np.random.default_rng(0)
    >>> gyro = [0.01, -0.02, 0.005] + 0.002 * rng.standard_normal((1000, 3))        # 10 s at rest
    >>> cal = gyroscope(gyro, fs=100.0)
    >>> cal.offset.round(3), bool(np.all(cal.offset_sigma < 1e-4))
    (array([ 0.01 , -0.02 ,  0.005]), True)
    """
    g = _v.as_float_array(gyro, "gyro", dtype=np.float64)
    if g.ndim != 2 or g.shape[1] != 3:
        raise ValueError(f"gyro must have shape (N, 3) (one 3-vector per sample), got shape {g.shape}")
    _v.check_finite(g, "gyro")
    if reference_rate is not None and reference_attitude is not None:
        raise ValueError("give reference_rate or reference_attitude, not both")
    if reference_attitude is not None:
        if fs is None:
            raise ValueError("fs (Hz) is needed to turn reference_attitude into rates")
        reference_rate = rates_from_attitude(reference_attitude, fs)
        if len(reference_rate) != len(g):
            raise ValueError(
                f"reference_attitude has {len(reference_rate) + 1} attitudes; with {len(g)} gyro samples it needs "
                f"{len(g) + 1} (one at each sample boundary)"
            )
    if reference_rate is not None:
        return _with_reference(g, reference_rate, frame)
    return _bias(g, fs, acc, rests, frame, rest_options)


def _bias(g, fs, acc, rests, frame, rest_options) -> Calibration:
    if rests is None:
        if fs is None:
            raise ValueError("fs (Hz) is needed to find the rests in gyro; or give rests=[(start, stop), ...]")
        rests = find_rests(acc, g, fs=fs, **rest_options)
    rests = np.asarray(rests, dtype=np.int64).reshape(-1, 2)
    if not len(rests):
        raise InsufficientMotionError(
            "no rest found in gyro: keep the sensor still for at least "
            f"{rest_options.get('min_duration', 1.0)} s so that the bias can be read"
        )
    parts = [g[a:b] for a, b in rests]
    still = np.concatenate(parts)
    bias = still.mean(axis=0)
    noise = still.std(axis=0, ddof=1) if len(still) > 1 else np.zeros(3)
    means = np.array([p.mean(axis=0) for p in parts])
    quality = {
        "rests": rests.tolist(),
        "samples": len(still),
        "noise": noise.tolist(),
        "fs": fs,
        "bias_spread": (means.std(axis=0, ddof=1) if len(parts) > 1 else np.zeros(3)).tolist(),
    }
    return Calibration(
        "gyro",
        offset=bias,
        matrix=np.eye(3),
        frame=frame,
        offset_sigma=noise / np.sqrt(len(still)),
        matrix_sigma=np.zeros((3, 3)),
        quality=quality,
        method="bias from rests",
    )


def _with_reference(g, reference_rate, frame) -> Calibration:
    w = _v.as_float_array(reference_rate, "reference_rate", dtype=np.float64)
    if w.shape != g.shape:
        raise ValueError(f"reference_rate has shape {w.shape}; it must match gyro, {g.shape}")
    _v.check_finite(w, "reference_rate")
    values, vectors = np.linalg.eigh(np.cov(w.T, bias=True))
    excitation = np.sqrt(np.maximum(values, 0.0))
    if excitation[0] < _MIN_RATE:
        raise InsufficientMotionError(
            f"the reference hardly turns about sensor axis {_e.axis_name(vectors[:, 0])} (rms "
            f"{np.degrees(excitation[0]):.2f}°/s about it, at least {np.degrees(_MIN_RATE):.0f}°/s needed): turn the"
            " sensor about that axis too, both ways (scale and coupling of an axis show only when it turns)"
        )
    a, b, cov_a, offset_sigma, _, noise = _linear.fit(w, g)
    matrix, matrix_sigma, figures = _linear.correction(a, cov_a)
    quality = {"samples": len(g), "noise": noise.tolist(), "excitation": excitation[::-1].tolist(), **figures}
    return Calibration(
        "gyro",
        offset=b,
        matrix=matrix,
        frame=frame,
        offset_sigma=offset_sigma,
        matrix_sigma=matrix_sigma,
        quality=quality,
        method="linear least squares against a reference rate",
    )
