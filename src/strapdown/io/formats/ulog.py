"""PX4 flight logs (ULog, ``.ulg``), read a block at a time: the IMU topics at their own rates, and the log's attitude.

* Gyro and accelerometer: ``sensor_combined`` (``gyro_rad`` in rad/s, ``accelerometer_m_s2`` in m/s², the
  accelerometer sample at ``timestamp + accelerometer_timestamp_relative``, kept on its row) when the log has it,
  else ``sensor_gyro`` and ``sensor_accel`` (``x, y, z``), each at its own rate; ``topic=`` chooses
  (``"sensor_gyro"``, or ``"sensor_gyro:1"`` for the second instance).
* Magnetometer: ``vehicle_magnetometer`` (``magnetometer_ga``, gauss) else ``sensor_mag`` (gauss), on the gyro's
  rows (:mod:`strapdown.io.merge`); ``mag_topic=`` chooses.
* Time: microseconds since boot, ``timestamp_sample`` (the raw sample's time) where a message has it, else
  ``timestamp``; t counts from the first gyro sample, and the origin (:class:`~strapdown.io.source.TimeOrigin`,
  kind ``"boot"``) is kept.
* Frames: PX4 sensor data are in body axes FRD, and ``vehicle_attitude.q`` is the "quaternion rotation from the
  FRD body frame to the NED earth frame", Hamilton convention, order (w, x, y, z) (PX4 uORB ``VehicleAttitude.msg``):
  strapdown's own convention, so the preset is reference NED, body FRD, and :func:`read_attitude` takes ``q`` as
  it is.  ``tests/io/test_io_formats.py`` checks it physically: at rest the log's tilt and the estimator's agree
  within 0.1°, where a conjugated quaternion would mirror the tilt.
* Position: the first 3D fix of ``vehicle_gps_position`` or ``sensor_gps`` (``lat``/``lon`` in 1e-7°, ``alt`` in mm
  above MSL, ``time_utc_usec``), for ``--declination auto`` (:func:`read_position`).

The file is never read whole.  pyulog parses the definitions (the message formats and their numpy layout); the data
section is walked a block at a time by a compiled loop over the message headers, and each wanted topic's payloads
are decoded with numpy and spooled (:mod:`._spool`), so memory stays bounded whatever the log's size.  ULog has no
checksums: a message whose type or size cannot be (a size of 0xFFFF where the topic's messages have 40 bytes) is
a corruption, which is skipped up to the next run of valid messages and reported with the samples lost and when
(:mod:`._walk`); a log cut inside a message says so too.
"""

from __future__ import annotations

import datetime
import struct
from pathlib import Path

import numpy as np

from ..._support.deps import need
from ._gps import first_fix
from ._spool import Spool, SpooledSource
from ._walk import BATCH, Blocks, Break, describe_breaks
from .base import Format

__all__ = ["ULOG_MAGIC", "UlogSource", "open_ulog", "read_attitude", "read_position", "scan_ulog"]

#: The first bytes of every ULog file.
ULOG_MAGIC = b"ULog\x01\x12\x35"
_INVALID_RELATIVE = 2147483647  # sensor_combined: RELATIVE_TIMESTAMP_INVALID, no accelerometer sample
_GYRO, _ACC, _MAG = ("sensor_combined", "sensor_gyro"), ("sensor_accel",), ("vehicle_magnetometer", "sensor_mag")
_GPS = ("vehicle_gps_position", "sensor_gps")
_PER_S = 1_000_000
_UNITS = {"gyro": "rad/s", "acc": "m/s2", "mag": "gauss"}


def _definitions(f, path: Path):
    """The formats and flag bits of a ULog's definitions section, and the offset where its data section starts."""
    pyulog = need("pyulog", "reading PX4 ULog files")
    header = f.read(16)
    if len(header) < 16 or header[:7] != ULOG_MAGIC:
        raise ValueError(f"{path} is not a ULog file (its first bytes are not ULog's magic {ULOG_MAGIC!r})")
    formats, appended, pos = {}, [], 16
    while True:
        head = f.read(3)
        if len(head) < 3:
            raise ValueError(f"{path}: the ULog ends at byte {pos}, inside its definitions section: no data")
        size, typ = struct.unpack("<HB", head)
        if typ in b"ALCD":
            return formats, appended, pos
        body = f.read(size)
        if len(body) < size:
            raise ValueError(f"{path}: the ULog ends at byte {pos + 3 + len(body)}, inside its definitions section")
        if typ == ord("F"):
            try:
                fmt = pyulog.ULog.MessageFormat(body, None)
            except (IndexError, ValueError, UnicodeDecodeError) as exc:
                raise ValueError(f"{path}: an unreadable message format at byte {pos}: {exc}") from None
            formats[fmt.name] = fmt
        elif typ == ord("B") and size >= 40:
            incompat = body[8:16]
            if incompat[0] & 1:  # DATA_APPENDED: data was added at these offsets after the log was closed
                appended = [o for o in struct.unpack("<3Q", body[16:40]) if o]
        elif typ not in b"IMPQ":
            raise ValueError(f"{path}: a message of type {typ} at byte {pos} of the ULog definitions; it is corrupt")
        pos += 3 + size


def scan_ulog(path, wanted, sink) -> tuple[list, list]:
    """Walk a ULog's data section and hand the payloads of the wanted topics to ``sink``, a block at a time.

    Parameters
    ----------
    path : path-like
        The ``.ulg`` file.
    wanted : callable
        ``wanted(name) -> bool`` for each topic name as it is subscribed.
    sink : callable
        ``sink((name, multi_id), records)``: the topic's messages of one block as a numpy structured array, fields
        named as pyulog names them (``gyro_rad[0]``, ``timestamp``).

    Returns
    -------
    topics : list of str
        Every topic of the log (``name`` or ``name:instance``).
    breaks : list of Break
        The stretches that could not be read; ``counts`` holds the messages of each topic read before each.

    Examples
    --------
    >>> from strapdown.io.formats.ulog import scan_ulog
    >>> topics, breaks = scan_ulog("tests/data/px4/sample_log_small.ulg", lambda n: False, None)
    >>> "sensor_combined" in topics, breaks
    (True, [])
    """
    from . import _logs_numba as k

    pyulog = need("pyulog", "reading PX4 ULog files")
    path = Path(path)
    item = np.full(65536, -1, dtype=np.int64)
    top = np.full(65536, -1, dtype=np.int64)
    want = np.full(65536, -1, dtype=np.int64)
    keys, dtypes, counts, topics, breaks = [], [], {}, [], []
    offs, ids = np.empty(BATCH, dtype=np.int64), np.empty(BATCH, dtype=np.int64)
    with open(path, "rb") as f:
        formats, appended, start = _definitions(f, path)
        size = f.seek(0, 2)
        blocks = Blocks(f, start)
        pos = 0

        def deliver(n):
            if not n:
                return
            for j, key in enumerate(keys):
                o = offs[:n][ids[:n] == j]
                if o.size:
                    width = dtypes[j].itemsize
                    rows = blocks.buf[o[:, None] + np.arange(width)]
                    counts[key] = counts.get(key, 0) + o.size
                    sink(key, rows.view(dtypes[j]).ravel())

        while True:
            jump = next((a - blocks.base for a in appended if blocks.base + pos < a < blocks.base + blocks.end), None)
            end = blocks.end if jump is None or jump < pos else jump
            pos, n, status = k.ulog_walk(blocks.buf, pos, end, item, top, want, offs, ids)
            deliver(n)
            if status == k.FULL:
                continue
            if status == k.STOP:
                msg_size, typ = struct.unpack("<HB", blocks.buf[pos : pos + 3].tobytes())
                body = blocks.buf[pos + 3 : pos + 3 + msg_size].tobytes()
                if typ == ord("A"):
                    multi_id, msg_id = struct.unpack("<BH", body[:3])
                    try:
                        sub = pyulog.ULog._MessageAddLogged(body, None, formats)  # the topic's numpy layout
                    except (KeyError, IndexError, ValueError, UnicodeDecodeError):
                        raise ValueError(
                            f"{path}: a subscription at byte {blocks.base + pos} names a topic with no format: "
                            "the ULog is corrupt"
                        ) from None
                    item[msg_id], top[msg_id] = sub.dtype.itemsize, sub.max_data_size
                    name = sub.message_name
                    topics.append(f"{name}:{multi_id}" if multi_id else name)
                    if wanted(name):
                        keys.append((name, multi_id))
                        dtypes.append(sub.dtype)
                        want[msg_id] = len(keys) - 1
                else:  # R: a topic no longer logged
                    (msg_id,) = struct.unpack("<H", body[:2])
                    item[msg_id] = top[msg_id] = want[msg_id] = -1
                pos += 3 + msg_size
                continue
            if status == k.NEED and end != blocks.end:  # an appended-data offset: go on from there
                pos = jump
                continue
            if status == k.NEED:
                if not blocks.eof:
                    pos = blocks.fill(pos)
                    continue
                if pos < blocks.end:
                    where = blocks.base + pos
                    breaks.append(
                        Break(where, None, f"the log is cut inside a message ({size - where} bytes)", dict(counts))
                    )
                break
            # CORRUPT: find the next run of valid messages, reading on as long as none is found
            where = blocks.base + pos
            what = _what(blocks.buf, pos, blocks.end, item, top)
            while True:
                found = k.ulog_resync(blocks.buf, pos, blocks.end, blocks.eof, item, top)
                if found >= 0 or blocks.eof:
                    break
                pos = blocks.fill(max(pos, blocks.end - (1 << 18)))  # the tail may start a valid run
            breaks.append(Break(where, None if found < 0 else blocks.base + found, what, dict(counts)))
            if found < 0:
                break
            pos = found
    return topics, breaks


def _what(buf, pos, end, item, top) -> str:
    """What is wrong with the message header at ``pos``, as a user can look it up."""
    if pos + 3 > end:
        return "a cut message header"
    size, typ = int(buf[pos]) | int(buf[pos + 1]) << 8, int(buf[pos + 2])
    name = chr(typ) if 32 < typ < 127 else str(typ)
    if typ == ord("D") and pos + 5 <= end:
        msg_id = int(buf[pos + 3]) | int(buf[pos + 4]) << 8
        if top[msg_id] < 0:
            return f"a data message for msg_id {msg_id}, which no topic has (size {size})"
        return f"a data message of {size - 2} bytes where msg_id {msg_id}'s have {item[msg_id]}"
    return f"a message of type {name!r} and size {size}, which cannot be"


def _times(records) -> np.ndarray:
    """Sample times, µs since boot: ``timestamp_sample`` (when the sensor sampled) where set, else ``timestamp``."""
    t = records["timestamp"].astype(np.int64)
    if "timestamp_sample" in records.dtype.names:
        sample = records["timestamp_sample"].astype(np.int64)
        t = np.where(sample > 0, sample, t)
    return t


def _vector(records, stem: str) -> np.ndarray:
    keys = [f"{stem}[{i}]" for i in range(3)] if stem else ["x", "y", "z"]
    return np.column_stack([records[k].astype(np.float64) for k in keys])


def _topic_name(key) -> str:
    return f"{key[0]}:{key[1]}" if key[1] else key[0]


class _ImuSpools:
    """The sink of an IMU read: a spool per candidate topic and instance."""

    def __init__(self):
        self.spools: dict[tuple, Spool] = {}

    def __call__(self, key, rec) -> None:
        name = key[0]
        if name == "sensor_combined":
            values = np.concatenate([_vector(rec, "gyro_rad"), _vector(rec, "accelerometer_m_s2")], axis=1)
            if "accelerometer_timestamp_relative" in rec.dtype.names:
                values[rec["accelerometer_timestamp_relative"] == _INVALID_RELATIVE, 3:] = np.nan
            t = rec["timestamp"].astype(np.int64)  # its gyro sample's time
        else:
            values = _vector(rec, "magnetometer_ga" if name == "vehicle_magnetometer" else "")
            t = _times(rec)
        spool = self.spools.get(key)
        if spool is None:
            spool = self.spools[key] = Spool(values.shape[1])
        spool.append(t, values)

    def has(self, spec: str) -> bool:
        name, _, instance = spec.partition(":")
        spool = self.spools.get((name, int(instance or 0)))
        return spool is not None and spool.n > 1

    def take(self, spec: str) -> Spool:
        name, _, instance = spec.partition(":")
        return self.spools.pop((name, int(instance or 0)))

    def close(self) -> None:
        for spool in self.spools.values():
            spool.close()


def _check_topic(spec: str, topics, path: Path) -> None:
    name, _, instance = spec.partition(":")
    if (f"{name}:{instance}" if instance and instance != "0" else name) not in topics:
        raise ValueError(f"{path}: no topic {spec!r} in this log; it has: {', '.join(sorted(set(topics)))}")


def open_ulog(path, topic: str | None = None, mag_topic: str | None = None) -> SpooledSource:
    """A PX4 ULog's IMU readings as a table on the gyro's rows (see the module's description).

    Parameters
    ----------
    path : path-like
        The ``.ulg`` file.
    topic : str, optional
        The gyro topic: ``"sensor_combined"`` (default when logged) or ``"sensor_gyro[:instance]"``.
    mag_topic : str, optional
        ``"vehicle_magnetometer"`` (default when logged) or ``"sensor_mag[:instance]"``; ``"none"``: no
        magnetometer.

    Returns
    -------
    SpooledSource
        Fields ``t`` (s from the first gyro sample) and the topics' columns (``sensor_combined/gyro_rad[0]``),
        frames NED/FRD; ``warnings`` lists the stretches of the log that could not be read.

    Examples
    --------
    >>> from strapdown.io.formats.ulog import open_ulog
    >>> src = open_ulog("tests/data/px4/sample_log_small.ulg")
    >>> src.rows, src.presets["gyro"][0], src.frame, src.body
    (1298, 'sensor_combined/gyro_rad[0]', 'NED', 'FRD')
    """
    path = Path(path)
    if topic is not None and topic.partition(":")[0] not in _GYRO:
        raise ValueError(f"{path}: topic {topic!r} holds no gyro; use sensor_combined or sensor_gyro")
    names = {*_GYRO, *_ACC, *(_MAG if mag_topic != "none" else ())}
    sink = _ImuSpools()
    try:
        topics, breaks = scan_ulog(path, names.__contains__, sink)
        if topic is None:
            topic = "sensor_combined" if sink.has("sensor_combined") else "sensor_gyro"
        _check_topic(topic, topics, path)
        if not sink.has(topic):
            raise ValueError(f"{path}: topic {topic!r} has no samples")
        gyro = sink.take(topic)
        placed, row_fields = {}, {}
        if topic == "sensor_combined":
            row_fields["gyro"] = tuple(f"sensor_combined/gyro_rad[{i}]" for i in range(3))
            row_fields["acc"] = tuple(f"sensor_combined/accelerometer_m_s2[{i}]" for i in range(3))
        else:
            row_fields["gyro"] = tuple(f"sensor_gyro/gyro_{c} [rad/s]" for c in "xyz")
            acc = f"sensor_accel:{topic.partition(':')[2] or '0'}"
            if sink.has(acc):
                placed["acc"] = (sink.take(acc), tuple(f"sensor_accel/acc_{c} [m/s2]" for c in "xyz"))
        if mag_topic != "none":
            if mag_topic is None:
                mag_topic = next((n for n in _MAG if sink.has(n)), None)
            elif mag_topic.partition(":")[0] not in _MAG:
                raise ValueError(f"{path}: mag_topic {mag_topic!r} is no magnetometer; use {' or '.join(_MAG)}")
            else:
                _check_topic(mag_topic, topics, path)
            if mag_topic is not None and sink.has(mag_topic):
                stem = mag_topic.partition(":")[0]
                fields = (
                    tuple(f"vehicle_magnetometer/magnetometer_ga[{i}]" for i in range(3))
                    if stem == "vehicle_magnetometer"
                    else tuple(f"sensor_mag/mag_{c} [gauss]" for c in "xyz")
                )
                placed["mag"] = (sink.take(mag_topic), fields)
        src = SpooledSource(path, "ulog", gyro, row_fields, placed, _PER_S, "boot", _UNITS)
    finally:
        sink.close()
    src.frame, src.body, src.upright = "NED", "FRD", True
    src.topic = topic
    name, _, instance = topic.partition(":")
    key = (name, int(instance or 0))
    src.warnings = describe_breaks(
        path,
        [_counted(b, key) for b in breaks],
        lambda i: int(gyro.times(i, i + 1)[0]) if 0 <= i < gyro.n else None,
        src.period_ticks,
        _PER_S,
        gyro.first,
        f"gyro ({topic})",
    )
    return src


def _counted(b: Break, key) -> Break:
    """A break with the count of the chosen gyro topic under the name describe_breaks looks for."""
    return Break(b.start, b.stop, b.what, {f"gyro ({_topic_name(key)})": b.counts.get(key, 0)})


#: The reader's former name: a class that opened the log whole (now a function that streams it).
UlogSource = open_ulog


class _First:
    """A sink keeping the first sample time and the count of each IMU topic, and every record of those in ``full``."""

    def __init__(self, full):
        self.full, self.first, self.counts, self.parts = set(full), {}, {}, {}

    def __call__(self, key, rec) -> None:
        if key[0] in self.full:
            self.parts.setdefault(key, []).append(rec.copy())
        elif key not in self.first and rec.size:
            self.first[key] = int((rec["timestamp"] if key[0] == "sensor_combined" else _times(rec))[0])
        self.counts[key] = self.counts.get(key, 0) + rec.size


def read_attitude(path, topic: str | None = None):
    """The log's own attitude estimate (``vehicle_attitude``) as times and quaternions.

    Parameters
    ----------
    path : path-like
        The ``.ulg`` file.
    topic : str, optional
        The IMU topic whose first sample is t = 0 (as in :func:`open_ulog`), so that both share a time line.

    Returns
    -------
    t : numpy.ndarray, shape (n,)
        Seconds from the IMU's first sample.
    q : numpy.ndarray, shape (n, 4)
        [w, x, y, z], FRD body to NED.
    origin : TimeOrigin
        The IMU's first sample, µs since boot.

    Examples
    --------
    >>> from strapdown.io.formats.ulog import read_attitude
    >>> read_attitude("no/such/log.ulg")
    Traceback (most recent call last):
    FileNotFoundError: no such file: no/such/log.ulg
    >>> t, q, origin = read_attitude("tests/data/px4/sample_log_small.ulg")
    >>> q.shape, origin.kind
    ((1298, 4), 'boot')
    """
    from ..source import TimeOrigin

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    sink = _First(("vehicle_attitude",))
    topics, _ = scan_ulog(path, {*_GYRO, "vehicle_attitude"}.__contains__, sink)
    if topic is None:
        topic = "sensor_combined" if sink.counts.get(("sensor_combined", 0), 0) > 1 else "sensor_gyro"
    name, _, instance = topic.partition(":")
    t0 = sink.first.get((name, int(instance or 0)))
    if t0 is None:
        raise ValueError(f"{path}: no topic {topic!r} with samples in this log; it has: {', '.join(sorted(topics))}")
    parts = sink.parts.get(("vehicle_attitude", 0))
    if not parts:
        raise ValueError(f"{path}: no vehicle_attitude messages (the log's own estimate); it has: {', '.join(topics)}")
    att = np.concatenate(parts)
    t_us = _times(att)  # timestamp_sample: the IMU sample the attitude is for
    q = np.column_stack([att[f"q[{i}]"].astype(np.float64) for i in range(4)])
    return (t_us - t0) / 1e6, q, TimeOrigin(t0, "us", "boot")


def reference(path, topic: str | None = None) -> dict:
    """The :class:`~strapdown.io.formats.base.Format` ``reference`` hook: ``vehicle_attitude`` (NED, FRD)."""
    t, q, origin = read_attitude(path, topic)
    return {"t": t, "q": q, "frame": "NED", "body": "FRD", "time_origin": origin, "source": "vehicle_attitude"}


def read_position(path) -> dict | None:
    """Where and when the log was made: its first 3D GPS fix (``vehicle_gps_position``, else ``sensor_gps``).

    Parameters
    ----------
    path : path-like
        The ``.ulg`` file.

    Returns
    -------
    dict or None
        ``latitude_deg``, ``longitude_deg``, ``altitude_m`` (above mean sea level), ``date`` (UTC) and ``source``
        (the topic and the fix's time); None when the log has no 3D fix with a UTC time.

    Examples
    --------
    >>> from strapdown.io.formats.ulog import read_position
    >>> fix = read_position("tests/data/px4/sample_log_small.ulg")
    >>> round(fix["latitude_deg"], 4), round(fix["longitude_deg"], 4), str(fix["date"])
    (63.417, 10.4082, '2021-04-21')
    """
    sink = _First(_GPS)
    scan_ulog(Path(path), set(_GPS).__contains__, sink)
    for name in _GPS:
        for rec in sink.parts.get((name, 0), []):
            fields = rec.dtype.names
            lat = rec["lat"] * 1e-7 if "lat" in fields else rec["latitude_deg"].astype(np.float64)
            lon = rec["lon"] * 1e-7 if "lon" in fields else rec["longitude_deg"].astype(np.float64)
            alt = rec["alt"] * 1e-3 if "alt" in fields else rec["altitude_msl_m"].astype(np.float64)
            utc = rec["time_utc_usec"].astype(np.int64)
            fix = first_fix(
                lat,
                lon,
                alt,
                (rec["fix_type"] >= 3) & (utc > 0),
                lambda i, utc=utc: datetime.datetime.fromtimestamp(utc[i] / 1e6, datetime.UTC),
                name,
            )
            if fix is not None:
                return fix
    return None


def _is_ulog(path: Path) -> bool:
    with open(path, "rb") as f:
        return f.read(7) == ULOG_MAGIC


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format(
    "ulog",
    open_ulog,
    suffixes=(".ulg", ".ulog"),
    detect=_is_ulog,
    options=("topic", "mag_topic"),
    description="PX4 ULog (pyulog, read a block at a time)",
    reference=reference,
    position=read_position,
)
