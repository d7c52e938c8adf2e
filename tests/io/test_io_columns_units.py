"""Column detection and units: the names loggers write, and the magnitudes that betray a wrong unit."""

import numpy as np
import pytest

from strapdown.io.columns import detect_rate, detect_time, detect_vector, pick_vector, split_name
from strapdown.io.plausibility import check_plausible
from strapdown.io.units import GRAVITY, parse_unit, scale


@pytest.mark.parametrize(
    ("names", "kind", "expected", "unit"),
    [
        (["t", "gx", "gy", "gz", "ax", "ay", "az"], "gyro", ("gx", "gy", "gz"), None),
        (["time", "gyr_x", "gyr_y", "gyr_z"], "gyro", ("gyr_x", "gyr_y", "gyr_z"), None),
        (["Gyro X [deg/s]", "Gyro Y [deg/s]", "Gyro Z [deg/s]"], "gyro", None, "deg/s"),
        (["gyro_x_dps", "gyro_y_dps", "gyro_z_dps"], "gyro", None, "deg/s"),
        (["wx", "wy", "wz"], "gyro", ("wx", "wy", "wz"), None),
        (["IMU_Acc_X", "IMU_Acc_Y", "IMU_Acc_Z"], "acc", None, None),
        (["accel_x_g", "accel_y_g", "accel_z_g"], "acc", None, "g"),
        (["ax m/s^2", "ay m/s^2", "az m/s^2"], "acc", None, "m/s2"),
        (["mag_x (µT)", "mag_y (µT)", "mag_z (µT)"], "mag", None, "uT"),
        (["bx", "by", "bz"], "mag", ("bx", "by", "bz"), None),
        (["Gyro X [°/s]", "Gyro Y [°/s]", "Gyro Z [°/s]"], "gyro", None, "deg/s"),  # not "/s", read as rad/s
        (["gyro_X_rad/sec", "gyro_Y_rad/sec", "gyro_Z_rad/sec"], "gyro", None, "rad/s"),
        (["acc_x [m/s²]", "acc_y [m/s²]", "acc_z [m/s²]"], "acc", None, "m/s2"),
    ],
)
def test_detects_component_columns(names, kind, expected, unit):
    fields = dict.fromkeys(names, 1)
    pick = detect_vector(kind, fields)
    assert pick is not None
    assert len(pick.fields) == 3 and all(f in names for f in pick.fields)
    if expected:
        assert pick.fields == expected
    # x, y, z in that order whatever the file's order
    assert [split_name(f, kind)[0][-1] for f in pick.fields] == ["x", "y", "z"]
    assert pick.unit_hint == unit


def test_detects_arrays_in_mat_and_hdf5_layouts():
    fields = {"imu_gyr": 3, "imu_acc": 3, "imu_mag": 3, "opt_quat": 4, "movement": 1}
    assert detect_vector("gyro", fields).fields == ("imu_gyr",)
    assert detect_vector("acc", fields).fields == ("imu_acc",)
    assert detect_vector("mag", fields).fields == ("imu_mag",)
    assert detect_vector("gyro", {"sensors/imu/gyro": 3}).fields == ("sensors/imu/gyro",)
    assert detect_vector("mag", {"gx": 1, "gy": 1, "gz": 1}) is None


def test_ambiguous_columns_ask_for_an_option():
    with pytest.raises(ValueError, match="--gyro"):
        detect_vector("gyro", {"gx": 1, "gy": 1, "gz": 1, "gyro": 3})


def test_time_and_rate_detection_with_units():
    assert detect_time({"timestamp_ns": 1, "gx": 1}).unit_hint == "ns"
    assert detect_time({"Time [ms]": 1}).unit_hint == "ms"
    assert detect_time({"t": 1}).fields == ("t",)
    assert detect_time({"gx": 1}) is None
    assert detect_rate({"sampling_rate": 285.714, "n": 3.0}) == 285.714
    assert detect_rate({"fs": 100.0}) == 100.0


def test_pick_vector_names_the_option_and_lists_the_columns():
    fields = {"t": 1, "wx": 1, "wy": 1}
    with pytest.raises(ValueError, match=r"no column 'wz' \(--gyro\); the file has: t, wx, wy"):
        pick_vector("wx,wy,wz", fields, "--gyro")
    with pytest.raises(ValueError, match="must name 3 columns"):
        pick_vector("wx,wy", fields, "--gyro")
    assert pick_vector("g", {"g": 3}, "--gyro").fields == ("g",)


def test_unit_aliases_and_factors():
    assert parse_unit("gyro", "dps") == parse_unit("gyro", "Deg/S") == "deg/s"
    assert parse_unit("acc", "m/s²") == "m/s2"
    assert parse_unit("mag", "G") == "gauss"
    assert scale("gyro", "deg/s") == pytest.approx(np.pi / 180, rel=1e-15)
    assert scale("mag", "gauss") == 100.0  # 1 G = 100 µT
    assert scale("mag", "nT") == 1e-3
    assert scale("acc", "g") == GRAVITY
    with pytest.raises(ValueError, match="unknown gyro unit 'rpm'"):
        parse_unit("gyro", "rpm")


def test_plausibility_flags_wrong_units_and_nothing_else():
    rng = np.random.default_rng(0)
    motion_deg = rng.normal(0, 200.0, (5000, 3))  # a lively motion in deg/s
    assert "look like deg/s" in check_plausible("gyro", motion_deg, "rad/s")
    assert check_plausible("gyro", np.radians(motion_deg), "rad/s") is None
    assert check_plausible("gyro", motion_deg, "deg/s") is None
    # increments of 0.01 rad at 100 Hz are 1 rad/s: fine; the same numbers at 10 kHz are 100 rad/s
    inc = np.full((100, 3), 0.01 / np.sqrt(3))
    assert check_plausible("gyro", inc, "rad/s", rate_hz=100.0) is None
    assert check_plausible("gyro", inc, "rad/s", rate_hz=1e4) is not None

    rest_g = np.tile([0.01, -0.02, 1.0], (100, 1))
    assert "look like g" in check_plausible("acc", rest_g, "m/s2")
    assert "look like m/s2" in check_plausible("acc", rest_g * GRAVITY, "g")
    assert check_plausible("acc", rest_g * GRAVITY, "m/s2") is None
    counts = np.tile([0.0, 0.0, 16384.0], (10, 1))  # raw LSB: no unit fits, and |a| is far from g (issue 12)
    assert "raw sensor counts" in check_plausible("acc", counts, "m/s2")

    field_gauss = np.tile([0.2, 0.0, -0.4], (10, 1))
    assert "look like gauss" in check_plausible("mag", field_gauss, "uT")
    assert "look like nT" in check_plausible("mag", field_gauss * 1e5, "uT")
    assert check_plausible("mag", field_gauss * 100, "uT") is None


def test_a_unit_in_brackets_that_is_not_known_is_not_taken_for_si():
    # passed on as written, so that using it stops with "unknown unit" instead of reading °C as rad/s
    pick = detect_vector("gyro", dict.fromkeys(["Gyro X [°C]", "Gyro Y [°C]", "Gyro Z [°C]"], 1))
    assert pick.unit_hint == "°C"
    with pytest.raises(ValueError, match="unknown gyro unit '°C'"):
        scale("gyro", pick.unit_hint)
    # a unit of another quantity in another column's name is no concern of this one
    assert split_name("Acc X [m/s^2]", "gyro") == ("accx", None)


def test_a_slashed_unit_is_no_hdf5_path():
    # "rad/sec" once left "sec" as the name, a time column; an HDF5 path still names its last segment
    fields = dict.fromkeys(["time [s]", "gyro_X_rad/sec", "gyro_Y_rad/sec", "gyro_Z_rad/sec"], 1)
    assert detect_time(fields).fields == ("time [s]",)
    assert split_name("imu/t", "time") == ("t", None)
