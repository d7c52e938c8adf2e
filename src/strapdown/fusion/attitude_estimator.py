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
   errors grow with the rate, and the more the body accelerates (``bias_noise_acc_factor``): the low-pass
   leaves LP[a] of a linear acceleration a in the filtered vector, and its horizontal rate over g moves the
   correction exactly as a bias error would.  The accelerometer's departure from the filtered vector, a - LP[a],
   passed through the same low-pass, estimates LP[a] (for the frequencies above the cutoff that move it; slower
   ones are indistinguishable from gravity anyway), and its rate, correlated over about tau_acc, adds
   mean(|rate|²) tau_acc / g² (times the factor²) to the measurement's noise density².  In simulation, a body
   accelerating at 2 m/s² learns a wrong bias without it (with it, the inclination error is 0.88 of that without:
   tests/fusion/test_attitude.py); the factor (0.1) is chosen by leave-one-group-out
   on BROAD (benchmarks/bench_attitude.py), where larger values cost the bias learning more than they save.
   An accelerometer bias b_a leaves LP[R b_a] in the filtered vector, which turns with the body and so also moves
   the correction like a gyro bias: a consumer accelerometer's 20 mg, uncorrected, makes the regression learn a
   wrong gyro bias (benchmarks/bench_testbed.py: consumer IMU 1.57° 6D against VQF's 1.27°). Three more states model
   it (prior ``acc_bias_sigma_init``, 0.1 m/s², a consumer part's spread): over a block the correction turns by
   (ΔLP[R_1] b_a, -ΔLP[R_0] b_a)/g (R_i the rows of R, ΔLP their low-passed change). Learnt freely, those states
   read BROAD's motion as a bias of tens of mg (6D 0.644° -> 0.722°). What they read is a lever arm: the board turns
   about a point a few centimetres off the sensor, and a least-squares fit of BROAD's accelerometer against its
   optical truth finds that offset, 5.3-5.7 cm along the sensor's x axis, in five of the seven rotation trials
   (benchmarks/bench_attitude.py --only lever; 2.4 and 0.4 cm in the other two). A sensor at r from the point the
   body turns about accelerates by ω̇ × r + ω × (ω × r), in the almost-inertial frame d²(R r)/dt², which the
   low-pass passes as y'' r (y = LP[R], y'' from the filter's ODE), fixed in the body like a bias but not a bias.
   Three more states model r (prior ``lever_arm_sigma_init``, 0.1 m, random walk ``lever_arm_noise``; the regressor
   is the change of y'' over the block); on the simulated pendulum the estimate finds the rod, r_z = -0.48 m of -0.5
   (tests/fusion/test_attitude.py). With the lever arm taking the turn's accelerations, the accelerometer's states
   can learn at the gyro's noise (``acc_bias_noise_acc_factor`` 0.1, not 1): BROAD 6D 0.644° where the bias alone
   gave 0.722°. The block's measurement is used twice, as two filters that each take the other's estimate as known
   and its uncertainty h P hᵀ as a rate correlated over tau_acc (the covariance stays block-diagonal): first the
   accelerometer bias and the lever arm, from what the gyro's estimate leaves; then the gyro's errors, from what the
   accelerometer bias and the lever arm leave. (One joint update of all twelve states: 6D 0.656°.) What is subtracted
   from the accelerometer is the bias estimate shrunk towards zero, x - k² σ²/x per axis, none while ``|x|`` <= k σ
   (``acc_bias_significance`` k, 1): an estimate within its uncertainty is left out, so a calibrated part's readings are
   kept as they are (``acc_bias_in_use``). The lever arm is not subtracted (its low-passed effect on the attitude is
   some hundredths of a degree); it only keeps the turn's accelerations out of the biases. Measured
   (benchmarks/bench_testbed.py, bench_attitude.py): test-bed online 6D ahead of VQF in 15 of 22 conditions (8 before),
   the consumer IMU 1.52° -> 1.24° (VQF 1.27°), the 30°/s turntable 1.32° -> 0.75° (VQF 1.04°); BROAD 6D 0.638° ->
   0.644°, 9D 1.922° -> 1.931°, offline 1.538° -> 1.505° (``offline_acc_bias_significance``).
   The accelerometer bias the gyro's update takes as known is the estimate shrunk likewise, by a smaller k
   (``gyro_acc_bias_significance``, 0.7).  With the readings' k, what the shrinkage keeps out of the readings of a
   real bias is left for the gyro's states to explain, and where the motion cannot tell a gyro bias from an
   accelerometer bias (a steady turn about the vertical: both are fixed in the body and tilt the estimate alike) it
   passes to the gyro block by block: on a simulated 30°/s turntable the inclination error grew from 0.79° to 1.0°
   over ten minutes, and stays near 0.55° at 0.7 (tests/fusion/test_attitude.py).  Test-bed online 6D ahead of VQF
   in 18 of 22 conditions (15 with the readings' k), the consumer IMU 1.23° -> 1.18°; BROAD unchanged.
4. Bias at rest.  When gyro and accelerometer have stayed near their 0.5 s means for ``rest_time`` and the
   mean rate is plausible as a bias (within three prior spreads; a turntable is steady but not at rest), the
   mean gyro is a direct measurement of the bias on all three axes, as noisy as the gyro's scatter about that
   mean says.
   The bias prior.  Gyro biases of a sensor class spread about zero (``bias_limit``), and a bias wanders.  A
   first-order Gauss-Markov process models both: stationary spread ``bias_limit``, correlation time
   t_c = 2 bias_limit² / q (q = bias_sigma_init² / bias_forgetting_time, the wander rate), so that far inside the
   prior the bias wanders exactly as a random walk of rate q, and the prior pulls towards zero only at the rate
   1/t_c (about an hour for the defaults).  A clip would hold a real 4.5°/s bias at the limit and leave the
   attitude drifting; the prior learns it (tests/fusion/test_attitude.py) and flags it, FLAG_BIAS_AT_LIMIT.
5. Heading (9D).  The magnetic field, taken into the 6D frame, gives a heading offset δ that a first-order
   filter (``tau_mag``) follows about the vertical only, so the magnetometer never tilts the estimate:
   ``q = q_z(δ) ⊗ q_6D``; until it has averaged that long it is the mean of the updates so far, so the first
   field sets the heading at once.  While the accelerometer start (step 2) still averages, its tilt, and so the
   field's heading in it (a tilt error ε shows as ε tan(dip) of heading), is poorer than the filter's after it:
   each update then sets the heading afresh, and the mean starts when the filter takes over.  In simulated
   starts in motion this brings the heading within 2° after 10 s where the mean over the whole start left
   4.5° (tests/fusion/test_attitude.py).  The first field is only a candidate for the reference until its norm
   and dip have stayed consistent for ``mag_start_time``; a different field meanwhile (a phone magnetometer's
   first second, say) replaces it and restarts the heading.  The field's norm and dip are compared with a slowly
   learnt reference;
   while they differ (a magnet, steel nearby) the magnetometer is left out and flagged.  A disturbance that lasts
   ``mag_new_time`` is taken as a new environment, and a return to the previous field is recognised at once.
   The rate of δ, regressed like the inclination's, measures the vertical bias, which the accelerometer cannot
   see on a level platform.
6. Offline: :func:`strapdown.fusion.offline.attitude_offline` (the notes of :mod:`strapdown.fusion.offline`).
7. Saturation.  A gyro clipped at its range turns the gyro frame by less than the body turned, and a low-pass in
   that frame (step 2) would then hold a stale gravity direction for several ``tau_acc``, the heading offset
   (step 5) a stale heading for ``tau_mag``.  Components pinned at the range (``gyro_range``, or found from the
   readings: :mod:`strapdown.fusion.saturation`) are flagged FLAG_SATURATED and replaced by the cubic that
   continues the readings on either side of the run (the top of the peak the range cut off).  A run longer
   than ``LONG_CLIP`` (0.5 s) is past bridging: once it has lasted that long, and again at its first
   unclipped sample, the inclination restarts as at the first sample (step 2's plain mean; the bias is not
   learnt meanwhile) and the heading's mean restarts when that is over, so that gravity and the field pull the
   attitude back within seconds instead of time constants.  A clipped accelerometer sample (``acc_range``)
   is left out, as a missing one.  A chunk boundary inside a clipped run changes its bridge (each chunk holds
   a run at its ends at the limit).

Steps 3-5 run at ``update_rate`` on time-averaged blocks, so the cost per sample stays that of steps 1-2.
Sensors may run at different rates: a NaN row in ``acc`` or ``mag`` means no sample of that sensor then.

Irregular sampling.  Every coefficient is computed for the interval it spans, so jitter, dropped rows and gaps
cost only the information they take away:

* The low-passes (the accelerometer's, per sample, and the regressors', per block) are one continuous
  second-order Butterworth filter, stepped exactly over each interval with the input held (``lowpass2`` in
  _kernels_numba.py).  Its states are the output and its rate, which mean the same whatever the interval; a
  direct-form filter's states belong to the coefficients that made them, and when a dropped row changed those
  for one step the output jumped (10 % of BROAD's rows dropped multiplied the 9D error by 5, 6D by 7).  No restart is
  needed after a gap.  The regressor is the filter output's mean over the block, as the measurement is the
  correction's mean rate over it (an exact integral of the filter's ODE).
* An interval longer than the nominal one (the shortest recent interval) holds lost gyro samples: the rate over
  the uncovered part is interpolated linearly between the samples on either side (``gap_step``), which
  integrates a linearly changing rate exactly; applying the next sample's rate over the whole gap errs by about
  the gap times the change of rate.  A lasting lower rate becomes the nominal interval within about a second.
* The rest detector's and the magnetometer's first-order means use 1 - exp(-interval/tau).

``benchmarks/bench_attitude.py --irregular`` measures it on BROAD (rows dropped at random with their true times,
and NaN accelerometer and magnetometer rows); tests/fusion/test_attitude.py on simulated data.

The defaults were chosen once on the 22 BROAD trials (one common set, BROAD's rule) and are physical: time
constants in seconds, rates in rad/s, noise densities in rad/s·√s.  The results change little across a wide
range (``benchmarks/bench_attitude.py`` prints the RMSE surface over ``tau_acc`` and ``tau_mag``).
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import cache
from itertools import pairwise
from numbers import Real

import numpy as np

from .._support import validate as _v
from .._support.renamed import renamed
from ..rotations.quaternion import rotate
from ._base import Estimator, params_of
from .estimate import FLAG_SATURATED, Estimate, PiecewiseEstimate, joined
from .saturation import ACC_FLOOR, GYRO_FLOOR, bridged, clipped_components, restarts

__all__ = ["AttitudeEstimator", "AttitudeParams", "attitude"]

_DEG = np.pi / 180.0
# the kernel run uncompiled, seconds per sample (9D measured 40 µs, 6D 23 µs, on the reference machine of
# docs/guide/performance.md): what a first call costs while the kernel compiles in the background
# (_support/uncompiled.py)
_UNCOMPILED_S_PER_SAMPLE = 5e-5


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
    bias_noise_acc_factor : float
        Growth of the in-motion noise with the linear acceleration a (dimensionless): noise² += factor²
        mean(|d LP[a]/dt|²_horizontal) tau_acc / g², the rate at which the low-passed acceleration moves the
        correction (module notes, step 3).  Default 0.1 (leave-one-group-out on BROAD); 0 turns it off.
    bias_noise_rest : float
        Least noise density of the at-rest bias measurement, rad/s·√s (default 0.0018°/s·√s).  Above it the
        noise comes from the gyro's own scatter at rest, so that ``bias_sigma`` stays honest for noisy gyros.
    scale_sigma_init : float
        Initial uncertainty of the gyro scale-factor errors (dimensionless, default 0.002 = 0.2 %).
    scale_noise : float
        Random walk of the scale-factor errors, 1/√s (default 1e-5).
    acc_bias_sigma_init : float
        Initial uncertainty of the accelerometer bias, m/s² (default 0.1, about 10 mg: a consumer part's
        spread; module notes, step 3); 0 leaves the bias out.
    acc_bias_noise : float
        Random walk of the accelerometer bias, m/s²/√s (default 1e-4).
    acc_bias_noise_acc_factor : float
        ``bias_noise_acc_factor`` for the update of the accelerometer bias and the lever arm (dimensionless).
        Default 0.1, the gyro's (leave-one-group-out on BROAD, benchmarks/bench_attitude.py): with the lever arm
        modelled, the accelerations of a turn about a point off the sensor are no longer read as a bias, and the
        whole linear-acceleration noise (1) learnt the simulated consumer part's 20 mg too slowly to help.
    acc_bias_significance : float
        The accelerometer bias subtracted is the estimate x shrunk to x - k² σ²/x per axis, and none while
        ``|x|`` <= k σ (σ its standard deviation); k is this, default 1 (leave-one-group-out on BROAD: 6D picks 1 in
        every fold, 9D in eight of nine; offline: ``offline_acc_bias_significance``); 0 subtracts the whole
        estimate.
    gyro_acc_bias_significance : float
        The accelerometer bias the gyro's update takes as known: the estimate shrunk as for
        :attr:`~AttitudeEstimator.acc_bias_in_use`, with this k (module notes, step 3).  Default 0.7:
        leave-one-group-out on BROAD picks 0.7 in seven of nine 6D folds (held out 0.645°) and 1 in seven 9D folds
        (held out 1.922°), in-sample 6D 0.649°, 0.647°, 0.645°, 0.645°, 0.645° and 9D 1.976°, 1.954°, 1.929°,
        1.921°, 1.921° at 0, 0.25, 0.5, 0.7, 1 (benchmarks/bench_attitude.py); on the simulated test-bed
        (benchmarks/bench_testbed.py) smaller is better throughout (consumer IMU 1.11°, 1.16°, 1.18°, 1.23° at 0,
        0.5, 0.7, 1), so 0.7 is the least k that costs BROAD nothing.
    lever_arm_sigma_init : float
        Initial uncertainty of the lever arm r, m: the sensor's offset, in sensor axes, from the point the body
        turns about, whose turning accelerates it by ω̇ × r + ω × (ω × r) (module notes, step 3).  Default 0.1
        (a hand-held or body-worn sensor; BROAD's board turns about a point 5-6 cm along its x axis in most
        rotation trials); 0 leaves it out.
    lever_arm_noise : float
        Random walk of the lever arm, m/√s (default 1e-3: a grip that changes over minutes).
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
        Spread (standard deviation) of the bias prior, rad/s (default 2°/s).  The bias is modelled as a
        Gauss-Markov process with this stationary spread that wanders as ``bias_forgetting_time`` says, so a
        larger bias the data show is learnt, not clipped; while an estimate lies beyond it on some axis the
        samples carry ``FLAG_BIAS_AT_LIMIT`` (check the sensor).  A steady mean rate up to three times it is
        taken as a bias at rest; a faster one is a steady turn.
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
    mag_start_time : float
        Seconds the first field must stay consistent (norm and dip within the thresholds) before it becomes the
        reference; a different field meanwhile replaces it and sets the heading afresh.  Default 2.
    update_rate : float
        Rate of the bias, scale and heading updates, Hz.  Default 3: the regressors are low-passed over
        seconds (tau_acc), so a block of a third of a second loses little, and each block's update of twelve
        states costs as much as about twelve samples.  On BROAD (benchmarks/bench_attitude.py, leave-one-group-out)
        6D 0.646°, 0.645°, 0.644°, 0.644°, 0.644° at 2, 3, 4, 5, 10 Hz (10 picked in every fold, held out
        0.644°), 9D 1.941°, 1.921°, 1.930°, 1.931°, 1.948° (3 in eight folds, held out 1.937°); 3 Hz instead of 5
        takes the speed at 100 Hz from 4.6x to 5.5-5.8x vqf's.
    offline_time_factor : float
        :func:`attitude_offline` learns the bias and scale in passes with ``tau_acc`` and ``tau_mag`` multiplied
        by this, and low-passes the accelerometer forward and backward with ``tau_acc`` times this (a
        zero-phase filter has no lag to pay for a longer time constant).  Default 1.5 (leave-one-group-out on
        BROAD, benchmarks/bench_attitude.py).
    offline_heading_tau : float
        Time constant of :func:`attitude_offline`'s local-linear smoothing of the heading from the field, s.
        Default 100 (leave-one-group-out on BROAD): with the bias smoothed, the 6D heading drifts only with what
        is left of it, a ramp the local-linear fit follows, so the field can be averaged longer than online.
    offline_acc_bias_significance : float
        ``acc_bias_significance`` for :func:`attitude_offline`'s passes.  Default 0, the whole estimate
        (leave-one-group-out on BROAD: 0 in all nine folds, the offline 9D total 1.548° -> 1.505° held out): the
        accelerometer is corrected by the passes' final estimates, each from the whole record, not by a running
        one that may still be wrong by its uncertainty.
    gyro_range : float
        The gyro's full-scale range, rad/s: a component at it is clipped (module notes, step 7).  Default 0:
        found from the readings (runs of three identical readings at an axis's extreme of the chunk, 2 rad/s or
        more: :func:`strapdown.fusion.saturation.saturated`); ``inf`` never.
    acc_range : float
        The accelerometer's full-scale range, m/s², likewise (default 0: found from the readings, extremes of
        1.5 g or more; ``inf`` never).
    """

    tau_acc: float = 3.5
    tau_mag: float = 20.0
    bias_sigma_init: float = 0.5 * _DEG
    bias_forgetting_time: float = 100.0
    bias_noise_motion: float = 0.18 * _DEG
    bias_noise_rate_factor: float = 6e-4
    bias_noise_rest: float = 0.0018 * _DEG
    bias_noise_acc_factor: float = 0.1
    scale_sigma_init: float = 0.002
    scale_noise: float = 1e-5
    acc_bias_sigma_init: float = 0.1
    acc_bias_noise: float = 1e-4
    acc_bias_noise_acc_factor: float = 0.1
    acc_bias_significance: float = 1.0
    lever_arm_sigma_init: float = 0.1
    lever_arm_noise: float = 1e-3
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
    mag_start_time: float = 2.0
    update_rate: float = 3.0
    offline_time_factor: float = 1.5
    offline_heading_tau: float = 100.0
    offline_acc_bias_significance: float = 0.0
    gyro_range: float = 0.0
    acc_range: float = 0.0
    gyro_acc_bias_significance: float = 0.7

    def __post_init__(self):
        zero_ok = {
            "bias_noise_acc_factor",
            "bias_noise_rate_factor",
            "scale_sigma_init",
            "scale_noise",
            "acc_bias_sigma_init",
            "acc_bias_noise",
            "bias_noise_mag",
            "rest_time",
            "gyro_range",
            "acc_range",
            "acc_bias_noise_acc_factor",
            "acc_bias_significance",
            "lever_arm_sigma_init",
            "lever_arm_noise",
            "offline_acc_bias_significance",
            "gyro_acc_bias_significance",
        }
        for f in fields(self):
            v = getattr(self, f.name)
            infinite_ok = f.name in ("gyro_range", "acc_range") and v == np.inf  # inf: no saturation detection
            if not isinstance(v, Real) or isinstance(v, (bool, np.bool_)) or not (np.isfinite(v) or infinite_ok):
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
                self.bias_noise_acc_factor**2,
                self.mag_start_time,
                self.acc_bias_noise**2 if self.acc_bias_sigma_init > 0 else 0.0,  # off: the states stay at 0
                self.acc_bias_noise_acc_factor**2,
                self.acc_bias_significance**2,
                self.lever_arm_noise**2 if self.lever_arm_sigma_init > 0 else 0.0,
                self.gyro_acc_bias_significance**2,
            ]
        )


# named parts of the kernel's state vector (offsets in _attitude_numba.py)
_LAYOUT = (
    ("q_gyro", "QG", 4),
    ("q_correction", "QC", 3),
    ("acc_filter_rate", "AF", 3),
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
    ("rest_gyro_variance", "RESTV", 1),
    ("acc_start_seconds", "AINIT", 1),
    ("acc_start_sum", "ASUM", 3),
    ("acc_start_count", "ACNT", 1),
    ("mag_updates", "MAGN", 1),
    ("gyro_previous", "GPREV", 3),
    ("nominal_interval", "NOMDT", 1),
    ("linear_acc_seconds", "ALIN", 1),
    ("linear_acc_filter", "RLP", 3),
    ("linear_acc_filter_rate", "RLV", 3),
    ("mag_start_seconds", "MCONF", 1),
    ("acc_bias", "XA", 3),
    ("rest_acc_last", "ALAST", 3),
    ("linear_acc_block_sum", "ARES", 3),
    ("gyro_steps_unnormalised", "QN", 1),
    ("lever_arm", "XL", 3),
    ("lever_regressor", "YDD", 6),
)


class AttitudeEstimator(Estimator):
    """Streaming 6D/9D orientation estimator with gyro bias and scale-factor estimation (module notes).

    Parameters
    ----------
    params : AttitudeParams or mapping, optional
        Time constants, noise densities and thresholds (a mapping overrides the defaults by name).

    Notes
    -----
    ``update(gyro, acc, mag=None, *, dt=None, t=None, known_acc=None)``: gyro in rad/s (finite), accelerometer
    in m/s², magnetic field in any unit; a NaN row in ``acc`` or ``mag`` means no sample of that sensor then;
    ``known_acc`` is a kinematic acceleration to subtract from the accelerometer.  Sample k's accelerometer and
    magnetometer readings are taken as those at the end of its gyro step; readings averaged over the step lag
    by half a step, which matters only where half a step's rotation is large (10° at 2000°/s and 100 Hz).  The
    :class:`~strapdown.fusion.Estimate` carries ``q``, ``bias`` (rad/s), ``flags`` (``FLAG_REST``,
    ``FLAG_ACC_REJECTED`` for a missing accelerometer sample, ``FLAG_MAG_REJECTED`` while the field is
    disturbed, ``FLAG_BIAS_AT_LIMIT`` while the bias lies beyond its prior's spread) and ``extra["bias_sigma"]``,
    the bias's standard deviation per axis (rad/s).  ``.state`` reads and restores everything; ``.scale`` and
    ``.bias_sigma`` give the current estimates.

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
    compact_intervals = True
    checks_in_kernel = True
    # state layout, checked when a state is restored (fusion/_base.py, _checked_state): the kernel indexes it
    # without bounds checks
    # the covariance is over gyro bias, gyro scale, accelerometer bias and lever arm (3 each; _new_state)
    # and the seconds of a clipped run under way at the chunk's end (step 7)
    _state_layout = (
        ("q", (4,)),
        ("covariance", (12, 12)),
        ("saturated", ()),
        *((name, (size,)) for name, _, size in _LAYOUT),
    )
    _unit_keys = ("q", "q_gyro", "q_correction")
    # new in this version: a state taken before starts them at 0
    _optional_keys = ("gyro_steps_unnormalised", "saturated")
    _replaces_state = True

    def __init__(self, params: AttitudeParams | None = None, *, q0=None, frame: str = "ENU"):
        super().__init__(params_of(AttitudeParams, params, "attitude"), q0=q0, frame=frame)

    @renamed(gyr="gyro")
    def update(self, gyro, acc, mag=None, *, dt=None, t=None, known_acc=None) -> Estimate:
        """Process a chunk of samples; any chunking gives the same result.

        Parameters
        ----------
        gyro, acc, mag, dt, t
            As for every filter (:mod:`strapdown.fusion`); a NaN row of ``acc`` or ``mag`` is no sample.
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
        return super().update(gyro, acc, mag, dt=dt, t=t)

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
    def acc_bias(self) -> np.ndarray | None:
        """The current accelerometer bias estimate, m/s² (sensor axes; zero if ``acc_bias_sigma_init`` is 0).

        What is subtracted from the readings is :attr:`acc_bias_in_use`.
        """
        return None if self._state is None else self._state["acc_bias"].copy()

    @property
    def acc_bias_in_use(self) -> np.ndarray | None:
        """The accelerometer bias subtracted from the readings, m/s² (sensor axes).

        The estimate x shrunk to x - k² σ²/x per axis, zero while ``|x|`` <= k σ (k = ``acc_bias_significance``;
        module notes, step 3).
        """
        if self._state is None:
            return None
        x, var = self._state["acc_bias"], np.diag(self._state["covariance"])[6:9]
        k2 = self.params.acc_bias_significance**2
        keep = x * x > k2 * var
        return np.where(keep, x - k2 * var / np.where(keep, x, 1.0), 0.0)

    @property
    def lever_arm(self) -> np.ndarray | None:
        """The current lever-arm estimate, m (sensor axes; zero if ``lever_arm_sigma_init`` is 0).

        The sensor's offset from the point the body turns about.  Not subtracted: it keeps the turn's
        accelerations out of the bias estimates (module notes, step 3).
        """
        return None if self._state is None else self._state["lever_arm"].copy()

    @property
    def bias_sigma(self) -> np.ndarray | None:
        """Standard deviation of the bias estimate, rad/s."""
        return None if self._state is None else np.sqrt(np.diag(self._state["covariance"])[:3])

    # ----------------------------------------------------------------------------------------------------
    def _new_state(self, q, gyro, acc, mag, dts, extra_in):
        from . import _attitude_numba as k

        p = self.params
        s = np.zeros(k.SIZE)
        s[k.QG : k.QG + 4] = q
        s[k.QC] = 1.0
        s[k.EXS] = 1.0
        ka, a0 = self._acc0
        # the filter starts at the first sample (in the start's averaging, then at rest: rate 0); a first sample
        # later than the first row is turned back to the sensor axes of the first row, which q is for
        s[k.AFO : k.AFO + 3] = rotate(q, a0)
        s[k.RESTA : k.RESTA + 3] = acc[ka]
        s[k.ALAST : k.ALAST + 3] = acc[ka]
        s[k.MOLD] = -1.0
        cov = np.diag(
            [p.bias_sigma_init**2] * 3
            + [p.scale_sigma_init**2] * 3
            + [p.acc_bias_sigma_init**2] * 3
            + [p.lever_arm_sigma_init**2] * 3
        )
        state = {"q": q.copy(), "covariance": cov, "saturated": 0.0}
        for name, off, size in _LAYOUT:
            state[name] = s[getattr(k, off) : getattr(k, off) + size].copy()
        return state

    def _run(self, gyro, acc, mag, dts, extra_in):
        p = self.params
        pin = clipped_components(gyro, p.gyro_range, GYRO_FLOOR)
        clipped = None if pin is None else pin.any(axis=-1)
        if pin is not None:
            gyro = bridged(gyro, pin)
        acc_pin = clipped_components(acc, p.acc_range, ACC_FLOOR)
        if acc_pin is not None:  # a clipped accelerometer sample reads neither gravity nor the specific force
            acc = acc.copy()
            acc[acc_pin.any(axis=-1)] = np.nan
        n = gyro.shape[0]
        # past bridging, the inclination and heading restart (module notes, step 7)
        carried = self._state.get("saturated", 0.0)
        cuts = ()
        if clipped is not None or carried > 0.0:
            none = np.zeros(n, dtype=bool)
            cuts, self._state["saturated"] = restarts(none if clipped is None else clipped, dts, carried)
        if not len(cuts):
            est, squares = self._run_piece(gyro, acc, mag, dts, 0, n)
        else:
            bounds = np.r_[0, cuts, n] if cuts[0] > 0 else np.r_[cuts, n]
            squares = np.zeros(3)
            parts = []
            for b, e in pairwise(bounds):
                if b in cuts:
                    self._restart()
                part, sq = self._run_piece(gyro, acc, mag, dts, int(b), int(e))
                squares += sq
                parts.append(part)
            est = joined(parts, self.natural_frame)
        for mask in (pin, acc_pin):
            if mask is not None:
                est.flags[mask.any(axis=-1)] |= np.uint8(FLAG_SATURATED)
        return est, squares

    def _restart(self) -> None:
        """Inclination and heading start afresh, as at the first sample; bias, scale and the rest are kept."""
        st = self._state
        for name in ("acc_start_seconds", "acc_start_sum", "acc_start_count", "mag_undisturbed_seconds", "started"):
            st[name] = np.zeros_like(st[name])
        st["mag_updates"] = np.full(1, -1.0)  # the heading waits for the inclination's restart, then its mean restarts

    def _run_piece(self, gyro, acc, mag, dts, b, e):
        """The kernel over samples b..e-1: (its PiecewiseEstimate, the sums of squares of its inputs)."""
        from .._support import uncompiled
        from . import _attitude_numba as k

        if b or e < gyro.shape[0]:
            # one interval per sample, or compact ones (the first sample's, then every later one's)
            if len(dts) == gyro.shape[0]:
                dts = dts[b:e]
            elif b:
                dts = dts[1:]
            gyro, acc = gyro[b:e], acc[b:e]
            mag = None if mag is None else mag[b:e]
        n = gyro.shape[0]
        st = self._state
        # the entries in the order of their offsets, which tile the vector: one concatenation packs them
        s = np.concatenate([st[name] if name in st else np.zeros(b - a) for name, a, b in _slices(k)])  # 0: missing
        P = np.ascontiguousarray(st["covariance"], dtype=np.float64).copy()
        out = np.empty((n, 4))
        flags = np.empty(n, dtype=np.uint8)
        p = self.params._vector()
        # Bias and sigma per block.  A block ends once its intervals sum to its length T (within 1e-9), so every
        # block but the first (which may be under way from the last chunk) holds more than T / (2 dt_max) samples:
        # with the unfinished last one, at most n // floor(T / (2 dt_max)) + 2 segments.  Buffers of that size,
        # not n + 1, spare a call the (huge) pages it would fault in for one row in every few dozen.
        longest = float(dts.max()) if n else 0.0
        per_block = int(0.5 * p[18] / longest) if longest > 0.0 else 0
        n_seg_max = n + 1 if per_block < 1 else min(n + 1, n // per_block + 2)
        seg_end = np.empty(n_seg_max, dtype=np.int64)
        seg_val = np.empty((2, n_seg_max, 3))  # bias, sigma
        m = mag if mag is not None else np.zeros((1, 3))
        squares = np.zeros(3)
        args = (gyro, acc, m, mag is not None, dts, p, s, P, out, seg_end, seg_val, flags, squares)
        n_seg = uncompiled.call(k.run, *args, python_seconds=n * _UNCOMPILED_S_PER_SAMPLE)
        # views of s, made afresh for each piece: nothing writes to a state's arrays in place (_replaces_state)
        for name, a, b in _slices(k):
            st[name] = s[a:b]
        st["covariance"] = P
        if n:
            st["q"] = out[-1].copy()
        ends, vals = seg_end[:n_seg], seg_val[:, :n_seg]
        if n_seg_max > 2 * n_seg + 2:  # views would keep a mostly unused buffer alive (long intervals): copies
            ends, vals = ends.copy(), vals.copy()
        segments = (ends, vals[0], {"bias_sigma": vals[1]})
        return PiecewiseEstimate(q=out, frame=self.natural_frame, flags=flags, segments=segments), squares


@cache
def _slices(k) -> tuple:
    """(name, start, end) of the state's entries in the kernel module k's vector, in order; they must tile it."""
    sl = tuple(
        sorted(((name, getattr(k, off), getattr(k, off) + size) for name, off, size in _LAYOUT), key=lambda e: e[1])
    )
    if [e[1] for e in sl] != [0, *(e[2] for e in sl[:-1])] or sl[-1][2] != k.SIZE:
        raise AssertionError("the state layout does not tile the kernel's vector")  # edited on one side only
    return sl


@renamed(gyr="gyro")
def attitude(
    gyro,
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
    gyro, acc, mag, dt, t, known_acc
        As for :meth:`AttitudeEstimator.update`.
    params, q0, frame
        As for :class:`AttitudeEstimator`.

    Returns
    -------
    Estimate
        As from :meth:`AttitudeEstimator.update`.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import attitude
    >>> est = attitude(np.zeros((100, 3)), np.tile([0.0, 0.0, 9.81], (100, 1)), dt=0.01)
    >>> est.q[-1].round(12)
    array([1., 0., 0., 0.])
    """
    return AttitudeEstimator(params, q0=q0, frame=frame).update(gyro, acc, mag, dt=dt, t=t, known_acc=known_acc)
