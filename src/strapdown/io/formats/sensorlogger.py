"""Sensor Logger exports (the Android/iOS app by Kelvin Choi): a folder, or its zip, of one CSV per sensor.

Layout, as the app documents it (awesome-sensor-logger, "One-Page Unit Reference"): ``Gyroscope.csv``,
``Accelerometer.csv``, ``TotalAcceleration.csv`` (Android), ``Gravity.csv``, ``Magnetometer.csv``, each with the
header ``time,seconds_elapsed,z,y,x`` (note the order), ``time`` in nanoseconds since the epoch; gyro in rad/s,
accelerations in m/s², field in µT.  On Android ``Accelerometer.csv`` has gravity removed and
``TotalAcceleration.csv`` is the raw accelerometer; on iOS only ``Accelerometer.csv`` (without gravity) and
``Gravity.csv`` exist.  So the specific force is ``TotalAcceleration.csv`` when there, else ``Accelerometer.csv``
plus ``Gravity.csv`` sample by sample, else ``Accelerometer.csv`` alone, which the accelerometer check refuses
as gravity-free.

Frames: the phone's axes are Android's (x right, y to the top of the screen, z out of the screen: body "RFU"),
and the reference ENU.  ``Metadata.csv`` names the platform; an iOS recording without the app's "standardise
units & frames" setting has other axes and units, so no preset is given for it.
"""

from __future__ import annotations

import csv
from pathlib import Path

from ..merge import place_on_rows
from .base import Format
from .multi import Export, first_line, merge_streams, open_streams

__all__ = ["SENSOR_FILES", "open_sensorlogger"]

#: The files read, in order of preference per sensor.
SENSOR_FILES = {
    "gyro": ("Gyroscope.csv",),
    "acc": ("TotalAcceleration.csv", "Accelerometer.csv"),
    "mag": ("Magnetometer.csv",),
}
_ALL = (
    "Gyroscope.csv",
    "TotalAcceleration.csv",
    "Accelerometer.csv",
    "Gravity.csv",
    "Magnetometer.csv",
    "Metadata.csv",
)
_UNITS = {"gyro": "rad/s", "acc": "m/s2", "mag": "uT"}


def _is_export(path: Path) -> bool:
    return first_line(path, "Gyroscope.csv").replace('"', "").strip().startswith("time,seconds_elapsed")


def _platform(meta: Path | None) -> dict:
    if meta is None:
        return {}
    with open(meta, newline="", encoding="utf-8-sig") as f:
        rows = list(csv.reader(f))
    return dict(zip(rows[0], rows[1], strict=False)) if len(rows) > 1 else {}


def open_sensorlogger(path, time_unit: str | None = None):
    r"""A Sensor Logger export (folder or zip) as one table on the gyro's rows.

    Parameters
    ----------
    path : path-like
        The export folder or its zip.
    time_unit : str, optional
        Overrides ``time``'s documented nanoseconds.

    Returns
    -------
    MemorySource
        Gyro (rad/s), accelerometer with gravity (m/s²) and magnetometer (µT) columns, ``t`` in s from the first
        gyro sample, the epoch origin, frames ENU/RFU.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io.formats.sensorlogger import open_sensorlogger
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "Gyroscope.csv").write_text(
    ...     "time,seconds_elapsed,z,y,x\n1700000000000000000,0.0,0.0,0.0,0.01\n1700000000010000000,0.01,0.0,0.0,0.01\n")
    >>> src = open_sensorlogger(folder)
    >>> src.presets["gyro"], src.body
    (('Gyroscope.csv/x', 'Gyroscope.csv/y', 'Gyroscope.csv/z'), 'RFU')
    >>> str(src.time_origin)
    '1700000000000000000 ns since the epoch (1970-01-01 UTC)'
    """
    path = Path(path)
    with Export(path, _ALL) as export:
        chosen = export.sensor_files(SENSOR_FILES)
        streams = open_streams(list(chosen), kinds=chosen)
        gravity = export.get("Gravity.csv")
        acc = streams.get("acc")
        if acc is not None and acc.path.name == "Accelerometer.csv" and gravity is not None:
            g = open_streams([gravity], kinds={gravity: "acc"})["acc"]
            # user acceleration + gravity = specific force, each gravity sample on the nearest acc sample
            acc.values = acc.values + place_on_rows(acc.t, g.t + (g.first - acc.first), g.values)
            acc.fields = tuple(f"{f}+Gravity.csv" for f in acc.fields)
        meta = _platform(export.get("Metadata.csv"))
        for kind, stream in streams.items():
            stream.unit = stream.unit or _UNITS[kind]
        src = merge_streams(path, streams, "sensorlogger", time_unit=time_unit or "ns", origin_kind="epoch")
    ios = meta.get("platform", "").lower() == "ios" and meta.get("standardisation", "").lower() not in ("true", "1")
    src.frame, src.body = (None, None) if ios else ("ENU", "RFU")
    return src


def _position(path):
    from ..position import export_position

    return export_position(path)


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format(
    "sensorlogger",
    open_sensorlogger,
    detect=_is_export,
    options=("time_unit",),
    description="Sensor Logger export (folder or zip)",
    position=_position,
)
