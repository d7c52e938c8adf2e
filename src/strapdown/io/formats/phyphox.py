"""phyphox exports (the RWTH Aachen app): a folder, or its zip, of one CSV per sensor.

Layout of a multi-sensor experiment's "CSV" export: ``Gyroscope.csv`` (``"Time (s)","Gyroscope x (rad/s)",
"Gyroscope y (rad/s)","Gyroscope z (rad/s)"``), ``Accelerometer.csv`` (``"Acceleration x (m/s^2)"``, ... with
gravity), ``Linear Accelerometer.csv`` (``"Linear Acceleration x (m/s^2)"``, ... gravity removed),
``Magnetometer.csv`` (``"Magnetic field x (µT)"``, ...), each with an ``Absolute ...`` column; a single-sensor
experiment writes ``Raw Data.csv``.  Times are seconds from the experiment's start; ``meta/time.csv`` gives the
start's system time (epoch seconds), which becomes the origin when present, and dates ``Location.csv``
(``"Latitude (°)"``, ``"Longitude (°)"``, ``"Height (m)"``: the ``position`` hook, for ``--declination auto``).
The export may use ``;`` and decimal commas (the "semicolon, decimal comma" option), which the CSV reader takes.

The accelerometer is ``Accelerometer.csv``; ``Linear Accelerometer.csv`` is used only when it is the only one,
and then refused by the accelerometer check as gravity-free (it gave roll -97° at exit code 0 before, issue 12).
Frames: Android's phone axes (x right, y to the top, z out of the screen: body "RFU"), reference ENU.
"""

from __future__ import annotations

import csv
from pathlib import Path

from ..source import TimeOrigin
from .base import Format
from .multi import Export, first_line, merge_streams, open_streams

__all__ = ["SENSOR_FILES", "open_phyphox"]

#: The files read, in order of preference per sensor.
SENSOR_FILES = {
    "gyro": ("Gyroscope.csv",),
    "acc": ("Accelerometer.csv", "Linear Accelerometer.csv"),
    "mag": ("Magnetometer.csv",),
}
_ALL = (
    "Gyroscope.csv",
    "Accelerometer.csv",
    "Linear Accelerometer.csv",
    "Magnetometer.csv",
    "Raw Data.csv",
    "time.csv",
)


def _is_export(path: Path) -> bool:
    head = first_line(path, "Gyroscope.csv") or first_line(path, "Raw Data.csv")
    return head.replace('"', "").strip().startswith("Time (s)")


def _start_epoch(time_csv: Path | None) -> float | None:
    """The system time (epoch s) at the experiment's START event, from ``meta/time.csv``."""
    if time_csv is None:
        return None
    with open(time_csv, newline="", encoding="utf-8-sig") as f:
        return start_epoch(f.read(1 << 20))  # a few lines of events; a larger file is no phyphox time.csv


def start_epoch(text: str) -> float | None:
    r"""The system time (epoch s) at the START event of the text of a ``meta/time.csv``, or None.

    Examples
    --------
    >>> from strapdown.io.formats.phyphox import start_epoch
    >>> start_epoch('"event","experiment time","system time"\n"START",2.5,1718030736.5\n')
    1718030734.0
    """
    delimiter = ";" if text.count(";") > text.count(",") else ","
    rows = list(csv.reader(text.splitlines(), delimiter=delimiter))
    if not rows:
        return None
    header = [h.strip().lower() for h in rows[0]]
    if "system time" not in header or "experiment time" not in header:
        return None
    for row in rows[1:]:
        if row and row[0].strip().upper() == "START":
            try:
                system = float(row[header.index("system time")].replace(",", "."))
                experiment = float(row[header.index("experiment time")].replace(",", "."))
            except (ValueError, IndexError):
                return None
            return system - experiment
    return None


def _position(path):
    """The ``position`` hook: the export's ``Location.csv`` dated by ``meta/time.csv``."""
    from ..position import export_position

    with Export(Path(path), ("time.csv",)) as export:
        start = _start_epoch(export.get("time.csv"))
    return export_position(path, start_epoch=start)


def open_phyphox(path, time_unit: str | None = None):
    r"""A phyphox export (folder or zip) as one table on the gyro's rows.

    Parameters
    ----------
    path : path-like
        The export folder or its zip.
    time_unit : str, optional
        Overrides the ``Time (s)`` header.

    Returns
    -------
    MemorySource
        Gyro (rad/s), accelerometer (m/s²) and magnetometer (µT) columns, ``t`` in s from the first gyro sample,
        frames ENU/RFU.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io.formats.phyphox import open_phyphox
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "Gyroscope.csv").write_text('"Time (s)","Gyroscope x (rad/s)","Gyroscope y (rad/s)",'
    ...     '"Gyroscope z (rad/s)"\n0.0,0.01,0,0\n0.01,0.01,0,0\n')
    >>> open_phyphox(folder).presets["gyro"][0], open_phyphox(folder).body
    ('Gyroscope.csv/Gyroscope x (rad/s)', 'RFU')
    """
    path = Path(path)
    with Export(path, _ALL) as export:
        chosen = export.sensor_files(SENSOR_FILES)
        if not chosen and export.get("Raw Data.csv") is not None:
            chosen[export.get("Raw Data.csv")] = None  # one sensor: told by its column names
        streams = open_streams(list(chosen), kinds={p: k for p, k in chosen.items() if k})
        start = _start_epoch(export.get("time.csv"))
        src = merge_streams(path, streams, "phyphox", time_unit=time_unit)
    if start is not None and "gyro" in streams:
        src.time_origin = TimeOrigin(start + float(streams["gyro"].first), "s", "epoch")
    src.frame, src.body = "ENU", "RFU"
    return src


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format(
    "phyphox",
    open_phyphox,
    detect=_is_export,
    options=("time_unit",),
    description="phyphox export (folder or zip)",
    position=_position,
)
