"""A reference attitude from a file (a flight log's own estimate, a table of quaternions), and a log's position.

Both through the format registry's readers: :func:`read_reference` and :func:`log_position` (where and when a
log was recorded).

For ``plot --truth`` and ``compare``: :func:`read_reference` returns times, quaternions and their frames, on the
same time line as :class:`~strapdown.io.ImuFile` reads the IMU of the same log, so that the two compare
directly (:meth:`Reference.at` interpolates onto other times by slerp).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .source import TimeOrigin

__all__ = ["Reference", "log_position", "read_reference"]

_QUATS = (("qw_true", "qx_true", "qy_true", "qz_true"), ("qw", "qx", "qy", "qz"))


@dataclass
class Reference:
    """Attitudes from a file: ``q[k]`` maps body vectors to ``frame`` at ``t[k]``.

    Attributes
    ----------
    t : numpy.ndarray, shape (n,)
        Seconds, from the same origin as the IMU of the same file (``time_origin``).
    q : numpy.ndarray, shape (n, 4)
        [w, x, y, z], body to reference.
    frame, body : str or None
        The reference frame and body axes (``"NED"``, ``"FRD"`` for PX4), None when the file does not say.
    time_origin : TimeOrigin or None
        What t = 0 is.
    source : str
        Where the attitudes came from (``"vehicle_attitude"``, the column names).
    """

    t: np.ndarray
    q: np.ndarray
    frame: str | None
    body: str | None
    time_origin: TimeOrigin | None
    source: str

    def at(self, t) -> np.ndarray:
        """The reference attitude at times ``t`` (s, same origin), by slerp between its samples.

        Parameters
        ----------
        t : array_like, shape (m,)
            Times inside the reference's span.

        Returns
        -------
        numpy.ndarray, shape (m, 4)
            Quaternions.

        Examples
        --------
        >>> import numpy as np
        >>> from strapdown.io.reference import Reference
        >>> half = [np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]
        >>> ref = Reference(np.array([0.0, 1.0]), np.array([[1.0, 0, 0, 0], half]), "NED", "FRD", None, "q")
        >>> np.degrees(2 * np.arccos(ref.at([0.5])[0, 0])).round(6)
        np.float64(45.0)
        """
        from ..propagate.interpolate import resample

        return resample(self.t, self.q, np.asarray(t, dtype=np.float64))


def read_reference(path, format: str | None = None, topic: str | None = None) -> Reference:
    """The reference attitude stored in a file: PX4's ``vehicle_attitude``, or ``qw..qz`` / ``qw_true..`` columns.

    Parameters
    ----------
    path : path-like
        A ULog, or a table with quaternion columns and a time column (a strapdown output, a simulated log).
    format : str, optional
        The input format, when the suffix does not tell it.
    topic : str, optional
        For a ULog: the IMU topic whose first sample is t = 0 (as :class:`~strapdown.io.ImuFile` reads it).

    Returns
    -------
    Reference
        Times (s from the first sample), quaternions (normalised), frames.

    Raises
    ------
    ValueError
        When a table has no quaternion or no time column, a quaternion row is not of unit norm, or the time
        column's unit (stated, or inferred from the median step for integers) makes no plausible sample period.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import read_reference, write_table
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "truth.csv"
    >>> one, zero = np.ones(2), np.zeros(2)
    >>> _ = write_table(path, {"t": np.array([5.0, 5.01]), "qw": one, "qx": zero, "qy": zero, "qz": zero})
    >>> ref = read_reference(path)
    >>> ref.t, ref.source
    (array([0.  , 0.01]), 'qw,qx,qy,qz')
    """
    from .readers import input_format, open_source, read_metadata
    from .registry import formats

    path = Path(path)
    fmt = input_format(path, format)
    hook = getattr(formats().get(fmt), "reference", None)
    if hook is not None:  # a log's own estimate (PX4 vehicle_attitude, ArduPilot ATT, a ROS Imu orientation)
        found = dict(hook(path, topic=topic))
        found["q"] = _unit(np.asarray(found["q"], dtype=np.float64), path, found.get("source", "attitude"))
        return Reference(**found)
    from .columns import detect_time
    from .timebase import origin_of
    from .units import scale

    with open_source(path, fmt) as src:
        names = next((n for n in _QUATS if all(c in src.fields for c in n)), None)
        if names is None:
            raise ValueError(f"{path} has no attitude (qw_true.. or qw,qx,qy,qz); it has: {', '.join(src.fields)}")
        time = detect_time(src.fields)
        if time is None:  # row numbers taken as seconds would be a silent wrong answer
            raise ValueError(
                f"{path} has attitudes ({','.join(names)}) but no time column (t, time, timestamp_ns, ...); "
                f"it has: {', '.join(src.fields)}"
            )
        name = time.fields[0]
        # integers count from the first value in integer arithmetic (epoch ns are past float64's 2**53)
        relative = (name,) if name in src.integers and not src.is_timestamp(name) else ()
        parts = [cols for _, cols in src.chunks([*names, name], 1 << 20, relative=relative)]
        cols = {n: np.concatenate([p[n] for p in parts]) for n in (*names, name)}
        unit = _time_unit(src, time, cols[name], bool(relative), path)
        origin_unit = unit
        if src.is_timestamp(name):  # date-times: seconds from the first one, which is kept as epoch ns
            stamp = src.origins.get(name)
            first = None if stamp is None else int(np.datetime64(stamp, "ns").astype(np.int64))
            origin_unit = "ns"
        else:
            first = src.origins.get(name) if relative else (cols[name][0] if cols[name].size else None)
        origin = getattr(src, "time_origin", None) or (None if first is None else origin_of(first, origin_unit))
    q = np.column_stack([cols[n] for n in names])
    t = cols[name] * scale("time", unit)
    meta = read_metadata(path, fmt) if fmt in ("csv", "parquet", "hdf5", "mat") else {}
    if "time_origin" in meta:
        value = meta["time_origin"]
        origin = TimeOrigin(
            int(value) if value.lstrip("-").isdigit() else float(value),
            meta.get("time_origin_unit", "s"),
            meta.get("time_origin_kind", "file"),
        )
    frame = meta.get("frame") or meta.get("reference_frame")
    return Reference(
        t - t[0] if t.size else t, _unit(q, path, ",".join(names)), frame, meta.get("body"), origin, ",".join(names)
    )


def _time_unit(src, time, values: np.ndarray, integer: bool, path: Path) -> str:
    """The unit of a reference's time column, told and checked as :class:`~strapdown.io.ImuFile` does it.

    A decoded log's seconds, else the unit the column's name or a unit row states, else (integers) the unit
    :func:`~strapdown.io.timebase.infer_time_unit` finds from the median step; every unit is then checked to make
    a plausible sample period, so epoch nanoseconds are never taken as seconds.
    """
    from .timebase import check_period, infer_time_unit
    from .units import parse_unit

    name = time.fields[0]
    stated = src.units.get(name)
    unit = "s" if src.time_in_seconds or src.is_timestamp(name) else time.unit_hint
    if unit is None and stated:
        unit = parse_unit("time", stated, strict=False)
    steps = np.diff(values[np.isfinite(values)])
    step = float(np.median(steps)) if steps.size else None
    if unit is None:
        first = float(src.origins.get(name, 0)) if integer else 0.0
        unit = infer_time_unit(step, first, name, str(path))[0] if integer and step else "s"
    if step:
        check_period(step, unit, name, str(path))
    return unit


def _unit(q: np.ndarray, path: Path, what: str) -> np.ndarray:
    n = np.linalg.norm(q, axis=1)
    bad = ~(np.isfinite(n) & (np.abs(n - 1) < 1e-3))
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{path}: {what} row {i} is not a unit quaternion (|q| = {n[i]:.6g})")
    return q / n[:, None]


def log_position(path, format: str | None = None):
    r"""Where and when a log was recorded, by its format's reader (the registry's ``position`` field).

    Parameters
    ----------
    path : path-like
        The input.
    format : str, optional
        Its format, when the suffix does not tell it.

    Returns
    -------
    LogPosition or None
        None when the format records no position, or this log holds no fix.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io.reference import log_position
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "log.csv"
    >>> _ = path.write_text("t,gx,gy,gz\n0,0,0,0\n")
    >>> log_position(path) is None          # a table records no position
    True
    """
    from .position import LogPosition
    from .readers import input_format
    from .registry import formats

    if isinstance(path, list | tuple):
        return None  # several files: no format records a position for them
    fmt = formats().get(input_format(Path(path), format))
    reader = getattr(fmt, "position", None)
    if reader is None:
        return None
    found = reader(Path(path))
    if found is None or isinstance(found, LogPosition):
        return found
    return LogPosition(**found)  # a format's reader may give the fields as a dict
