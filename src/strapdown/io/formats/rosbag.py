"""ROS 1 bags (``.bag``) and ROS 2 bags (a folder with ``metadata.yaml``; sqlite3 or mcap) through rosbags.

``sensor_msgs/Imu`` gives the gyro (``angular_velocity``, rad/s) and accelerometer (``linear_acceleration``,
m/s²; left out when ``linear_acceleration_covariance[0]`` is -1, REP 145's "no data"); ``sensor_msgs/MagneticField``
the magnetometer (``magnetic_field``, tesla, read as µT).  Times are the header stamps (``sec`` and ``nanosec``,
integer nanoseconds, usually since the epoch; the bag's receive time when a driver leaves them zero).
``topic=`` chooses the Imu topic and ``mag_topic=`` the MagneticField one; when there are several and none is
chosen the error lists them.  Frames: REP 103 and 145 say body axes FLU (x forward, y left, z up) and an ENU
world, so those are the presets.  rosbags reads both bag versions in pure Python, without a ROS installation.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..._support.deps import need
from .base import Format
from .multi import Stream, merge_streams

__all__ = ["IMU_TYPE", "MAG_TYPE", "open_bag"]

IMU_TYPE = "sensor_msgs/msg/Imu"
MAG_TYPE = "sensor_msgs/msg/MagneticField"


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


def open_bag(path, topic: str | None = None, mag_topic: str | None = None):
    """The Imu (and MagneticField) messages of a ROS 1 or ROS 2 bag as one table on the gyro's rows.

    Parameters
    ----------
    path : path-like
        A ``.bag`` file, a ROS 2 bag folder, or one of its ``.db3``/``.mcap`` files.
    topic : str, optional
        The ``sensor_msgs/Imu`` topic (required when there are several).
    mag_topic : str, optional
        The ``sensor_msgs/MagneticField`` topic (required when there are several; ``"none"``: no magnetometer).

    Returns
    -------
    MemorySource
        Gyro (rad/s), accelerometer (m/s²) and magnetometer (µT) columns named ``topic/field``, ``t`` in s from
        the first Imu stamp, frames ENU/FLU.

    Examples
    --------
    >>> from strapdown.io.formats.rosbag import open_bag
    >>> open_bag("no/such.bag")
    Traceback (most recent call last):
    FileNotFoundError: no such bag: no/such.bag
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no such bag: {path}")
    highlevel = need("rosbags.highlevel", "reading ROS bags")
    typesys = need("rosbags.typesys", "reading ROS bags")
    bag = _bag_path(path)
    with highlevel.AnyReader([bag], default_typestore=typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)) as reader:
        connections = list(reader.connections)
        imu_topic = _choose(connections, IMU_TYPE, topic, "--topic", path, required=True)
        mag = None if mag_topic == "none" else _choose(connections, MAG_TYPE, mag_topic, "--mag-topic", path, False)
        streams = {}
        for kind, chosen, msgtype in (("gyro", imu_topic, IMU_TYPE), ("mag", mag, MAG_TYPE)):
            if chosen is None:
                continue
            conns = [c for c in connections if c.topic == chosen and c.msgtype == msgtype]
            stamps, first, second = [], [], []
            for conn, received, raw in reader.messages(connections=conns):
                msg = reader.deserialize(raw, conn.msgtype)
                stamps.append(_stamp(msg, received))
                if kind == "gyro":
                    w, a = msg.angular_velocity, msg.linear_acceleration
                    first.append((w.x, w.y, w.z))
                    no_acc = float(msg.linear_acceleration_covariance[0]) == -1.0
                    second.append((np.nan,) * 3 if no_acc else (a.x, a.y, a.z))
                else:
                    b = msg.magnetic_field
                    first.append((b.x * 1e6, b.y * 1e6, b.z * 1e6))  # tesla -> µT
            if not stamps:
                raise ValueError(f"{path}: topic {chosen!r} has no messages")
            ns = np.asarray(stamps, dtype=np.int64)
            t0 = int(ns[0])
            rel = (ns - t0).astype(np.float64)
            if kind == "gyro":
                fields = tuple(f"{chosen}/angular_velocity.{c}" for c in "xyz")
                streams["gyro"] = Stream(
                    path, "gyro", fields, "rad/s", "header.stamp", rel, t0, True, np.array(first), True
                )
                acc = np.array(second)
                if not np.isnan(acc).all():
                    fields = tuple(f"{chosen}/linear_acceleration.{c}" for c in "xyz")
                    streams["acc"] = Stream(path, "acc", fields, "m/s2", "header.stamp", rel, t0, True, acc, True)
            else:
                fields = tuple(f"{chosen}/magnetic_field.{c}" for c in "xyz")
                streams["mag"] = Stream(path, "mag", fields, "uT", "header.stamp", rel, t0, True, np.array(first), True)
    src = merge_streams(path, streams, "rosbag", time_unit="ns")
    src.frame, src.body = "ENU", "FLU"
    src.topic = imu_topic
    return src


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
    description="ROS 1 / ROS 2 bag (rosbags)",
)
