"""The fitted calibration of one sensor triad, and its JSON file.

A triad's readings r (one 3-vector per sample, in the sensor's own axes ``frame``) are calibrated by
``c = matrix @ (r - offset)``: the offset is the hard iron of a magnetometer or the bias of a gyroscope or
accelerometer, the matrix undoes the scale factors, the cross-axis coupling and the soft iron.  A file holds
one calibration per sensor, each with its units, the axes it was fitted in, its parameter uncertainties and
its quality figures, so a calibration found once can be applied to later recordings (``--calibration``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._support import validate as _v

__all__ = ["SENSORS", "Calibration", "load", "save"]

#: Sensor names and the units their readings are in.
SENSORS = {"mag": "uT", "acc": "m/s^2", "gyro": "rad/s"}
# Release 0.1 named the sensors in full; its files and calls are read with these names still.
_LONG_NAMES = {"magnetometer": "mag", "accelerometer": "acc", "gyroscope": "gyro"}


def sensor_name(name) -> str:
    """A sensor's name, ``"gyro"``, ``"acc"`` or ``"mag"`` (release 0.1's full names are taken too)."""
    return _LONG_NAMES.get(name, name)


_FORMAT = "strapdown-calibration"
_VERSION = 1


def _json_number(x: float):
    """JSON has no NaN or infinity: say so with null."""
    x = float(x)
    return x if math.isfinite(x) else None


def _plain(value):
    """Quality figures and metadata as JSON-ready Python values."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return _json_number(value)
    return value


@dataclass(frozen=True, eq=False)
class Calibration:
    """A fitted calibration of one triad: ``calibrated = matrix @ (reading - offset)``.

    Parameters
    ----------
    sensor : {"gyro", "acc", "mag"}
        What was calibrated (the names of the whole library; ``"gyroscope"`` ... of release 0.1 are taken).
    offset : array_like, shape (3,)
        Hard iron or bias, in the reading's units.
    matrix : array_like, shape (3, 3)
        Correction of scale, cross-axis coupling and soft iron (dimensionless).
    frame : str
        The sensor axes the readings were in when fitted (e.g. ``"sensor"`` or ``"FLU"``); a calibration
        applies only to readings in the same axes.
    units : str, optional
        Units of readings and offset; by default those of :data:`SENSORS`.
    offset_sigma : array_like, shape (3,), optional
        One-sigma uncertainty of the offset (units).
    matrix_sigma : array_like, shape (3, 3), optional
        One-sigma uncertainty of each matrix element.
    quality : dict, optional
        Figures of the fit (residual, coverage, condition ...); see the function that made it.
    method : str
        How it was fitted.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import Calibration
    >>> cal = Calibration("gyro", offset=[0.01, 0.0, -0.02], matrix=np.eye(3), frame="FLU")
    >>> cal.apply([[0.01, 1.0, -0.02]])
    array([[0., 1., 0.]])
    >>> Calibration.from_dict(cal.to_dict()).offset
    array([ 0.01,  0.  , -0.02])
    """

    sensor: str
    offset: np.ndarray
    matrix: np.ndarray
    frame: str = "sensor"
    units: str | None = None
    offset_sigma: np.ndarray | None = None
    matrix_sigma: np.ndarray | None = None
    quality: dict = field(default_factory=dict)
    method: str = ""

    def __post_init__(self):
        object.__setattr__(self, "sensor", sensor_name(self.sensor))
        _v.choice(self.sensor, "sensor", tuple(SENSORS))
        offset = _v.finite(self.offset, "offset", dtype=np.float64)
        if offset.shape != (3,):
            raise ValueError(f"offset must have shape (3,), got shape {offset.shape}")
        matrix = _v.finite(self.matrix, "matrix", dtype=np.float64)
        if matrix.shape != (3, 3):
            raise ValueError(f"matrix must have shape (3, 3), got shape {matrix.shape}")
        if not abs(np.linalg.det(matrix)) > 1e-12:
            raise ValueError(f"matrix is singular (determinant {np.linalg.det(matrix):.3g}); it must be invertible")
        if not isinstance(self.frame, str) or not self.frame:
            raise ValueError(f"frame must be a non-empty string naming the sensor axes, got {self.frame!r}")
        values = {
            "offset": offset,
            "matrix": matrix,
            "units": SENSORS[self.sensor] if self.units is None else str(self.units),
            "quality": dict(self.quality),
        }
        for name, shape in (("offset_sigma", (3,)), ("matrix_sigma", (3, 3))):
            value = getattr(self, name)
            if value is not None:
                arr = _v.as_float_array(value, name, dtype=np.float64)
                if arr.shape != shape:
                    raise ValueError(f"{name} must have shape {shape}, got shape {arr.shape}")
                values[name] = arr
        for name, value in values.items():
            if isinstance(value, np.ndarray):
                value = value.copy()
                value.flags.writeable = False
            object.__setattr__(self, name, value)

    def apply(self, readings) -> np.ndarray:
        """Calibrated readings ``matrix @ (reading - offset)``.

        Parameters
        ----------
        readings : array_like, shape (..., 3)
            Raw readings in ``frame`` axes and ``units``; NaN rows (no sample) stay NaN.

        Returns
        -------
        numpy.ndarray, shape (..., 3)
            Calibrated readings, float32 for float32 input.
        """
        r = _v.as_float_array(readings, "readings")
        _v.check_last_axis(r, "readings", 3, "one 3-vector per sample")
        if np.isinf(r).any():
            _v.check_finite(np.where(np.isnan(r), 0.0, r), "readings")
        out = (r.astype(np.float64) - self.offset) @ self.matrix.T
        return out.astype(r.dtype, copy=False)

    def invert(self, calibrated) -> np.ndarray:
        """The raw readings that calibrate to ``calibrated``: ``offset + matrix⁻¹ @ calibrated``."""
        c = _v.as_float_array(calibrated, "calibrated")
        _v.check_last_axis(c, "calibrated", 3, "one 3-vector per sample")
        out = np.linalg.solve(self.matrix, c.astype(np.float64).reshape(-1, 3).T).T.reshape(c.shape) + self.offset
        return out.astype(c.dtype, copy=False)

    def to_dict(self) -> dict:
        """The calibration as JSON-ready values (units and frame included)."""
        out = {
            "sensor": self.sensor,
            "units": self.units,
            "frame": self.frame,
            "model": "calibrated = matrix @ (reading - offset)",
            "method": self.method,
            "offset": [_json_number(x) for x in self.offset],
            "matrix": [[_json_number(x) for x in row] for row in self.matrix],
        }
        if self.offset_sigma is not None:
            out["offset_sigma"] = [_json_number(x) for x in self.offset_sigma]
        if self.matrix_sigma is not None:
            out["matrix_sigma"] = [[_json_number(x) for x in row] for row in self.matrix_sigma]
        out["quality"] = _plain(self.quality)
        return out

    @classmethod
    def from_dict(cls, data: dict, *, source: str = "calibration") -> Calibration:
        """A calibration from :meth:`to_dict` values; ``source`` names the file in errors."""
        if not isinstance(data, dict):
            raise ValueError(f"{source}: a calibration must be a JSON object, got {type(data).__name__}")
        missing = [k for k in ("sensor", "offset", "matrix") if k not in data]
        if missing:
            raise ValueError(f"{source}: calibration entry lacks {', '.join(missing)}")
        sensor = sensor_name(data["sensor"])
        if sensor in SENSORS and data.get("units", SENSORS[sensor]) != SENSORS[sensor]:
            raise ValueError(
                f"{source}: the {sensor} calibration is in {data['units']!r}; strapdown reads {sensor} readings in "
                f"{SENSORS[sensor]!r}"
            )

        def arr(key):
            value = data.get(key)
            return None if value is None else np.array(value, dtype=np.float64)

        try:
            return cls(
                sensor=sensor,
                offset=arr("offset"),
                matrix=arr("matrix"),
                frame=data.get("frame", "sensor"),
                units=data.get("units"),
                offset_sigma=arr("offset_sigma"),
                matrix_sigma=arr("matrix_sigma"),
                quality=data.get("quality", {}),
                method=data.get("method", ""),
            )
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{source}: {exc}") from None

    def save(self, path) -> None:
        """Write this calibration to a JSON file (see :func:`save` for several sensors in one file)."""
        save(path, self)

    @classmethod
    def load(cls, path, sensor: str | None = None) -> Calibration:
        """Read a calibration from a JSON file written by :meth:`save` or :func:`save`.

        Parameters
        ----------
        path : path-like
            The file.
        sensor : str, optional
            Which sensor's calibration to take; needed only when the file holds several.
        """
        cals = load(path)
        sensor = None if sensor is None else sensor_name(sensor)
        if sensor is None:
            if len(cals) != 1:
                raise ValueError(f"{path} holds calibrations of {', '.join(cals)}; say which with sensor=")
            return next(iter(cals.values()))
        if sensor not in cals:
            raise ValueError(f"{path} holds no {sensor} calibration (it has {', '.join(cals) or 'none'})")
        return cals[sensor]


def save(path, *calibrations: Calibration) -> None:
    """Write calibrations (at most one per sensor) to one JSON file.

    The file is written whole or not at all (a temporary file renamed into place).

    Parameters
    ----------
    path : path-like
        Output file.
    *calibrations : Calibration
        The calibrations to store.
    """
    if not calibrations:
        raise ValueError("save needs at least one Calibration")
    seen = one_per_sensor(calibrations, "save takes")
    doc = {
        "format": _FORMAT,
        "version": _VERSION,
        "calibrations": [cal.to_dict() for cal in seen.values()],
    }
    path = Path(path)
    tmp = path.with_name(path.name + ".partial")
    tmp.write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
    tmp.replace(path)


def load(path) -> dict[str, Calibration]:
    """Read the calibrations of a JSON file written by :func:`save`.

    Parameters
    ----------
    path : path-like
        A JSON file of format version 1; another version, or any other file, is a ``ValueError``.

    Returns
    -------
    dict
        Sensor name -> :class:`Calibration`.
    """
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise FileNotFoundError(f"no such calibration file: {path}") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ValueError(f"{path} is not a JSON calibration file: {exc}") from None
    if not isinstance(doc, dict) or doc.get("format") != _FORMAT:
        raise ValueError(f'{path} is not a strapdown calibration file (no "format": "{_FORMAT}")')
    if doc.get("version") != _VERSION:
        raise ValueError(f"{path} has calibration format version {doc.get('version')!r}; this strapdown reads 1")
    entries = doc.get("calibrations")
    if not isinstance(entries, list) or not entries:
        raise ValueError(f"{path} holds no calibrations")
    out = {}
    for i, entry in enumerate(entries):
        cal = Calibration.from_dict(entry, source=f"{path} (calibration {i})")
        if cal.sensor in out:  # the later one silently winning would apply a calibration nobody chose
            raise ValueError(f"{path} holds two {cal.sensor} calibrations (entries {out[cal.sensor][1]} and {i})")
        out[cal.sensor] = cal, i
    return {sensor: cal for sensor, (cal, _) in out.items()}


def one_per_sensor(calibrations, what: str) -> dict:
    """Calibrations by sensor name; anything but a Calibration, or two of one sensor, is refused.

    ``what`` starts the message about a wrong type (``"save takes"``), naming who asked.
    """
    out = {}
    for cal in calibrations:
        if not isinstance(cal, Calibration):
            raise ValueError(f"{what} Calibration objects, got {type(cal).__name__}")
        if cal.sensor in out:
            raise ValueError(f"two {cal.sensor} calibrations given; give one per sensor")
        out[cal.sensor] = cal
    return out


def by_sensor(calibrations) -> dict:
    """Calibrations by sensor name, one each, from None, :func:`load`'s mapping or a sequence of them.

    Parameters
    ----------
    calibrations : None, mapping or sequence of Calibration
        What :func:`load` returns, or the calibrations themselves.

    Returns
    -------
    dict of str to Calibration
        By :attr:`Calibration.sensor` (``"gyro"``, ``"acc"``, ``"mag"``); empty for None.

    Examples
    --------
    >>> from strapdown.calibrate import by_sensor
    >>> by_sensor(None)
    {}
    """
    if calibrations is None:
        return {}
    items = calibrations.values() if isinstance(calibrations, dict) else calibrations
    return one_per_sensor(items, "calibration must hold strapdown.calibrate.Calibration objects:")
