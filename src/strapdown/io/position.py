"""Where and when a log was recorded, from its own GPS: for ``--declination auto`` without ``--lat/--lon/--date``.

Each input format may say how to read it (the ``position`` field of :class:`strapdown.io.formats.base.Format`);
:func:`strapdown.io.reference.log_position` asks the registry, so a format that fills the field (ArduPilot's
GPS, a ROS ``NavSatFix``) is read the same way.  The readers here:

* PX4 ULog: ``vehicle_gps_position`` or ``sensor_gps`` (``lat``/``lon`` in 1e-7 degrees and ``alt`` in mm, or
  the newer ``latitude_deg``/``longitude_deg``/``altitude_msl_m``), the date from ``time_utc_usec``;
* a phone export's ``Location.csv`` (Sensor Logger: ``latitude``, ``longitude``, ``altitude`` and epoch
  nanoseconds in ``time``).

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


_LOCATION_NAMES = ("location.csv",)


def export_position(path) -> LogPosition | None:
    r"""A phone export's place and date from its ``Location.csv`` (epoch-nanosecond ``time``, ``latitude``, ...).

    Parameters
    ----------
    path : path-like
        The export folder, or a zip of it (Sensor Logger).

    Returns
    -------
    LogPosition or None
        None when it has no location file, or no fix.

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
    import zipfile

    path = Path(path)
    text = None
    if path.is_dir():
        found = [p for p in path.iterdir() if p.name.lower() in _LOCATION_NAMES]
        text = found[0].read_text(encoding="utf-8-sig") if found else None
    elif zipfile.is_zipfile(path):
        with zipfile.ZipFile(path) as z:
            names = [n for n in z.namelist() if Path(n).name.lower() in _LOCATION_NAMES]
            # a location file is a few rows a second: 64 MiB is hours of it, and no more is unpacked
            if names and z.getinfo(names[0]).file_size < 64 << 20:
                text = z.read(names[0]).decode("utf-8-sig")
    if not text:
        return None
    rows = list(csv.DictReader(io.StringIO(text)))
    if not rows or not {"time", "latitude", "longitude"} <= set(rows[0]):
        return None

    def column(name):
        return np.array([float(r.get(name) or "nan") for r in rows])

    utc = column("time") / 1e3  # ns -> µs
    return _fixes(column("latitude"), column("longitude"), column("altitude"), utc, "Location.csv", path)
