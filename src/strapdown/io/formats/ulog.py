"""PX4 flight logs (ULog, ``.ulg``) through pyulog: the IMU topics at their own rates, and the log's attitude.

* Gyro and accelerometer: ``sensor_combined`` (``gyro_rad`` in rad/s, ``accelerometer_m_s2`` in m/s², the
  accelerometer sample at ``timestamp + accelerometer_timestamp_relative``, kept on its row) when the log has it,
  else ``sensor_gyro`` and ``sensor_accel`` (``x, y, z``), each at its own rate; ``topic=`` chooses
  (``"sensor_gyro"``, or ``"sensor_gyro:1"`` for the second instance).
* Magnetometer: ``vehicle_magnetometer`` (``magnetometer_ga``, gauss) else ``sensor_mag`` (gauss), on the gyro's
  rows (:mod:`strapdown.io.merge`); ``mag_topic=`` chooses.
* Time: microseconds since boot, ``timestamp_sample`` (the raw sample's time) where a topic has it, else
  ``timestamp``; t counts from the first gyro sample, and the origin (:class:`~strapdown.io.source.TimeOrigin`,
  kind ``"boot"``) is kept.
* Frames: PX4 sensor data are in body axes FRD, and ``vehicle_attitude.q`` is the "quaternion rotation from the
  FRD body frame to the NED earth frame", Hamilton convention, order (w, x, y, z) (PX4 uORB ``VehicleAttitude.msg``):
  strapdown's own convention, so the preset is reference NED, body FRD, and :func:`read_attitude` takes ``q`` as
  it is.  ``tests/io/test_io_formats.py`` checks it physically: at rest the log's tilt and the estimator's agree
  within 0.1°, where a conjugated quaternion would mirror the tilt.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..._support.deps import need
from ..merge import place_on_rows
from ..source import MemorySource, TimeOrigin
from .base import Format

__all__ = ["ULOG_MAGIC", "UlogSource", "read_attitude"]

#: The first bytes of every ULog file.
ULOG_MAGIC = b"ULog\x01\x12\x35"
_IMU_TOPICS = ("sensor_combined", "sensor_gyro", "sensor_accel", "sensor_mag", "vehicle_magnetometer")
_INVALID_RELATIVE = 2147483647  # sensor_combined: RELATIVE_TIMESTAMP_INVALID, no accelerometer sample


def _topic(ulog, spec: str, path: Path):
    """The dataset named ``"name"`` or ``"name:instance"``; a ValueError listing the log's topics if absent."""
    name, _, instance = spec.partition(":")
    for d in ulog.data_list:
        if d.name == name and d.multi_id == int(instance or 0):
            return d
    have = sorted({f"{d.name}:{d.multi_id}" if d.multi_id else d.name for d in ulog.data_list})
    raise ValueError(f"{path}: no topic {spec!r} in this log; it has: {', '.join(have)}")


def _has(ulog, name: str) -> bool:
    return any(d.name == name and len(d.data["timestamp"]) > 1 for d in ulog.data_list)


def _load(path: Path, names):
    pyulog = need("pyulog", "reading PX4 ULog files")
    try:
        return pyulog.ULog(str(path), message_name_filter_list=list(names))
    except Exception as exc:  # pyulog raises bare Exceptions for a bad header
        raise ValueError(f"{path} is not a readable ULog file: {exc}") from None


def _times(d) -> np.ndarray:
    """A topic's sample times, µs since boot.

    ``timestamp_sample`` (when the sensor sampled) where the log has it, else ``timestamp`` (when the message was
    published; sensor_combined's is its gyro sample's).
    """
    stamp = d.data.get("timestamp_sample")
    if stamp is not None and d.name != "sensor_combined" and np.all(stamp > 0):
        return np.asarray(stamp, dtype=np.int64)
    return np.asarray(d.data["timestamp"], dtype=np.int64)


def _vector(d, stem: str) -> np.ndarray:
    keys = [f"{stem}[{i}]" for i in range(3)] if stem else ["x", "y", "z"]
    return np.column_stack([np.asarray(d.data[k], dtype=np.float64) for k in keys])


class UlogSource(MemorySource):
    """A PX4 ULog's IMU readings as a table on the gyro's rows (see the module's description).

    Parameters
    ----------
    path : pathlib.Path
        The ``.ulg`` file.
    topic : str, optional
        The gyro topic: ``"sensor_combined"`` (default when logged) or ``"sensor_gyro[:instance]"``.
    mag_topic : str, optional
        ``"vehicle_magnetometer"`` (default when logged) or ``"sensor_mag[:instance]"``; ``"none"``: no
        magnetometer.
    """

    def __init__(self, path: Path, topic: str | None = None, mag_topic: str | None = None):
        ulog = _load(path, _IMU_TOPICS)
        if topic is None:
            topic = "sensor_combined" if _has(ulog, "sensor_combined") else "sensor_gyro"
        gyro = _topic(ulog, topic, path)
        t_us = _times(gyro)
        if t_us.size == 0:
            raise ValueError(f"{path}: topic {topic!r} has no samples")
        cols: dict[str, np.ndarray] = {}
        if gyro.name == "sensor_combined":
            g = _vector(gyro, "gyro_rad")
            a = _vector(gyro, "accelerometer_m_s2")
            rel = np.asarray(gyro.data.get("accelerometer_timestamp_relative", np.zeros(len(t_us))))
            a[rel == _INVALID_RELATIVE] = np.nan
            prefix_g = prefix_a = "sensor_combined/"
            names_g = [f"gyro_rad[{i}]" for i in range(3)]
            names_a = [f"accelerometer_m_s2[{i}]" for i in range(3)]
        elif gyro.name == "sensor_gyro":
            g = _vector(gyro, "")
            instance = topic.partition(":")[2] or "0"
            acc = _topic(ulog, f"sensor_accel:{instance}", path) if _has(ulog, "sensor_accel") else None
            a = None if acc is None else place_on_rows(t_us, _times(acc), _vector(acc, ""))
            prefix_g, prefix_a = "sensor_gyro/gyro_", "sensor_accel/acc_"
            names_g = [f"{c} [rad/s]" for c in "xyz"]
            names_a = [f"{c} [m/s2]" for c in "xyz"]
        else:
            raise ValueError(f"{path}: topic {topic!r} holds no gyro; use sensor_combined or sensor_gyro")
        cols["t"] = (t_us - t_us[0]) / 1e6
        for i in range(3):
            cols[prefix_g + names_g[i]] = g[:, i]
        if a is not None:
            for i in range(3):
                cols[prefix_a + names_a[i]] = a[:, i]
        mag = self._mag(ulog, path, mag_topic)
        if mag is not None:
            d, stem = mag
            m = place_on_rows(t_us, _times(d), _vector(d, stem))
            mag_names = (
                [f"{d.name}/magnetometer_ga[{i}]" for i in range(3)]
                if stem
                else [f"{d.name}/mag_{c} [gauss]" for c in "xyz"]
            )
            for i in range(3):
                cols[mag_names[i]] = m[:, i]
        super().__init__(path, cols, "ulog")
        # a slower sensor on the gyro's rows, or sensor_combined rows without an accelerometer sample
        self.sparse = {n for n, v in cols.items() if n != "t" and np.isnan(v).any()}
        self.frame, self.body, self.upright = "NED", "FRD", True
        self.time_origin = TimeOrigin(int(t_us[0]), "us", "boot")
        self.topic = topic

    @staticmethod
    def _mag(ulog, path, mag_topic):
        if mag_topic == "none":
            return None
        if mag_topic is None:
            mag_topic = next((n for n in ("vehicle_magnetometer", "sensor_mag") if _has(ulog, n)), None)
            if mag_topic is None:
                return None
        d = _topic(ulog, mag_topic, path)
        return d, ("magnetometer_ga" if d.name == "vehicle_magnetometer" else "")


def read_attitude(path, topic: str | None = None):
    """The log's own attitude estimate (``vehicle_attitude``) as times and quaternions.

    Parameters
    ----------
    path : path-like
        The ``.ulg`` file.
    topic : str, optional
        The IMU topic whose first sample is t = 0 (as in :class:`UlogSource`), so that both share a time line.

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
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    ulog = _load(path, ("vehicle_attitude", "sensor_combined", "sensor_gyro"))
    if topic is None:
        topic = "sensor_combined" if _has(ulog, "sensor_combined") else "sensor_gyro"
    t0 = int(_times(_topic(ulog, topic, path))[0])
    att = _topic(ulog, "vehicle_attitude", path)
    t_us = _times(att)  # timestamp_sample: the IMU sample the attitude is for
    q = np.column_stack([np.asarray(att.data[f"q[{i}]"], dtype=np.float64) for i in range(4)])
    return (t_us - t0) / 1e6, q, TimeOrigin(t0, "us", "boot")


def _is_ulog(path: Path) -> bool:
    with open(path, "rb") as f:
        return f.read(7) == ULOG_MAGIC


def _open(path, topic=None, mag_topic=None):
    return UlogSource(Path(path), topic=topic, mag_topic=mag_topic)


def _reference(path, topic=None) -> dict:
    t, q, origin = read_attitude(path, topic)
    return {"t": t, "q": q, "frame": "NED", "body": "FRD", "time_origin": origin, "source": "vehicle_attitude"}


def _position(path):
    from ..position import ulog_position

    return ulog_position(path)


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format(
    "ulog",
    _open,
    suffixes=(".ulg", ".ulog"),
    detect=_is_ulog,
    options=("topic", "mag_topic"),
    description="PX4 ULog (pyulog)",
    reference=_reference,
    position=_position,
)
