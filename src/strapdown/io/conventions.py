"""What an output says about itself: frames and axes, time origin, units; and gaps, found while streaming.

Every file that ``integrate_file`` and ``estimate_file`` write carries the same metadata (Parquet schema metadata,
HDF5 attributes, MATLAB variables, ``# key: value`` lines above a CSV header), read back by
:func:`strapdown.io.read_metadata`:

======================  ==================================================================================
``frame``               reference frame of the attitudes (``ENU``, ``NED``, ``NWU``)
``body``                body axes of the attitudes (``FLU``, ``FRD``, ...): ``q`` maps ``body`` to ``frame``
``sensor_axes``         axes of the readings as read (``--body``, or the format's preset); the readings are
                        re-expressed in ``body`` before anything is computed
``quaternion``          ``w,x,y,z scalar first, Hamilton, body to frame``
``time_unit``           ``s``: ``t`` counts seconds from the first sample
``time_origin``         the instant of ``t = 0``: a number in ``time_origin_unit`` since ``time_origin_kind``
                        (``epoch``: 1970-01-01 UTC; ``boot``: the logger's start, as in PX4 logs; ``file``: the
                        input's own time scale, whatever its zero is)
``angle_unit``          ``deg`` or ``rad`` (Euler angles), ``bias_unit`` ``deg/s`` or ``rad/s``
``euler``               the Euler sequence of the angle columns and its outer range
``flags``               the bits of the ``flags`` column (also written as boolean columns)
======================  ==================================================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "BRIDGE_ERROR",
    "GAP_BIAS",
    "Axes",
    "GapSplitter",
    "bridge_limit",
    "gyro_noise",
    "natural_body",
    "output_metadata",
    "resolve_axes",
    "time_metadata",
]

#: The body axes whose level attitude is the identity in each reference frame (z down with z down, ...):
#: aviation's NED/FRD, ROS REP 103's ENU/FLU (x forward; yaw 0 faces east), and NWU/FLU.
_NATURAL_BODY = {"NED": "FRD", "ENU": "FLU", "NWU": "FLU"}

QUATERNION = "w,x,y,z scalar first, Hamilton, body to frame"


def natural_body(frame: str) -> str:
    """The body axes that go with a reference frame: FRD for z-down frames (NED), FLU for z-up ones (ENU, NWU).

    Examples
    --------
    >>> from strapdown.io.conventions import natural_body
    >>> natural_body("NED"), natural_body("enu")
    ('FRD', 'FLU')
    """
    frame = frame.upper()
    if frame in _NATURAL_BODY:
        return _NATURAL_BODY[frame]
    from ..rotations.frames import frame_matrix

    up = frame_matrix(frame, "NED")[2, 2] < 0  # validates the name; True when the frame's z is up
    return "FLU" if up else "FRD"


@dataclass(frozen=True)
class Axes:
    """The frames of one run: readings in ``sensor`` axes, re-expressed in ``body``; attitudes ``body`` -> ``frame``.

    Attributes
    ----------
    frame, body, sensor : str
        Reference frame, body axes of the attitudes, axes of the readings.
    declared : str
        Where ``sensor`` came from: ``"--body"``, ``"preset of <format>"`` or ``"assumed"``.
    """

    frame: str
    body: str
    sensor: str
    declared: str

    @property
    def matrix(self) -> np.ndarray | None:
        """``v_body = M @ v_sensor``, or None when the axes are the same."""
        if self.sensor == self.body:
            return None
        from ..rotations.frames import frame_matrix

        return frame_matrix(self.sensor, self.body)

    def rotate(self, v):
        """Readings (n, 3) in sensor axes -> body axes (a signed permutation: exact)."""
        m = self.matrix
        return v if v is None or m is None else v @ m.T

    def metadata(self) -> dict:
        """The output's ``frame``, ``body``, ``sensor_axes`` and ``quaternion`` entries."""
        sensor = self.sensor if self.declared != "assumed" else f"{self.sensor} (assumed: not declared; use --body)"
        return {"frame": self.frame, "body": self.body, "sensor_axes": sensor, "quaternion": QUATERNION}

    def describe(self) -> str:
        """One line for the command's report."""
        turned = f", readings turned from {self.sensor} ({self.declared})" if self.sensor != self.body else ""
        return f"attitude of {self.body} axes in {self.frame}{turned}"


def resolve_axes(imu, frame: str | None, body: str | None, out_body: str | None) -> Axes:
    """The frames of a run from the options and the reader's presets (``imu.frame``, ``imu.body``).

    Parameters
    ----------
    imu : ImuFile
        The input (its ``frame`` and ``body`` presets, when its format has them: a ULog is NED/FRD, a ROS Imu
        message ENU/FLU).
    frame : str, optional
        Output reference frame; default the preset, else ENU.
    body : str, optional
        Axes of the readings; default the preset, else those of the output (nothing turned; said in the output).
    out_body : str, optional
        Body axes of the output attitudes; default :func:`natural_body` of the frame.

    Returns
    -------
    Axes
        Validated (three right-handed axis letters each).
    """
    from ..rotations.frames import frame_matrix

    fmt = getattr(imu, "format", None) or getattr(imu.source, "format", "")
    frame = (frame or getattr(imu, "frame", None) or "ENU").upper()
    target = (out_body or natural_body(frame)).upper()
    preset = getattr(imu, "body", None)
    if body:
        sensor, declared = body.upper(), "--body"
    elif preset:
        sensor, declared = preset.upper(), f"preset of {fmt}"
    else:
        sensor, declared = target, "assumed"
    frame_matrix(frame, "NED")  # a reference frame
    for name, axes in (("--body", sensor), ("--out-body", target)):
        try:
            frame_matrix(axes, "FRD")
        except ValueError as exc:
            raise ValueError(f"{name} {axes}: {exc}") from None
    return Axes(frame, target, sensor, declared)


def time_metadata(imu, t_first: float) -> dict:
    """``time_unit`` and the origin of ``t = 0`` (the first sample) for the output's metadata.

    The reader's ``imu.time_origin`` when it knows one (an epoch, a logger's boot time, or the shift of a file's own
    float times); else the file's times start at zero (``t_first``, normally 0), or rows are timed by a rate.
    """
    meta = {"time_unit": "s"}
    origin = getattr(imu, "time_origin", None)
    if origin is not None:
        meta.update({k: str(v) for k, v in origin.metadata().items()})
        if t_first:  # a reader that left t not starting at zero: the shift is part of the origin
            meta["time_origin_offset_s"] = repr(float(t_first))
        return meta
    meta.update(time_origin=repr(float(t_first)), time_origin_unit="s", time_origin_kind="file")
    if imu.time is None:
        meta["time_origin_note"] = f"rows timed by a rate of {imu.rate:g} Hz"
    return meta


def output_metadata(out, *, bias: bool = False, flags: bool = False) -> dict:
    """The units of the output's columns: ``angle_unit``, ``euler`` and, for an estimator, ``bias_unit``, ``flags``.

    Parameters
    ----------
    out : OutputSpec
        What is written.
    bias, flags : bool
        The estimator has a bias, flags.

    Returns
    -------
    dict of str to str
        Metadata items.

    Examples
    --------
    >>> from strapdown.io.conventions import output_metadata
    >>> from strapdown.io.tables import OutputSpec
    >>> output_metadata(OutputSpec())
    {'angle_unit': 'deg', 'euler': 'ZYX (yaw_deg, pitch_deg, roll_deg), outer angle positive'}
    """
    from .tables import column_names, flag_bits

    angles = out.angles
    meta = {"angle_unit": "deg" if angles.degrees else "rad"}
    if out.euler:
        meta["euler"] = f"{angles.seq} ({', '.join(column_names('euler', angles))}), outer angle {angles.range}"
    if bias and out.bias:
        meta["bias_unit"] = "deg/s" if angles.degrees else "rad/s"
    if flags and out.flags:
        bits = ", ".join(f"{name}={bit}" for name, bit in flag_bits().items())
        meta["flags"] = f"bit mask ({bits}); the same as boolean columns"
    if out.float32:
        meta["precision"] = "float32 (the float64 results rounded: quaternion, angles, bias); t float64"
    return meta


#: The attitude error a bridged gap may cost, rad (about a degree: :func:`bridge_limit`).
BRIDGE_ERROR = float(np.radians(1.0))

#: The gyro bias that is left uncorrected across a gap, rad/s: 0.5°/s, an uncalibrated consumer MEMS gyro's
#: turn-on bias (the AttitudeEstimator's prior ``bias_sigma_init``); a filter's estimate is no better than that
#: while it still converges, and an integration corrects none of it.
GAP_BIAS = float(np.radians(0.5))


def gyro_noise(gyro) -> float:
    """The white noise of one gyro sample, rad/s (per axis; the largest axis), from a stretch of readings.

    The second difference of white noise of standard deviation σ has variance 6σ², while a smooth motion
    (a rate that changes linearly over three samples) leaves none in it, so σ = 1.4826 MAD(Δ²ω) / √6 (the
    median absolute deviation, 1.4826 its Gaussian factor, so that a few jumps do not count) tells the noise in
    motion as well as at rest.  Vibration at the sample rate counts as noise: it is what a held sample gets wrong.

    Parameters
    ----------
    gyro : array_like, shape (n, 3)
        Consecutive rates, rad/s (finite rows are used).

    Returns
    -------
    float
        σ, rad/s; 0 for fewer than 8 rows.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.conventions import gyro_noise
    >>> rng = np.random.default_rng(0)
    >>> t = np.arange(20000) * 0.01
    >>> motion = np.column_stack([np.sin(t), np.cos(0.5 * t), 0 * t])       # a smooth motion
    >>> round(gyro_noise(motion + 0.01 * rng.standard_normal((t.size, 3))), 3)
    0.01
    """
    g = np.asarray(gyro, dtype=np.float64)
    g = g[np.isfinite(g).all(axis=1)] if g.ndim == 2 else g[:0]
    if g.shape[0] < 8:
        return 0.0
    d2 = g[2:] - 2.0 * g[1:-1] + g[:-2]
    mad = np.median(np.abs(d2 - np.median(d2, axis=0)), axis=0)
    return float((1.4826 * mad / np.sqrt(6.0)).max())


def bridge_limit(noise: float, bias: float = GAP_BIAS, error: float = BRIDGE_ERROR) -> float:
    """The longest gap that an estimator or integration may bridge, s: what its gyro errors cost in it.

    Across a gap of T seconds no sample is read: the rate is held (integration) or interpolated between the
    samples on either side (the AttitudeEstimator), and no accelerometer or magnetometer sample corrects it.
    Whatever those one or two samples got wrong then acts over the whole gap, not averaged as the samples of a
    measured stretch are: the bias b that is left uncorrected, and the white noise σ of one sample
    (:func:`gyro_noise`).  The attitude error of the bridge is about

        θ(T) = (b + σ) T,

    so a gap may be bridged while θ(T) stays within ``error`` (about 1°): T_max = error / (b + σ).  For a quiet
    consumer gyro (b = 0.5°/s, σ small) that is 2 s; a drone's vibration (σ of a few °/s) brings it to tenths of
    a second.  A longer gap restarts the estimator: the attitude after it is then the accelerometer's and
    magnetometer's again, which a bridge of more than a degree would be worse than.

    Parameters
    ----------
    noise : float
        σ, the white noise of one gyro sample, rad/s.
    bias : float
        b, the bias left uncorrected, rad/s (:data:`GAP_BIAS`).
    error : float
        The error a bridge may cost, rad (:data:`BRIDGE_ERROR`).

    Returns
    -------
    float
        T_max, s.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.conventions import bridge_limit
    >>> round(bridge_limit(0.0), 6), round(bridge_limit(np.radians(4.5)), 6)   # quiet, and a vibrating drone
    (2.0, 0.2)
    """
    rate = float(bias) + float(noise)
    return float(error) / rate if rate > 0 else float("inf")


class GapSplitter:
    """Finds the gaps of a stream of chunks: steps longer than ``max_gap`` nominal sample periods (``--on-gap``).

    The period is the median step of the first chunk that has two rows (or ``period``).  A gap that lasts at most
    ``bridge`` seconds is bridged (kept in ``bridged``: the estimator carries on across it); a longer one starts
    a new segment (kept in ``gaps``).  Call it with each chunk's times; it returns the indices where a new
    segment starts in that chunk (0 can be one, when the gap falls between two chunks); :meth:`split` also
    returns the rows that follow a bridged gap.
    """

    def __init__(self, max_gap: float, period: float | None = None, bridge: float = 0.0):
        self.max_gap = max_gap
        self.period = period
        self.bridge = bridge
        self.last: float | None = None
        self.segment = 0
        self.gaps: list[tuple[float, float]] = []  # (time before, time after), in output seconds: restarts
        self.bridged: list[tuple[float, float]] = []  # the same for the gaps bridged

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """Indices in ``t`` where a segment starts after a gap (the gaps are kept in ``gaps``)."""
        return self.split(t)[0]

    def split(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The indices in ``t`` where a segment starts after a gap, and those of the rows after a bridged gap."""
        none = np.zeros(0, dtype=np.intp)
        if t.size == 0:
            return none, none
        if self.period is None and t.size > 1:
            self.period = float(np.median(np.diff(t)))
        d = np.diff(t, prepend=t[0] if self.last is None else self.last)
        self.last = float(t[-1])
        if not self.max_gap or not self.period:
            return none, none
        over = np.flatnonzero(d > self.max_gap * self.period)
        short = d[over] <= self.bridge
        cuts, bridged = over[~short], over[short]
        for kept, i in [(self.gaps, i) for i in cuts] + [(self.bridged, i) for i in bridged]:
            kept.append((float(t[i] - d[i]), float(t[i])))
        return cuts, bridged
