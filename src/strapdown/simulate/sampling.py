"""Sampling a trajectory into IMU readings with exact truth: gyro, accelerometer, magnetometer, timestamps.

What a gyro sample is (``gyro=``), and which integrator reproduces an ideal IMU's readings:

===============  ===============================================  ====================================================
``gyro=``        sample k is                                      reproduced to rounding by
===============  ===============================================  ====================================================
``"rate"``       the body rate at t[k], the start of step k       none exactly (rk4 is fourth order)
``"average"``    the mean rate over step k                        ``exact`` on rotations about body-fixed axes
                                                                  (every aerobatic figure, constant rotation)
``"increment"``  ``∫ω dt`` over step k (a delta-angle sensor)      the same; ``coning2`` is fourth order on any motion
``"rotvec"``     the rotation vector of step k's attitude change  ``exact`` (input="increment"), on any motion
===============  ===============================================  ====================================================

The accelerometer reads the specific force in the same form (instants, means, or velocity increments for the
last two); the magnetometer reads the field at t[k].  :attr:`ImuData.gyro_input` tells
:func:`strapdown.integrate` which ``input`` to use, and :meth:`ImuData.integrate` does it for you.

Frames: the trajectories fly in NED/FRD; ``reference=`` and ``body=`` re-express the truth and the readings
(sensor errors are applied in the output body axes, the sensor's own).  The accelerometer's sign convention:
specific force, +g along body up at rest.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..rotations.frames import change_frame, frame_matrix
from ..rotations.quaternion import conjugate, rotate
from .imu import apply_clock, corrupt
from .models import ImuModel
from .trajectories import Trajectory, _positive, _seed

# The most samples one call makes: about 10 GB of readings and truth.  More is a rate or duration typed wrong
# (1e9 Hz asked for terabytes and ended in a MemoryError).
MAX_SAMPLES = 50_000_000

__all__ = ["ImuData", "MagneticDisturbance", "MagneticField", "sample"]

_KIND = {"rate": "rate", "average": "average", "increment": "increment", "rotvec": "increment"}  # gyro= -> kind
_INPUT = {"rate": "rate", "average": "average", "increment": "increment", "rotvec": "increment"}


@dataclass(frozen=True)
class MagneticField:
    """The Earth's field: strength, inclination (dip, positive below the horizon) and declination (east of north).

    Examples
    --------
    >>> from strapdown.simulate import MagneticField
    >>> MagneticField(50.0, 60.0, 0.0).ned().round(4)        # µT in NED
    array([25.    ,  0.    , 43.3013])
    """

    strength_uT: float = 50.0
    inclination_deg: float = 66.0  # Berlin, where BROAD was recorded, is about 67°
    declination_deg: float = 4.0

    def ned(self) -> np.ndarray:
        """The field vector in NED, µT."""
        inc = np.radians(self.inclination_deg)
        dec = np.radians(self.declination_deg)
        return self.strength_uT * np.array([np.cos(inc) * np.cos(dec), np.cos(inc) * np.sin(dec), np.sin(inc)])


@dataclass(frozen=True)
class MagneticDisturbance:
    """A transient field added between ``start`` and ``stop`` (s), faded in and out over ``ramp`` seconds.

    ``field_uT`` is a 3-vector in the reference frame (NED; a magnet lying near the path) or in body axes (FRD;
    a magnet carried along), per ``frame``.

    Examples
    --------
    >>> from strapdown.simulate import MagneticDisturbance
    >>> MagneticDisturbance(10.0, 20.0, (30.0, 0.0, 0.0)).envelope([5.0, 15.0]).tolist()
    [0.0, 1.0]
    """

    start: float
    stop: float
    field_uT: tuple = (30.0, 0.0, 0.0)
    frame: str = "reference"
    ramp: float = 0.5

    def __post_init__(self):
        if not (np.isfinite(self.start) and np.isfinite(self.stop) and self.stop > self.start):
            raise ValueError(f"stop must come after start, got start={self.start!r}, stop={self.stop!r}")
        if self.frame not in ("reference", "body"):
            raise ValueError(f"frame must be 'reference' or 'body', got {self.frame!r}")
        if not (0 <= self.ramp <= (self.stop - self.start) / 2):
            raise ValueError(f"ramp must be in [0, (stop - start)/2], got {self.ramp!r}")

    def envelope(self, t) -> np.ndarray:
        """0 outside, 1 inside, a smoothstep in between."""
        t = np.asarray(t, dtype=float)
        if self.ramp == 0:
            return ((t >= self.start) & (t <= self.stop)).astype(float)
        up = np.clip((t - self.start) / self.ramp, 0, 1)
        down = np.clip((self.stop - t) / self.ramp, 0, 1)
        x = np.minimum(up, down)
        return x * x * (3 - 2 * x)


@dataclass
class ImuData:
    """Simulated IMU readings with their truth.

    Attributes
    ----------
    t : numpy.ndarray, shape (N + 1,)
        Recorded times of the step boundaries (s); sample k covers ``t[k]`` to ``t[k+1]``.
    gyro, acc, mag : numpy.ndarray, shape (N, 3)
        Readings in the body axes ``body``: rad/s (or rad), m/s² (or m/s), µT.
    q_true : numpy.ndarray, shape (N + 1, 4)
        True attitude at the (actual) boundary instants, body to ``reference``.
    gyro_input : str
        The ``input`` of :func:`strapdown.integrate` that matches the gyro readings.
    reference, body : str
        Frames of the truth and the readings.
    rate_hz : float
        Nominal sample rate.
    t_true : numpy.ndarray, shape (N + 1,)
        Actual boundary instants (differ from ``t`` with a clock model that records nominal times).
    """

    t: np.ndarray
    gyro: np.ndarray
    acc: np.ndarray
    mag: np.ndarray
    q_true: np.ndarray
    gyro_input: str
    reference: str
    body: str
    rate_hz: float
    t_true: np.ndarray = field(repr=False, default=None)

    def integrate(self, method=None, **options) -> np.ndarray:
        """Integrate the gyro readings from the true initial attitude (see :func:`strapdown.integrate`).

        Parameters
        ----------
        method : str, optional
            Propagation method.
        **options
            Passed on to :func:`strapdown.integrate`.

        Returns
        -------
        numpy.ndarray, shape (N + 1, 4)
            Attitudes at ``t``.

        Examples
        --------
        >>> from strapdown import angle_between
        >>> from strapdown.simulate import hammerhead_loop, sample
        >>> data = sample(hammerhead_loop(), 100.0, gyro="increment")
        >>> bool(angle_between(data.integrate("exact"), data.q_true).max() < 1e-12)
        True
        """
        options.setdefault("q0", self.q_true[0])
        if self.gyro_input == "increment":
            return _integrate(self.gyro, method=method, input="increment", **options)
        return _integrate(self.gyro, t=self.t, method=method, input=self.gyro_input, **options)


def _integrate(gyro, **kwargs):
    from ..propagate.integrate import integrate

    return integrate(gyro, **kwargs)


def sample(
    trajectory: Trajectory,
    rate_hz: float,
    *,
    gyro: str = "average",
    imu: ImuModel | None = None,
    magnetic_field: MagneticField | None = None,
    disturbances=(),
    seed: int = 0,
    reference: str = "NED",
    body: str = "FRD",
    duration: float | None = None,
) -> ImuData:
    """Sample a trajectory into IMU readings at ``rate_hz``, with the sensor errors of ``imu``.

    Parameters
    ----------
    trajectory : Trajectory
        What is flown.
    rate_hz : float
        Nominal sample rate.
    gyro : {"rate", "average", "increment", "rotvec"}
        What a gyro sample is (module notes); the accelerometer follows.
    imu : ImuModel, optional
        Sensor errors; ``ImuModel.ideal()`` by default (readings exact to rounding).
    magnetic_field : MagneticField, optional
        The Earth's field (default: 50 µT, dip 66°, declination 4°).
    disturbances : sequence of MagneticDisturbance
        Transient fields.
    seed : int
        Seeds the errors (reproducible).
    reference, body : str
        Output frames (:mod:`strapdown.rotations.frames`), e.g. ``"ENU"`` and ``"FLU"``.
    duration : float, optional
        Seconds to sample (the whole trajectory by default).

    Returns
    -------
    ImuData
        Readings and truth.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.simulate import ConstantRotation, sample
    >>> data = sample(ConstantRotation([0.0, 0.0, 1.0], duration=1.0), 10.0, reference="ENU", body="FLU")
    >>> data.gyro.shape, data.t.shape
    ((10, 3), (11,))
    >>> data.acc[0].round(5)          # at rest, FLU: +g along z (up)
    array([0.     , 0.     , 9.80665])
    """
    rate_hz = _positive(rate_hz, "rate_hz")
    seed = _seed(seed)
    if gyro not in _KIND:
        raise ValueError(f"gyro must be one of {', '.join(map(repr, _KIND))}; got {gyro!r}")
    imu = ImuModel.ideal() if imu is None else imu
    field_ned = (magnetic_field or MagneticField()).ned()
    span = trajectory.duration if duration is None else _positive(duration, "duration")
    if span > trajectory.duration * (1 + 1e-12):
        raise ValueError(f"duration={span:g} s is longer than the trajectory ({trajectory.duration:g} s)")
    if span * rate_hz > MAX_SAMPLES:
        raise ValueError(
            f"rate_hz={rate_hz:g} over {span:g} s makes {span * rate_hz:.3g} samples, more than {MAX_SAMPLES:,} "
            "(about 10 GB); lower rate_hz or give a shorter duration"
        )
    n = int(np.floor(span * rate_hz + 1e-9))
    if n < 1:
        raise ValueError(f"duration {span:g} s holds no sample at {rate_hz:g} Hz")
    t_nominal = np.arange(n + 1) / rate_hz
    streams = np.random.default_rng(seed).spawn(4)  # independent streams: clock, gyro, acc, mag
    t_actual, t_recorded, keep = apply_clock(imu.clock, t_nominal, streams[0])
    h = np.diff(t_actual)
    starts = t_actual[:-1]

    if gyro == "rate":
        w, f = trajectory.rate(starts), trajectory.specific_force(starts)
    elif gyro == "average":
        w = trajectory.increments(t_actual) / h[:, None]
        f = trajectory.specific_force_increments(t_actual) / h[:, None]
    elif gyro == "increment":
        w, f = trajectory.increments(t_actual), trajectory.specific_force_increments(t_actual)
    else:
        w, f = trajectory.rotation_vectors(t_actual), trajectory.specific_force_increments(t_actual)

    q_frd = trajectory.attitude(starts)
    m_ref = np.broadcast_to(field_ned, (n, 3)).copy()
    m_body = np.zeros((n, 3))
    for d in disturbances:
        if not isinstance(d, MagneticDisturbance):
            raise ValueError("disturbances must be MagneticDisturbance objects")
        target = m_ref if d.frame == "reference" else m_body
        target += d.envelope(starts)[:, None] * np.asarray(d.field_uT, dtype=float)
    m = rotate(conjugate(q_frd), m_ref) + m_body

    to_body = frame_matrix("FRD", body)
    kind = _KIND[gyro]
    gyro_out = corrupt(imu.gyro, w @ to_body.T, h, kind, streams[1])
    acc_out = corrupt(imu.acc, f @ to_body.T, h, kind, streams[2])
    mag_out = corrupt(imu.mag, m @ to_body.T, h, "rate", streams[3])

    # a dropped sample k takes its start boundary with it: the previous sample's step then runs on
    bounds = np.concatenate([keep, [True]])
    q_true = change_frame(
        trajectory.attitude(t_actual[bounds]), ref_from="NED", ref_to=reference, body_from="FRD", body_to=body
    )
    return ImuData(
        t=t_recorded[bounds],
        gyro=gyro_out[keep],
        acc=acc_out[keep],
        mag=mag_out[keep],
        q_true=q_true,
        gyro_input=_INPUT[gyro],
        reference=reference,
        body=body,
        rate_hz=rate_hz,
        t_true=t_actual[bounds],
    )
