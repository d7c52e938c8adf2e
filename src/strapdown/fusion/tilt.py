"""Tilt estimation with gyro-drift correction, after the Rowe patent (US 6,377,906 B1).

The estimator reports the patent's tilt quaternion (:mod:`strapdown.rotations.tilt`, whose functions this module
also exports: ``q = q_z(ψ) ⊗ e`` with e yaw-free).

The estimator
-------------
:class:`TiltEstimator` reports the tilt quaternion ``e`` of ``q_c ⊗ q_g``, where the correction ``q_c`` is itself
a tilt quaternion (the patent's form), and corrects it and the gyro bias from the tilt sensor (an
accelerometer, or inclinometer angles):

1. ``q_g`` integrates the bias-corrected gyro exactly: the frame it maps to drifts only with the bias error, so
   it is almost inertial.
2. The tilt-sensor vector (accelerometer minus any known kinematic acceleration) is rotated into that frame
   and low-passed over ``tau_acc`` seconds by a second-order Butterworth filter stepped exactly over each
   interval (``lowpass2``; it replaced two first-order stages, whose slower roll-off let more acceleration
   through: BROAD 0.80° -> 0.76°).  There, linear acceleration averages out (velocity stays bounded) while
   gravity does not.  This is the idea of VQF (Laidig & Seel, Information Fusion 2023), and it is what makes
   the tilt survive sustained accelerations that defeat a proportional loop on the raw accelerometer.  For
   the first ``tau_acc`` seconds the output is the plain mean of the samples instead (VQF's start): a filter
   started at the first sample would carry that sample's linear acceleration for several tau_acc (simulated
   start at 2 m/s²: 3.2° -> 2.6°).
3. ``q_c`` is the tilt quaternion that turns the filtered vector vertical (math.md §5.5: the patent's tilt
   sensor -> tilt quaternion, applied to the filtered vector).  The estimate is ``q_c ⊗ q_g``, reported as its
   tilt quaternion, pitch and roll; its heading is the gyro's and drifts, unobservable without a heading
   reference.
4. The gyro bias b and scale-factor errors s (the gyro reads (1 + s) ω + b; q_g integrates the rate so
   corrected) are a Kalman filter's state (covariance P; random walks ``bias_noise`` and ``scale_noise``,
   starting spreads ``bias_sigma_init`` and ``scale_sigma_init``), updated every 0.1 s from one of two
   measurements.  At rest (gyro and tilt sensor steady for ``rest_time``) the 0.5 s gyro mean measures b on
   all three axes.  In motion, the patent's drift loop: when the estimates are off by δb and δs, the
   almost-inertial frame turns at R (δb + δs ∘ ω) (reference axes, R the attitude's matrix) and the
   correction q_c turns with it, through the tilt sensor's low-pass: its mean rate over the block is
   -LP[R (δb + δs ∘ ω)], horizontal.  So y = -rate + LP[R (b̂ + ŝ ∘ ω)] measures LP[R] b + LP[R diag ω] s,
   with the two horizontal rows of LP[R] and LP[R diag ω] as the regressor (VQF's regression for the bias;
   the AttitudeEstimator's for both): R, R diag ω and the prediction are run through the same low-pass as
   the tilt sensor, so the filter's lag is modelled, and taken at the block's middle.  (The patent's loop as
   first built fed the rate back through the current R, which is wrong by the rotation during the lag: on a
   30°/s turntable it learnt nothing, 2.8° against VQF's 1.0°; and its fixed gain was slow from the start:
   8.5° against 6.5° with a 5°/s bias.)  The scale factors matter in fast, sustained rotation, where a 1 %
   error turns the frame by 1 % of the rotation: on BROAD they take the inclination error from 0.787° to
   0.644°; on the simulated test-bed (random motion, 0.3-0.5 % scale errors) they change little.  The
   measurement noise density is ``tau_bias · bias_noise``, so that once the bias is known the loop forgets
   over ``tau_bias``; at rest ``tau_rest_bias · bias_noise``.  The regressor has no vertical row, so in motion
   the component along the vertical is learnt only as the body tilts.  The noise grows with the correction rate
   an accelerometer bias of ``acc_bias_sigma`` would cause as the body turns: its apparent gravity offset
   b_a/g, fixed in the body, turns with it and moves the correction as a gyro bias would (the
   AttitudeEstimator's finding on the test-bed).  ``bias_limit``
   is a prior's bound, not a clip: the bias leaks towards zero over ten hours (a Gauss-Markov bias) and is
   flagged ``FLAG_BIAS_AT_LIMIT`` beyond the bound, so a real 4.5°/s bias is learnt instead of held at the
   limit; each in-motion innovation is clipped to it (a correction faster than any plausible bias is no
   bias: the start, a shock).
5. Irregular sampling: every coefficient is computed for its interval, and over an interval that holds lost
   rows the gyro rate is interpolated across the gap (as in the AttitudeEstimator, whose notes explain it).
   A NaN row of ``acc`` (or ``pitch_roll``) means no tilt-sensor sample then (sensors at different rates): it
   holds the filter, as a sample the gate rejects does (both flagged ``FLAG_ACC_REJECTED``), and the next
   sample steps it over the whole time since; the rest detector holds the last sample present.

Where the patent leaves the design open (its gains and rates were not retrieved, math.md §5.6), these choices
are ours.  Parameters were chosen once on the 22 BROAD trials with one common set (BROAD's rule) and checked by
leave-one-group-out and on the simulated test-bed against VQF (benchmarks/bench_attitude.py,
benchmarks/bench_testbed.py; figures in docs/guide/estimators.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._support import validate as _v
from .._support.renamed import renamed
from ..rotations.euler import from_euler
from ..rotations.quaternion import rotate
from ..rotations.tilt import INVERTED_TOL, tilt_from_pitch_roll, tilt_from_quaternion, tilt_from_up, tilt_rates
from ._base import GRAVITY, Estimator, float32_if, nonnegative
from .estimate import FLAG_SATURATED, Estimate
from .saturation import GYRO_FLOOR, bridged, clipped_components

__all__ = [
    "TiltEstimator",
    "TiltParams",
    "tilt",
    "tilt_from_pitch_roll",
    "tilt_from_quaternion",
    "tilt_from_up",
    "tilt_rates",
]


@dataclass(frozen=True)
class TiltParams:
    """Parameters of :class:`TiltEstimator`, all in physical units.

    Attributes
    ----------
    tau_acc : float
        Time constant of the tilt sensor's low-pass filter (second-order Butterworth, cutoff √2/tau_acc rad/s)
        in the almost-inertial frame, s.  Longer rejects more linear acceleration, shorter follows a drifting
        gyro closer.  Default 3.5, the AttitudeEstimator's (leave-one-group-out on BROAD picks 3.5 in six of nine
        folds, 3.0, VQF's, in three: in-sample 0.644° against 0.646°, held out 0.654°; on the simulated test-bed
        3.5 is ahead of VQF 6D in 19 of 22 conditions, 3.0 in 10, 4.0 in 16: longer loses where there is no
        linear acceleration to reject, as in the long rests, and on the fast turntable).
    tau_bias : float
        Time constant of the gyro-bias learning in motion once the bias is known (the steady state of the drift
        loop's Kalman filter: its measurement noise density is tau_bias · bias_noise), s; 0 disables it.
        Default 100 (VQF's).  Shorter learns faster but lets sustained accelerations leak into the bias: on
        BROAD 50 is level (0.643° against 0.644°, picked in six folds, held out 0.652°), on the simulated
        test-bed it is behind VQF in 16 of 22 conditions (ideal IMU 1.12° against 0.79°).
    rest_gyro : float
        Rest detection: largest deviation of the gyro from its 0.5 s mean, rad/s.  Default 2°/s.
    rest_acc : float
        Rest detection: largest deviation of the tilt sensor from its 0.5 s mean, m/s².  Default 0.5.
    rest_time : float
        Seconds of steadiness before rest is declared.  Default 1.5.
    tau_rest_bias : float
        Time constant with which the bias follows the gyro at rest once known (the rest measurement's noise
        density is tau_rest_bias · bias_noise), s.  Default 1.0.
    bias_sigma_init : float
        Standard deviation of the bias before any data, per axis, rad/s: how fast the first seconds learn it.
        Default 0.5°/s (VQF's).
    bias_noise : float
        The bias's random walk, rad/s/√s: how fast what was learnt is forgotten.  Default 0.01°/s/√s (VQF's:
        0.1°/s in 100 s), five times a consumer gyro's rate random walk, for temperature drift.
    scale_sigma_init : float
        Spread of the gyro's scale-factor errors before any data (dimensionless; the gyro reads (1 + s) ω + b).
        Default 0.01, a consumer MEMS gyro's sensitivity tolerance (±1-3 % on datasheets), chosen by
        leave-one-group-out on BROAD (0: 0.787°, 0.002: 0.712°, 0.005: 0.664°, 0.01: 0.644°, 0.02: 0.651°); 0
        turns the scale estimation off.
    scale_noise : float
        Random walk of the scale-factor errors, 1/√s.  Default 1e-5 (the AttitudeEstimator's).
    acc_bias_sigma : float
        Accelerometer bias believed, per axis, m/s² (default 0.1, 10 mg: a consumer part after its factory
        calibration; 0 ignores it).  Its apparent gravity offset, fixed in the body, turns the correction as the
        body turns, at a rate up to |dLP[R]/dt| acc_bias_sigma/g, which the drift loop would learn as a gyro
        bias (on a turntable it is exactly one, (ω × b_a)/g); the loop's measurement noise grows by that rate,
        coloured over tau_acc (module notes, 4).  On the simulated test-bed (``bench_testbed.py --tilt-params``,
        at tau_acc 3.5 s) 0 and 0.1 are level, ahead of VQF 6D in 19 of 22 conditions and behind by at most
        6.4 % (the 90°/s turntable; the pendulum +4.2 % and +4.4 %, long rests +3.2 % and +3.6 %); 0.2 wins as
        many but every loss is larger (up to +6.9 %), 0.5 wins 13 (up to +8.4 %).  On BROAD 0: 0.645°,
        0.1: 0.644°, 0.2: 0.642°, 0.5: 0.640°, the gain all in the attached-magnet trials, so that
        leave-one-group-out picks 0.5 in eight folds and 0 in the ninth (held out 0.650°).
    bias_limit : float
        Largest bias believed, per axis, rad/s (default 2°/s): not a clip but a prior's bound.  The estimate is
        pulled towards zero over ten hours (a Gauss-Markov bias), so a larger bias the data show is learnt, and
        flagged ``FLAG_BIAS_AT_LIMIT`` while it lies beyond the bound; a steady mean rate up to three times it
        counts as a bias at rest, and each in-motion innovation of the drift loop is clipped to it.
    acc_gate : float
        Leave the tilt sensor out of the low-pass filter when its magnitude differs from g by more than this,
        m/s² (a gate against shocks); inf keeps every sample.  Default inf.
    gyro_range : float
        The gyro's full-scale range, rad/s: components at it are flagged ``FLAG_SATURATED`` and bridged by the
        cubic that continues the readings on either side (:mod:`strapdown.fusion.saturation`).  Default 0:
        found from the readings; ``inf``: never.
    """

    tau_acc: float = 3.5
    tau_bias: float = 100.0
    rest_gyro: float = float(np.radians(2.0))
    rest_acc: float = 0.5
    rest_time: float = 1.5
    tau_rest_bias: float = 1.0
    bias_limit: float = float(np.radians(2.0))
    acc_gate: float = np.inf
    bias_sigma_init: float = float(np.radians(0.5))
    bias_noise: float = float(np.radians(0.01))
    acc_bias_sigma: float = 0.1
    scale_sigma_init: float = 0.01
    scale_noise: float = 1e-5
    gyro_range: float = 0.0

    def __post_init__(self):
        positive = (
            "tau_acc",
            "rest_gyro",
            "rest_acc",
            "tau_rest_bias",
            "bias_limit",
            "acc_gate",
            "bias_sigma_init",
            "bias_noise",
        )
        for name in positive:
            v = getattr(self, name)
            if not (v > 0 and not np.isnan(v)):
                raise ValueError(f"{name} must be positive, got {v!r}")
        nonnegative(self, ("tau_bias", "rest_time"), "number of seconds")
        nonnegative(self, ("acc_bias_sigma", "scale_sigma_init", "scale_noise"), "number")
        if not self.gyro_range >= 0:  # inf allowed: no detection
            raise ValueError(f"gyro_range must be a range >= 0 (0: found from the readings), got {self.gyro_range!r}")


class TiltEstimator(Estimator):
    """Streaming tilt estimator with gyro-bias estimation (module notes).

    Parameters
    ----------
    params : TiltParams, optional
        Time constants and thresholds.
    bias0 : array_like, shape (3,), optional
        Initial gyro bias estimate, rad/s, e.g. restored from an earlier run.

    Notes
    -----
    ``update(gyro, acc=None, *, dt=None, t=None, known_acc=None, pitch_roll=None, degrees=False)`` takes either
    accelerometer samples, minus ``known_acc`` (kinematic acceleration in sensor axes, m/s², e.g. centripetal
    from wheel speed) when given, or inclinometer angles ``pitch_roll`` (N, 2) in the ZYX convention of
    ``frame`` (radians, or degrees with ``degrees=True``).  The :class:`~strapdown.fusion.Estimate` carries
    ``q`` (heading from the gyro), ``bias`` and ``flags``; its ``tilt`` (N, 4), ``pitch`` and ``roll`` (N,)
    (radians) are computed from ``q`` when asked for.

    ``.state`` (readable and assignable) holds the estimate ``q`` = ``q_correction ⊗ q_gyro``, the gyro-frame
    attitude ``q_gyro``, the correction ``q_correction`` (a tilt quaternion, e3 = 0) and its value at the start
    of the drift loop's block ``q_correction_previous``, ``bias`` (rad/s) and ``scale`` (the Kalman filter's
    states) and their ``covariance`` (6, 6), ``acc_filter`` (2, 3) (the low-pass filter's rate, m/s³, and
    output, m/s², almost-inertial frame), ``acc_start`` (5,) (its plain mean at the start), ``drift_filter``
    (2, 14) (the drift loop's low-pass of its regressors, rates and outputs) and ``block_seconds``,
    ``rest_filter`` (6,) (0.5 s means of gyro and tilt sensor), ``rest_seconds``, ``gyro_previous`` (3,),
    ``nominal_interval``, ``acc_interval`` and ``acc_previous`` (3,) (lost rows and missing samples), all in
    ENU.  A state saved before the Kalman drift loop existed restores (the new entries start afresh: the
    covariance at its initial value, so the bias is relearnt).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import TiltEstimator
    >>> est = TiltEstimator().update(np.zeros((300, 3)), pitch_roll=np.tile([0.1, -0.2], (300, 1)), dt=0.01)
    >>> est.pitch[-1].round(9), est.roll[-1].round(9)
    (np.float64(0.1), np.float64(-0.2))
    """

    natural_frame = "ENU"
    estimates_bias = True
    reports_flags = True
    _state_layout = (
        ("q", (4,)),
        ("q_gyro", (4,)),
        ("q_correction", (4,)),
        ("q_correction_previous", (4,)),
        ("bias", (3,)),
        ("acc_filter", (2, 3)),
        ("rest_filter", (6,)),
        ("rest_seconds", ()),
        ("gyro_previous", (3,)),
        ("nominal_interval", ()),
        ("acc_interval", ()),
        ("acc_previous", (3,)),
        ("covariance", (6, 6)),
        ("scale", (3,)),
        ("drift_filter", (2, 14)),
        ("block_seconds", ()),
        ("acc_start", (5,)),
    )
    _unit_keys = ("q", "q_gyro", "q_correction", "q_correction_previous")
    # states saved before these existed restore too
    _optional_keys = (
        "gyro_previous",
        "nominal_interval",
        "acc_interval",
        "acc_previous",
        "covariance",
        "scale",
        "drift_filter",
        "block_seconds",
        "acc_start",
    )
    missing_samples = True  # a NaN row of acc (or pitch_roll): no tilt-sensor sample then

    params_class = TiltParams

    def __init__(self, params: TiltParams | None = None, *, q0=None, frame: str = "ENU", bias0=None):
        super().__init__(params, q0=q0, frame=frame)
        self._bias0 = np.zeros(3) if bias0 is None else _v.vectors(bias0, "bias0", dtype=np.float64).reshape(3)

    @renamed(gyr="gyro")
    def update(
        self, gyro, acc=None, mag=None, *, dt=None, t=None, known_acc=None, pitch_roll=None, degrees: bool = False
    ) -> Estimate:
        """Process a chunk of samples (see the class notes for the inputs).

        Parameters
        ----------
        gyro, dt, t
            As for every filter (:mod:`strapdown.fusion`).
        acc : array_like, shape (N, 3), optional
            Specific force, m/s² (NaN rows: no sample); or give ``pitch_roll``.
        mag : None
            Not used: the tilt needs no magnetometer (given, it is an error).
        known_acc : array_like, shape (N, 3), optional
            Kinematic acceleration to subtract from ``acc``, sensor axes, m/s².
        pitch_roll : array_like, shape (N, 2), optional
            Inclinometer pitch and roll instead of ``acc`` (NaN rows: no sample).
        degrees : bool
            ``pitch_roll`` in degrees.

        Returns
        -------
        Estimate
            Attitudes, tilt quaternions, pitch, roll, bias and flags.
        """
        if mag is not None:
            raise ValueError("TiltEstimator estimates the tilt from gravity alone: do not give mag")
        if (acc is None) == (pitch_roll is None):
            raise ValueError("give exactly one tilt sensor: acc (accelerometer) or pitch_roll (inclinometer)")
        gyr_arr = _v.vectors(gyro, "gyro", dtype=np.float64)
        if gyr_arr.ndim != 2:
            raise ValueError(f"gyro must have shape (N, 3), got {gyr_arr.shape}")
        n = gyr_arr.shape[0]
        if pitch_roll is not None:
            pr = _v.finite(pitch_roll, "pitch_roll", check=False, dtype=np.float64)
            if pr.shape != (n, 2):
                raise ValueError(f"pitch_roll must have shape (N, 2) = ({n}, 2), got {pr.shape}")
            absent = np.isnan(pr).all(axis=1)  # a NaN row: no inclinometer sample then
            if not np.isfinite(pr[~absent]).all():
                i = int(np.flatnonzero(~absent & ~np.isfinite(pr).all(axis=1))[0])
                raise ValueError(f"pitch_roll[{i}] = {pr[i].tolist()}: a row must be finite, or all NaN for no sample")
            q_pr = from_euler(np.column_stack([np.zeros(n), np.where(absent[:, None], 0.0, pr)]), "ZYX", degrees)
            up_out = rotate(self._to_out, [0.0, 0.0, 1.0])  # the frame's "up" ("ENU": z; "NED": -z)
            acc_arr = GRAVITY * rotate(q_pr * [1.0, -1.0, -1.0, -1.0], np.broadcast_to(up_out, (n, 3)))
            acc_arr[absent] = np.nan
        else:
            acc_arr = _v.vectors(acc, "acc", check=False, dtype=np.float64)  # NaN rows: no sample (checked later)
            if known_acc is not None:
                known = _v.vectors(known_acc, "known_acc", dtype=np.float64)
                if known.shape != acc_arr.shape:
                    raise ValueError(f"known_acc must have the shape of acc {acc_arr.shape}, got {known.shape}")
                acc_arr = acc_arr - known
        est = super().update(gyr_arr, acc_arr, dt=dt, t=t)
        return float32_if(est, gyro, pitch_roll if acc is None else acc)

    def _new_state(self, q, gyro, acc, mag, dts, extra_in):
        # the first tilt-sensor sample present, turned back to the axes of the first sample (q's)
        _, a0 = self._acc0
        a_i = rotate(q, a0)
        return {
            "q": q.copy(),  # the estimate q_c ⊗ q_g
            "q_gyro": q.copy(),  # q_g: sensor -> almost-inertial frame
            "q_correction": np.array([1.0, 0.0, 0.0, 0.0]),  # q_c: a tilt quaternion (e3 = 0)
            "q_correction_previous": np.array([1.0, 0.0, 0.0, 0.0]),  # q_c one sample earlier (drift loop)
            "bias": self._bias0.copy(),
            "acc_filter": np.array([np.zeros(3), a_i]),  # the low-pass's rate and output, almost-inertial frame
            "rest_filter": np.concatenate([np.zeros(3), a0]),  # 0.5 s means of gyro and tilt sensor
            "rest_seconds": 0.0,
            "gyro_previous": np.zeros(3),  # the last gyro sample, rad/s (rate interpolation across lost rows)
            "nominal_interval": 0.0,  # s, the shortest recent sample interval (0: none yet)
            "acc_interval": 0.0,  # s since the last tilt-sensor sample the filter took
            "acc_previous": a0.copy(),  # the last tilt-sensor sample present (rest detection)
            "covariance": self._covariance0(),  # of the bias (rad/s) and scale-factor errors
            "scale": np.zeros(3),  # the gyro scale-factor errors (it reads (1 + s) ω + b)
            "drift_filter": _drift_filter(q, self._bias0),  # the drift loop's low-pass (rates, outputs)
            "block_seconds": 0.0,  # s into the drift loop's block
            # the start's plain mean over tau_acc: seconds so far (-1: over), sum of the samples in I, count
            "acc_start": np.zeros(5),
        }

    def _covariance0(self) -> np.ndarray:
        p = self.params
        return np.diag([p.bias_sigma_init**2] * 3 + [p.scale_sigma_init**2] * 3)

    @property
    def bias(self) -> np.ndarray | None:
        """The current gyro bias estimate, rad/s (sensor axes)."""
        return None if self._state is None else self._state["bias"].copy()

    @property
    def scale(self) -> np.ndarray | None:
        """The current gyro scale-factor error estimate (dimensionless: the gyro reads (1 + s) ω + b)."""
        return None if self._state is None else self._state.get("scale", np.zeros(3)).copy()

    def _run(self, gyro, acc, mag, dts, extra_in):
        from .._support import uncompiled
        from . import _tilt_numba as k

        n = gyro.shape[0]
        out = np.empty((n, 4))
        bias = np.empty((n, 3))
        flags = np.empty(n, dtype=np.uint8)
        p = self.params
        pin = clipped_components(gyro, p.gyro_range, GYRO_FLOOR)
        if pin is not None:
            gyro = bridged(gyro, pin)
        st = self._state
        cov = st.get("covariance", self._covariance0())
        s = np.concatenate(
            [
                st["q_gyro"],
                st["q_correction"],
                st["q_correction_previous"],
                st["q"],
                st["bias"],
                st["acc_filter"].ravel(),
                st["rest_filter"],
                [st["rest_seconds"]],
                st.get("gyro_previous", np.zeros(3)),  # states saved before these existed restore too
                [st.get("nominal_interval", 0.0)],
                [st.get("acc_interval", 0.0)],
                st.get("acc_previous", st["rest_filter"][3:]),
                cov.ravel(),
                st.get("drift_filter", _drift_filter(st["q"], st["bias"])).ravel(),
                [st.get("block_seconds", 0.0)],
                st.get("acc_start", [-1.0, 0.0, 0.0, 0.0, 0.0]),
                st.get("scale", np.zeros(3)),
            ]
        )
        uncompiled.call(  # uncompiled, 22 µs a sample measured (_support/uncompiled.py)
            k.run,
            gyro,
            acc,
            dts,
            p.tau_acc,
            p.rest_gyro,
            p.rest_acc,
            p.rest_time,
            p.tau_rest_bias,
            p.tau_bias,
            p.bias_limit,
            p.bias_noise,
            p.scale_noise,
            p.acc_bias_sigma,
            GRAVITY,
            p.acc_gate,
            self._to_out,
            INVERTED_TOL,
            s,
            out,
            bias,
            flags,
            python_seconds=3e-5 * n,
        )
        st["q_gyro"], st["q_correction"], st["bias"] = s[k.QG : k.QG + 4], s[k.QC : k.QC + 4], s[k.BIAS : k.BIAS + 3]
        st["q_correction_previous"], st["q"] = s[k.QCP : k.QCP + 4], s[k.Q : k.Q + 4]
        st["acc_filter"] = s[k.LP1 : k.LP2 + 3].reshape(2, 3)
        st["rest_filter"] = s[k.GLP : k.ALP + 3].copy()
        st["rest_seconds"] = float(s[k.REST])
        st["gyro_previous"] = s[k.GPREV : k.GPREV + 3].copy()
        st["nominal_interval"] = float(s[k.NOMDT])
        st["acc_interval"] = float(s[k.ATIME])
        st["acc_previous"] = s[k.ALAST : k.ALAST + 3].copy()
        st["covariance"] = s[k.COV : k.COV + 36].reshape(6, 6)
        st["drift_filter"] = s[k.DRIFT : k.DRIFT + 2 * k.ND].reshape(2, k.ND)
        st["block_seconds"] = float(s[k.BLOCK])
        st["acc_start"] = s[k.START : k.START + 5].copy()
        st["scale"] = s[k.SCALE : k.SCALE + 3].copy()
        if pin is not None:
            flags[pin.any(axis=-1)] |= np.uint8(FLAG_SATURATED)
        return Estimate(q=out, frame=self.natural_frame, bias=bias, flags=flags)


def _drift_filter(q, bias) -> np.ndarray:
    """The drift loop's low-pass in steady state at attitude q and bias: rates 0, outputs R's rows 0-1 and R b."""
    from ..rotations.matrix import as_matrix

    r = as_matrix(q)[:2]
    return np.array([np.zeros(14), np.concatenate([r.ravel(), np.zeros(6), r @ bias])])


@renamed(gyr="gyro")
def tilt(
    gyro,
    acc=None,
    *,
    dt=None,
    t=None,
    params: TiltParams | None = None,
    q0=None,
    frame: str = "ENU",
    bias0=None,
    known_acc=None,
    pitch_roll=None,
    degrees: bool = False,
) -> Estimate:
    """Run the TiltEstimator over whole arrays (the batch form of :class:`TiltEstimator`).

    Parameters
    ----------
    gyro, acc, dt, t, known_acc, pitch_roll, degrees
        As for :meth:`TiltEstimator.update`.
    params, q0, frame, bias0
        As for :class:`TiltEstimator`.

    Returns
    -------
    Estimate
        See :class:`TiltEstimator`.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import tilt
    >>> est = tilt(np.zeros((200, 3)), np.tile([0.0, 0.0, 9.81], (200, 1)), dt=0.01)
    >>> est.tilt[-1]
    array([1., 0., 0., 0.])
    """
    return TiltEstimator(params, q0=q0, frame=frame, bias0=bias0).update(
        gyro, acc, dt=dt, t=t, known_acc=known_acc, pitch_roll=pitch_roll, degrees=degrees
    )
