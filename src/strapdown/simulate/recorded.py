"""Synthetic IMU data for a recorded motion (optical motion capture, a reference system) through the C² spline.

Recorded attitudes go through :class:`strapdown.propagate.spline.RotationSpline` into gyro readings, with the sensor
errors of an :class:`~strapdown.simulate.ImuModel`.

:class:`RecordedMotion` is a :class:`~strapdown.simulate.Trajectory` whose attitude is the
:class:`strapdown.propagate.spline.RotationSpline` through the samples, so its body rate is the spline's (continuous,
with continuous angular acceleration) and every gyro form of :func:`~strapdown.simulate.sample` comes out
consistent with the recording:

* ``gyro="rotvec"``: the rotation vector of each step, which ``integrate(..., method="exact",
  input="increment")`` turns back into the spline's attitudes to rounding (at the samples: the recording);
* ``gyro="increment"``: ``∫ω dt`` over each step, by 8-point Gauss-Legendre on pieces cut at the recording's
  sample times (inside a piece the rate is analytic, so the quadrature is exact to rounding);
* ``gyro="average"`` and ``"rate"``: the mean rate over each step, the rate at the start of each step.

Positions, when given, go through a natural cubic spline per axis, whose second derivative is the kinematic
acceleration the accelerometer adds to gravity; without them the body is taken to stay where it is (the
accelerometer reads gravity only).  Gravity points down in the recording's reference frame, so that frame must be
named by axis letters with a vertical axis (``"NED"``, ``"ENU"``, a Y-up ``"NUE"``...); the magnetometer reads the
Earth's field of ``magnetic_field`` with its north along the frame's N.

The recording's times can start anywhere; the IMU's first sample starts at the first recorded time.  Sample
rates: any (a 1 kHz IMU from 100 Hz capture gives readings between the samples, from the spline); ``rate_hz=None``
takes the recording's own mean rate.  The spline's end conditions (the rate at the first and last sample is
that of the end interval) make the rates of the first and last few intervals less faithful to the real motion
(errors fall by about 3.7 per interval inwards): trim them when the ends matter.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from ..rotations.frames import change_frame, frame_matrix
from .sampling import ImuData, MagneticField, sample
from .trajectories import Trajectory, _quadrature, _times

__all__ = ["RecordedMotion", "sample_recorded"]


def _natural_cubic_second_derivatives(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Second derivatives M at the knots of the natural cubic spline through (t, y), y of shape (n, 3).

    The C² conditions h_{i-1} M_{i-1} + 2 (h_{i-1} + h_i) M_i + h_i M_{i+1} = 6 (Δ_i - Δ_{i-1}), Δ_i the slope of
    interval i, with M_0 = M_{n-1} = 0, solved by the Thomas algorithm (diagonally dominant, no pivoting).
    """
    n = t.shape[0]
    m = np.zeros_like(y)
    if n < 3:
        return m
    h = np.diff(t)
    slope = np.diff(y, axis=0) / h[:, None]
    rhs = 6 * (slope[1:] - slope[:-1])
    diag = 2 * (h[:-1] + h[1:])
    sub = h[1:-1]  # off-diagonals (symmetric)
    c = np.empty(n - 2)
    d = np.empty_like(rhs)
    c[0] = sub[0] / diag[0] if n > 3 else 0.0
    d[0] = rhs[0] / diag[0]
    for i in range(1, n - 2):
        den = diag[i] - sub[i - 1] * c[i - 1]
        c[i] = sub[i] / den if i < n - 3 else 0.0
        d[i] = (rhs[i] - sub[i - 1] * d[i - 1]) / den
    x = np.empty_like(rhs)
    x[-1] = d[-1]
    for i in range(n - 4, -1, -1):
        x[i] = d[i] - c[i] * x[i + 1]
    m[1:-1] = x
    return m


def _frames(q, reference, body) -> tuple[str, str]:
    """The recording's frames: as given, else those an Attitude carries, else NED and FRD."""
    from ..rotations.attitude import Attitude

    if isinstance(q, Attitude):
        for given, carried, side in ((reference, q.reference, "reference"), (body, q.body, "body")):
            if given is not None and carried is not None and given != carried:
                raise ValueError(f"{side}={given!r} but the Attitude q names its {side} {carried!r}")
        reference = reference or q.reference
        body = body or q.body
    return reference or "NED", body or "FRD"


class RecordedMotion(Trajectory):
    """A trajectory through recorded attitudes (and optionally positions), C² in attitude.

    Parameters
    ----------
    t : array_like, shape (n,)
        Strictly increasing sample times, seconds (n ≥ 2).
    q : array_like or strapdown.Attitude, shape (n, 4)
        Attitudes at those times, body to ``reference``, scalar first.
    reference, body : str, optional
        Frames of ``q`` (and of ``positions``), by axis letters (:mod:`strapdown.rotations.frames`): the reference frame
        must have a vertical axis for gravity.  By default those named by an Attitude ``q``, else NED and FRD.
    positions : array_like, shape (n, 3), optional
        Positions of the IMU in ``reference`` (metres); None: at rest.

    Notes
    -----
    Internally the motion is flown in NED/FRD, like every trajectory of :mod:`strapdown.simulate`; times run
    from 0 at ``t[0]`` (:attr:`t0` holds the offset).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_rotvec
    >>> from strapdown.simulate import RecordedMotion
    >>> t = np.arange(5) / 100.0
    >>> motion = RecordedMotion(t, from_rotvec(np.outer(t, [0.0, 0.0, 1.0])), reference="NED", body="FRD")
    >>> motion.rate([0.015]).round(12)          # 1 rad/s about the body's z
    array([[0., 0., 1.]])
    """

    def __init__(self, t, q, *, reference: str | None = None, body: str | None = None, positions=None):
        from ..propagate.interpolate import RotationSpline

        reference, body = _frames(q, reference, body)
        self.reference, self.body = reference, body

        tv = _v.finite(t, "t", dtype=np.float64)
        if tv.ndim != 1 or tv.shape[0] < 2:
            raise ValueError(f"t must have shape (n,) with n ≥ 2 sample times, got shape {tv.shape}")
        try:
            to_ned = frame_matrix(reference, "NED")
        except ValueError:
            raise ValueError(
                f"reference must name a frame with a vertical axis by letters, such as 'NED', 'ENU' or 'NUE'; "
                f"got {reference!r}"
            ) from None
        q = _v.quaternions(q, "q", dtype=np.float64)
        q_ned = change_frame(q, ref_from=reference, ref_to="NED", body_from=body, body_to="FRD")
        self.t0 = float(tv[0])
        self.duration = float(tv[-1] - tv[0])
        self._spline = RotationSpline(tv - self.t0, q_ned)
        self._knots = self._spline.t
        self._m = None
        if positions is not None:
            p = _v.vectors(positions, "positions", dtype=np.float64)
            if p.shape != (tv.shape[0], 3):
                raise ValueError(f"positions must have shape (n, 3) = ({tv.shape[0]}, 3), got {p.shape}")
            self._m = _natural_cubic_second_derivatives(self._knots, p @ to_ned.T)

    @property
    def spline(self):
        """The :class:`strapdown.propagate.interpolate.RotationSpline` through the samples (NED/FRD, times from 0)."""
        return self._spline

    def _inside(self, t) -> np.ndarray:
        # _times allows a relative 1e-12 beyond the end (a nominal clock's rounding); the spline does not
        return np.clip(_times(t, self.duration), 0.0, self.duration)

    def attitude(self, t):
        """See :meth:`Trajectory.attitude`."""
        return self._spline(self._inside(t))

    def rate(self, t):
        """See :meth:`Trajectory.rate` (the spline's body rate)."""
        return self._spline(self._inside(t), 1)

    def acceleration(self, t):
        """Second derivative of the positions' natural cubic spline (NED, m/s²): linear between the samples."""
        t = self._inside(t)
        if self._m is None:
            return np.zeros((t.size, 3))
        k = np.clip(np.searchsorted(self._knots, t, side="right") - 1, 0, self._knots.shape[0] - 2)
        s = ((t - self._knots[k]) / (self._knots[k + 1] - self._knots[k]))[:, None]
        return (1 - s) * self._m[k] + s * self._m[k + 1]

    def _integrals(self, func, t) -> np.ndarray:
        """∫ func over consecutive times, with the recording's samples as extra breakpoints (see module notes)."""
        t = _times(t, self.duration)
        inner = self._knots[(self._knots > t[0]) & (self._knots < t[-1])]
        fine = np.union1d(t, inner)
        pieces = _quadrature(func, fine)
        starts = np.searchsorted(fine, t[:-1])
        return np.add.reduceat(pieces, starts, axis=0) if pieces.shape[0] else pieces

    def increments(self, t):
        """See :meth:`Trajectory.increments` (quadrature cut at the samples)."""
        return self._integrals(self.rate, t)

    def specific_force_increments(self, t):
        """See :meth:`Trajectory.specific_force_increments` (quadrature cut at the samples)."""
        return self._integrals(self.specific_force, t)


def sample_recorded(
    t,
    q,
    rate_hz: float | None = None,
    *,
    reference: str | None = None,
    body: str | None = None,
    positions=None,
    gyro: str = "increment",
    imu=None,
    magnetic_field: MagneticField | None = None,
    seed: int = 0,
) -> ImuData:
    """IMU readings of a recorded motion (attitudes, optionally positions), through the C² rotation spline.

    Parameters
    ----------
    t : array_like, shape (n,)
        Strictly increasing times of the recording, seconds.
    q : array_like or strapdown.Attitude, shape (n, 4)
        Recorded attitudes, body to ``reference``, scalar first.
    rate_hz : float, optional
        IMU sample rate; None: the recording's mean rate ``(n - 1)/(t[-1] - t[0])``.
    reference, body : str, optional
        Frames of the recording, which are also the frames of the readings and the truth; by default those named
        by an Attitude ``q``, else NED and FRD.
    positions : array_like, shape (n, 3), optional
        Recorded positions in ``reference`` (m); None: the body does not translate.
    gyro : {"increment", "rotvec", "average", "rate"}
        What a gyro sample is (:func:`strapdown.simulate.sample`).
    imu : ImuModel, optional
        Sensor errors (noise, bias, scale factor, clock...); ideal by default.
    magnetic_field : MagneticField, optional
        The Earth's field.
    seed : int
        Seeds the errors.

    Returns
    -------
    ImuData
        Readings and the spline's truth; ``t`` and ``t_true`` on the recording's clock (starting at ``t[0]``).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import angle_between, from_euler
    >>> from strapdown.simulate import sample_recorded
    >>> t = np.arange(201) / 100.0                                       # 2 s of capture at 100 Hz
    >>> q = from_euler(np.stack([np.sin(t), 0.3 * np.sin(2 * t), 0.2 * t], -1), "ZYX")
    >>> data = sample_recorded(t, q, reference="ENU", body="FLU", gyro="rotvec")
    >>> data.gyro.shape, data.t[[0, -1]]
    ((200, 3), array([0., 2.]))
    >>> bool(angle_between(data.integrate("exact"), q).max() < 1e-13)    # back onto the samples
    True
    """
    motion = RecordedMotion(t, q, reference=reference, body=body, positions=positions)
    if rate_hz is None:
        rate_hz = (len(motion.spline) - 1) / motion.duration
    data = sample(
        motion,
        rate_hz,
        gyro=gyro,
        imu=imu,
        magnetic_field=magnetic_field,
        seed=seed,
        reference=motion.reference,
        body=motion.body,
    )
    data.t = data.t + motion.t0
    data.t_true = data.t_true + motion.t0
    return data
