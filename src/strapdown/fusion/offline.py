"""The AttitudeEstimator offline: a smoother over the whole recording, using the future as well as the past.

A smoother of the bias and scale states, then of the attitude.  The
estimator runs forward and backward in time (time constants ``offline_time_factor`` times longer, 9D with a
magnetometer); at each sample the two bias estimates, each from one side of the record and so independent,
are combined by their inverse variances (the two-filter form of the Rauch-Tung-Striebel smoother), and the
scale is the mean of the two passes' final estimates, each of which has seen the whole record.  The gyro,
corrected by that smoothed bias and scale, then gives one gyro frame over the whole record, and the
accelerometer in it passes the step-2 low-pass (time constant tau_acc times ``offline_time_factor``) forward
and then backward in time: a zero-phase filter whose gain is the square of the online one's, so linear
acceleration above the cutoff is attenuated as (ω tau)⁻⁴ instead of (ω tau)⁻², with no lag (a shaken level
body keeps 1/20 of the online tilt error at 0.2 Hz, exactly |H|²: tests/fusion/test_attitude.py).  The mean of
a forward and a backward pass, used before, cancels the lags too but has the gain Re H, the attenuation of
one pass; in the simulated test-bed the zero-phase filter cuts an ideal IMU's offline inclination error from
0.32° to 0.10° (benchmarks/bench_testbed.py), and on BROAD it is level (0.542° against 0.539°).
With a magnetometer the heading is then taken from the field in that 6D frame, smoothed
forward and backward in time by a local-linear fit (time constant ``offline_heading_tau``; it follows the
ramp a residual vertical bias gives the 6D heading right to the ends of the record), with the samples
either bias pass found disturbed left out.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .._support import validate as _v
from .._support.renamed import renamed
from ..rotations.quaternion import multiply, rotate
from ._base import float32_if, params_of
from .attitude_estimator import (
    AttitudeEstimator,
    AttitudeParams,
    attitude,  # noqa: F401  (strapdown.fusion.attitude of release 0.1 is this module)
)
from .estimate import FLAG_MAG_REJECTED, Estimate
from .saturation import GYRO_FLOOR, bridged, clipped_components

__all__ = ["attitude_offline"]


def _reverse(gyro, acc, mag, dt, t):
    """Inputs for the backward pass: time reversed, rates negated, sample j covering forward interval n - j."""
    n = gyro.shape[0]
    g = np.zeros_like(gyro)
    g[1:] = -gyro[:0:-1]
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
    e = multiply(reference, q * np.array([1.0, -1.0, -1.0, -1.0]), check=False)  # q_ref ⊗ q*: the angle needs no norm
    angle = 2.0 * np.arctan2(e[:, 3], e[:, 0])
    offset = np.arctan2(np.sum(w * np.sin(angle)), np.sum(w * np.cos(angle)))
    return multiply([np.cos(offset / 2), 0.0, 0.0, np.sin(offset / 2)], q, check=False)


@renamed(gyr="gyro")
def attitude_offline(
    gyro,
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

    1. The estimator (9D with a magnetometer) runs forward and backward in time with ``tau_acc`` and
       ``tau_mag`` multiplied by ``params.offline_time_factor``; at each sample the two bias estimates are
       combined by inverse variance (two-filter smoother), and the scale is the mean of the passes' final ones.
    2. The gyro corrected by that bias and scale gives one gyro frame for the whole record; the accelerometer
       in it, low-passed forward and then backward in time (zero phase, time constant ``tau_acc`` times
       ``offline_time_factor``), gives the inclination.
    3. With a magnetometer, the field is taken into that 6D frame and the heading that turns it north
       is smoothed forward and backward in time by a local-linear fit (time constant
       ``offline_heading_tau``), leaving out every sample either pass of step 1 flagged as magnetically
       disturbed; the gaps are bridged by the samples around them.  If every sample is disturbed (a
       magnetometer with uncalibrated hard iron, say), the 6D attitude is turned onto the forward
       pass's mean heading instead.

    Parameters
    ----------
    gyro, acc, mag, dt, t, frame
        As for :func:`attitude` (the whole recording).
    params : AttitudeParams or mapping, optional
        Parameters, their online values (the factor is applied here); a mapping overrides the defaults by name.
    known_acc : array_like, shape (N, 3), optional
        Kinematic acceleration to subtract from ``acc``, m/s² (as for :func:`attitude`).

    Returns
    -------
    Estimate
        Attitudes, the smoothed bias (the two passes' estimates weighted by their inverse variances) with its
        standard deviation (``extra["bias_sigma"]``, the passes taken as independent), and flags: rest, missing
        accelerometer, saturation and bias at the limit from the forward pass, magnetic disturbance from either.
        A clipped gyro is bridged as online (:mod:`strapdown.fusion.saturation`); after a run too long to
        bridge, the smoother does not restart (its zero-phase low-pass spreads the turn the gyro lost over
        ``tau_acc`` on both sides).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import attitude_offline
    >>> est = attitude_offline(np.zeros((300, 3)), np.tile([0.0, 0.0, 9.81], (300, 1)), dt=0.01)
    >>> est.q[0].round(12), est.q[-1].round(12)
    (array([1., 0., 0., 0.]), array([1., 0., 0., 0.]))
    """
    from ..rotations.frames import frame_quaternion
    from ._attitude_numba import smooth_directions
    from ._offline_numba import zero_phase_6d

    p = params_of(AttitudeParams, params, "attitude")
    f = p.offline_time_factor
    # the passes subtract their accelerometer bias as offline_acc_bias_significance says (attitude_estimator.py)
    po = replace(p, tau_acc=p.tau_acc * f, tau_mag=p.tau_mag * f, acc_bias_significance=p.offline_acc_bias_significance)
    g = _v.vectors(gyro, "gyro", dtype=np.float64)
    # shape and dtype here (NaN rows mean no sample; the forward pass checks the values): a complex acc lost its
    # imaginary part in asarray, and a scalar mag (attitude_offline(g, a, 0.5)) gave an IndexError
    a = _v.vectors(acc, "acc", check=False, dtype=np.float64)
    m = None if mag is None else _v.vectors(mag, "mag", check=False, dtype=np.float64)
    # 1. the bias and scale: forward and backward passes, combined per sample by inverse variance (the
    # two-filter smoother: each pass has seen one side of the sample, independently)
    first = AttitudeEstimator(po)  # ENU: the heading arithmetic below is in ENU
    fwd = first.update(g, a, m, dt=dt, t=t, known_acc=known_acc)  # validates every input before anything else
    if known_acc is not None:
        a = a - np.asarray(known_acc, dtype=np.float64)  # validated by the forward pass
    if g.shape[0] == 0:  # nothing to smooth
        empty = AttitudeEstimator(po, frame=frame).update(g, a, m, dt=dt, t=t)
        empty.extra = {"bias_sigma": np.zeros((0, 3))}
        return empty
    gr, ar, mr, dtr, tr = _reverse(g, a, m, dt, t)
    back = AttitudeEstimator(po)
    bwd = back.update(gr, ar, mr, dt=dtr, t=tr)
    sigma_f, sigma_b = fwd.extra["bias_sigma"], bwd.extra["bias_sigma"][::-1]
    info_f, info_b = 1.0 / np.maximum(sigma_f, 1e-12) ** 2, 1.0 / np.maximum(sigma_b, 1e-12) ** 2
    bias = (info_f * fwd.bias - info_b * bwd.bias[::-1]) / (info_f + info_b)  # the backward rates are negated
    sigma = 1.0 / np.sqrt(info_f + info_b)
    scale = 0.5 * (first.scale + back.scale)  # each pass's final estimate has seen the whole record
    # 2. the inclination: the gyro frame of the gyro corrected by the smoothed bias and scale (and the accelerometer
    # by the passes' accelerometer bias in use, zero where the data do not show one), corrected by the accelerometer
    # in that frame low-passed forward and backward in time (zero phase: _offline_numba.py)
    pin = clipped_components(g, p.gyro_range, GYRO_FLOOR)  # the passes bridged the clipped gyro; so does this frame
    gb = g if pin is None else bridged(g, pin)
    corrected = gb - bias - scale * gb
    a6 = np.ascontiguousarray(a - 0.5 * (first.acc_bias_in_use + back.acc_bias_in_use))
    n = g.shape[0]
    dts = np.zeros(n)  # the interval ending at each sample; the first attitude is the one at the first sample
    dts[1:] = np.diff(np.asarray(t, dtype=np.float64)) if t is not None else np.broadcast_to(dt, (n,))[1:]
    intervals = dts[1:]
    q = np.empty((n, 4))
    zero_phase_6d(corrected, a6, dts, np.ascontiguousarray(fwd.q[0], dtype=np.float64), po.tau_acc, q)
    flags = fwd.flags.copy()
    if m is not None:
        disturbed = ((fwd.flags | bwd.flags[::-1]) & FLAG_MAG_REJECTED) > 0
        h = rotate(q, np.nan_to_num(m))
        psi = np.arctan2(h[:, 0], h[:, 1])  # the heading offset that turns the field north (+y of ENU)
        weight = (~disturbed & np.isfinite(m[:, 0])).astype(np.float64)
        if weight.any():
            # local-linear: the 6D passes cannot see a vertical gyro bias, so psi drifts in a ramp, which an
            # exponential mean would lag by tau_mag times its slope at both ends of the record
            smooth = smooth_directions(
                np.column_stack([np.cos(psi), np.sin(psi)]), weight, np.r_[0.0, intervals], p.offline_heading_tau
            )
            delta = np.arctan2(smooth[:, 1], smooth[:, 0])
            q = multiply(np.column_stack([np.cos(delta / 2), 0 * delta, 0 * delta, np.sin(delta / 2)]), q, check=False)
        else:  # disturbed everywhere (an uncalibrated magnetometer): keep the forward 9D pass's mean heading
            q = _align_heading(fwd.q, q, np.ones(n))
        flags = (fwd.flags & np.uint8(0xFF ^ FLAG_MAG_REJECTED)) | np.where(disturbed, FLAG_MAG_REJECTED, 0).astype(
            np.uint8
        )
    if frame != "ENU":
        q = multiply(frame_quaternion("ENU", frame), q, check=False)
    est = Estimate(q=q, frame=frame, bias=bias, flags=flags, extra={"bias_sigma": sigma})
    return float32_if(est, gyro, acc, mag)  # float32 in, float32 out (computed in float64)
