"""ROS 1 bags (``.bag``), ROS 2 bags (a folder with ``metadata.yaml``; sqlite3 or mcap) and standalone ``.mcap`` files.

``sensor_msgs/Imu`` gives the gyro (``angular_velocity``, rad/s) and accelerometer (``linear_acceleration``,
m/s²; left out when ``linear_acceleration_covariance[0]`` is -1, REP 145's "no data"); ``sensor_msgs/MagneticField``
the magnetometer (``magnetic_field``, tesla, read as µT).  Times are the header stamps (``sec`` and ``nanosec``,
integer nanoseconds, usually since the epoch; the bag's receive time when a driver leaves them zero).
``topic=`` chooses the Imu topic and ``mag_topic=`` the MagneticField one; when there are several and none is
chosen the error lists them.  Frames: REP 103 and 145 say body axes FLU (x forward, y left, z up) and an ENU
world, so those are the presets.  rosbags reads both bag versions and standalone MCAP files (Foxglove's,
``ros2 bag record -s mcap``'s) in pure Python, without a ROS installation, one message at a time; the samples are
spooled (:mod:`._spool`), so a bag larger than memory is read in bounded memory.  The Imu ``orientation`` (when
its covariance is not -1) is the ``reference`` hook, the first ``NavSatFix`` with a fix the ``position`` hook.
"""

from __future__ import annotations

import contextlib
import datetime
import struct
from pathlib import Path

import numpy as np

from ..._support.deps import need
from ._gps import first_fix
from ._mcap import mcap_break
from ._spool import Spool, SpooledSource
from .base import Format

__all__ = ["FIX_TYPE", "IMU_TYPE", "MAG_TYPE", "open_bag", "read_attitude", "read_position"]

IMU_TYPE = "sensor_msgs/msg/Imu"
MAG_TYPE = "sensor_msgs/msg/MagneticField"
FIX_TYPE = "sensor_msgs/msg/NavSatFix"
_UNITS = {"gyro": "rad/s", "acc": "m/s2", "mag": "uT"}
_BATCH = 1 << 14  # messages decoded into Python tuples before they go to the spool


def _bag_path(path: Path) -> Path:
    """The path rosbags opens: a ROS 2 bag's folder when given one of its storage files."""
    if path.is_file() and path.suffix.lower() in (".db3", ".mcap") and (path.parent / "metadata.yaml").is_file():
        return path.parent
    return path


def _choose(connections, msgtype: str, topic: str | None, option: str, path: Path, required: bool):
    topics = sorted({c.topic for c in connections if c.msgtype == msgtype})
    if topic is not None:
        if topic not in topics:
            listing = ", ".join(topics) or "none"
            raise ValueError(f"{path}: no {msgtype} topic {topic!r}; its {msgtype} topics: {listing}")
        return topic
    if len(topics) == 1:
        return topics[0]
    if len(topics) > 1:
        raise ValueError(f"{path}: several {msgtype} topics: {', '.join(topics)}; choose one with {option}")
    if required:
        every = ", ".join(f"{c.topic} ({c.msgtype})" for c in connections) or "no topics"
        raise ValueError(f"{path}: no {msgtype} messages; it has: {every}")
    return None


def _stamp(msg, received: int) -> int:
    stamp = msg.header.stamp
    ns = int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)
    return ns if ns else int(received)


@contextlib.contextmanager
def _reader(path: Path):
    """Rosbags' AnyReader on a bag (a ROS 2 bag's folder for one of its files; a standalone .mcap or .db3 as is)."""
    if not path.exists():
        raise FileNotFoundError(f"no such bag: {path}")
    highlevel = need("rosbags.highlevel", "reading ROS bags")
    typesys = need("rosbags.typesys", "reading ROS bags")
    reader = highlevel.AnyReader([_bag_path(path)], default_typestore=typesys.get_typestore(typesys.Stores.ROS2_HUMBLE))
    try:
        reader.open()
    except Exception:
        broken = _mcap_breaks(path, chunks=False)
        if broken:  # rosbags says "File end magic is invalid": where the file breaks is ours to find
            raise ValueError(f"{path}: {broken}") from None
        raise
    try:
        yield reader
    finally:
        reader.close()


def _mcap_breaks(path: Path, chunks: bool) -> str:
    """Where the MCAP files of a bag break (:func:`._mcap.mcap_break`), each named when a folder has several."""
    found = [(m, what) for m in _mcap_files(path) if (what := mcap_break(m, chunks=chunks))]
    return "; ".join(what if m == path else f"{m.name}: {what}" for m, what in found)


def _mcap_files(path: Path) -> list[Path]:
    """The MCAP storage files of a bag: the file itself, or those of a ROS 2 bag's folder."""
    folder = _bag_path(path)
    if folder.is_dir():
        return sorted(folder.glob("*.mcap"))
    return [path] if path.suffix.lower() == ".mcap" else []


def _messages(reader, connections, topic: str, msgtype: str, path: Path, short: list | None = None):
    """The deserialised messages of one topic with their receive times, naming the file when one cannot be read.

    A bag's index counts each topic's messages (ROS 1's connection records, ROS 2's metadata, MCAP's statistics);
    when fewer can be read (a damaged MCAP chunk ends the reading early, without an error), ``(topic, read,
    counted, seconds from the first to the last receive time)`` is appended to ``short``.
    """
    conns = [c for c in connections if c.topic == topic and c.msgtype == msgtype]
    count, first, last = 0, None, None
    try:
        for conn, received, raw in reader.messages(connections=conns):
            count += 1
            first, last = received if first is None else first, received
            yield reader.deserialize(raw, conn.msgtype), received
        counted = sum(int(getattr(c, "msgcount", 0) or 0) for c in conns)
        if short is not None and count < counted:
            short.append((topic, count, counted, 0.0 if first is None else (last - first) / 1e9))
    except (ValueError, OSError, KeyError, IndexError, struct.error) as exc:
        raise ValueError(f"{path}: message {count + 1} of {topic} cannot be read ({exc}): the bag is corrupt") from None
    except Exception as exc:  # rosbags' own errors (ReaderError, deserialisation errors) name no file
        if type(exc).__module__.startswith("rosbags"):
            raise ValueError(
                f"{path}: message {count + 1} of {topic} cannot be read ({exc}): the bag is corrupt"
            ) from None
        raise


def _spooled(path: Path, stream, width: int, decode) -> Spool:
    """Messages into a spool, :data:`_BATCH` at a time: ``decode(msg)`` gives a sample's values."""
    spool, stamps, values = Spool(width), [], []
    for msg, received in stream:
        stamps.append(_stamp(msg, received))
        values.append(decode(msg))
        if len(stamps) == _BATCH:
            spool.append(np.array(stamps, dtype=np.int64), np.array(values, dtype=np.float64))
            stamps, values = [], []
    spool.append(np.array(stamps, dtype=np.int64), np.array(values, dtype=np.float64).reshape(-1, width))
    return spool


def _imu_values(msg):
    w, a = msg.angular_velocity, msg.linear_acceleration
    if float(msg.linear_acceleration_covariance[0]) == -1.0:  # REP 145: no accelerometer data
        return (w.x, w.y, w.z, np.nan, np.nan, np.nan)
    return (w.x, w.y, w.z, a.x, a.y, a.z)


def _mag_values(msg):
    b = msg.magnetic_field
    return (b.x * 1e6, b.y * 1e6, b.z * 1e6)  # tesla -> µT


def open_bag(path, topic: str | None = None, mag_topic: str | None = None):
    """The Imu (and MagneticField) messages of a ROS 1 or ROS 2 bag as one table on the gyro's rows.

    Parameters
    ----------
    path : path-like
        A ``.bag`` file, a ROS 2 bag folder, one of its ``.db3``/``.mcap`` files, or a standalone ``.mcap``
        file (as Foxglove and ``ros2 bag record -s mcap`` write them).
    topic : str, optional
        The ``sensor_msgs/Imu`` topic (required when there are several).
    mag_topic : str, optional
        The ``sensor_msgs/MagneticField`` topic (required when there are several; ``"none"``: no magnetometer).

    Returns
    -------
    SpooledSource
        Gyro (rad/s), accelerometer (m/s²) and magnetometer (µT) columns named ``topic/field``, ``t`` in s from
        the first Imu stamp, frames ENU/FLU; the messages are read one by one and spooled, never held whole.

    Examples
    --------
    >>> from strapdown.io.formats.rosbag import open_bag
    >>> open_bag("no/such.bag")
    Traceback (most recent call last):
    FileNotFoundError: no such bag: no/such.bag
    """
    path = Path(path)
    with _reader(path) as reader:
        connections = list(reader.connections)
        imu_topic = _choose(connections, IMU_TYPE, topic, "--topic", path, required=True)
        mag = None if mag_topic == "none" else _choose(connections, MAG_TYPE, mag_topic, "--mag-topic", path, False)
        short = []  # topics of which fewer messages could be read than the bag's index counts
        rows = _spooled(path, _messages(reader, connections, imu_topic, IMU_TYPE, path, short), 6, _imu_values)
        placed = {}
        try:
            if rows.n == 0:
                raise ValueError(f"{path}: topic {imu_topic!r} has no messages")
            if mag is not None:
                spool = _spooled(path, _messages(reader, connections, mag, MAG_TYPE, path, short), 3, _mag_values)
                if spool.n == 0:
                    raise ValueError(f"{path}: topic {mag!r} has no messages")
                placed["mag"] = (spool, tuple(f"{mag}/magnetic_field.{c}" for c in "xyz"))
            fields = {"gyro": tuple(f"{imu_topic}/angular_velocity.{c}" for c in "xyz")}
            if rows.finite[3]:  # else REP 145's "no accelerometer" on every message: no acc columns at all
                fields["acc"] = tuple(f"{imu_topic}/linear_acceleration.{c}" for c in "xyz")
            src = SpooledSource(path, "rosbag", rows, fields, placed, 1_000_000_000, "epoch", _UNITS)
        except BaseException:
            rows.close()
            for spool, _ in placed.values():
                spool.close()
            raise
    src.frame, src.body = "ENU", "FLU"
    src.topic = imu_topic
    where = _mcap_breaks(path, chunks=True) if short else ""
    src.warnings = [
        f"{path}: {topic}: {got} of the {counted} messages its index counts could be read, {counted - got} lost "
        f"after {span:.6g} s of the topic (receive time): the bag is damaged or cut there"
        + (f"; {where}" if where else "")
        for topic, got, counted, span in short
    ]
    return src


def read_attitude(path, topic: str | None = None):
    """The orientation of a bag's Imu messages (a driver's own estimate, REP 145), as times and quaternions.

    Parameters
    ----------
    path : path-like
        The bag.
    topic : str, optional
        The Imu topic (required when there are several).

    Returns
    -------
    t : numpy.ndarray, shape (n,)
        Seconds from the topic's first stamp (the IMU's t = 0).
    q : numpy.ndarray, shape (n, 4)
        [w, x, y, z], the FLU body to the world frame (ENU by REP 103).
    origin : TimeOrigin
        The first stamp, ns since the epoch.

    Examples
    --------
    >>> from strapdown.io.formats.rosbag import read_attitude
    >>> read_attitude("no/such.bag")
    Traceback (most recent call last):
    FileNotFoundError: no such bag: no/such.bag
    """
    from ..source import TimeOrigin

    path = Path(path)
    with _reader(path) as reader:
        connections = list(reader.connections)
        chosen = _choose(connections, IMU_TYPE, topic, "--topic", path, required=True)

        def decode(msg):
            o = msg.orientation
            none = float(msg.orientation_covariance[0]) == -1.0  # REP 145: no orientation estimate
            return (np.nan,) * 4 if none else (o.w, o.x, o.y, o.z)

        spool = _spooled(path, _messages(reader, connections, chosen, IMU_TYPE, path), 4, decode)
    try:
        block = spool.read(0, spool.n)
    finally:
        spool.close()
    q, ns = block["v"], block["t"]
    keep = np.isfinite(q).all(axis=1) & (np.linalg.norm(q, axis=1) > 0.5)
    if not keep.any():
        raise ValueError(f"{path}: the Imu messages of {chosen} carry no orientation (covariance[0] = -1 or q = 0)")
    t0 = int(ns[0])
    return (ns[keep] - t0) / 1e9, q[keep], TimeOrigin(t0, "ns", "epoch")


def reference(path, topic: str | None = None) -> dict:
    """The :class:`~strapdown.io.formats.base.Format` ``reference`` hook: the Imu ``orientation`` (ENU, FLU)."""
    t, q, origin = read_attitude(path, topic)
    return {"t": t, "q": q, "frame": "ENU", "body": "FLU", "time_origin": origin, "source": "Imu orientation"}


def read_position(path) -> dict | None:
    """Where and when the bag was recorded: its first ``sensor_msgs/NavSatFix`` with a fix.

    Parameters
    ----------
    path : path-like
        The bag.

    Returns
    -------
    dict or None
        ``latitude_deg``, ``longitude_deg``, ``altitude_m`` (above the WGS 84 ellipsoid, as NavSatFix has it),
        ``date`` (UTC, from the header stamp) and ``source``; None when the bag has no fix or its stamps are no
        dates (simulated time).

    Examples
    --------
    >>> from strapdown.io.formats.rosbag import read_position
    >>> read_position("no/such.bag")
    Traceback (most recent call last):
    FileNotFoundError: no such bag: no/such.bag
    """
    path = Path(path)
    with _reader(path) as reader:
        connections = list(reader.connections)
        for topic in sorted({c.topic for c in connections if c.msgtype == FIX_TYPE}):
            fixes = [
                (msg.latitude, msg.longitude, msg.altitude, msg.status.status >= 0, _stamp(msg, received))
                for msg, received in _messages(reader, connections, topic, FIX_TYPE, path)
            ]
            if not fixes:
                continue
            lat, lon, alt, good, ns = (np.array(c) for c in zip(*fixes, strict=True))
            fix = first_fix(lat, lon, alt, good, lambda i, ns=ns: _utc(int(ns[i])), topic, "first fix")
            if fix is not None:
                return fix
    return None


def _utc(ns: int):
    """The UTC time of a stamp, None before 1990 (simulated time: no date)."""
    return None if ns < 631_152_000 * 10**9 else datetime.datetime.fromtimestamp(ns / 1e9, datetime.UTC)


def _is_bag(path: Path) -> bool:
    if path.is_dir():
        return (path / "metadata.yaml").is_file()
    with open(path, "rb") as f:
        return f.read(13) == b"#ROSBAG V2.0\n"


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format(
    "rosbag",
    open_bag,
    suffixes=(".bag", ".db3", ".mcap"),
    detect=_is_bag,
    options=("topic", "mag_topic"),
    description="ROS 1 / ROS 2 bag, standalone MCAP (rosbags)",
    reference=reference,
    position=read_position,
)
