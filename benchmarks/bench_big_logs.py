"""Peak memory of ``strapdown estimate`` on logs larger than memory should allow: 2 GiB in each format's layout.

    nice -n 10 python benchmarks/bench_big_logs.py [--gib 2] [--formats ulog,dataflash,rosbag1,mcap] [--keep DIR]

Each log is written in its own format's layout, with the other traffic a real log carries around the IMU:

* **ulog**: the real PX4 log ``tests/data/px4/sample_logging_tagged_and_default_params.ulg`` (header,
  definitions and subscriptions as they are), its data messages of every topic repeated with their timestamps
  moved on by the log's length each time, as one long flight (``sensor_combined`` is about a tenth of the bytes);
* **dataflash**: ArduPilot's binary layout (FMT, then ``0xA3 0x95 type`` and the packed payloads), IMU at 400 Hz,
  MAG at 100 Hz, ATT at 50 Hz, and filler messages of the size of ArduPilot's EKF and RC logging (``XKF1``-like,
  ``RCOU``-like) at 400 Hz, from 60 s of simulated motion tiled on;
* **rosbag1** and **mcap**: rosbags' writers (ROS 1 ``.bag``; a ROS 2 bag with MCAP storage, whose ``.mcap`` file
  is given alone), ``sensor_msgs/Imu`` at 200 Hz, ``MagneticField`` at 50 Hz and a 640 x 480 ``mono8``
  ``sensor_msgs/Image`` at 10 Hz (a camera: most of a real bag's bytes).

Then ``strapdown estimate LOG -o OUT.parquet -q`` runs in a child of a fresh interpreter, which reports the
child's peak RSS (``resource.getrusage(RUSAGE_CHILDREN)``).  The target is under 1 GiB whatever the log's size:
the readers walk the file a block or a message at a time and spool the samples to disk.  Memory, not time: the
figures do not depend on the machine's load (the wall time is printed for information only).
"""

from __future__ import annotations

import argparse
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # sim_exports: the DataFlash layouts
PX4 = ROOT / "tests" / "data" / "px4" / "sample_logging_tagged_and_default_params.ulg"


# ----------------------------------------------------------------------------------------------------- ULog
def write_ulog(path: Path, size: int) -> Path:
    """The real PX4 log, its data messages repeated (timestamps moved on) until the file holds ``size`` bytes.

    Kept as they are, first: the header, the definitions and every subscription (``A``) of the log; then its
    data messages (``D``) over and over, as one long flight.
    """
    data = PX4.read_bytes()
    pos, starts, subscriptions, every, first_d = 16, [], [], [], None
    while pos + 3 <= len(data):
        n, typ = struct.unpack_from("<HB", data, pos)
        if typ == ord("D"):
            first_d = pos if first_d is None else first_d
            starts.append((pos, n))
        elif typ == ord("A"):
            every.append(data[pos : pos + 3 + n])
            if first_d is not None:
                subscriptions.append(every[-1])
        pos += 3 + n
    # the subscriptions (uint8 multi_id, uint16 msg_id, the topic's name); the gyro's span sets the copies' step
    topic = {struct.unpack_from("<H", a, 4)[0]: a[6:].decode() for a in every}
    gyro_id = next(i for i, name in topic.items() if name == "sensor_combined")
    ids = np.array([struct.unpack_from("<H", data, s + 3)[0] for s, _ in starts])
    stamps = np.array([struct.unpack_from("<Q", data, s + 5)[0] for s, _ in starts])
    sample_at = _timestamp_sample_offsets()  # topic -> offset of its timestamp_sample, which readers prefer
    gyro = stamps[ids == gyro_id]
    span = int(gyro[-1] - gyro[0]) + 4000  # the gyro's length and one 250 Hz period, µs
    keep = (stamps >= gyro[0]) & (stamps < gyro[0] + span)  # every topic's messages of that time, once
    starts = [s for s, k in zip(starts, keep, strict=True) if k]
    raw = np.frombuffer(data, np.uint8)
    body = np.concatenate([raw[s : s + 3 + n] for s, n in starts])
    sizes = np.array([n for _, n in starts])
    # where each message's timestamp (its first field, uint64 after the uint16 msg_id) sits in the body
    offsets = np.concatenate(([0], np.cumsum(3 + sizes)[:-1])) + 5
    kept_ids = ids[keep]
    second = [o + sample_at[topic[i]] for o, i in zip(offsets, kept_ids, strict=True) if topic[i] in sample_at]
    offsets = np.concatenate([offsets, np.array(second, dtype=offsets.dtype)])
    stamp_bytes = offsets[:, None] + np.arange(8)
    stamps = body[stamp_bytes].copy().view("<u8").reshape(-1)
    with open(path, "wb") as f:
        f.write(data[:first_d] + b"".join(subscriptions))
        copy, written = 0, f.tell()
        while written < size:
            block = body.copy()
            block[stamp_bytes] = (stamps + copy * span).view(np.uint8).reshape(-1, 8)
            f.write(block.tobytes())
            written += block.size
            copy += 1
    return path


_SIZES = {"int8_t": 1, "uint8_t": 1, "bool": 1, "char": 1, "int16_t": 2, "uint16_t": 2, "int32_t": 4}
_SIZES |= {"uint32_t": 4, "float": 4, "int64_t": 8, "uint64_t": 8, "double": 8}


def _timestamp_sample_offsets() -> dict:
    """For each topic of the PX4 log with a ``timestamp_sample``: its offset from the ``timestamp`` field."""
    from pyulog import ULog

    formats = ULog(str(PX4)).message_formats

    def size(kind: str) -> int:
        return _SIZES.get(kind) or sum(size(t) * max(n, 1) for t, n, _ in formats[kind].fields)  # 0: a scalar

    out = {}
    for name, fmt in formats.items():
        at = 0
        for kind, n, field in fmt.fields:
            if field == "timestamp_sample":
                out[name] = at  # from the message start, where timestamp (the first field) is
            at += size(kind) * max(n, 1)
    return out


# ----------------------------------------------------------------------------------------------------- DataFlash
_FILLERS = {"XKF1": (90, "QBccCfffffffccce", 1), "RCOU": (91, "QHHHHHHHHHHHHHH", 1)}  # name: type, format, per IMU


def _packed(fmt: str) -> np.dtype:
    codes = {"Q": "<u8", "B": "u1", "f": "<f4", "I": "<u4", "H": "<u2", "h": "<i2", "c": "<i2", "C": "<u2"}
    codes |= {"L": "<i4", "e": "<i4", "i": "<i4"}
    return np.dtype([("h0", "u1"), ("h1", "u1"), ("typ", "u1")] + [(f"f{i}", codes[c]) for i, c in enumerate(fmt)])


def write_dataflash(path: Path, size: int) -> Path:
    """An ArduPilot binary log of ``size`` bytes: IMU 400 Hz, MAG 100 Hz, ATT 50 Hz and EKF/RC-sized fillers."""
    import sim_exports as sim
    from strapdown import as_euler
    from strapdown.simulate import ImuModel, RandomMotion, sample

    layouts = dict(sim.DATAFLASH_LAYOUTS)
    for name, (typ, fmt, _) in _FILLERS.items():
        layouts[name] = (typ, fmt, ",".join(["TimeUS", *(f"V{i}" for i in range(len(fmt) - 1))]))
    data = sample(RandomMotion(60.0, seed=3), 400.0, gyro="rate", imu=ImuModel.consumer_mems(), seed=3)
    n = len(data.t) - 1
    euler = as_euler(data.q_true[:n], "ZYX", degrees=True)
    # one frame: 8 IMU samples (2.5 ms apart), 2 MAG, 1 ATT, a filler of each kind per IMU sample
    parts = []
    for k in range(8):
        parts += [("imu", k), *((name, k) for name in _FILLERS)]
        if k % 4 == 0:
            parts.append(("mag", k))
        if k == 0:
            parts.append(("att", k))
    dtypes = {"imu": _packed(layouts["IMU"][1]), "mag": _packed(layouts["MAG"][1]), "att": _packed(layouts["ATT"][1])}
    dtypes |= {name: _packed(layouts[name][1]) for name in _FILLERS}
    frame = np.dtype([(f"{kind}{k}", dtypes[kind]) for kind, k in parts])
    frames = n // 8
    with open(path, "wb") as f:
        for name, (typ, fmt, cols) in layouts.items():
            length = 3 + struct.calcsize("<" + "".join(sim._STRUCT[c] for c in fmt))
            payload = struct.pack("<BB4s16s64s", typ, length, name.encode(), fmt.encode(), cols.encode())
            f.write(bytes([0xA3, 0x95, 128]) + payload)
        written, copy = f.tell(), 0
        while written < size:
            block = np.zeros(frames, dtype=frame)
            t0 = 10_000_000 + copy * n * 2500
            for kind, k in parts:
                rec = block[f"{kind}{k}"]
                rec["h0"], rec["h1"] = 0xA3, 0x95
                rec["typ"] = layouts[kind.upper()][0] if kind in ("imu", "mag", "att") else layouts[kind][0]
                i = np.arange(frames) * 8 + k
                rec["f0"] = t0 + i * 2500
                if kind == "imu":
                    for j in range(3):
                        rec[f"f{2 + j}"], rec[f"f{5 + j}"] = data.gyro[i, j], data.acc[i, j]
                elif kind == "mag":
                    for j in range(3):
                        rec[f"f{2 + j}"] = np.round(data.mag[i, j] * 10)  # µT -> mG
                elif kind == "att":
                    rec["f2"], rec["f4"] = np.round(euler[i, 2] * 100), np.round(euler[i, 1] * 100)
                    rec["f6"] = np.round((euler[i, 0] % 360) * 100)
            f.write(block.tobytes())
            written += block.nbytes
            copy += 1
    return path


# ----------------------------------------------------------------------------------------------------- bags
def write_bag(path: Path, size: int, version: int) -> Path:
    """A ROS 1 bag or a ROS 2 MCAP file: Imu 200 Hz, MagneticField 50 Hz, a 640 x 480 mono8 Image at 10 Hz."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if version == 2 else Stores.ROS1_NOETIC)
    T = store.types
    Header, Time = T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"]
    V3, Quat = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    Imu, Mag, Image = T["sensor_msgs/msg/Imu"], T["sensor_msgs/msg/MagneticField"], T["sensor_msgs/msg/Image"]
    if version == 2:
        from rosbags.rosbag2 import StoragePlugin, Writer

        folder = path.with_suffix("")
        writer, serialize = Writer(folder, version=9, storage_plugin=StoragePlugin.MCAP), store.serialize_cdr
    else:
        from rosbags.rosbag1 import Writer

        writer, serialize = Writer(path), store.serialize_ros1

    def header(ns):
        stamp = Time(sec=int(ns // 1_000_000_000), nanosec=int(ns % 1_000_000_000))
        return Header(stamp=stamp, frame_id="imu") if version == 2 else Header(seq=0, stamp=stamp, frame_id="imu")

    rng = np.random.default_rng(1)
    pixels = rng.integers(0, 256, 640 * 480, dtype=np.uint8)  # incompressible, as camera noise is
    zeros = np.zeros(9)
    writer.open()
    try:
        imu = writer.add_connection("/imu/data", Imu.__msgtype__, typestore=store)
        mag = writer.add_connection("/imu/mag", Mag.__msgtype__, typestore=store)
        cam = writer.add_connection("/camera/image_raw", Image.__msgtype__, typestore=store)
        t0, k, written = 1_718_030_736_000_000_000, 0, 0
        while written < size:
            ns = t0 + k * 5_000_000
            w = 0.1 * np.sin(k * 0.01 + np.arange(3))
            msg = Imu(header=header(ns), orientation=Quat(x=0.0, y=0.0, z=0.0, w=1.0), orientation_covariance=zeros,
                      angular_velocity=V3(x=w[0], y=w[1], z=w[2]), angular_velocity_covariance=zeros,
                      linear_acceleration=V3(x=0.1, y=-0.2, z=9.81), linear_acceleration_covariance=zeros)  # fmt: skip
            writer.write(imu, ns, serialize(msg, Imu.__msgtype__))
            if k % 4 == 0:
                field = Mag(
                    header=header(ns), magnetic_field=V3(x=2e-5, y=0.0, z=-4e-5), magnetic_field_covariance=zeros
                )
                writer.write(mag, ns, serialize(field, Mag.__msgtype__))
            if k % 20 == 0:
                image = Image(header=header(ns), height=480, width=640, encoding="mono8", is_bigendian=0, step=640,
                              data=np.roll(pixels, k))  # fmt: skip
                raw = serialize(image, Image.__msgtype__)
                writer.write(cam, ns, raw)
                written += len(raw)
            k += 1
    finally:
        writer.close()
    return next(folder.glob("*.mcap")) if version == 2 else path


# ----------------------------------------------------------------------------------------------------- measuring
def peak_rss(args) -> tuple[int, float, str]:
    """(peak RSS of ``strapdown ARGS`` in bytes, wall time in s, its output) from a fresh interpreter's child."""
    code = (
        "import resource, subprocess, sys, time\n"
        "t = time.perf_counter()\n"
        "r = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
        "sys.stdout.write(r.stdout + r.stderr)\n"
        "print('\\nMEASURED', resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, time.perf_counter() - t)\n"
        "sys.exit(r.returncode)\n"
    )
    cmd = [sys.executable, "-c", code, sys.executable, "-m", "strapdown.cli", *map(str, args)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    text, _, figures = res.stdout.rpartition("MEASURED")
    if res.returncode:
        raise SystemExit(f"strapdown {' '.join(map(str, args))} failed:\n{text}{res.stderr}")
    kib, wall = figures.split()
    return int(kib) * 1024, float(wall), text


WRITERS = {
    "ulog": lambda d, size: write_ulog(d / "big.ulg", size),
    "dataflash": lambda d, size: write_dataflash(d / "big.bin", size),
    "rosbag1": lambda d, size: write_bag(d / "big.bag", size, 1),
    "mcap": lambda d, size: write_bag(d / "big.mcap", size, 2),
}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gib", type=float, default=2.0, help="Size of each log, GiB (default 2).")
    parser.add_argument("--formats", default=",".join(WRITERS), help="Comma-separated: " + ", ".join(WRITERS))
    parser.add_argument("--keep", type=Path, help="Folder to write the logs to and keep (default: a temporary one).")
    args = parser.parse_args(argv)
    size = int(args.gib * 2**30)
    folder = args.keep or Path(tempfile.mkdtemp(prefix="bench-big-logs-"))
    folder.mkdir(parents=True, exist_ok=True)
    print(f"{'format':10} {'log':>9} {'rows':>10} {'peak RSS':>9} {'target':>7} {'wall':>7}")
    try:
        for name in args.formats.split(","):
            t = time.perf_counter()
            log = WRITERS[name](folder, size)
            written = time.perf_counter() - t
            log_bytes = sum(p.stat().st_size for p in log.parent.glob(log.name))
            out = folder / f"{name}.parquet"
            peak, wall, text = peak_rss(["estimate", log, "-o", out, "-q"])
            import pyarrow.parquet as pq

            rows = pq.ParquetFile(out).metadata.num_rows
            verdict = "ok" if peak < 2**30 else "OVER"
            print(f"{name:10} {log_bytes / 2**30:7.2f}Gi {rows:10d} {peak / 2**20:7.0f}Mi {verdict:>7} {wall:6.0f}s"
                  f"   (written in {written:.0f} s)", flush=True)  # fmt: skip
            for line in text.strip().splitlines():
                if line.startswith("warning"):
                    print("   ", line[:200])
            out.unlink()
            if args.keep is None:  # the next log's room
                if name == "mcap":
                    shutil.rmtree(log.parent, ignore_errors=True)
                else:
                    log.unlink()
    finally:
        if args.keep is None:
            shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
