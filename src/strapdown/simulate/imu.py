"""What the error models of an IMU do to its readings and to its sample times.

Conventions
-----------
* The models (:mod:`strapdown.simulate.models`) are SI: rad/s for gyros, m/s² for accelerometers, µT for
  magnetometers (the "sensor units" below), seconds for time.
* Timing is that of :func:`strapdown.integrate`: N samples make N steps, step k runs from ``t[k]`` to
  ``t[k+1]`` (duration ``h[k]``) and the record starts at ``t[0]``.  A sample (``kind``) is the true value at the
  start of its step (``"rate"``, as for ``integrate``; release 0.1 said ``"instant"``, still taken), its mean
  over the step (``"average"``) or its integral over the step (``"increment"``).
* :func:`corrupt` applies, in this order::

      reading = quantise(saturate(S (I + diag(s) + M) truth + b(t) + noise))

  with S the soft-iron matrix, s the scale-factor errors, M the misalignment (zero diagonal), b(t) the bias and
  noise white.  The bias is a Wiener process that starts at ``t[0]`` from the constant ``bias`` and grows by
  ``bias_random_walk · √T`` (standard deviation per axis) after T seconds: a rate random walk.
* White noise has the one-sided density ``noise_density`` (units/√Hz): its integral over T seconds has standard
  deviation ``noise_density · √T`` (for a gyro, the angle random walk).  A sample over a step of h seconds then
  has standard deviation ``noise_density / √h`` as a rate or mean (``noise_density · √fs`` at a uniform rate fs)
  and ``noise_density · √h`` as an increment, which is also what its Allan deviation at τ = 1 s reads.

Random numbers come only from the ``numpy.random.Generator`` passed in, so every result is reproducible.
Flicker noise (the "bias instability" floor of a datasheet) is not modelled; the presets approximate it by a
small rate random walk.

Simulating a sensor
-------------------
>>> import numpy as np
>>> from strapdown.simulate.imu import ImuModel, apply_clock, corrupt
>>> imu = ImuModel.consumer_mems()
>>> rng = np.random.default_rng(0)
>>> t_nominal = np.arange(101) * 0.01                             # 100 steps at 100 Hz
>>> t_actual, t_recorded, keep = apply_clock(imu.clock, t_nominal, rng)
>>> true_rate = np.zeros((100, 3))                                # truth evaluated at t_actual[:-1]
>>> gyro = corrupt(imu.gyro, true_rate, np.diff(t_actual), "rate", rng)
>>> gyro, t = gyro[keep], t_recorded[np.append(keep, True)]      # what the logger keeps
>>> gyro.shape, t.shape
((100, 3), (101,))
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from .models import ClockModel, G, ImuModel, TriadModel  # noqa: F401  (G, ImuModel: this module's names in 0.1)

__all__ = ["KINDS", "ClockModel", "ImuModel", "TriadModel", "apply_clock", "corrupt"]

#: What a sample is: the value at the start of its step, the mean over the step, or the integral over it.
KINDS = ("rate", "average", "increment")


def _steps(h, n: int, name: str = "h") -> np.ndarray:
    """Step durations as an (n,) float64 array of positive finite numbers."""
    arr = _v.finite(h, name, dtype=np.float64)
    if arr.ndim != 0 and arr.shape != (n,):
        raise ValueError(f"{name} must be a scalar or have shape (N,) = ({n},) (one step per sample), got {arr.shape}")
    bad = ~(arr > 0)
    if bad.any():
        raise ValueError(f"{name}{_v.first_index(bad)} is {arr[bad][0]}; step durations must be positive")
    return np.broadcast_to(arr, (n,))


def _generator(rng) -> np.random.Generator:
    if not isinstance(rng, np.random.Generator):
        raise ValueError(
            f"rng must be a numpy.random.Generator (np.random.default_rng(seed)), got {type(rng).__name__}"
        )
    return rng


def corrupt(model: TriadModel, truth, h, kind: str, rng: np.random.Generator) -> np.ndarray:
    """Readings of a sensor with errors ``model`` for N samples of true values.

    Parameters
    ----------
    model : TriadModel
        The sensor's errors.
    truth : array_like, shape (N, 3)
        True values in the sensor frame: rates at the start of each step (``"rate"``), means over each step
        (``"average"``) or integrals over each step (``"increment"``).
    h : float or array_like, shape (N,)
        Step durations (s); the bias walk starts at the start of step 0.
    kind : {"rate", "average", "increment"}
        What a sample is (module notes); ``"instant"`` is the name of release 0.1 for ``"rate"``.
    rng : numpy.random.Generator
        Source of every random number; the result is a function of its state.

    Returns
    -------
    numpy.ndarray, shape (N, 3), float64
        ``quantise(saturate(model.matrix @ truth + bias + noise))`` per sample, where

        * the bias is ``model.bias`` plus a Wiener process W of intensity K = ``bias_random_walk`` started at 0
          at the start of step 0: ``W[k+1] = W[k] + K √h[k] ξ[k]`` at the step boundaries.  An instant sample
          takes ``W[k]``; a mean the exact mean of W over the step, ``(W[k] + W[k+1])/2 + K √(h[k]/12) η[k]``
          (the Brownian-bridge part has variance ``K² h/12``); an increment ``h[k]`` times that, plus
          ``model.bias · h[k]``;
        * the white noise has standard deviation ``noise_density / √h[k]`` per instant or mean sample and
          ``noise_density · √h[k]`` per increment;
        * saturation clips to ±range (±range·h[k] for increments);
        * quantisation rounds to the nearest multiple of ``resolution``; a value rounded beyond the range
          becomes the largest multiple within it.  For increments ``resolution`` is an increment LSB (rad, m/s,
          µT·s) and each sample is rounded on its own: the remainder is not carried to the next sample as an
          accumulating counter would.

        The same ``rng`` state gives the same bias path (ξ, drawn first) whatever ``kind``.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.simulate.imu import TriadModel, corrupt
    >>> model = TriadModel(bias=[0.1, 0.0, 0.0], scale_factor=[0.0, 0.5, 0.0], resolution=0.25)
    >>> truth = np.array([[1.0, 1.0, 1.0], [2.0, -2.0, 0.3]])
    >>> corrupt(model, truth, 0.01, "rate", np.random.default_rng(1))
    array([[ 1.  ,  1.5 ,  1.  ],
           [ 2.  , -3.  ,  0.25]])
    >>> corrupt(TriadModel(bias=[0.1, 0.0, 0.0]), truth, 0.5, "increment", np.random.default_rng(1))
    array([[ 1.05,  1.  ,  1.  ],
           [ 2.05, -2.  ,  0.3 ]])
    """
    if not isinstance(model, TriadModel):
        raise ValueError(f"model must be a TriadModel, got {type(model).__name__}")
    x = _v.as_float_array(truth, "truth", dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"truth must have shape (N, 3) (one 3-vector per sample), got shape {x.shape}")
    _v.check_finite(x, "truth")
    n = x.shape[0]
    h = _steps(h, n)
    kind = "rate" if kind == "instant" else _v.choice(kind, "kind", KINDS)
    rng = _generator(rng)
    increment = kind == "increment"

    out = x @ model.matrix.T
    bias = np.broadcast_to(model.bias, (n, 3))
    k = model.bias_random_walk
    if k > 0:
        xi = rng.standard_normal((n, 3))
        walk = np.zeros((n + 1, 3))
        np.cumsum(k * np.sqrt(h)[:, None] * xi, axis=0, out=walk[1:])
        if kind == "rate":
            bias = bias + walk[:-1]
        else:
            bridge = k * np.sqrt(h / 12)[:, None] * rng.standard_normal((n, 3))
            bias = bias + 0.5 * (walk[:-1] + walk[1:]) + bridge
    out += bias * h[:, None] if increment else bias
    if model.noise_density > 0:
        std = model.noise_density * (np.sqrt(h) if increment else 1 / np.sqrt(h))
        out += std[:, None] * rng.standard_normal((n, 3))

    limit = (model.range * h if increment else np.full(n, model.range))[:, None]
    if np.isfinite(model.range):
        out = np.clip(out, -limit, limit)
    res = model.resolution
    if res > 0:
        out = np.round(out / res) * res
        if np.isfinite(model.range):
            # A range that is not a whole number of LSBs would let rounding step outside it; the minimum guards
            # against floor(...) * res landing one ulp above a range that is.
            top = np.minimum(np.floor(limit / res) * res, limit)
            out = np.clip(out, -top, top)
    return out


def apply_clock(model: ClockModel, t_nominal, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Actual and recorded sample times, and which samples survive, for a record of N steps.

    Parameters
    ----------
    model : ClockModel
        The clock's errors.
    t_nominal : array_like, shape (N + 1,)
        Nominal step boundaries (s), strictly increasing; sample k is taken at ``t_nominal[k]`` (instants) or
        over ``t_nominal[k]..t_nominal[k+1]`` (means and increments).
    rng : numpy.random.Generator
        Source of every random number (the jitter is drawn first, then the drops).

    Returns
    -------
    t_actual : numpy.ndarray, shape (N + 1,)
        When the sensor really sampled: the interior boundaries ``t_nominal[1:N]`` plus independent Gaussian
        offsets of std ``jitter``, each redrawn until it is smaller than half of both adjacent nominal steps, so
        the order is kept strictly.  The first and last boundaries, the ends of the record, are not moved.  The
        redraw truncates the Gaussian at ±h/2 ≥ ±2σ (jitter < h/4), which lowers the std by at most 12 %, and
        by less than 0.1 % for jitter ≤ h/8.  Evaluate the truth on these times.
    t_recorded : numpy.ndarray, shape (N + 1,)
        The times the logger writes: ``t_actual`` (``timestamps="actual"``) or a copy of ``t_nominal``
        (``"nominal"``).
    keep : numpy.ndarray of bool, shape (N,)
        False for a lost sample; each of samples 1..N-1 is lost independently with ``drop_probability``, sample 0
        never.  Losing sample k also loses the boundary ``t[k]`` at its start, so the previous kept sample
        spans both steps: the logged record is ``samples[keep]`` with times ``t_recorded[np.append(keep, True)]``
        (N' samples, N' + 1 times).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.simulate.imu import ClockModel, apply_clock
    >>> clock = ClockModel(jitter=0.001, drop_probability=0.3, timestamps="nominal")
    >>> t_actual, t_recorded, keep = apply_clock(clock, np.arange(6) * 0.01, np.random.default_rng(3))
    >>> bool(np.all(np.diff(t_actual) > 0)), t_recorded
    (True, array([0.  , 0.01, 0.02, 0.03, 0.04, 0.05]))
    >>> keep, t_recorded[np.append(keep, True)]
    (array([ True, False,  True,  True, False]), array([0.  , 0.02, 0.03, 0.05]))
    """
    if not isinstance(model, ClockModel):
        raise ValueError(f"model must be a ClockModel, got {type(model).__name__}")
    t = _v.finite(t_nominal, "t_nominal", dtype=np.float64)
    if t.ndim != 1 or t.shape[0] < 2:
        raise ValueError(f"t_nominal must have shape (N + 1,) with N >= 1 steps, got shape {t.shape}")
    steps = np.diff(t)
    bad = ~(steps > 0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"t_nominal[{i + 1}] is not after t_nominal[{i}]; t_nominal must be strictly increasing")
    rng = _generator(rng)
    if not model.jitter < steps.min() / 4:
        raise ValueError(
            f"jitter is {model.jitter} s; it must be below a quarter of the shortest nominal step "
            f"({steps.min() / 4} s) so that the samples stay in order"
        )
    n = steps.shape[0]

    t_actual = t.copy()
    if model.jitter > 0 and n > 1:
        half_gap = 0.5 * np.minimum(steps[:-1], steps[1:])  # for the interior boundaries 1..N-1
        offset = model.jitter * rng.standard_normal(n - 1)
        redo = np.abs(offset) >= half_gap
        while redo.any():  # rejection sampling: a truncated Gaussian, one pass per ~2 % at the largest jitter
            offset[redo] = model.jitter * rng.standard_normal(int(redo.sum()))
            redo = np.abs(offset) >= half_gap
        t_actual[1:-1] += offset
    keep = np.ones(n, dtype=bool)
    if model.drop_probability > 0:
        keep[1:] = rng.random(n - 1) >= model.drop_probability
    t_recorded = t_actual.copy() if model.timestamps == "actual" else t.copy()
    return t_actual, t_recorded, keep
