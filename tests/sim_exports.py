"""Recordings written in the field's layouts from simulated motion (strapdown.simulate), for the format tests.

Nothing here is a real recording: each writer puts simulated readings into a tool's exact layout (header, units,
time base, file names) as its documentation describes it, so a test knows the truth behind every file.
"""

from pathlib import Path

import numpy as np

from strapdown.simulate import ConstantRotation, ImuModel, sample

EPOCH_NS = 1_718_030_736_872_695_300  # a Sensor Logger-like epoch in ns (2024-06-10)


def phone_at_rest(rate_hz=100.0, duration=20.0, seed=1, body="RFU"):
    """A phone lying flat on a table (screen up, top to the North), consumer-grade sensors, ENU world."""
    return sample(
        ConstantRotation([0.0, 0.0, 0.0], duration=duration),
        rate_hz,
        gyro="rate",
        imu=ImuModel.consumer_mems(),
        reference="ENU",
        body=body,
        seed=seed,
    )


def _write(path: Path, header: str, rows) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        f.write(header + "\n")
        for r in rows:
            f.write(",".join(r) + "\n")
    return path


def sensor_logger(
    folder: Path, data, *, total=True, gravity_file=False, rate_div=(1, 1, 2), jitter_ns=(0, 1_234_567, 3_456_789)
):
    """An Android Sensor Logger export: time (epoch ns), seconds_elapsed, z, y, x per sensor file.

    The accelerometer and magnetometer are sampled at their own instants (offset from the gyro's) and the
    magnetometer at half the rate, as phones do; ``total=False`` writes only the gravity-free Accelerometer.csv.
    """
    t_ns = np.round(data.t[:-1] * 1e9).astype(np.int64)
    gravity = np.tile(data.acc.mean(axis=0), (len(t_ns), 1))
    files = {"Gyroscope.csv": (data.gyro, 0), "Magnetometer.csv": (data.mag, 2)}
    if total:
        files["TotalAcceleration.csv"] = (data.acc, 1)
    files["Accelerometer.csv"] = (data.acc - gravity, 1)  # user acceleration: gravity removed
    if gravity_file:
        files["Gravity.csv"] = (gravity, 1)  # iOS: gravity apart, at the accelerometer's instants
    for name, (values, k) in files.items():
        step = rate_div[k]
        ns = EPOCH_NS + t_ns[::step] + jitter_ns[k]
        v = values[::step]
        rows = (
            (str(int(a)), repr((int(a) - EPOCH_NS) / 1e9), repr(float(z)), repr(float(y)), repr(float(x)))
            for a, (x, y, z) in zip(ns, v, strict=True)
        )
        _write(folder / name, "time,seconds_elapsed,z,y,x", rows)
    return folder


def phyphox(folder: Path, data, *, linear_only=False, semicolon=False, start_epoch=None, location=None):
    """A phyphox multi-sensor export: "Time (s)" from the start and the sensor's columns, quoted headers.

    ``start_epoch`` also writes ``meta/time.csv`` with the START event's system time (epoch s); ``location``
    (latitude, longitude in degrees, height in m) a ``Location.csv`` at 1 Hz in the layout of phyphox's "Location
    (GPS)" sensor, its first fix 1.5 s after the start (a receiver takes a moment) and a few metres of noise.
    """
    sep = ";" if semicolon else ","
    if location is not None:
        names = ("Time (s)", "Latitude (°)", "Longitude (°)", "Height (m)", "Velocity (m/s)", "Direction (°)",
                 "Horizontal Accuracy (m)", "Vertical Accuracy (m)")  # fmt: skip
        rng = np.random.default_rng(5)
        lines = [sep.join(f'"{n}"' for n in names)]
        for ti in np.arange(1.5, data.t[-1], 1.0):
            lat, lon = location[0] + 2e-5 * rng.standard_normal(), location[1] + 2e-5 * rng.standard_normal()
            cells = [f"{ti:.9E}", f"{lat:.9E}", f"{lon:.9E}", f"{location[2] + rng.normal():.9E}", "0.0E0", "0.0E0"]
            cells = [c.replace(".", ",") if semicolon else c for c in [*cells, "4.0E0", "6.0E0"]]
            lines.append(sep.join(cells))
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "Location.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    if start_epoch is not None:
        meta = folder / "meta"
        meta.mkdir(parents=True, exist_ok=True)
        (meta / "time.csv").write_text(
            '"event","experiment time","system time","system time text"\n'
            f'"START",0.000000000E0,{start_epoch:.3f},"2024-06-10 14:45:36.500 UTC+00:00"\n'
        )
    t = data.t[:-1]
    gravity = data.acc.mean(axis=0)
    specs = {
        "Gyroscope.csv": ("Gyroscope {} (rad/s)", "Absolute (rad/s)", data.gyro, 0.0),
        "Magnetometer.csv": ("Magnetic field {} (µT)", "Absolute field (µT)", data.mag, 0.0031),
        "Linear Accelerometer.csv": (
            "Linear Acceleration {} (m/s^2)",
            "Absolute acceleration (m/s^2)",
            data.acc - gravity,
            0.0017,
        ),
    }
    if not linear_only:
        specs["Accelerometer.csv"] = ("Acceleration {} (m/s^2)", "Absolute acceleration (m/s^2)", data.acc, 0.0017)
    for name, (pattern, absolute, values, offset) in specs.items():
        header = sep.join(f'"{h}"' for h in ["Time (s)", *(pattern.format(c) for c in "xyz"), absolute])
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "w", encoding="utf-8") as f:
            f.write(header + "\n")
            for ti, v in zip(t + offset, values, strict=True):
                cells = [f"{ti:.9E}", *(f"{x:.9E}" for x in v), f"{np.linalg.norm(v):.9E}"]
                if semicolon:
                    cells = [c.replace(".", ",") for c in cells]
                f.write(sep.join(cells) + "\n")
    return folder


def euroc(folder: Path, data, t0_ns=1_403_636_579_758_555_392):
    """An ASL/EuRoC mav0/imu0/data.csv: #timestamp [ns], w_RS_S_[xyz] [rad s^-1], a_RS_S_[xyz] [m s^-2]."""
    header = "#timestamp [ns]," + ",".join(f"w_RS_S_{c} [rad s^-1]" for c in "xyz") + ","
    header += ",".join(f"a_RS_S_{c} [m s^-2]" for c in "xyz")
    ns = t0_ns + np.round(data.t[:-1] * 1e9).astype(np.int64)
    rows = (
        (str(int(a)), *(repr(float(x)) for x in w), *(repr(float(x)) for x in f))
        for a, w, f in zip(ns, data.gyro, data.acc, strict=True)
    )
    return _write(folder / "mav0" / "imu0" / "data.csv", header, rows)


def rosbag(
    path: Path,
    data,
    *,
    version=2,
    imu_topics=("/imu/data",),
    mag_topic="/imu/mag",
    t0_ns=EPOCH_NS,
    storage="sqlite3",
    orientation=False,
    fix=None,
):
    """A ROS bag (rosbags' own writer) with sensor_msgs/Imu on ``imu_topics`` and MagneticField (tesla).

    ``storage="mcap"``: a ROS 2 bag folder whose storage is MCAP (``ros2 bag record -s mcap``); its one ``.mcap``
    file alone is what Foxglove and ``ros2 bag record`` leave as a standalone MCAP.  ``orientation=True``: the
    Imu messages carry the true attitude as a driver's own estimate (else covariance[0] = -1, REP 145's "none");
    ``fix=(lat, lon, alt)``: a ``sensor_msgs/NavSatFix`` on ``/gps/fix`` at 1 Hz (status 0: a fix).
    """
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if version == 2 else Stores.ROS1_NOETIC)
    T = store.types
    Imu, Mag = T["sensor_msgs/msg/Imu"], T["sensor_msgs/msg/MagneticField"]
    Header, Time = T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"]
    Vector3, Quaternion = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    Fix, FixStatus = T["sensor_msgs/msg/NavSatFix"], T["sensor_msgs/msg/NavSatStatus"]

    def header(ns):
        stamp = Time(sec=int(ns // 1_000_000_000), nanosec=int(ns % 1_000_000_000))
        return Header(stamp=stamp, frame_id="imu") if version == 2 else Header(seq=0, stamp=stamp, frame_id="imu")

    ns = t0_ns + np.round(data.t[:-1] * 1e9).astype(np.int64)
    if version == 2:
        from rosbags.rosbag2 import StoragePlugin, Writer

        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        writer, serialize = Writer(path, version=9, storage_plugin=plugin), store.serialize_cdr
    else:
        from rosbags.rosbag1 import Writer

        writer, serialize = Writer(path), store.serialize_ros1
    writer.open()
    try:
        zeros = np.zeros(9)
        imus = [writer.add_connection(tp, Imu.__msgtype__, typestore=store) for tp in imu_topics]
        mag = writer.add_connection(mag_topic, Mag.__msgtype__, typestore=store) if mag_topic else None
        gps = writer.add_connection("/gps/fix", Fix.__msgtype__, typestore=store) if fix else None
        for k, stamp in enumerate(ns):
            w, f, m = data.gyro[k], data.acc[k], data.mag[k]
            q = data.q_true[k] if orientation else (1.0, 0.0, 0.0, 0.0)
            msg = Imu(
                header=header(stamp),
                orientation=Quaternion(x=q[1], y=q[2], z=q[3], w=q[0]),
                orientation_covariance=zeros if orientation else np.full(9, -1.0),
                angular_velocity=Vector3(x=w[0], y=w[1], z=w[2]),
                angular_velocity_covariance=zeros,
                linear_acceleration=Vector3(x=f[0], y=f[1], z=f[2]),
                linear_acceleration_covariance=zeros,
            )
            for conn in imus:
                writer.write(conn, int(stamp), serialize(msg, Imu.__msgtype__))
            if mag is not None and k % 2 == 0:  # the magnetometer at half the rate
                b = m * 1e-6  # µT -> T (sensor_msgs/MagneticField is in tesla)
                field = Mag(
                    header=header(stamp + 1_000_000),
                    magnetic_field=Vector3(x=b[0], y=b[1], z=b[2]),
                    magnetic_field_covariance=zeros,
                )
                writer.write(mag, int(stamp + 1_000_000), serialize(field, Mag.__msgtype__))
            if gps is not None and k % max(round(data.rate_hz), 1) == 0:
                status = FixStatus(status=0, service=1)
                point = Fix(header=header(stamp), status=status, latitude=fix[0], longitude=fix[1], altitude=fix[2],
                            position_covariance=zeros, position_covariance_type=0)  # fmt: skip
                writer.write(gps, int(stamp), serialize(point, Fix.__msgtype__))
    finally:
        writer.close()
    return path


# ArduPilot's message layouts (libraries/AP_Logger/LogStructure.h): name -> (type, format, columns)
DATAFLASH_LAYOUTS = {
    "FMT": (128, "BBnNZ", "Type,Length,Name,Format,Columns"),
    "PARM": (64, "QNff", "TimeUS,Name,Value,Default"),
    "MSG": (65, "QZ", "TimeUS,Message"),
    "IMU": (66, "QBffffffIIfBBHH", "TimeUS,I,GyrX,GyrY,GyrZ,AccX,AccY,AccZ,EG,EA,T,GH,AH,GHz,AHz"),
    "MAG": (67, "QBhhhhhhhhhBI", "TimeUS,I,MagX,MagY,MagZ,OfsX,OfsY,OfsZ,MOX,MOY,MOZ,Health,S"),
    "ATT": (68, "QccccCCCCB", "TimeUS,DesRoll,Roll,DesPitch,Pitch,DesYaw,Yaw,ErrRP,ErrYaw,AEKF"),
    "GPS": (69, "QBBIHBcLLeffffB", "TimeUS,I,Status,GMS,GWk,NSats,HDop,Lat,Lng,Alt,Spd,GCrs,VZ,Yaw,U"),
}
_STRUCT = {
    "Q": "Q",
    "B": "B",
    "f": "f",
    "I": "I",
    "H": "H",
    "h": "h",
    "c": "h",
    "C": "H",
    "L": "i",
    "e": "i",
    "n": "4s",
    "N": "16s",
    "Z": "64s",
    "i": "i",
}


def dataflash_messages(data, *, t0_us=12_345_678, imus=1, mag_every=2, att_every=4, gps=None):
    """The messages (name, values as ArduPilot stores them) of a log of simulated NED/FRD readings ``data``.

    IMU at the data's rate (``imus`` instances, the later ones with a small offset on the gyro), MAG every
    ``mag_every`` samples in mG (int16), ATT every ``att_every`` samples from the true attitude in centidegrees,
    GPS (``(lat, lon, alt_m, datetime UTC)``) at 5 Hz with GPS week and time of week.
    """
    import datetime

    from strapdown import as_euler

    out = [("PARM", (t0_us, b"INS_GYRO_FILTER", 20.0, 20.0)), ("MSG", (t0_us, b"ArduCopter V4.5.0 (simulated)"))]
    t_us = t0_us + np.round(data.t[:-1] * 1e6).astype(np.int64)
    euler = as_euler(data.q_true[: len(t_us)], "ZYX", degrees=True)  # yaw, pitch, roll
    for k, t in enumerate(t_us):
        for i in range(imus):
            g = data.gyro[k] + 0.001 * i
            out.append(("IMU", (int(t), i, *g, *data.acc[k], 0, 0, 25.0, 1, 1, 400, 400)))
        if k % mag_every == 0:
            m = np.round(data.mag[k] * 10.0).astype(int)  # µT -> mG
            out.append(("MAG", (int(t) + 500, 0, *m, 0, 0, 0, 0, 0, 0, 1, int(t) // 1000)))
        if k % att_every == 0:
            yaw, pitch, roll = euler[k]
            c = [round(v * 100) for v in (roll, roll, pitch, pitch)]
            out.append(("ATT", (int(t), *c, round((yaw % 360) * 100), round((yaw % 360) * 100), 0, 0, 1)))
        if gps is not None and k % max(round(0.2 / float(np.median(np.diff(data.t)))), 1) == 0:
            lat, lon, alt, when = gps
            gps_time = when + datetime.timedelta(seconds=18 + float(data.t[k]))  # UTC -> GPS time
            since = gps_time - datetime.datetime(1980, 1, 6, tzinfo=datetime.UTC)
            week, ms = divmod(round(since.total_seconds() * 1000), 7 * 86_400_000)
            values = (int(t), 0, 3, ms, week, 12, 80, round(lat * 1e7), round(lon * 1e7), round(alt * 100))
            out.append(("GPS", (*values, 0.0, 0.0, 0.0, 0.0, 1)))
    return out


def dataflash(path: Path, messages, *, text=False) -> Path:
    """A DataFlash log of ``messages`` (:func:`dataflash_messages`): binary (``.bin``) or text (``.log``).

    Binary: ``0xA3 0x95 type`` and the packed little-endian payload of each message, each type's FMT before its
    first use.  Text: ``NAME, v, v, ...`` lines as Mission Planner writes them, the scaled values (c and C / 100,
    L / 1e7, e / 100).
    """
    import struct

    def payload(fmt, values):
        return struct.pack("<" + "".join(_STRUCT[c] for c in fmt), *values)

    def scaled(fmt, values):
        div = {"c": 100, "C": 100, "e": 100, "E": 100, "L": 1e7}
        return [
            v.decode() if isinstance(v, bytes) else f"{v / div[c]:.7f}" if c in div else repr(v)
            for c, v in zip(fmt, values, strict=True)
        ]

    def text_of(fmt, values):
        return [
            s
            if isinstance(v, bytes)
            else s
            if fmt_char in "cCeEL"
            else str(v)
            if isinstance(v, int | np.integer)
            else repr(float(v))
            for fmt_char, v, s in zip(fmt, values, scaled(fmt, values), strict=True)
        ]

    path.parent.mkdir(parents=True, exist_ok=True)
    declared = set()
    with open(path, "wb") as f:
        for name, values in [("FMT", None), *messages]:
            typ, fmt, cols = DATAFLASH_LAYOUTS[name]
            if name not in declared:
                declared.add(name)
                length = 3 + struct.calcsize("<" + "".join(_STRUCT[c] for c in fmt))
                fmt_values = (typ, length, name.encode(), fmt.encode(), cols.encode())
                if text:
                    f.write(f"FMT, {typ}, {length}, {name}, {fmt}, {cols}\n".encode())
                else:
                    f.write(bytes([0xA3, 0x95, 128]) + payload(DATAFLASH_LAYOUTS["FMT"][1], fmt_values))
            if values is None:
                continue
            if text:
                f.write((", ".join([name, *text_of(fmt, values)]) + "\n").encode())
            else:
                f.write(bytes([0xA3, 0x95, typ]) + payload(fmt, values))
    return path
