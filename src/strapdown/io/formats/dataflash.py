"""ArduPilot DataFlash logs, binary (``.bin``) and text (``.log``): the IMU, the magnetometer, GPS and ATT.

What ArduPilot writes (``libraries/AP_Logger/LogStructure.h`` and the log message reference of ardupilot.org):

* ``IMU``: ``TimeUS`` (µs since boot), ``I`` (the instance: 0, 1, 2 for a vehicle's IMUs), ``GyrX..GyrZ`` (rad/s),
  ``AccX..AccZ`` (m/s², specific force); older logs name the second and third IMU ``IMU2`` and ``IMU3`` without
  ``I``.  ``topic=`` chooses the instance (``"IMU"``, ``"IMU:1"`` or ``"IMU2"``); the gyro and accelerometer
  share the message, so both are on each row.
* ``MAG``: ``TimeUS``, ``I``, ``MagX..MagZ`` in milligauss, read as µT (1 mG = 0.1 µT), on the gyro's nearest
  rows; ``mag_topic=`` chooses (``"MAG:1"``, ``"none"``).
* ``ATT``: ``Roll``, ``Pitch`` and ``Yaw`` in degrees (stored × 100): the autopilot's own estimate, the
  ``reference`` hook (:func:`read_attitude`), as the quaternion of the ZYX (yaw, pitch, roll) Euler angles, turned
  from the vehicle's axes to the IMU's by the log's ``AHRS_TRIM_X/Y`` parameters (``PARM``).
* ``GPS``: ``Status`` (3: a 3D fix), ``GMS``/``GWk`` (GPS time of week, ms, and week; ``TimeMS``/``Week`` in logs
  before ArduPilot 3.3), ``Lat``/``Lng`` (degrees, stored × 1e7) and ``Alt`` (m above mean sea level, stored × 100):
  the ``position`` hook (:func:`read_position`).
* Time: ``TimeUS``, µs since boot; logs before ArduPilot 3.3 have ``TimeMS``, ms since boot (read as µs × 1000).
* Messages of no payload (an ``FMT`` of length 3, the header alone: ``STRT``, events) are walked over.
* Frames: ArduPilot's body axes are FRD and its earth frame NED; a vehicle starts upright.

The binary file is never read whole: a compiled walk over the message headers finds the wanted messages a block at
a time, numpy decodes them in the layout their ``FMT`` declares, and the samples are spooled (:mod:`._spool`).
pymavlink's DFReader, the reference reader, indexes every message of a log in Python lists (some 40 bytes each:
1.6 GB for a 2 GiB log) and decodes them one by one, so it serves as the tests' oracle rather than as this reader.
A stretch the walk cannot read (a type no FMT declares, bytes that start no message) is skipped to the next run of
valid messages and reported with the samples lost and when; a log cut inside a message says so.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ._dataflash_scan import HEAD, is_text_log, scan_binary, scan_text
from ._gps import first_fix, gps_time
from ._spool import Spool, SpooledSource
from ._walk import Break, describe_breaks
from .base import Format

__all__ = ["open_dataflash", "read_attitude", "read_position", "scan"]

_PER_S = 1_000_000
_UNITS = {"gyro": "rad/s", "acc": "m/s2", "mag": "uT"}
_MG_TO_UT = 0.1


def scan(path, wanted, sink) -> tuple[list, list]:
    """Walk a DataFlash log (binary or text) and hand the wanted messages' columns to ``sink`` in blocks.

    Parameters
    ----------
    path : path-like
        The ``.bin`` or text ``.log`` file.
    wanted : callable
        ``wanted(name) -> bool`` for each message type (``"IMU"``).
    sink : callable
        ``sink(name, columns)``: the numeric columns of a block of that type's messages, float64 in their units
        (``TimeUS`` as int64).

    Returns
    -------
    names : list of str
        The log's message types.
    breaks : list of Break
        The stretches that could not be read.

    Examples
    --------
    >>> from strapdown.io.formats.dataflash import scan
    >>> scan("no/such.bin", None, None)
    Traceback (most recent call last):
    FileNotFoundError: no such file: no/such.bin
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    return (scan_text if is_text_log(path) else scan_binary)(path, wanted, sink)


def _instance(name: str, cols: dict, base: str) -> np.ndarray:
    """The instance of each message: its ``I`` column, else the digit of IMU2/IMU3-style names (2 -> 1)."""
    n = len(cols["TimeUS"])
    if "I" in cols:
        return cols["I"].astype(np.int64)
    digit = name[len(base) :]
    return np.full(n, int(digit) - 1 if digit else 0, dtype=np.int64)


class _Spools:
    """The sink of an IMU read: a spool per instance of IMU and MAG, and the messages of each read so far."""

    def __init__(self):
        self.spools: dict[tuple, Spool] = {}
        self.counts: dict[str, int] = {}

    def __call__(self, name, cols) -> None:
        base = "IMU" if name.startswith("IMU") else "MAG"
        need = ("GyrX", "GyrY", "GyrZ", "AccX", "AccY", "AccZ") if base == "IMU" else ("MagX", "MagY", "MagZ")
        missing = [c for c in ("TimeUS", *need) if c not in cols]
        if missing:
            missing = ["TimeUS (or TimeMS)" if c == "TimeUS" else c for c in missing]
            raise ValueError(f"{name} messages without {', '.join(missing)}: not ArduPilot's {base} layout")
        values = np.column_stack([cols[c] for c in need]) * (1.0 if base == "IMU" else _MG_TO_UT)
        instance = _instance(name, cols, base)
        for i in np.unique(instance):
            rows = instance == i
            key = (base, int(i))
            spool = self.spools.get(key) or self.spools.setdefault(key, Spool(values.shape[1]))
            spool.append(cols["TimeUS"][rows], values[rows])
            self.counts[f"{base}:{int(i)}"] = spool.n

    def take(self, key):
        return self.spools.pop(key)

    def close(self) -> None:
        for spool in self.spools.values():
            spool.close()


def _which(spec: str | None, base: str, path: Path, have) -> tuple:
    """``("IMU", instance)`` from ``"IMU"``, ``"IMU:1"``, ``"IMU[1]"`` or ``"IMU2"``."""
    if spec is None:
        return (base, min((i for b, i in have if b == base), default=0))
    m = re.fullmatch(rf"{base}(?:(\d)|[:\[](\d+)\]?)?", spec.strip())
    if m is None:
        raise ValueError(f"{path}: {spec!r} names no {base} instance; use {base}, {base}:1 or {base}2")
    instance = int(m.group(1)) - 1 if m.group(1) else int(m.group(2) or 0)
    if (base, instance) not in have:
        listing = ", ".join(f"{b}:{i}" for b, i in sorted(have) if b == base) or "none"
        raise ValueError(f"{path}: no {base} instance {instance} in this log; its {base} instances: {listing}")
    return (base, instance)


def _label(key) -> str:
    return key[0] if key[1] == 0 else f"{key[0]}[{key[1]}]"


def open_dataflash(path, topic: str | None = None, mag_topic: str | None = None) -> SpooledSource:
    """A DataFlash log's IMU (and magnetometer) readings as a table on the gyro's rows (module description).

    Parameters
    ----------
    path : path-like
        The ``.bin`` or text ``.log`` file.
    topic : str, optional
        The IMU instance: ``"IMU"`` (the first, default), ``"IMU:1"`` or ``"IMU2"`` (the second).
    mag_topic : str, optional
        The magnetometer instance (``"MAG"``, ``"MAG:1"``); ``"none"``: no magnetometer.

    Returns
    -------
    SpooledSource
        Fields ``t`` (s from the first IMU sample), ``IMU/GyrX..`` (rad/s), ``IMU/AccX..`` (m/s²), ``MAG/MagX..``
        (µT); frames NED/FRD; ``warnings`` lists what could not be read.

    Examples
    --------
    >>> from strapdown.io.formats.dataflash import open_dataflash
    >>> open_dataflash("no/such.bin")
    Traceback (most recent call last):
    FileNotFoundError: no such file: no/such.bin
    """
    path = Path(path)
    sink = _Spools()
    try:
        wanted = re.compile(r"IMU\d?" + ("" if mag_topic == "none" else r"|MAG\d?")).fullmatch
        names, breaks = scan(path, wanted, sink)
        if not any(b == "IMU" for b, _ in sink.spools):
            size = path.stat().st_size
            where = f" before {breaks[0].what} at byte {breaks[0].start}" if breaks else f" (its {size} bytes)"
            declared = ", ".join(sorted(set(names)))
            raise ValueError(f"{path}: no IMU messages in this DataFlash log{where}; its FMTs declare: {declared}")
        key = _which(topic, "IMU", path, sink.spools)
        gyro = sink.take(key)
        label = _label(key)
        rows = {"gyro": tuple(f"{label}/Gyr{c}" for c in "XYZ"), "acc": tuple(f"{label}/Acc{c}" for c in "XYZ")}
        placed = {}
        if mag_topic != "none" and any(b == "MAG" for b, _ in sink.spools):
            mag = _which(mag_topic, "MAG", path, sink.spools)
            placed["mag"] = (sink.take(mag), tuple(f"{_label(mag)}/Mag{c}" for c in "XYZ"))
        elif mag_topic not in (None, "none"):
            raise ValueError(f"{path}: no MAG messages in this log for mag_topic {mag_topic!r}")
        src = SpooledSource(path, "dataflash", gyro, rows, placed, _PER_S, "boot", _UNITS)
    finally:
        sink.close()
    src.frame, src.body, src.upright = "NED", "FRD", True
    src.topic = f"{key[0]}:{key[1]}"
    stream = f"gyro ({src.topic})"
    src.warnings = describe_breaks(
        path,
        [Break(b.start, b.stop, b.what, {stream: b.counts.get(src.topic, 0)}) for b in breaks],
        lambda i: int(gyro.times(i, i + 1)[0]) if 0 <= i < gyro.n else None,
        src.period_ticks,
        _PER_S,
        gyro.first,
        stream,
    )
    return src


class _Collect:
    """A sink keeping every block of some message types, and the first IMU time of each instance."""

    def __init__(self, full):
        self.full, self.parts, self.first = set(full), {}, {}

    def __call__(self, name, cols) -> None:
        if name in self.full:
            self.parts.setdefault(name, []).append(cols)
        else:
            instance = _instance(name, cols, "IMU")
            for i in np.unique(instance):
                self.first.setdefault(("IMU", int(i)), int(cols["TimeUS"][instance == i][0]))

    def table(self, name) -> dict:
        parts = self.parts.get(name, [])
        return {c: np.concatenate([p[c] for p in parts]) for c in (parts[0] if parts else ())}


def read_attitude(path, topic: str | None = None, *, trim: bool = True):
    """The autopilot's own attitude (``ATT``: roll, pitch, yaw) as times and quaternions, FRD body to NED.

    ArduPilot reports the attitude of the vehicle, which is the board's (the IMU's axes) turned by the parameters
    ``AHRS_TRIM_X`` and ``AHRS_TRIM_Y`` (roll and pitch, radians: the board mounted out of level).  The IMU's
    readings are in the board's axes, so by default the trim is undone here, and ATT becomes the attitude of the
    axes an estimate from those readings has.

    Parameters
    ----------
    path : path-like
        The log.
    topic : str, optional
        The IMU instance whose first sample is t = 0 (as :func:`open_dataflash` reads it).
    trim : bool, optional
        Undo the log's ``AHRS_TRIM_X/Y`` (default); False: the vehicle's attitude as ATT has it.

    Returns
    -------
    t : numpy.ndarray, shape (n,)
        Seconds from that IMU's first sample.
    q : numpy.ndarray, shape (n, 4)
        [w, x, y, z] of the ZYX Euler angles (yaw, pitch, roll), composed with the trim.
    origin : TimeOrigin
        The IMU's first sample, µs since boot.

    Examples
    --------
    >>> from strapdown.io.formats.dataflash import read_attitude
    >>> read_attitude("no/such.bin")
    Traceback (most recent call last):
    FileNotFoundError: no such file: no/such.bin
    """
    t, q, origin, _ = _attitude(path, topic, trim)
    return t, q, origin


def _attitude(path, topic, trim: bool):
    """:func:`read_attitude`, and the trim it undid (radians, or None)."""
    from ...rotations.euler import from_euler
    from ...rotations.quaternion import multiply
    from ..source import TimeOrigin

    sink = _Collect(("ATT", "PARM"))
    scan(path, re.compile(r"IMU\d?|ATT|PARM").fullmatch, sink)
    key = _which(topic, "IMU", Path(path), sink.first)
    att = sink.table("ATT")
    if not att or not all(c in att for c in ("TimeUS", "Roll", "Pitch", "Yaw")):
        raise ValueError(f"{path}: no ATT messages with Roll, Pitch and Yaw (the autopilot's estimate)")
    t0 = sink.first[key]
    q = from_euler(np.column_stack([att["Yaw"], att["Pitch"], att["Roll"]]), "ZYX", degrees=True)
    trim = _trim(sink.table("PARM")) if trim else None
    if trim is not None:
        # AP_AHRS: the vehicle's body (what ATT gives) is the board's (the IMU's axes) turned by the trim's roll and
        # pitch, dcm_vehicle = dcm_board R(trim)^T, so the IMU axes' attitude is ATT composed with the trim
        q = multiply(q, from_euler(np.array([0.0, trim[1], trim[0]]), "ZYX"))
    return (att["TimeUS"] - t0) / _PER_S, q, TimeOrigin(t0, "us", "boot"), trim


def _trim(parm: dict) -> tuple | None:
    """``(AHRS_TRIM_X, AHRS_TRIM_Y)`` in radians as the log's parameters first give them; None when absent or 0."""
    if not parm or "Name" not in parm or "Value" not in parm:
        return None
    found = []
    for name in ("AHRS_TRIM_X", "AHRS_TRIM_Y"):
        rows = np.flatnonzero(parm["Name"] == name)
        found.append(float(parm["Value"][rows[0]]) if rows.size else 0.0)
    return tuple(found) if any(found) else None


def reference(path, topic: str | None = None) -> dict:
    """The :class:`~strapdown.io.formats.base.Format` ``reference`` hook: ``ATT`` (NED, FRD), the trim undone."""
    t, q, origin, trim = _attitude(path, topic, True)
    source = "ATT"
    if trim is not None:
        source += f" (AHRS_TRIM_X {np.degrees(trim[0]):.3f} deg, AHRS_TRIM_Y {np.degrees(trim[1]):.3f} deg undone)"
    return {"t": t, "q": q, "frame": "NED", "body": "FRD", "time_origin": origin, "source": source}


def read_position(path) -> dict | None:
    """Where and when the log was made: the first 3D fix of its first GPS with a GPS week.

    Parameters
    ----------
    path : path-like
        The log.

    Returns
    -------
    dict or None
        ``latitude_deg``, ``longitude_deg``, ``altitude_m``, ``date`` (UTC: GPS week and time of week less the
        leap seconds of that date, 18 since 2017) and ``source``; None when no GPS message has a 3D fix and a week.

    Examples
    --------
    >>> from strapdown.io.formats.dataflash import read_position
    >>> read_position("no/such.bin")
    Traceback (most recent call last):
    FileNotFoundError: no such file: no/such.bin
    """
    sink = _Collect(("GPS",))
    scan(path, "GPS".__eq__, sink)
    gps = sink.table("GPS")
    # ArduPilot 3.3 on: GWk and GMS; before: Week and TimeMS (the GPS time of week, the boot time being T)
    week, ms = ("GWk", "GMS") if "GWk" in gps else ("Week", "TimeMS")
    if not all(c in gps for c in ("Status", week, ms, "Lat", "Lng")):
        return None
    lat, lon = gps["Lat"], gps["Lng"]
    if np.abs(lat).max() > 90 or np.abs(lon).max() > 180:  # stored as integers without the L format's scale
        lat, lon = lat / 1e7, lon / 1e7
    good = (gps["Status"] >= 3) & (gps[week] > 0)
    if "I" in gps:
        good &= gps["I"] == 0
    return first_fix(lat, lon, gps.get("Alt"), good, lambda i: gps_time(gps[week][i], gps[ms][i]), "GPS")


def _is_dataflash(path: Path) -> bool:
    if path.is_dir():
        return False
    with open(path, "rb") as f:
        head = f.read(4)
    return tuple(head[:3]) == (*HEAD, 0x80) or head == b"FMT,"


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format(
    "dataflash",
    open_dataflash,
    suffixes=(".bin",),
    detect=_is_dataflash,
    options=("topic", "mag_topic"),
    description="ArduPilot DataFlash (.bin, text .log)",
    reference=reference,
    position=read_position,
)
