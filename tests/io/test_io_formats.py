"""The field's formats read with no options beyond topic=: columns, units, time and frames found, and a
physical check of what comes out (a vehicle at rest shows the tilt its own estimator logged; a phone lying flat
reads level).

The two PX4 logs in tests/data/px4 are real (PROVENANCE.md); every other file here is SIMULATED motion
(strapdown.simulate) written by tests/sim_exports.py in the tool's documented layout.
"""

from pathlib import Path

import numpy as np
import pytest

import sim_exports as sim
from strapdown.evaluate.metrics import attitude_errors
from strapdown.fusion import AttitudeEstimator
from strapdown.io import ImuColumns, ImuFile, read_imu, read_reference

DATA = Path(__file__).resolve().parents[1] / "data"
PX4 = sorted((DATA / "px4").glob("*.ulg"))


def options(log):
    """No options but for the small log, whose real 161 ms gap after its first sample the gap check stops."""
    return ImuColumns(max_gap=0) if log.name == "sample_log_small.ulg" else None


def level_angles(data, frame):
    """Pitch and roll (deg) that AttitudeEstimator reaches on the last second of a recording at rest."""
    est = AttitudeEstimator(frame=frame).update(data.gyro, data.acc, data.mag, t=data.t)
    late = data.t > data.t[-1] - 1.0
    return np.degrees(np.abs(est.pitch[late])).max(), np.degrees(np.abs(est.roll[late])).max()


# ----------------------------------------------------------------------------------------------------- PX4
@pytest.mark.parametrize("log", PX4, ids=lambda p: p.stem)
def test_px4_ulog_reads_sensor_combined_in_si_with_boot_time_and_ned_frd(log):
    imu = ImuFile(log, options(log), optional=("acc", "mag"))
    assert imu.format == "ulog" and (imu.frame, imu.body) == ("NED", "FRD")
    assert imu.picks["gyro"].fields[0] == "sensor_combined/gyro_rad[0]" and imu.units["gyro"] == "rad/s"
    assert imu.picks["acc"].fields[2] == "sensor_combined/accelerometer_m_s2[2]" and imu.units["acc"] == "m/s2"
    assert imu.picks["mag"].fields[0] == "vehicle_magnetometer/magnetometer_ga[0]" and imu.units["mag"] == "gauss"
    assert imu.sparse == {"mag"}  # 50 Hz or slower beside the gyro's 200-250 Hz: NaN rows between
    from pyulog import ULog  # an independent read of the same topic

    raw = ULog(str(log), message_name_filter_list=["sensor_combined"]).get_dataset("sensor_combined").data
    assert imu.time_origin.value == int(raw["timestamp"][0]) and imu.time_origin.kind == "boot"
    assert imu.time_origin.unit == "us"
    data = read_imu(log, options(log), optional=("acc", "mag"))
    np.testing.assert_array_equal(data.t, (raw["timestamp"] - raw["timestamp"][0]) / 1e6)
    np.testing.assert_array_equal(data.gyro[:, 1], raw["gyro_rad[1]"].astype(float))
    # vehicle_magnetometer is in gauss: read as µT, the Earth's field
    b = np.linalg.norm(data.mag[~np.isnan(data.mag).any(axis=1)], axis=1)
    assert 20 < np.median(b) < 70


def test_px4_metadata_says_format_frames_and_origin():
    from strapdown.io import read_metadata

    meta = read_metadata(DATA / "px4" / "sample_logging_tagged_and_default_params.ulg")
    assert meta == {
        "format": "ulog",
        "frame": "NED",
        "body": "FRD",
        "time_origin": "284000",
        "time_origin_unit": "us",
        "time_origin_kind": "boot",
    }


def test_px4_log_gap_after_the_first_sample_is_reported_not_read_through():
    # the small log's first sensor_combined sample is 161 ms before the second (logging starting up)
    with pytest.raises(ValueError, match=r"a gap of 0\.161303 s .* before row 1"):
        read_imu(DATA / "px4" / "sample_log_small.ulg")


@pytest.mark.parametrize("log", PX4, ids=lambda p: p.stem)
def test_px4_vehicle_at_rest_shows_the_tilt_its_own_estimator_logged(log):
    data = read_imu(log, options(log), optional=("acc",))
    ref = read_reference(log)
    assert (ref.frame, ref.body) == ("NED", "FRD")
    assert ref.time_origin == ImuFile(log, options(log)).time_origin  # one time line for IMU and reference
    est = AttitudeEstimator(frame="NED").update(data.gyro, data.acc, t=data.t)
    keep = (ref.t > 2.0) & (ref.t <= data.t[-1])  # after the estimators' start-up
    rows = np.searchsorted(data.t, ref.t[keep])
    incl = np.degrees(attitude_errors(est.q[rows], ref.q[keep])["inclination"])
    assert incl.max() < 1.0
    # and the tilt itself is what gravity says in FRD axes: roll = atan2(-f_y, -f_z)
    f = data.acc.mean(axis=0)
    assert abs(np.degrees(est.roll[-1]) - np.degrees(np.arctan2(-f[1], -f[2]))) < 0.2


def test_px4_topic_chooses_the_raw_sensor_at_its_own_rate():
    log = DATA / "px4" / "sample_logging_tagged_and_default_params.ulg"
    imu = ImuFile(log, ImuColumns(topic="sensor_gyro", max_gap=0), optional=("acc",))
    assert imu.picks["gyro"].fields[0].startswith("sensor_gyro/") and imu.period == pytest.approx(1.0, rel=0.01)
    with pytest.raises(ValueError, match=r"no topic 'sensor_gyro:7'.*sensor_combined"):
        ImuFile(log, ImuColumns(topic="sensor_gyro:7"))


def test_px4_a_flipped_accelerometer_is_refused_as_a_sign_error(monkeypatch):
    # the same log with the accelerometer negated, as a driver reporting acceleration instead of specific force
    from strapdown.io.formats import ulog

    original = ulog._vector

    def flipped(records, stem):
        return -original(records, stem) if stem == "accelerometer_m_s2" else original(records, stem)

    monkeypatch.setattr(ulog, "_vector", flipped)
    log = DATA / "px4" / "sample_logging_tagged_and_default_params.ulg"
    with pytest.raises(ValueError, match=r"reads gravity downward.*sign flipped"):
        ImuFile(log, ImuColumns(max_gap=0), optional=("acc",))


# ----------------------------------------------------------------------------------------------------- ROS
@pytest.mark.parametrize("version", [1, 2])
def test_ros_bag_imu_and_magnetic_field_topics_with_enu_flu(tmp_path, version):
    data = sim.phone_at_rest(body="FLU", duration=8.0)
    path = sim.rosbag(tmp_path / ("run.bag" if version == 1 else "run"), data, version=version)
    imu = ImuFile(path, optional=("acc", "mag"))
    assert imu.format == "rosbag" and (imu.frame, imu.body) == ("ENU", "FLU")
    assert imu.picks["gyro"].fields == tuple(f"/imu/data/angular_velocity.{c}" for c in "xyz")
    assert imu.units == {"gyro": "rad/s", "acc": "m/s2", "mag": "uT", "time": "s"}
    assert imu.time_origin.value == sim.EPOCH_NS and imu.time_origin.kind == "epoch"
    got = read_imu(path, optional=("acc", "mag"))
    np.testing.assert_allclose(got.t, data.t[:-1] - data.t[0], atol=1e-9)  # stamps are whole ns
    np.testing.assert_array_equal(got.gyro, data.gyro)
    present = ~np.isnan(got.mag).any(axis=1)
    assert present[::2].all() and not present[1::2].any()  # the half-rate magnetometer on every other row
    np.testing.assert_allclose(got.mag[present], data.mag[::2], rtol=1e-12)  # tesla read back as µT
    pitch, roll = level_angles(got, imu.frame)
    assert pitch < 2.0 and roll < 2.0


def test_ros_bag_with_several_imu_topics_lists_them_until_one_is_chosen(tmp_path):
    data = sim.phone_at_rest(body="FLU", duration=2.0)
    path = sim.rosbag(tmp_path / "two", data, imu_topics=("/imu/data", "/imu/data_raw"))
    with pytest.raises(ValueError, match=r"several sensor_msgs/msg/Imu topics: /imu/data, /imu/data_raw; .*--topic"):
        ImuFile(path)
    imu = ImuFile(path, ImuColumns(topic="/imu/data_raw"))
    assert imu.picks["gyro"].fields[0] == "/imu/data_raw/angular_velocity.x"
    with pytest.raises(ValueError, match="no sensor_msgs/msg/Imu topic '/nope'"):
        ImuFile(path, ImuColumns(topic="/nope"))


# ----------------------------------------------------------------------------------------------------- phones
@pytest.mark.parametrize("as_zip", [False, True])
def test_sensor_logger_export_folder_or_zip_lying_flat(tmp_path, as_zip):
    data = sim.phone_at_rest(duration=10.0)
    folder = sim.sensor_logger(tmp_path / "2024-06-10_14-45-36", data)
    path = folder
    if as_zip:
        import shutil

        path = Path(shutil.make_archive(str(tmp_path / "export"), "zip", folder))
    imu = ImuFile(path, optional=("acc", "mag"))
    assert imu.format == "sensorlogger" and (imu.frame, imu.body) == ("ENU", "RFU")
    # the file's columns are z, y, x: read as x, y, z; the gravity-bearing TotalAcceleration.csv is taken
    assert imu.picks["gyro"].fields == ("Gyroscope.csv/x", "Gyroscope.csv/y", "Gyroscope.csv/z")
    assert imu.picks["acc"].fields[0] == "TotalAcceleration.csv/x"
    assert imu.units["mag"] == "uT" and imu.time_origin.kind == "epoch" and imu.time_origin.unit == "ns"
    got = read_imu(path, optional=("acc", "mag"))
    np.testing.assert_allclose(got.gyro, data.gyro, rtol=1e-15)
    assert np.isnan(got.mag[1::2]).all() and not np.isnan(got.mag[::2]).any()
    pitch, roll = level_angles(got, imu.frame)
    assert pitch < 2.0 and roll < 2.0


def test_one_sensor_logger_file_alone_is_read_as_its_sensor(tmp_path):
    data = sim.phone_at_rest(duration=3.0)
    gyro = sim.sensor_logger(tmp_path / "e", data) / "Gyroscope.csv"
    imu = ImuFile(gyro)
    assert imu.picks["gyro"].fields == ("x", "y", "z") and imu.units["time"] == "ns"
    assert (imu.frame, imu.body) == ("ENU", "RFU")
    np.testing.assert_allclose(read_imu(gyro).gyro, data.gyro, rtol=1e-15)


def test_sensor_logger_without_gravity_is_refused_as_linear_acceleration(tmp_path):
    folder = sim.sensor_logger(tmp_path / "ios", sim.phone_at_rest(duration=5.0), total=False)
    with pytest.raises(ValueError, match="gravity-free 'linear acceleration' stream"):
        read_imu(folder, optional=("acc",))


def test_sensor_logger_ios_style_acceleration_plus_gravity_is_the_specific_force(tmp_path):
    data = sim.phone_at_rest(duration=6.0)
    folder = sim.sensor_logger(tmp_path / "ios", data, total=False, gravity_file=True)
    imu = ImuFile(folder, optional=("acc",))
    assert imu.picks["acc"].fields[0] == "Accelerometer.csv/x+Gravity.csv"
    np.testing.assert_allclose(read_imu(folder, optional=("acc",)).acc, data.acc, atol=1e-12)


def test_phyphox_start_time_gives_the_epoch_origin(tmp_path):
    folder = sim.phyphox(tmp_path / "p", sim.phone_at_rest(duration=2.0), start_epoch=1718030736.5)
    origin = ImuFile(folder).time_origin
    assert origin.kind == "epoch" and origin.unit == "s" and origin.value == pytest.approx(1718030736.5)
    assert origin.iso.startswith("2024-06-10T14:45:36.5")


@pytest.mark.parametrize("semicolon", [False, True])
def test_phyphox_export_lying_flat(tmp_path, semicolon):
    data = sim.phone_at_rest(duration=10.0)
    folder = sim.phyphox(tmp_path / "Gyroscope rotation rate 2024-06-10 14-45-36", data, semicolon=semicolon)
    imu = ImuFile(folder, optional=("acc", "mag"))
    assert imu.format == "phyphox" and (imu.frame, imu.body) == ("ENU", "RFU")
    assert imu.picks["acc"].fields[0] == "Accelerometer.csv/Acceleration x (m/s^2)"
    assert imu.units["mag"] == "uT" and imu.units["gyro"] == "rad/s"
    got = read_imu(folder, optional=("acc", "mag"))
    np.testing.assert_allclose(got.gyro, data.gyro, rtol=1e-8)  # 10 significant digits in the file
    pitch, roll = level_angles(got, imu.frame)
    assert pitch < 2.0 and roll < 2.0


def test_phyphox_linear_accelerometer_alone_is_refused(tmp_path):
    # issue 12: |a| about 1.6 m/s2 was taken for specific force and gave roll -97 deg with exit code 0
    data = sim.phone_at_rest(duration=5.0)
    data.acc[:] = data.acc + np.random.default_rng(3).normal(0, 1.2, data.acc.shape)  # a hand-held phone
    folder = sim.phyphox(tmp_path / "linear", data, linear_only=True)
    with pytest.raises(ValueError, match=r"Linear Accelerometer.csv.*gravity-free|gravity-free.*Linear"):
        read_imu(folder, optional=("acc",))


# ----------------------------------------------------------------------------------------------------- lab files
def test_euroc_folder_and_its_data_csv(tmp_path):
    data = sim.phone_at_rest(rate_hz=200.0, duration=5.0, body="FLU")
    csv = sim.euroc(tmp_path / "MH_01", data)
    for path in (tmp_path / "MH_01", csv):
        imu = ImuFile(path, optional=("acc",))
        assert imu.picks["gyro"].fields == tuple(f"w_RS_S_{c} [rad s^-1]" for c in "xyz")
        assert imu.picks["acc"].fields[0] == "a_RS_S_x [m s^-2]" and imu.units["acc"] == "m/s2"
        assert imu.units["time"] == "ns" and imu.time_origin.value == 1_403_636_579_758_555_392
        assert imu.period == pytest.approx(np.median(np.diff(data.t)), abs=1e-7)  # the clock drifts: not 5 ms
    got = read_imu(csv, optional=("acc",))
    np.testing.assert_array_equal(got.acc, data.acc)
    assert imu.frame is None and imu.body is None  # the IMU's own axes: no preset
    pitch, roll = level_angles(got, "ENU")  # simulated level in FLU axes
    assert pitch < 2.0 and roll < 2.0


def test_several_files_one_per_sensor_merge_on_the_gyro_rows(tmp_path):
    data = sim.phone_at_rest(duration=6.0)
    folder = sim.sensor_logger(tmp_path / "exp", data)
    files = [folder / "Magnetometer.csv", folder / "Gyroscope.csv", folder / "TotalAcceleration.csv"]
    imu = ImuFile(files, optional=("acc", "mag"))
    assert imu.format == "files" and imu.sparse == {"mag"} and (imu.frame, imu.body) == ("ENU", "RFU")
    got = read_imu(files, optional=("acc", "mag"))
    # the accelerometer's samples are 1.2 ms after the gyro's: each lands on its own gyro row
    np.testing.assert_allclose(got.acc, data.acc, rtol=1e-15)
    assert got.t[0] == 0.0 and imu.time_origin.value == sim.EPOCH_NS
    pitch, roll = level_angles(got, "ENU")
    assert pitch < 2.0 and roll < 2.0


def test_generic_csv_with_a_unit_row_semicolons_and_decimal_commas(tmp_path):
    data = sim.phone_at_rest(duration=3.0)
    lines = ["Zeit;Gyro X;Gyro Y;Gyro Z;Acc X;Acc Y;Acc Z", "s;deg/s;deg/s;deg/s;g;g;g"]
    for t, w, f in zip(data.t[:-1], np.degrees(data.gyro), data.acc / 9.80665, strict=True):
        lines.append(";".join(f"{v:.12f}".replace(".", ",") for v in (t, *w, *f)))
    path = tmp_path / "lab.csv"
    path.write_text("\n".join(lines) + "\n")
    imu = ImuFile(path, ImuColumns(time="Zeit"), optional=("acc",))
    assert imu.units["gyro"] == "deg/s" and imu.units["acc"] == "g"
    assert imu.where(0) == "line 3"
    got = read_imu(path, ImuColumns(time="Zeit"), optional=("acc",))
    np.testing.assert_allclose(got.gyro, data.gyro, atol=1e-12)
    np.testing.assert_allclose(got.acc, data.acc, atol=1e-10)


@pytest.mark.parametrize(
    ("header", "step", "unit"),
    [
        ("timestamp,gyro_rad[0],gyro_rad[1],gyro_rad[2]", 4000, "us"),  # PX4's csv export (ulog2csv), µs since boot
        ("t,X (rad/s),Y (rad/s),Z (rad/s)", 10, "ms"),
        ("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1]", 5_000_000, "ns"),
    ],
)
def test_field_column_names_are_found(tmp_path, header, step, unit):
    path = tmp_path / "g.csv"
    path.write_text(header + "\n" + "".join(f"{20_000_000 + step * k},0.1,0.2,0.3\n" for k in range(5)))
    imu = ImuFile(path)
    assert imu.units["gyro"] == "rad/s" and len(imu.picks["gyro"].fields) == 3
    assert imu.units["time"] == unit
    np.testing.assert_allclose(next(imu.chunks()).t, np.arange(5) * step * {"us": 1e-6, "ms": 1e-3, "ns": 1e-9}[unit])


def test_one_sensor_per_file_with_bare_xyz_columns(tmp_path):
    g = tmp_path / "gyro.csv"
    a = tmp_path / "accel.csv"
    g.write_text("t,x,y,z\n" + "".join(f"{0.01 * k:.2f},0,0,0.1\n" for k in range(10)))
    a.write_text("t,x,y,z\n" + "".join(f"{0.02 * k + 0.001:.3f},0,0,9.8\n" for k in range(5)))
    got = read_imu([g, a], optional=("acc",))
    assert np.isnan(got.acc[1::2]).all() and (got.acc[::2, 2] == 9.8).all()


@pytest.mark.parametrize("integer", [True, False])
def test_files_whose_time_columns_name_different_units_share_one_clock(tmp_path, integer):
    """A gyro file in ns (s) and an accelerometer file in us (ms): each sample lands on its own gyro row."""
    n = 50
    k = np.arange(n)
    if integer:
        t_gyro, t_acc, names = 1718030736000000000 + k * 10_000_000, 1718030736000000 + k * 10_000, ("ns", "us")
    else:
        t_gyro, t_acc, names = 12.5 + k * 0.01, 12500.0 + k * 10.0, ("s", "ms")
    gyro, acc = tmp_path / "Gyroscope.csv", tmp_path / "Accelerometer.csv"
    gyro.write_text(f"time_{names[0]},x,y,z\n" + "".join(f"{t},0,0,0.1\n" for t in t_gyro))
    acc.write_text(f"time_{names[1]},x,y,z\n" + "".join(f"{t},{i},0,9.81\n" for i, t in enumerate(t_acc)))
    got = read_imu([gyro, acc], optional=("acc",))
    np.testing.assert_allclose(got.t, k * 0.01, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(got.acc[:, 0], k)  # every row its own sample, none dropped


def test_a_sensor_file_on_another_clock_is_refused_not_dropped(tmp_path):
    gyro, mag = tmp_path / "Gyroscope.csv", tmp_path / "Magnetometer.csv"
    gyro.write_text("time,x,y,z\n" + "".join(f"{1718030736000000000 + k * 10_000_000},0,0,0\n" for k in range(50)))
    mag.write_text("time,x,y,z\n" + "".join(f"{k * 100_000_000},20,0,-40\n" for k in range(5)))  # since boot
    with pytest.raises(ValueError, match=r"Magnetometer.csv: none of its 5 samples .* do not share a clock"):
        read_imu([gyro, mag], optional=("mag",))
