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


def phyphox(folder: Path, data, *, linear_only=False, semicolon=False, start_epoch=None):
    """A phyphox multi-sensor export: "Time (s)" from the start and the sensor's columns, quoted headers.

    ``start_epoch`` also writes ``meta/time.csv`` with the START event's system time (epoch s).
    """
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
    sep = ";" if semicolon else ","
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


def rosbag(path: Path, data, *, version=2, imu_topics=("/imu/data",), mag_topic="/imu/mag", t0_ns=EPOCH_NS):
    """A ROS bag (rosbags' own writer) with sensor_msgs/Imu on ``imu_topics`` and MagneticField (tesla)."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if version == 2 else Stores.ROS1_NOETIC)
    T = store.types
    Imu, Mag = T["sensor_msgs/msg/Imu"], T["sensor_msgs/msg/MagneticField"]
    Header, Time = T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"]
    Vector3, Quaternion = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]

    def header(ns):
        stamp = Time(sec=int(ns // 1_000_000_000), nanosec=int(ns % 1_000_000_000))
        return Header(stamp=stamp, frame_id="imu") if version == 2 else Header(seq=0, stamp=stamp, frame_id="imu")

    ns = t0_ns + np.round(data.t[:-1] * 1e9).astype(np.int64)
    if version == 2:
        from rosbags.rosbag2 import Writer

        writer, serialize = Writer(path, version=9), store.serialize_cdr
    else:
        from rosbags.rosbag1 import Writer

        writer, serialize = Writer(path), store.serialize_ros1
    writer.open()
    try:
        zeros = np.zeros(9)
        imus = [writer.add_connection(tp, Imu.__msgtype__, typestore=store) for tp in imu_topics]
        mag = writer.add_connection(mag_topic, Mag.__msgtype__, typestore=store) if mag_topic else None
        for k, stamp in enumerate(ns):
            w, f, m = data.gyro[k], data.acc[k], data.mag[k]
            msg = Imu(
                header=header(stamp),
                orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                orientation_covariance=np.full(9, -1.0),
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
    finally:
        writer.close()
    return path
