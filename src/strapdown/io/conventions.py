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

__all__ = ["Axes", "GapSplitter", "natural_body", "output_metadata", "resolve_axes", "time_metadata"]

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


class GapSplitter:
    """Cuts a stream of chunks at gaps longer than ``max_gap`` nominal sample periods (``--on-gap``).

    The period is the median step of the first chunk that has two rows (or ``period``).  Call it with each
    chunk's times; it returns the indices where a new segment starts in that chunk (0 can be one, when the gap
    falls between two chunks) and counts the segments.
    """

    def __init__(self, max_gap: float, period: float | None = None):
        self.max_gap = max_gap
        self.period = period
        self.last: float | None = None
        self.segment = 0
        self.gaps: list[tuple[float, float]] = []  # (time before, time after), in output seconds

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """Indices in ``t`` where a segment starts after a gap (the gaps are kept in ``gaps``)."""
        if t.size == 0:
            return np.zeros(0, dtype=np.intp)
        if self.period is None and t.size > 1:
            self.period = float(np.median(np.diff(t)))
        d = np.diff(t, prepend=t[0] if self.last is None else self.last)
        if not self.max_gap or not self.period:
            cuts = np.zeros(0, dtype=np.intp)
        else:
            cuts = np.flatnonzero(d > self.max_gap * self.period)
        for i in cuts:
            self.gaps.append((float(t[i] - d[i]), float(t[i])))
        self.last = float(t[-1])
        return cuts
