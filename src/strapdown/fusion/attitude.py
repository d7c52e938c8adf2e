"""A 6D/9D orientation estimator with gyro bias and scale-factor estimation, online and offline.

How it works
------------
1. Gyro frame.  ``q_g`` integrates the gyro corrected by the current bias b and scale-factor errors s,
   ``ω - b - s ∘ ω``, with the exact step.  It maps the sensor to an almost-inertial frame I that drifts only
   with the errors left in b and s.
2. Inclination.  The accelerometer, rotated into I, passes a second-order Butterworth low-pass (``tau_acc``).
   In I gravity is fixed while linear acceleration averages out (velocity stays bounded), so the filtered
   vector points up however long the body accelerates.  The correction ``q_c`` is the tilt quaternion that
   turns it vertical (math.md §5.5), and ``q_6D = q_c ⊗ q_g``.  Filtering in an almost-inertial frame is the
   central idea of VQF (Laidig & Seel, Information Fusion 2023).  For the first ``tau_acc`` seconds the filter
   is the plain mean of the samples in I (as VQF starts), so the first sample's linear acceleration averages
   out instead of decaying over several time constants; bias and scale are not learnt from motion meanwhile.
3. Bias and scale in motion.  When b or s is wrong, I turns at ``R(q) (δb + δs ∘ ω)`` and the correction has
   to turn with it.  Seen through the low-pass, the correction's rate is ``LP[R_h(q)] δb + LP[R_h(q) diag ω] δs``
   (R_h: the two horizontal rows of R), so filtering the regressors with the same low-pass turns every block
   of samples into a linear measurement of (b, s).  VQF filters its regressor the same way for the bias.  Here a
   six-state Kalman filter also estimates the scale factors, because in fast motion scale errors drift the
   frame far more than bias does: on BROAD this alone lowers the 6D inclination error by a tenth.  A
   measurement is trusted less the faster the body turns (``bias_noise_rate_factor``), since unmodelled gyro
   errors grow with the rate.
4. Bias at rest.  When gyro and accelerometer have stayed near their 0.5 s means for ``rest_time`` and the
   mean rate is small enough to be a bias (a turntable is steady but not at rest), the mean gyro is a direct
   measurement of the bias on all three axes, as noisy as the gyro's scatter about that mean says.
5. Heading (9D).  The magnetic field, taken into the 6D frame, gives a heading offset δ that a first-order
   filter (``tau_mag``) follows about the vertical only, so the magnetometer never tilts the estimate:
   ``q = q_z(δ) ⊗ q_6D``; until it has averaged that long it is the mean of the updates so far, so the first
   field sets the heading at once.  The field's norm and dip are compared with a slowly learnt reference;
   while they differ (a magnet, steel nearby) the magnetometer is left out and flagged.  A disturbance that lasts
   ``mag_new_time`` is taken as a new environment, and a return to the previous field is recognised at once.
   The rate of δ, regressed like the inclination's, measures the vertical bias, which the accelerometer cannot
   see on a level platform.
6. Offline (:func:`attitude_offline`).  The recording runs forward and backward in time with time constants
   ``offline_time_factor`` times longer; their lags are equal and opposite, so their weighted mean cancels them.
   With a magnetometer the heading is then taken from the field in that combined 6D frame, smoothed forward
   and backward in time by a local-linear fit (which follows the ramp a vertical gyro bias gives the 6D heading
   right to the ends of the record), with the samples either pass found disturbed left out.

Steps 3-5 run at ``update_rate`` on time-averaged blocks, so the cost per sample stays that of steps 1-2.
Sensors may run at different rates: a NaN row in ``acc`` or ``mag`` means no sample of that sensor then.

The defaults were chosen once on the 22 BROAD trials (one common set, BROAD's rule) and are physical: time
constants in seconds, rates in rad/s, noise densities in rad/s·√s.  The results change little across a wide
range (``benchmarks/bench_attitude.py`` prints the RMSE surface over ``tau_acc`` and ``tau_mag``).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from numbers import Real

import numpy as np

from .. import _validate as _v
from ..quaternion import multiply, rotate
from ._base import FLAG_MAG_REJECTED, Estimate, Estimator, _back_to_first_sample, _first_present, params_of

__all__ = ["AttitudeEstimator", "AttitudeParams", "attitude", "attitude_offline"]

_DEG = np.pi / 180.0


@dataclass(frozen=True)
class AttitudeParams:
    """Parameters of :class:`AttitudeEstimator`, in physical units.

    Attributes
    ----------
    tau_acc : float
        Time constant of the accelerometer low-pass in the almost-inertial frame, s.  Default 3.5.
    tau_mag : float
        Time constant of the heading correction from the magnetometer, s.  Default 20.
    bias_sigma_init : float
        Initial uncertainty of the gyro bias, rad/s (default 0.5°/s).
    bias_forgetting_time : float
        Time in which the bias uncertainty grows back to ``bias_sigma_init`` without information, s (how fast
        the bias may wander).  Default 100.
    bias_noise_motion : float
        Noise density of the in-motion bias measurement, rad/s·√s (default 0.18°/s·√s: one second of motion
        tells the bias to about that much).
    bias_noise_rate_factor : float
        Growth of that noise with the angular rate, √s (noise² += factor² |ω|²).  Default 6e-4.
    bias_noise_rest : float
        Least noise density of the at-rest bias measurement, rad/s·√s (default 0.0018°/s·√s).  Above it the
        noise comes from the gyro's own scatter at rest, so that ``bias_sigma`` stays honest for noisy gyros.
    scale_sigma_init : float
        Initial uncertainty of the gyro scale-factor errors (dimensionless, default 0.002 = 0.2 %).
    scale_noise : float
        Random walk of the scale-factor errors, 1/√s (default 1e-5).
    bias_noise_mag : float
        Noise density of the vertical-bias measurement from the heading rate, rad/s·√s (default 1.8°/s·√s);
        0 turns it off.
    rest_gyro : float
        Rest detection: largest deviation of the gyro from its 0.5 s mean, rad/s (default 2°/s).
    rest_acc : float
        Rest detection: largest deviation of the accelerometer from its 0.5 s mean, m/s².  Default 0.5.
    rest_time : float
        Seconds of steadiness before rest is declared.  Default 1.5.
    rest_tau : float
        Time constant of the rest detector's means, s.  Default 0.5.
    bias_limit : float
        Largest bias believed on any axis, rad/s (default 2°/s).
    mag_norm_threshold : float
        Relative departure of the field norm from its reference that counts as disturbed.  Default 0.1.
    mag_dip_threshold : float
        Departure of the dip angle from its reference that counts as disturbed, rad (default 10°).
    mag_ref_tau : float
        Time constant with which the reference norm and dip follow an undisturbed field, s.  Default 20.
    mag_current_tau : float
        Time constant of the current norm and dip, s.  Default 0.05.
    mag_new_time : float
        Seconds of a steady new field after which it becomes the reference.  Default 20.
    update_rate : float
        Rate of the bias, scale and heading updates, Hz.  Default 5: the regressors are low-passed over
        seconds, and on BROAD 2-50 Hz give the same errors within 0.05°.
    offline_time_factor : float
        :func:`attitude_offline` runs with ``tau_acc`` and ``tau_mag`` multiplied by this.  Default 1.5.
    """

    tau_acc: float = 3.5
    tau_mag: float = 20.0
    bias_sigma_init: float = 0.5 * _DEG
    bias_forgetting_time: float = 100.0
    bias_noise_motion: float = 0.18 * _DEG
    bias_noise_rate_factor: float = 6e-4
    bias_noise_rest: float = 0.0018 * _DEG
    scale_sigma_init: float = 0.002
    scale_noise: float = 1e-5
    bias_noise_mag: float = 1.8 * _DEG
    rest_gyro: float = 2.0 * _DEG
    rest_acc: float = 0.5
    rest_time: float = 1.5
    rest_tau: float = 0.5
    bias_limit: float = 2.0 * _DEG
    mag_norm_threshold: float = 0.1
    mag_dip_threshold: float = 10.0 * _DEG
    mag_ref_tau: float = 20.0
    mag_current_tau: float = 0.05
    mag_new_time: float = 20.0
    update_rate: float = 5.0
    offline_time_factor: float = 1.5

    def __post_init__(self):
        zero_ok = {"bias_noise_rate_factor", "scale_sigma_init", "scale_noise", "bias_noise_mag", "rest_time"}
        for f in fields(self):
            v = getattr(self, f.name)
            if not isinstance(v, Real) or isinstance(v, (bool, np.bool_)) or not np.isfinite(v):
                raise ValueError(f"{f.name} must be a finite number, got {v!r}")
            if v < 0 or (v == 0 and f.name not in zero_ok):
                raise ValueError(f"{f.name} must be {'non-negative' if f.name in zero_ok else 'positive'}, got {v!r}")
        if self.mag_dip_threshold > np.pi:  # 10 meant as degrees would switch the dip test off unnoticed
            raise ValueError(f"mag_dip_threshold is in radians, at most π; got {self.mag_dip_threshold!r}")

    def _vector(self) -> np.ndarray:
        """The kernel's parameter vector (run() in _attitude_numba.py)."""
        return np.array(
            [
                self.tau_acc,
                self.tau_mag,
                self.bias_sigma_init**2 / self.bias_forgetting_time,
                self.scale_noise**2,
                self.bias_noise_motion**2,
                self.bias_noise_rate_factor**2,
                self.bias_noise_rest**2,
                self.bias_noise_mag**2,
                self.rest_gyro**2,
                self.rest_acc**2,
                self.rest_time,
                self.rest_tau,
                self.bias_limit,
                self.mag_norm_threshold,
                self.mag_dip_threshold,
                self.mag_ref_tau,
                self.mag_current_tau,
                self.mag_new_time,
                1.0 / self.update_rate,
            ]
        )


# named parts of the kernel's state vector (offsets in _attitude_numba.py)
_LAYOUT = (
    ("q_gyro", "QG", 4),
    ("q_correction", "QC", 3),
    ("acc_filter", "AF", 6),
    ("bias_scale", "X", 6),
    ("regressor_filter", "REG", 28),
    ("mag_regressors", "V7", 7),
    ("block_sums", "ACC", 24),
    ("block_time", "TB", 1),
    ("correction_start", "EXS", 3),
    ("rate_sum", "W2", 1),
    ("mag_time", "NMAG", 1),
    ("rest_gyro_mean", "RESTG", 3),
    ("rest_acc_mean", "RESTA", 3),
    ("rest_seconds", "REST", 1),
    ("heading_offset", "DELTA", 1),
    ("mag_reference", "MREF", 2),
    ("mag_current", "MCUR", 2),
    ("mag_previous", "MOLD", 2),
    ("mag_disturbed_seconds", "DIST", 1),
    ("mag_undisturbed_seconds", "UND", 1),
    ("started", "STARTED", 1),
    ("acc_gap_seconds", "TACC", 1),
    ("acc_filter_output", "AFO", 3),
    ("acc_filter_interval", "AFDT", 1),
    ("rest_gyro_variance", "RESTV", 1),
    ("acc_start_seconds", "AINIT", 1),
    ("acc_start_sum", "ASUM", 3),
    ("acc_start_count", "ACNT", 1),
    ("mag_updates", "MAGN", 1),
)


class AttitudeEstimator(Estimator):
    """Streaming 6D/9D orientation estimator with gyro bias and scale-factor estimation (module notes).

    Parameters
    ----------
    params : AttitudeParams or mapping, optional
        Time constants, noise densities and thresholds (a mapping overrides the defaults by name).
    q0 : array_like, shape (4,), optional
        Initial attitude (sensor to ``frame``); by default from the first accelerometer (and magnetometer)
        sample.
    frame : str
        Reference frame of ``q0`` and of the outputs (z up or down).

    Notes
    -----
    ``update(gyr, acc, mag=None, *, dt=None, t=None, known_acc=None)``: gyro in rad/s (finite), accelerometer
    in m/s², magnetic field in any unit; a NaN row in ``acc`` or ``mag`` means no sample of that sensor then;
    ``known_acc`` is a kinematic acceleration to subtract from the accelerometer.  Sample k's accelerometer and
    magnetometer readings are taken as those at the end of its gyro step; readings averaged over the step lag
    by half a step, which matters only where half a step's rotation is large (10° at 2000°/s and 100 Hz).  The
    :class:`~strapdown.fusion.Estimate` carries ``q``, ``bias`` (rad/s), ``flags`` (``FLAG_REST``,
    ``FLAG_ACC_REJECTED`` for a missing accelerometer sample, ``FLAG_MAG_REJECTED`` while the field is
    disturbed) and ``extra["bias_sigma"]``, the bias's standard deviation per axis (rad/s).  ``.state`` reads and
    restores everything; ``.scale`` and ``.bias_sigma`` give the current estimates.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import AttitudeEstimator
    >>> bias = np.radians([0.4, -0.3, 0.2])
    >>> est = AttitudeEstimator().update(np.tile(bias, (1000, 1)), np.tile([0.0, 0.0, 9.81], (1000, 1)), dt=0.01)
    >>> np.degrees(est.bias[-1]).round(3)      # learnt at rest within 10 s
    array([ 0.4, -0.3,  0.2])
    """

    natural_frame = "ENU"
    estimates_bias = True
    reports_flags = True
    missing_samples = True
    # state layout, checked when a state is restored (fusion/_base.py): the kernel indexes it without bounds checks
    _state_layout = (("q", (4,)), ("covariance", (6, 6)), *((name, (size,)) for name, _, size in _LAYOUT))
    _unit_keys = ("q", "q_gyro", "q_correction")

    def __init__(self, params: AttitudeParams | None = None, *, q0=None, frame: str = "ENU"):
        super().__init__(params_of(AttitudeParams, params, "attitude"), q0=q0, frame=frame)

    def update(self, gyr, acc, mag=None, *, dt=None, t=None, known_acc=None) -> Estimate:
        """Process a chunk of samples; any chunking gives the same result.

        Parameters
        ----------
        gyr : array_like, shape (N, 3)
            Angular rate, rad/s.
        acc : array_like, shape (N, 3)
            Specific force, m/s² (NaN rows: no sample).
        mag : array_like, shape (N, 3), optional
            Magnetic field, any unit (NaN rows: no sample); 9D when given.
        dt, t : optional
            Seconds per sample, or sample times.
        known_acc : array_like, shape (N, 3), optional
            Kinematic acceleration to subtract from ``acc``, sensor axes, m/s²: for a body whose acceleration is
            known from elsewhere (air data, wheel speed, GNSS), e.g. an aircraft in a coordinated turn, where the
            accelerometer alone reads lift, not gravity.

        Returns
        -------
        Estimate
            Attitudes, bias, its standard deviation (``extra["bias_sigma"]``) and flags.
        """
        if known_acc is not None:
            a = _v.vectors(acc, "acc", check=False, dtype=np.float64)  # NaN rows allowed; complex refused
            known = _v.vectors(known_acc, "known_acc", dtype=np.float64)
            if known.shape != a.shape:
                raise ValueError(f"known_acc must have the shape of acc {a.shape}, got {known.shape}")
            acc = a - known
        return super().update(gyr, acc, mag, dt=dt, t=t)

    # ----------------------------------------------------------------------------------------------------
    @property
    def bias(self) -> np.ndarray | None:
        """The current gyro bias estimate, rad/s (sensor axes)."""
        return None if self._state is None else self._state["bias_scale"][:3].copy()

    @property
    def scale(self) -> np.ndarray | None:
        """The current gyro scale-factor error estimate (dimensionless: the gyro reads (1 + s) ω)."""
        return None if self._state is None else self._state["bias_scale"][3:].copy()

    @property
    def bias_sigma(self) -> np.ndarray | None:
        """Standard deviation of the bias estimate, rad/s."""
        return None if self._state is None else np.sqrt(np.diag(self._state["covariance"])[:3])

    # ----------------------------------------------------------------------------------------------------
    def _new_state(self, q, gyr, acc, mag, dts, extra_in):
        from . import _attitude_numba as k

        p = self.params
        s = np.zeros(k.SIZE)
        s[k.QG : k.QG + 4] = q
        s[k.QC] = 1.0
        s[k.EXS] = 1.0
        ka = _first_present(acc, "acc")
        # the filter starts in steady state at the first sample once its interval is known (AFDT = 0: the kernel
        # restarts it at its first step), so that the first chunk's length does not matter; a first sample
        # later than the first row is turned back to the sensor axes of the first row, which q is for
        s[k.AFO : k.AFO + 3] = rotate(q, _back_to_first_sample(gyr, dts, ka, acc[ka]))
        s[k.RESTA : k.RESTA + 3] = acc[ka]
        s[k.MOLD] = -1.0
        cov = np.diag([p.bias_sigma_init**2] * 3 + [p.scale_sigma_init**2] * 3)
        state = {"q": q.copy(), "covariance": cov}
        for name, off, size in _LAYOUT:
            state[name] = s[getattr(k, off) : getattr(k, off) + size].copy()
        return state

    def _run(self, gyr, acc, mag, dts, extra_in):
        from . import _attitude_numba as k

        n = gyr.shape[0]
        st = self._state
        s = np.empty(k.SIZE)
        for name, off, size in _LAYOUT:
            s[getattr(k, off) : getattr(k, off) + size] = st[name]
        P = np.ascontiguousarray(st["covariance"], dtype=np.float64).copy()
        out = np.empty((n, 4))
        bias = np.empty((n, 3))
        sigma = np.empty((n, 3))
        flags = np.empty(n, dtype=np.uint8)
        m = mag if mag is not None else np.zeros((1, 3))
        k.run(gyr, acc, m, mag is not None, dts, self.params._vector(), s, P, out, bias, sigma, flags)
        for name, off, size in _LAYOUT:
            st[name] = s[getattr(k, off) : getattr(k, off) + size].copy()
        st["covariance"] = P
        if n:
            st["q"] = out[-1].copy()
        return Estimate(q=out, frame=self.natural_frame, bias=bias, flags=flags, extra={"bias_sigma": sigma})


def attitude(
    gyr,
    acc,
    mag=None,
    *,
    dt=None,
    t=None,
    params: AttitudeParams | None = None,
    q0=None,
    frame: str = "ENU",
    known_acc=None,
) -> Estimate:
    """Run the AttitudeEstimator over whole arrays (the batch form of :class:`AttitudeEstimator`).

    Parameters
    ----------
    gyr : array_like, shape (N, 3)
        Angular rate, rad/s.
    acc : array_like, shape (N, 3)
        Specific force, m/s² (NaN rows: no sample).
    mag : array_like, shape (N, 3), optional
        Magnetic field, any unit (NaN rows: no sample); 9D when given.
    dt, t : optional
        Seconds per sample, or sample times.
    params : AttitudeParams or mapping, optional
        Parameters (a mapping overrides the defaults by name).
    q0 : array_like, shape (4,), optional
        Initial attitude.
    frame : str
        Reference frame.
    known_acc : array_like, shape (N, 3), optional
        Kinematic acceleration to subtract from ``acc``, m/s².

    Returns
    -------
    Estimate
        Attitudes, bias, its standard deviation (``extra["bias_sigma"]``) and flags.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import attitude
    >>> est = attitude(np.zeros((100, 3)), np.tile([0.0, 0.0, 9.81], (100, 1)), dt=0.01)
    >>> est.q[-1].round(12)
    array([1., 0., 0., 0.])
    """
    return AttitudeEstimator(params, q0=q0, frame=frame).update(gyr, acc, mag, dt=dt, t=t, known_acc=known_acc)


def _reverse(gyr, acc, mag, dt, t):
    """Inputs for the backward pass: time reversed, rates negated, sample j covering forward interval n - j."""
    n = gyr.shape[0]
    g = np.zeros_like(gyr)
    g[1:] = -gyr[:0:-1]
    a = np.ascontiguousarray(acc[::-1])
    m = None if mag is None else np.ascontiguousarray(mag[::-1])
    if t is not None:
        return g, a, m, None, -np.asarray(t, dtype=np.float64)[::-1]
    d = np.asarray(dt, dtype=np.float64)
    if d.ndim == 0:
        return g, a, m, float(d), None
    dr = np.empty(n)
    dr[1:] = d[:0:-1]
    dr[0] = d[0]
    return g, a, m, dr, None


def _align_heading(reference, q, w) -> np.ndarray:
    """Turn q about the vertical by its weighted circular-mean heading offset from ``reference``."""
    from ..metrics import error_quaternion

    e = error_quaternion(reference, q)
    angle = 2.0 * np.arctan2(e[:, 3], e[:, 0])
    offset = np.arctan2(np.sum(w * np.sin(angle)), np.sum(w * np.cos(angle)))
    return multiply([np.cos(offset / 2), 0.0, 0.0, np.sin(offset / 2)], q, check=False)


def _combine(qf, qb, wf, wb, align_heading: bool) -> np.ndarray:
    """Weighted mean of two attitude series (sign-aligned), optionally turning qb about z onto qf first."""
    if align_heading:  # 6D passes have arbitrary, different headings: remove their mean offset
        qb = _align_heading(qf, qb, wf * wb)
    sign = np.where(np.sum(qf * qb, axis=1) < 0, -1.0, 1.0)[:, None]
    q = (wf[:, None] * qf + wb[:, None] * sign * qb) / (wf + wb)[:, None]
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def attitude_offline(
    gyr,
    acc,
    mag=None,
    *,
    dt=None,
    t=None,
    params: AttitudeParams | None = None,
    frame: str = "ENU",
    known_acc=None,
) -> Estimate:
    """Orientation from a whole recording, using the future as well as the past (module notes, step 6).

    1. The 6D estimator runs forward and backward in time with ``tau_acc`` and ``tau_mag`` multiplied by
       ``params.offline_time_factor``; their lags are equal and opposite, and each sample takes their mean,
       weighted by how long each pass has been running (``1 - exp(-t/tau_acc)``), after turning the backward
       heading onto the forward one.
    2. With a magnetometer, the field is taken into that combined 6D frame and the heading that turns it north
       is smoothed forward and backward in time by a local-linear fit (time constant ``tau_mag``; no lag
       behind the heading drift of a vertical gyro bias, even at the ends), leaving out every sample either
       9D pass flagged as magnetically disturbed; the gaps are bridged by the samples around them.  If every
       sample is disturbed (a magnetometer with uncalibrated hard iron, say), the combined 6D attitude is
       turned onto the forward 9D pass's mean heading instead.

    Parameters
    ----------
    gyr, acc, mag, dt, t, frame
        As for :func:`attitude` (the whole recording).
    params : AttitudeParams or mapping, optional
        Parameters, their online values (the factor is applied here); a mapping overrides the defaults by name.
    known_acc : array_like, shape (N, 3), optional
        Kinematic acceleration to subtract from ``acc``, m/s² (as for :func:`attitude`).

    Returns
    -------
    Estimate
        Attitudes, the two passes' bias estimates weighted by their inverse variances, with the standard
        deviation of that mean (``extra["bias_sigma"]``, the passes taken as independent), and flags: rest and
        missing accelerometer from the forward pass, magnetic disturbance from either.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import attitude_offline
    >>> est = attitude_offline(np.zeros((300, 3)), np.tile([0.0, 0.0, 9.81], (300, 1)), dt=0.01)
    >>> est.q[0].round(12), est.q[-1].round(12)
    (array([1., 0., 0., 0.]), array([1., 0., 0., 0.]))
    """
    from ..frames import frame_quaternion
    from ._attitude_numba import smooth_directions

    p = params_of(AttitudeParams, params, "attitude")
    f = p.offline_time_factor
    po = replace(p, tau_acc=p.tau_acc * f, tau_mag=p.tau_mag * f)
    g = _v.vectors(gyr, "gyr", dtype=np.float64)
    # shape and dtype here (NaN rows mean no sample; the forward pass checks the values): a complex acc lost its
    # imaginary part in asarray, and a scalar mag (attitude_offline(g, a, 0.5)) gave an IndexError
    a = _v.vectors(acc, "acc", check=False, dtype=np.float64)
    m = None if mag is None else _v.vectors(mag, "mag", check=False, dtype=np.float64)
    fwd = AttitudeEstimator(po)  # ENU: the heading arithmetic below is in ENU
    fwd6 = fwd.update(g, a, dt=dt, t=t, known_acc=known_acc)  # validates every input before anything else
    if known_acc is not None:
        a = a - np.asarray(known_acc, dtype=np.float64)  # validated by the forward pass
    if g.shape[0] == 0:  # nothing to smooth
        empty = AttitudeEstimator(po, frame=frame).update(g, a, m, dt=dt, t=t)
        empty.extra = {"bias_sigma": np.zeros((0, 3))}
        return empty
    gr, ar, mr, dtr, tr = _reverse(g, a, m, dt, t)
    intervals = np.diff(np.asarray(t, dtype=np.float64)) if t is not None else None
    n = g.shape[0]
    if intervals is None:
        intervals = np.broadcast_to(np.asarray(dt, dtype=np.float64), (n,))[1:]
    time = np.concatenate([[0.0], np.cumsum(intervals)])
    bwd6 = AttitudeEstimator(po).update(gr, ar, dt=dtr, t=tr)
    wf = 1.0 - np.exp(-time / po.tau_acc) + 1e-12
    wb = 1.0 - np.exp(-(time[-1] - time) / po.tau_acc) + 1e-12
    q = _combine(fwd6.q, bwd6.q[::-1], wf, wb, align_heading=True)
    bias_f, bias_b, flags = fwd6.bias, -bwd6.bias[::-1], fwd6.flags.copy()
    sigma_f, sigma_b = fwd6.extra["bias_sigma"], bwd6.extra["bias_sigma"][::-1]
    if m is not None:
        fwd9 = AttitudeEstimator(po).update(g, a, m, dt=dt, t=t)
        bwd9 = AttitudeEstimator(po).update(gr, ar, mr, dt=dtr, t=tr)
        disturbed = ((fwd9.flags | bwd9.flags[::-1]) & FLAG_MAG_REJECTED) > 0
        h = rotate(q, np.nan_to_num(m))
        psi = np.arctan2(h[:, 0], h[:, 1])  # the heading offset that turns the field north (+y of ENU)
        weight = (~disturbed & np.isfinite(m[:, 0])).astype(np.float64)
        if weight.any():
            # local-linear: the 6D passes cannot see a vertical gyro bias, so psi drifts in a ramp, which an
            # exponential mean would lag by tau_mag times its slope at both ends of the record
            smooth = smooth_directions(
                np.column_stack([np.cos(psi), np.sin(psi)]), weight, np.r_[0.0, intervals], po.tau_mag
            )
            delta = np.arctan2(smooth[:, 1], smooth[:, 0])
            q = multiply(np.column_stack([np.cos(delta / 2), 0 * delta, 0 * delta, np.sin(delta / 2)]), q, check=False)
        else:  # disturbed everywhere (an uncalibrated magnetometer): keep the forward 9D pass's mean heading
            q = _align_heading(fwd9.q, q, np.ones(n))
        bias_f, bias_b = fwd9.bias, -bwd9.bias[::-1]
        sigma_f, sigma_b = fwd9.extra["bias_sigma"], bwd9.extra["bias_sigma"][::-1]
        flags = (fwd9.flags & np.uint8(0xFF ^ FLAG_MAG_REJECTED)) | np.where(disturbed, FLAG_MAG_REJECTED, 0).astype(
            np.uint8
        )
    if frame != "ENU":
        q = multiply(frame_quaternion("ENU", frame), q, check=False)
    # the two passes' bias estimates, each weighted by how well it knows the bias (inverse variance)
    info_f, info_b = 1.0 / np.maximum(sigma_f, 1e-12) ** 2, 1.0 / np.maximum(sigma_b, 1e-12) ** 2
    bias = (info_f * bias_f + info_b * bias_b) / (info_f + info_b)
    sigma = 1.0 / np.sqrt(info_f + info_b)
    return Estimate(q=q, frame=frame, bias=bias, flags=flags, extra={"bias_sigma": sigma})
