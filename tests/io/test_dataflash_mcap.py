"""ArduPilot DataFlash logs (binary ``.bin`` and text ``.log``) and standalone MCAP files (issue 28, part B).

Every log below is SIMULATED motion (a real log, of ArduCopter 3.3, is tests/io/test_dataflash_real.py's), written
by tests/sim_exports.py in the exact DataFlash layout (ArduPilot's LogStructure.h: FMT messages, then
``0xA3 0x95 type`` and the packed payload; the text layout as Mission Planner exports it).  pymavlink's DFReader,
ArduPilot's own Python reader, reads the same bytes as the independent oracle.  The MCAP files are written by
rosbags' ROS 2 writer with MCAP storage; the ``.mcap`` file alone is what Foxglove and ``ros2 bag record`` leave.
"""

import datetime
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sim_exports as sim
from strapdown.evaluate.metrics import attitude_errors
from strapdown.io import ImuColumns, ImuFile, read_imu, read_reference
from strapdown.io.registry import formats
from strapdown.simulate import ImuModel, RandomMotion, sample

T0_US = 12_345_678  # the simulated boot time of the first IMU sample
PLACE = (47.397742, 8.545594, 488.0)  # lat, lon, alt (m)


def flight(duration=12.0, seed=4):
    """Random motion of a drone (gentle accelerations), consumer-grade IMU, NED/FRD as ArduPilot logs it."""
    motion = RandomMotion(duration, seed=seed, acceleration_scale=0.2)
    return sample(motion, 200.0, gyro="rate", imu=ImuModel.consumer_mems(), reference="NED", body="FRD", seed=seed)


def write_log(tmp_path, data, *, text=False, **kw):
    name = "flight.log" if text else "flight.bin"
    return sim.dataflash(tmp_path / name, sim.dataflash_messages(data, t0_us=T0_US, **kw), text=text)


@pytest.fixture(scope="module")
def data():
    return flight()


def _run(*args):
    return subprocess.run(
        [sys.executable, "-m", "strapdown.cli", *map(str, args)], capture_output=True, text=True, timeout=600
    )


# ----------------------------------------------------------------------------------------------------- DataFlash
@pytest.mark.parametrize("text", [False, True])
def test_dataflash_reads_the_imu_and_mag_in_si_on_boot_time_ned_frd(tmp_path, data, text):
    path = write_log(tmp_path, data, text=text)
    imu = ImuFile(path, optional=("acc", "mag"))
    assert imu.format == "dataflash" and (imu.frame, imu.body) == ("NED", "FRD")
    assert imu.units == {"gyro": "rad/s", "acc": "m/s2", "mag": "uT", "time": "s"}
    assert imu.time_origin.value == T0_US and (imu.time_origin.unit, imu.time_origin.kind) == ("us", "boot")
    got = read_imu(path, optional=("acc", "mag"))
    n = len(data.t) - 1
    np.testing.assert_allclose(got.t, np.round(data.t[:n] * 1e6) / 1e6 - data.t[0], atol=1e-9)  # TimeUS: whole µs
    np.testing.assert_allclose(got.gyro, data.gyro[:n], rtol=1e-6, atol=1e-6)  # stored as float32
    np.testing.assert_allclose(got.acc, data.acc[:n], rtol=1e-6, atol=1e-5)
    present = ~np.isnan(got.mag).any(axis=1)
    assert present[::2].all() and not present[1::2].any()  # MAG every other IMU sample
    # MagX.. are whole milligauss: 1 mG = 0.1 µT, so within half a count of the simulated µT
    np.testing.assert_allclose(got.mag[present], data.mag[:n:2], atol=0.05 + 1e-9)


def test_dataflash_values_are_those_pymavlink_reads(tmp_path, data):
    from pymavlink import DFReader

    path = write_log(tmp_path, data, gps=(*PLACE, datetime.datetime(2024, 5, 1, 12, tzinfo=datetime.UTC)))
    log = DFReader.DFReader_binary(str(path))
    imu, mag, att = [], [], []
    while (m := log.recv_match(type=["IMU", "MAG", "ATT"])) is not None:
        kind = m.get_type()
        if kind == "IMU":
            imu.append((m.TimeUS, m.GyrX, m.GyrY, m.GyrZ, m.AccX, m.AccY, m.AccZ))
        elif kind == "MAG":
            mag.append((m.TimeUS, m.MagX, m.MagY, m.MagZ))
        else:
            att.append((m.TimeUS, m.Roll, m.Pitch, m.Yaw))
    imu, mag, att = np.array(imu), np.array(mag), np.array(att)
    got = read_imu(path, optional=("acc", "mag"))
    np.testing.assert_array_equal(got.t, (imu[:, 0] - imu[0, 0]) / 1e6)
    np.testing.assert_array_equal(np.column_stack([got.gyro, got.acc]), imu[:, 1:])
    present = ~np.isnan(got.mag).any(axis=1)
    np.testing.assert_allclose(got.mag[present], mag[:, 1:] * 0.1, rtol=1e-12)  # mG -> µT
    ref = formats()["dataflash"].reference(path)
    assert (ref["frame"], ref["body"], ref["source"]) == ("NED", "FRD", "ATT")
    np.testing.assert_allclose(ref["t"], (att[:, 0] - imu[0, 0]) / 1e6)
    from strapdown import as_euler

    ypr = as_euler(ref["q"], "ZYX", degrees=True)
    np.testing.assert_allclose(ypr[:, 2], att[:, 1], atol=1e-9)  # roll
    np.testing.assert_allclose(ypr[:, 1], att[:, 2], atol=1e-9)  # pitch
    np.testing.assert_allclose(ypr[:, 0] % 360, att[:, 3] % 360, atol=1e-9)  # yaw (ArduPilot: 0..360)


def test_dataflash_att_reference_is_the_attitude_it_was_written_from(tmp_path, data):
    path = write_log(tmp_path, data)
    ref = formats()["dataflash"].reference(path)
    truth = data.q_true[: len(data.t) - 1 : 4]
    err = np.degrees(attitude_errors(ref["q"], truth)["total"])
    assert err.max() < 0.02  # ATT stores centidegrees: at most 0.005° on each angle


def test_dataflash_imu_instances_are_chosen_with_topic(tmp_path, data):
    path = write_log(tmp_path, data, imus=3)
    n = len(data.t) - 1
    first = read_imu(path)
    np.testing.assert_allclose(first.gyro, data.gyro[:n], atol=1e-6)
    for spec, offset in (("IMU:1", 0.001), ("IMU[2]", 0.002), ("IMU2", 0.001), ("IMU3", 0.002)):
        got = read_imu(path, ImuColumns(topic=spec))
        np.testing.assert_allclose(got.gyro, data.gyro[:n] + offset, atol=1e-6)  # the writer's per-instance offset
    with pytest.raises(
        ValueError, match=r"flight\.bin: no IMU instance 5 in this log; its IMU instances: IMU:0, IMU:1, IMU:2"
    ):
        ImuFile(path, ImuColumns(topic="IMU:5"))


def test_dataflash_position_is_the_first_gps_fix_in_utc(tmp_path, data):
    from pymavlink import DFReader

    # GPS week 2048 began on 2019-04-07 00:00:00 GPS time (the second week-number rollover), when UTC was 18 s
    # behind: that UTC instant is week 2048 and 18 000 ms of GPS time
    path = write_log(tmp_path, data, gps=(*PLACE, datetime.datetime(2019, 4, 7, tzinfo=datetime.UTC)))
    first = DFReader.DFReader_binary(str(path)).recv_match(type="GPS")
    assert (first.GWk, first.GMS) == (2048, 18_000)
    pos = formats()["dataflash"].position(path)
    assert pos["latitude_deg"] == pytest.approx(PLACE[0], abs=1e-7)
    assert pos["longitude_deg"] == pytest.approx(PLACE[1], abs=1e-7)
    assert pos["altitude_m"] == pytest.approx(PLACE[2], abs=0.01)
    assert pos["date"] == datetime.date(2019, 4, 7) and "2019-04-07T00:00:00" in pos["source"]
    assert formats()["dataflash"].position(write_log(tmp_path, data)) is None  # no GPS message: nothing made up


@pytest.mark.parametrize("text", [False, True])
def test_estimate_a_dataflash_log_with_no_options_agrees_with_its_att(tmp_path, data, text):
    path = write_log(tmp_path, data, text=text)
    out = tmp_path / "att.csv"
    res = _run("estimate", path, "-o", out)
    assert res.returncode == 0, res.stderr
    assert "frames: NED/FRD (dataflash)" in res.stdout + res.stderr
    est = read_reference(out)
    ref = formats()["dataflash"].reference(path)
    assert (est.frame, est.body) == ("NED", "FRD")
    rows = np.searchsorted(est.t, ref["t"])  # ATT on every fourth IMU sample, on the same clock
    keep = (rows < len(est.t)) & (ref["t"] > 2.0)  # past the first seconds of convergence
    err = attitude_errors(est.q[rows[keep]], ref["q"][keep])
    # the same estimator on the same readings in a plain table (what the reader must not change) gives 1.67°:
    # consumer-grade sensors and an uncalibrated magnetometer; a wrong axis or unit would be tens of degrees
    assert np.degrees(np.sqrt(np.mean(err["inclination"] ** 2))) < 2.5


def test_dataflash_without_imu_messages_says_what_it_has(tmp_path, data):
    msgs = [m for m in sim.dataflash_messages(data) if m[0] != "IMU"]
    path = sim.dataflash(tmp_path / "noimu.bin", msgs)
    with pytest.raises(
        ValueError,
        match=r"noimu\.bin: no IMU messages in this DataFlash log \(its \d+ bytes\); its FMTs declare: .*ATT",
    ):
        ImuFile(path)


# ----------------------------------------------------------------------------------------------------- MCAP
def test_standalone_mcap_reads_as_its_ros2_bag_folder(tmp_path):
    data = sim.phone_at_rest(body="FLU", duration=4.0)
    folder = sim.rosbag(tmp_path / "bag", data, storage="mcap")
    alone = tmp_path / "recording.mcap"
    shutil.copy(next(folder.glob("*.mcap")), alone)
    assert not (tmp_path / "metadata.yaml").exists()
    imu = ImuFile(alone, optional=("acc", "mag"))
    assert imu.format == "rosbag" and (imu.frame, imu.body) == ("ENU", "FLU")
    got, whole = read_imu(alone, optional=("acc", "mag")), read_imu(folder, optional=("acc", "mag"))
    np.testing.assert_array_equal(got.gyro, data.gyro[: len(got.t)])
    assert len(got.t) == len(data.t) - 1
    np.testing.assert_array_equal(got.mag, whole.mag)
    out = tmp_path / "att.csv"
    res = _run("estimate", alone, "-o", out)
    assert res.returncode == 0, res.stderr
    assert out.is_file()


def test_a_magnetometer_that_stops_leaves_nan_rows_in_every_later_chunk(tmp_path, data):
    from strapdown.io.formats.dataflash import open_dataflash

    msgs = sim.dataflash_messages(data, t0_us=T0_US)
    imu_times = [v[0] for name, v in msgs if name == "IMU"]
    stop = imu_times[len(imu_times) // 4]
    path = sim.dataflash(tmp_path / "stops.bin", [m for m in msgs if m[0] != "MAG" or m[1][0] < stop])
    with open_dataflash(path) as src:
        names = [f for f in src.fields if f.startswith("MAG/")]
        blocks = [cols[names[0]] for _, cols in src.chunks(names, 200)]  # chunks after the stop hold no sample
    mag = np.concatenate(blocks)
    assert len(mag) == len(imu_times) and not np.isnan(mag[: len(mag) // 4 - 2 : 2]).any()
    assert np.isnan(mag[len(mag) // 4 + 1 :]).all()


# ----------------------------------------------------------------------------------------------------- the hooks
def test_ulog_hooks_are_vehicle_attitude_and_the_first_3d_gps_fix_as_pyulog_reads_them():
    from pyulog import ULog

    log = Path(__file__).resolve().parents[1] / "data" / "px4" / "sample_log_small.ulg"
    ulog = ULog(str(log), ["vehicle_attitude", "vehicle_gps_position", "sensor_combined"])
    att = ulog.get_dataset("vehicle_attitude").data
    gyro0 = ulog.get_dataset("sensor_combined").data["timestamp"][0]
    ref = formats()["ulog"].reference(log)
    assert (ref["frame"], ref["body"], ref["source"]) == ("NED", "FRD", "vehicle_attitude")
    np.testing.assert_allclose(ref["q"], np.column_stack([att[f"q[{i}]"] for i in range(4)]), rtol=1e-6)
    stamp = att.get("timestamp_sample", att["timestamp"])
    np.testing.assert_allclose(ref["t"], (stamp.astype(np.int64) - int(gyro0)) / 1e6)
    gps = ulog.get_dataset("vehicle_gps_position").data
    i = int(np.argmax((gps["fix_type"] >= 3) & (gps["time_utc_usec"] > 0)))
    pos = formats()["ulog"].position(log)
    assert pos["latitude_deg"] == pytest.approx(gps["lat"][i] * 1e-7) and pos["altitude_m"] == pytest.approx(
        gps["alt"][i] * 1e-3
    )
    when = datetime.datetime.fromtimestamp(int(gps["time_utc_usec"][i]) / 1e6, datetime.UTC)
    assert pos["date"] == when.date() == datetime.date(2021, 4, 21)


@pytest.mark.parametrize("version", [1, 2])
def test_bag_hooks_are_the_imu_orientation_and_the_first_navsatfix(tmp_path, version):
    data = sim.phone_at_rest(body="FLU", duration=3.0)
    path = sim.rosbag(tmp_path / ("r.bag" if version == 1 else "r"), data, version=version, orientation=True,
                      fix=PLACE)  # fmt: skip
    ref = formats()["rosbag"].reference(path)
    assert (ref["frame"], ref["body"], ref["source"]) == ("ENU", "FLU", "Imu orientation")
    np.testing.assert_allclose(ref["q"], data.q_true[: len(data.t) - 1], atol=1e-12)
    np.testing.assert_allclose(ref["t"], data.t[:-1] - data.t[0], atol=1e-9)
    pos = formats()["rosbag"].position(path)
    assert (pos["latitude_deg"], pos["longitude_deg"], pos["altitude_m"]) == PLACE
    expected = datetime.datetime.fromtimestamp(sim.EPOCH_NS / 1e9, datetime.UTC).date()  # the first stamp's day
    assert pos["date"] == expected
    bare = sim.rosbag(tmp_path / ("b.bag" if version == 1 else "b"), data, version=version)
    assert formats()["rosbag"].position(bare) is None
    with pytest.raises(ValueError, match="carry no orientation"):
        formats()["rosbag"].reference(bare)
