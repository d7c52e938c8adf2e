"""Where and when a log was recorded, from its own GPS: for ``--declination auto`` without ``--lat/--lon/--date``.

Each input format may say how to read it (the ``position`` field of :class:`strapdown.io.formats.base.Format`);
:func:`strapdown.io.reference.log_position` asks the registry, so a format that fills the field (ArduPilot's
GPS, a ROS ``NavSatFix``) is read the same way.  The readers here:

* PX4 ULog: ``vehicle_gps_position`` or ``sensor_gps`` (``lat``/``lon`` in 1e-7 degrees and ``alt`` in mm, or
  the newer ``latitude_deg``/``longitude_deg``/``altitude_msl_m``), the date from ``time_utc_usec``;
* a phone export's ``Location.csv`` (Sensor Logger: ``latitude``, ``longitude``, ``altitude`` and epoch
  nanoseconds in ``time``; phyphox: ``"Latitude (°)"``, ``"Longitude (°)"``, ``"Height (m)"`` and seconds from the
  start in ``"Time (s)"``, the start's system time in ``meta/time.csv``).

The place is the median of the fixes (a few metres of GPS noise move the declination by nothing), the date that
of the first fix with a UTC time.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["LogPosition", "export_position", "ulog_position"]


@dataclass(frozen=True)
class LogPosition:
    """A log's place and date.

    Attributes
    ----------
    latitude_deg, longitude_deg : float
        Degrees (WGS-84), north and east positive.
    altitude_m : float
        Metres above mean sea level (NaN when not recorded).
    date : datetime.date
        The UTC date.
    source : str
        What was read (``"vehicle_gps_position, 32 fixes"``).
    """

    latitude_deg: float
    longitude_deg: float
    altitude_m: float
    date: _dt.date
    source: str

    def describe(self) -> str:
        """One line for a report: ``47.39774 N, 8.54559 E on 2022-04-29 (sensor_gps, 11 fixes)``."""
        ns = "N" if self.latitude_deg >= 0 else "S"
        ew = "E" if self.longitude_deg >= 0 else "W"
        return (
            f"{abs(self.latitude_deg):.5f} {ns}, {abs(self.longitude_deg):.5f} {ew} on {self.date.isoformat()} "
            f"({self.source})"
        )


def _fixes(lat, lon, alt, utc, source: str, path) -> LogPosition | None:
    """The median place of the plausible fixes and the date of the first one with a UTC time, or None."""
    lat, lon = np.asarray(lat, dtype=np.float64), np.asarray(lon, dtype=np.float64)
    alt = np.full(lat.shape, np.nan) if alt is None else np.asarray(alt, dtype=np.float64)
    utc = np.asarray(utc, dtype=np.float64)  # µs since the epoch
    # a receiver without a fix writes zeros; the UTC time of a fix from before 2000 is a clock not yet set
    good = np.isfinite(lat) & np.isfinite(lon) & (np.abs(lat) <= 90) & (np.abs(lon) <= 180) & ((lat != 0) | (lon != 0))
    good &= np.isfinite(utc) & (utc > 946684800e6)
    if not good.any():
        return None
    when = _dt.datetime.fromtimestamp(float(utc[good][0]) / 1e6, tz=_dt.UTC).date()
    height = float(np.nanmedian(alt[good])) if np.isfinite(alt[good]).any() else float("nan")
    return LogPosition(
        float(np.median(lat[good])), float(np.median(lon[good])), height, when, f"{source}, {int(good.sum())} fixes"
    )


def ulog_position(path) -> LogPosition | None:
    """A PX4 ULog's place and date: its first 3D GPS fix.

    The ULog reader's ``position`` hook, read a block at a time (:func:`strapdown.io.formats.ulog.read_position`).

    Parameters
    ----------
    path : str or pathlib.Path
        The ULog.

    Returns
    -------
    LogPosition or None
        Its fields as the hook gives them; None without a 3D fix that has a UTC time.

    Examples
    --------
    >>> from strapdown.io.position import ulog_position
    >>> ulog_position("tests/data/px4/sample_log_small.ulg").describe()[:40]
    '63.41706 N, 10.40822 E on 2021-04-21 (ve'
    """
    from .formats.ulog import read_position

    found = read_position(path)
    return None if found is None else LogPosition(**found)


def export_position(path, start_epoch: float | None = None) -> LogPosition | None:
    r"""A phone export's place and date from its ``Location.csv``: Sensor Logger's or phyphox's.

    Sensor Logger writes epoch nanoseconds in ``time`` beside ``latitude``, ``longitude`` and ``altitude``;
    phyphox (its "Location (GPS)" sensor) ``"Time (s)"`` from the experiment's start beside ``"Latitude (°)"``,
    ``"Longitude (°)"`` and ``"Height (m)"``, so its date comes from ``start_epoch``, which the phyphox reader takes
    from the START event's system time in ``meta/time.csv`` (none without it: no date is made up).  phyphox's
    "semicolon, decimal comma" layout is read too.

    Parameters
    ----------
    path : path-like
        The export folder, or a zip of it.
    start_epoch : float, optional
        The epoch seconds of the export's time 0 (phyphox's ``"Time (s)"``).

    Returns
    -------
    LogPosition or None
        None when it has no location file, or no fix (or, phyphox, no start time).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io.position import export_position
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "Location.csv").write_text(
    ...     "time,seconds_elapsed,latitude,longitude,altitude\n1700000000000000000,0,52.5,13.4,35\n")
    >>> export_position(folder).describe()
    '52.50000 N, 13.40000 E on 2023-11-14 (Location.csv, 1 fixes)'
    """
    import csv
    import io

    from .formats.multi import Export

    path = Path(path)
    with Export(path, ("Location.csv",)) as export:
        location = export.get("Location.csv")
        if location is None or location.stat().st_size > 64 << 20:  # a few rows a second: 64 MiB is hours of it
            return None
        text = location.read_text(encoding="utf-8-sig")
    head = text.split("\n", 1)[0]
    semicolon = head.count(";") > head.count(",")  # the header's: decimal commas outnumber the ; of the rows
    rows = list(csv.reader(io.StringIO(text), delimiter=";" if semicolon else ","))
    if len(rows) < 2:
        return None
    header = [h.strip() for h in rows[0]]

    def column(name):
        i = header.index(name)
        cells = [(r[i] if i < len(r) else "").strip() for r in rows[1:]]
        return np.array([float((c.replace(",", ".") if semicolon else c) or "nan") for c in cells])

    if {"time", "latitude", "longitude"} <= set(header):  # Sensor Logger
        utc = column("time") / 1e3  # ns -> µs
        height = column("altitude") if "altitude" in header else None
        return _fixes(column("latitude"), column("longitude"), height, utc, "Location.csv", path)
    if {"Time (s)", "Latitude (°)", "Longitude (°)"} <= set(header):  # phyphox
        if start_epoch is None:
            return None
        utc = (start_epoch + column("Time (s)")) * 1e6
        height = column("Height (m)") if "Height (m)" in header else None
        source = "Location.csv, date from meta/time.csv"
        return _fixes(column("Latitude (°)"), column("Longitude (°)"), height, utc, source, path)
    return None
