"""What the file commands write and how they are told about frames, gaps and parameters: the CLI as a subprocess.

Inputs are written here from closed forms (a still IMU, level or tilted, with the readings physics gives it), so
every expected number comes from physics, not from the code under test.
"""

import re

import numpy as np
import pytest

from conftest import strapdown_cli
from strapdown.fusion import AttitudeParams
from strapdown.io import read_metadata, read_table, write_table

G = 9.80665
# The field at 45 deg dip pointing north: (north, east, down) in µT
B_NED = np.array([30.0, 0.0, 30.0])


run = strapdown_cli


def ok(*args):
    res = run(*args)
    assert res.returncode == 0, res.stderr
    return res


def still(n=600, rate=100.0, *, roll_deg=0.0, axes="FRD", t0=0.0, gyro_bias=(0.0, 0.0, 0.0), seed=0):
    """A still IMU, level or rolled about its forward axis, facing north, read in FRD or FLU axes.

    At rest the accelerometer reads minus gravity (specific force: +g up); in FRD axes of a level body, z points
    down, so az = -g.  Rolled by phi about forward, the body's y axis dips by phi: f_FRD = g (0, sin phi, -cos phi).
    The magnetometer reads the NED field rotated into the body the same way.
    """
    rng = np.random.default_rng(seed)
    phi = np.radians(roll_deg)
    c, s = np.cos(phi), np.sin(phi)
    # body-from-NED for a roll phi about x (FRD): the transpose of the body-to-NED rotation
    r = np.array([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])
    acc = r @ np.array([0.0, 0.0, -G])
    mag = r @ B_NED
    if axes == "FLU":  # y and z flip
        flip = np.array([1.0, -1.0, -1.0])
        acc, mag, gyro_bias = acc * flip, mag * flip, np.asarray(gyro_bias) * flip
    cols = {"t": t0 + np.arange(n) / rate}
    noise = rng.normal(0.0, 1e-4, (n, 9))
    for i, a in enumerate("xyz"):
        cols[f"g{a}"] = gyro_bias[i] + noise[:, i]
    for i, a in enumerate("xyz"):
        cols[f"a{a}"] = acc[i] + noise[:, 3 + i]
    for i, a in enumerate("xyz"):
        cols[f"m{a}"] = mag[i] + noise[:, 6 + i]
    return cols


def signed(angle):
    return (np.asarray(angle) + 180.0) % 360.0 - 180.0


# ------------------------------------------------------------------------------------------------ frames and axes
@pytest.mark.parametrize(
    ("options", "yaw", "body"),
    [
        (["--body", "FRD", "--frame", "NED"], 0.0, "FRD"),  # aviation: north is yaw 0
        (["--body", "FRD", "--frame", "ENU"], 90.0, "FLU"),  # ROS REP 103: yaw 0 faces east, north is +90
        (["--body", "FRD", "--frame", "ENU", "--out-body", "RFU"], 0.0, "RFU"),  # x right: north is yaw 0
    ],
)
def test_a_level_frd_drone_is_level_in_any_frame_once_its_axes_are_declared(tmp_path, options, yaw, body):
    src = write_table(tmp_path / "drone.csv", still())
    ok("estimate", src, "-o", tmp_path / "att.parquet", *options)
    table = read_table(tmp_path / "att.parquet")
    assert abs(table["roll_deg"][-1]) < 0.1 and abs(table["pitch_deg"][-1]) < 0.1
    assert abs(signed(table["yaw_deg"][-1] - yaw)) < 0.5
    meta = read_metadata(tmp_path / "att.parquet")
    assert meta["frame"] == options[3] and meta["body"] == body and meta["sensor_axes"] == "FRD"


def test_undeclared_frd_axes_in_enu_show_the_drone_upside_down_and_say_the_axes_were_assumed(tmp_path):
    # the silent failure of issue 12: without --body, FRD readings taken for FLU read a level drone as rolled 180°
    src = write_table(tmp_path / "drone.csv", still())
    ok("estimate", src, "-o", tmp_path / "att.parquet")
    table = read_table(tmp_path / "att.parquet")
    assert abs(abs(table["roll_deg"][-1]) - 180.0) < 0.1
    assert "assumed" in read_metadata(tmp_path / "att.parquet")["sensor_axes"]


def test_a_rolled_body_shows_its_roll_with_flu_axes_too(tmp_path):
    src = write_table(tmp_path / "flu.parquet", still(roll_deg=30.0, axes="FLU"))
    for frame, sign in (("ENU", 1.0), ("NED", 1.0)):  # roll about forward is the same angle in FLU/ENU and FRD/NED
        ok("estimate", src, "-o", tmp_path / f"{frame}.parquet", "--body", "FLU", "--frame", frame)
        roll = read_table(tmp_path / f"{frame}.parquet")["roll_deg"][-1]
        assert abs(roll - sign * 30.0) < 0.1, frame


def test_integrate_turns_the_readings_into_the_declared_body_axes(tmp_path):
    # 90 deg/s about FRD's z (down) for 1 s is a -90 deg yaw about FLU's z (up)
    n = 101
    cols = {"t": np.arange(n) * 0.01, "gx": np.zeros(n), "gy": np.zeros(n), "gz": np.full(n, np.pi / 2)}
    src = write_table(tmp_path / "spin.parquet", cols)
    ok("integrate", src, "-o", tmp_path / "flu.parquet", "--body", "FRD", "--out-body", "FLU", "--euler", "ZYX")
    ok("integrate", src, "-o", tmp_path / "frd.parquet", "--body", "FRD")
    assert signed(read_table(tmp_path / "flu.parquet")["yaw_deg"][-1]) == pytest.approx(-90.0, abs=1e-9)
    assert signed(read_table(tmp_path / "frd.parquet")["yaw_deg"][-1]) == pytest.approx(90.0, abs=1e-9)
    meta = read_metadata(tmp_path / "frd.parquet")
    assert meta["body"] == "FRD" and meta["frame"].startswith("inertial")


def test_bad_axes_are_refused_with_the_option_named(tmp_path):
    src = write_table(tmp_path / "a.csv", still(50))
    res = run("estimate", src, "--body", "FRU")
    assert res.returncode == 1 and "--body FRU" in res.stderr and "left-handed" in res.stderr
    res = run("estimate", src, "--frame", "NUE")  # z east: no frame for a tilt from gravity
    assert res.returncode == 2 and "--frame" in res.stderr and "up (U) or down (D)" in res.stderr


def test_any_vertical_frame_is_taken(tmp_path):
    # a level FRD drone facing north in "west, south, up" axes (z up): level, and yaw -90, F pointing along -y
    src = write_table(tmp_path / "a.parquet", still(300))
    ok("estimate", src, "-o", tmp_path / "wsu.parquet", "--body", "FRD", "--frame", "wsu")
    table, meta = read_table(tmp_path / "wsu.parquet"), read_metadata(tmp_path / "wsu.parquet")
    assert abs(table["roll_deg"][-1]) < 0.1 and abs(table["pitch_deg"][-1]) < 0.1
    assert abs(signed(table["yaw_deg"][-1] + 90.0)) < 0.5 and (meta["frame"], meta["body"]) == ("WSU", "FLU")


# ------------------------------------------------------------------------------------------------ time and metadata
def test_t_counts_from_the_first_sample_and_the_origin_is_stored(tmp_path):
    cols = still(300, t0=1000.25)
    src = write_table(tmp_path / "late.parquet", cols)
    ok("estimate", src, "-o", tmp_path / "att.h5")
    table = read_table(tmp_path / "att.h5")
    np.testing.assert_array_equal(table["t"], cols["t"] - cols["t"][0])
    meta = read_metadata(tmp_path / "att.h5")
    assert float(meta["time_origin"]) == 1000.25 and meta["time_origin_unit"] == "s"
    assert meta["time_unit"] == "s" and meta["quaternion"].startswith("w,x,y,z")
    assert meta["angle_unit"] == "deg" and meta["bias_unit"] == "deg/s"


def test_integer_epoch_nanoseconds_become_seconds_from_the_first_sample_with_the_epoch_kept(tmp_path):
    # the silent failure of issue 12: epoch ns taken as seconds gave t up to 2e11 and meaningless attitudes
    n, t0 = 300, 1_718_030_736_872_695_300
    lines = ["time,gx,gy,gz"] + [f"{t0 + k * 10_000_000},0,0,{np.pi / 2!r}" for k in range(n)]  # 100 Hz, 90 deg/s
    (tmp_path / "ns.csv").write_text("\n".join(lines) + "\n")
    ok("integrate", tmp_path / "ns.csv", "-o", tmp_path / "att.parquet")
    table, meta = read_table(tmp_path / "att.parquet"), read_metadata(tmp_path / "att.parquet")
    np.testing.assert_allclose(table["t"], np.arange(n) * 0.01, rtol=0, atol=1e-12)
    assert table["yaw_deg"][-1] == pytest.approx(90.0 * 2.99, abs=1e-9)
    assert (meta["time_origin"], meta["time_origin_unit"], meta["time_origin_kind"]) == (str(t0), "ns", "epoch")


def test_every_output_format_carries_frame_body_and_units(tmp_path):
    src = write_table(tmp_path / "a.parquet", still(200))
    for suffix in ("parquet", "h5", "mat"):
        ok("estimate", src, "-o", tmp_path / f"att.{suffix}", "--body", "FRD", "--frame", "NED", "--radians")
        meta = read_metadata(tmp_path / f"att.{suffix}")
        assert (meta["frame"], meta["body"], meta["angle_unit"], meta["bias_unit"]) == ("NED", "FRD", "rad", "rad/s")


def test_mat_output_has_an_n_by_4_q_and_only_valid_matlab_names(tmp_path):
    import scipy.io

    src = write_table(tmp_path / "a.parquet", still(200))
    ok("estimate", src, "-o", tmp_path / "att.mat", "--euler", "ZXZ")
    data = scipy.io.loadmat(tmp_path / "att.mat")
    names = [n for n in data if not n.startswith("__")]
    assert all(re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,62}", n) for n in names), names
    q = data["q"]
    assert q.shape == (200, 4)
    np.testing.assert_array_equal(q, np.column_stack([data[c].ravel() for c in ("qw", "qx", "qy", "qz")]))
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)


# ------------------------------------------------------------------------------------------------ flags and bias
def test_named_flag_columns_mark_rest_and_the_rejected_accelerometer(tmp_path):
    cols = still(600)
    jolt = slice(300, 310)  # ten rows of 3 g: a knock, which a gate of 2 m/s² from g rejects
    for a in "xyz":
        cols[f"a{a}"][jolt] *= 3.0
    src = write_table(tmp_path / "knock.parquet", cols)
    ok("estimate", src, "-o", tmp_path / "tilt.parquet", "-e", "tilt", "-p", "acc_gate=2", "--body", "FRD")
    table = read_table(tmp_path / "tilt.parquet")
    rejected = table["acc_rejected"].astype(bool)
    assert rejected[jolt].all() and not rejected[:300].any() and not rejected[310:].any()
    np.testing.assert_array_equal(rejected, (table["flags"].astype(int) & 2) != 0)
    ok("estimate", src, "-o", tmp_path / "att.parquet", "--body", "FRD")
    rest = read_table(tmp_path / "att.parquet")["rest"].astype(bool)
    # still from the start: rest is declared after rest_time (1.5 s) and not before
    assert not rest[:100].any() and rest[250:300].all()


def test_a_bias_at_its_limit_is_flagged_and_warned_about_once(tmp_path):
    bias = np.radians(5.0)  # 5 deg/s about forward: observable from the tilt, beyond the default 2 deg/s limit
    src = write_table(tmp_path / "biased.parquet", still(6000, gyro_bias=(bias, 0.0, 0.0)))
    res = ok("estimate", src, "-o", tmp_path / "att.parquet", "--body", "FRD", "--6d", "-q")
    assert res.stderr.count("warning:") == 1 and "bias_limit" in res.stderr
    table = read_table(tmp_path / "att.parquet")
    # at the limit (an estimator that clips) or beyond it (one whose limit is a prior): flagged either way
    assert table["bias_at_limit"][-1] and table["bias_x_deg_s"][-1] >= 2.0 * (1 - 1e-9)
    # the limit given in the output's unit: the bias is learnt, and nothing is said
    res = ok("estimate", src, "-o", tmp_path / "free.parquet", "--body", "FRD", "--6d", "-p", "bias_limit_deg_s=10")
    assert "warning:" not in res.stderr
    free = read_table(tmp_path / "free.parquet")
    assert not free["bias_at_limit"][-1000:].any()
    assert free["bias_x_deg_s"][-1] == pytest.approx(5.0, abs=0.25)


def test_parameters_in_degrees_equal_the_same_in_radians(tmp_path):
    src = write_table(tmp_path / "a.parquet", still(300))
    ok("estimate", src, "-o", tmp_path / "deg.parquet", "-p", "rest_gyro_deg_s=3", "-p", "mag_dip_threshold_deg=20")
    radians = ["-p", f"rest_gyro={3 * np.pi / 180!r}", "-p", f"mag_dip_threshold={20 * np.pi / 180!r}"]
    ok("estimate", src, "-o", tmp_path / "rad.parquet", *radians)
    ok("estimate", src, "-o", tmp_path / "default.parquet")
    a, b = read_table(tmp_path / "deg.parquet"), read_table(tmp_path / "rad.parquet")
    for name in ("qw", "qx", "qy", "qz", "bias_x_deg_s"):
        np.testing.assert_allclose(a[name], b[name], rtol=0, atol=1e-12)
    res = run("estimate", src, "-p", "tau_acc_deg=2")
    assert res.returncode == 2 and "tau_acc" in res.stderr and "not an angle" in res.stderr
    listing = ok("estimate", "--list-params", "-e", "tilt").stdout
    assert re.search(r"bias_limit\s+0.0349066 rad/s\s+= bias_limit_deg_s=2\b", listing)


# ------------------------------------------------------------------------------------------------ gaps
def _with_gap(tmp_path):
    """3 s level, a 5 s gap, then 3 s rolled 30 deg (FRD)."""
    first = still(300)
    second = still(300, roll_deg=30.0, t0=8.0, seed=1)
    cols = {k: np.concatenate([first[k], second[k]]) for k in first}
    return write_table(tmp_path / "gap.parquet", cols), cols


def test_a_gap_stops_estimate_with_on_gap_error(tmp_path):
    src, _ = _with_gap(tmp_path)
    res = run("estimate", src, "--body", "FRD", "--on-gap", "error")
    assert res.returncode == 1 and "gap of 5.01 s" in res.stderr and "--on-gap bridge" in res.stderr
    assert not (tmp_path / "gap.estimate.csv").exists()


def test_a_long_gap_restarts_estimate_by_default_with_a_warning(tmp_path):
    src, _ = _with_gap(tmp_path)
    res = ok("estimate", src, "-o", tmp_path / "att.parquet", "--body", "FRD", "--frame", "NED")
    # a quiet gyro bridges up to 1 deg / (0.5 deg/s + noise): with this file's 1e-4 rad/s of noise 1.98 s; 5 s
    # is longer, so the run starts afresh
    limit = np.radians(1.0) / (np.radians(0.5) + 1e-4)
    assert (
        "warning: 1 gap(s)" in res.stderr
        and f"longer than {limit:.3g} s" in res.stderr
        and "--on-gap error" in res.stderr
    )
    table = read_table(tmp_path / "att.parquet")
    np.testing.assert_array_equal(table["segment"], np.repeat([0, 1], 300))
    assert not table["gap"].any()
    assert abs(table["roll_deg"][300] - 30.0) < 0.1


def test_a_short_gap_is_bridged_by_default_with_a_gap_column(tmp_path):
    first = still(300)
    second = still(300, t0=3.5, seed=1)  # 0.5 s without samples: 51 periods, within the 2 s bridge
    cols = {k: np.concatenate([first[k], second[k]]) for k in first}
    src = write_table(tmp_path / "short.parquet", cols)
    res = ok("estimate", src, "-o", tmp_path / "att.parquet", "--body", "FRD", "--frame", "NED")
    assert "1 gap(s) over 10 sample periods bridged" in res.stderr and "2.99 s -> 3.5 s" in res.stderr
    table = read_table(tmp_path / "att.parquet")
    assert np.flatnonzero(table["gap"]).tolist() == [300]  # the first row after the gap
    assert (table["segment"] == 0).all()
    # the same run with the gap restarting it: bridged, the estimator's state (here its heading) carries over
    ok("estimate", src, "-o", tmp_path / "r.parquet", "--body", "FRD", "--frame", "NED", "--on-gap", "restart")
    assert (read_table(tmp_path / "r.parquet")["segment"] == np.repeat([0, 1], 300)).all()
    # --bridge sets the limit: 0.1 s restarts this gap
    ok("estimate", src, "-o", tmp_path / "b.parquet", "--body", "FRD", "--frame", "NED", "--bridge", "0.1")
    assert read_table(tmp_path / "b.parquet")["segment"][-1] == 1


def test_a_plausibility_check_comes_before_the_gap_refusal(tmp_path):
    src, cols = _with_gap(tmp_path)
    cols = {**cols, "ax": cols["ax"] / G, "ay": cols["ay"] / G, "az": cols["az"] / G}  # g declared m/s2
    src = write_table(tmp_path / "g.parquet", cols)
    res = run("estimate", src, "--body", "FRD", "--on-gap", "error")
    assert res.returncode == 1 and "--acc-unit g" in res.stderr and "gap" not in res.stderr


def test_on_gap_restart_starts_the_estimator_afresh_in_one_file(tmp_path):
    src, cols = _with_gap(tmp_path)
    res = ok("estimate", src, "-o", tmp_path / "att.parquet", "--body", "FRD", "--frame", "NED", "--on-gap", "restart")
    assert "1 gap(s)" in res.stderr and "2.99 s -> 8 s" in res.stderr  # the last row before it, the first after
    table = read_table(tmp_path / "att.parquet")
    np.testing.assert_array_equal(table["segment"], np.repeat([0, 1], 300))
    np.testing.assert_array_equal(table["t"], cols["t"])
    # started afresh from its own first sample: the new tilt at once, not the old one slowly pulled over
    assert abs(table["roll_deg"][300] - 30.0) < 0.1 and abs(table["roll_deg"][299]) < 0.1


def test_on_gap_split_writes_a_file_per_segment(tmp_path):
    src, cols = _with_gap(tmp_path)
    res = ok("estimate", src, "-o", tmp_path / "att.csv", "--body", "FRD", "--frame", "NED", "--on-gap", "split")
    assert "in 2 files" in res.stdout
    one, two = read_table(tmp_path / "att.csv"), read_table(tmp_path / "att-2.csv")
    np.testing.assert_array_equal(one["t"], cols["t"][:300])
    np.testing.assert_array_equal(two["t"], cols["t"][300:])  # one time scale for the whole recording
    assert abs(two["roll_deg"][0] - 30.0) < 0.1


def test_integrate_restarts_from_q0_after_a_gap(tmp_path):
    n = 200
    t = np.concatenate([np.arange(n) * 0.01, 10.0 + np.arange(n) * 0.01])
    cols = {"t": t, "gx": np.full(2 * n, np.pi / 2), "gy": np.zeros(2 * n), "gz": np.zeros(2 * n)}
    src = write_table(tmp_path / "spin.parquet", cols)
    ok("integrate", src, "-o", tmp_path / "att.parquet", "--on-gap", "restart", "--q0", "0,0,10")
    table = read_table(tmp_path / "att.parquet")
    roll = table["roll_deg"]
    # 90 deg/s from 10 deg: row k of a segment is at 10 + 0.9 k deg (the last sample before the gap is unused)
    expected = signed(10.0 + 0.9 * np.arange(n))
    np.testing.assert_allclose(signed(roll[:n]), expected, atol=1e-9)
    np.testing.assert_allclose(signed(roll[n:]), expected, atol=1e-9)


# ------------------------------------------------------------------------------------------------ real layouts
DATA = __import__("pathlib").Path(__file__).resolve().parents[1] / "data"
PX4_LOG = DATA / "px4" / "sample_logging_tagged_and_default_params.ulg"


def test_a_phone_export_given_as_its_files_or_its_folder_lies_flat(tmp_path):
    import sim_exports as sim

    data = sim.phone_at_rest(duration=10.0)  # flat on a table, top to the north: simulated, Sensor Logger layout
    folder = sim.sensor_logger(tmp_path / "export", data)
    files = [folder / n for n in ("Gyroscope.csv", "TotalAcceleration.csv", "Magnetometer.csv")]
    from conftest import rotation_angle
    from strapdown import change_frame
    from strapdown.fusion import AttitudeEstimator
    from strapdown.io import read_imu

    got = read_imu(folder, optional=("acc", "mag"))  # the library on the same readings, in the phone's axes
    q_rfu = AttitudeEstimator().update(got.gyro, got.acc, got.mag, t=got.t).q
    library_flu = change_frame(q_rfu, body_from="RFU", body_to="FLU")
    ok("estimate", *files, "-o", tmp_path / "files.parquet")
    ok("estimate", folder, "-o", tmp_path / "folder.parquet")
    ok("estimate", folder, "-o", tmp_path / "folder.mat")
    import scipy.io

    # the epoch in ns is past float64's 2**53: a MATLAB file keeps it exact, as text
    assert str(scipy.io.loadmat(tmp_path / "folder.mat")["time_origin"][0]) == str(sim.EPOCH_NS)
    for name in ("files", "folder"):
        table = read_table(tmp_path / f"{name}.parquet")
        late = table["t"] > table["t"][-1] - 1.0
        assert np.abs(table["pitch_deg"][late]).max() < 2.0 and np.abs(table["roll_deg"][late]).max() < 2.0
        # Android's axes (RFU) turned into ENU's FLU: the library's attitude of the phone's own axes, re-expressed
        # (the simulated consumer magnetometer's hard iron puts the heading off north; it is the same in both)
        q = np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])
        assert rotation_angle(q, library_flu).max() < 1e-9
        meta = read_metadata(tmp_path / f"{name}.parquet")
        assert (meta["frame"], meta["body"], meta["sensor_axes"]) == ("ENU", "FLU", "RFU")
        assert meta["time_origin_kind"] == "epoch" and int(meta["time_origin"]) == sim.EPOCH_NS
        assert table["t"][0] == 0.0


def test_a_px4_log_goes_in_with_no_options_in_its_own_frames(tmp_path):
    from strapdown.evaluate.metrics import attitude_errors
    from strapdown.io import read_reference

    res = ok("estimate", PX4_LOG, "-o", tmp_path / "att.parquet")
    assert "read:" in res.stderr
    meta = read_metadata(tmp_path / "att.parquet")
    assert (meta["frame"], meta["body"], meta["sensor_axes"]) == ("NED", "FRD", "FRD")
    assert (meta["time_origin"], meta["time_origin_unit"], meta["time_origin_kind"]) == ("284000", "us", "boot")
    table = read_table(tmp_path / "att.parquet")
    q = np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])
    ref = read_reference(PX4_LOG)  # the log's own estimator, on the same time origin
    keep = (ref.t > 2.0) & (ref.t <= table["t"][-1])
    rows = np.searchsorted(table["t"], ref.t[keep])
    assert np.degrees(attitude_errors(q[rows], ref.q[keep])["inclination"]).max() < 1.0


def test_sensors_at_lower_rates_are_refused_by_an_estimator_that_needs_every_row():
    err = run("estimate", PX4_LOG, "-e", "mahony").stderr  # its magnetometer runs at a fraction of the gyro rate
    assert "mag" in err and "-e attitude" in err
    res = run("estimate", PX4_LOG, "-e", "mahony", "--6d", "-o", "/dev/null", "--format", "csv")
    assert res.returncode == 0, res.stderr


# ------------------------------------------------------------------------------------------------ plot --truth
def test_plot_truth_in_other_frames_is_re_expressed_and_said_so(tmp_path):
    from conftest import rotation_angle
    from strapdown.evaluate.metrics import attitude_errors
    from strapdown.io.pipelines.truth import align_truth

    ok("simulate", tmp_path / "sim.parquet", "--scenario", "rocking", "--duration", 20)  # truth in ENU, FLU axes
    ok("estimate", tmp_path / "sim.parquet", "-o", tmp_path / "ned.parquet", "--frame", "NED", "--body", "FLU")
    res = ok("plot", tmp_path / "ned.parquet", "--truth", tmp_path / "sim.parquet", "--out", tmp_path / "fig")
    assert "truth re-expressed from ENU/FLU to NED/FRD" in res.stderr
    assert sorted(p.name for p in (tmp_path / "fig").iterdir())[:2] == ["ned_angles.png", "ned_bias.png"]
    # the numbers behind the error figure: small once re-expressed, a half turn as the files stand
    table = read_table(tmp_path / "ned.parquet")
    q = np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])
    aligned = align_truth(tmp_path / "ned.parquet", tmp_path / "sim.parquet")
    # a few degrees: the simulated field's 4 deg declination in the heading, the rocking's accelerations in the tilt
    assert np.degrees(rotation_angle(q, aligned.q)).max() < 8.0
    assert np.degrees(attitude_errors(q, aligned.q)["inclination"]).max() < 5.0
    raw = read_table(tmp_path / "sim.parquet")
    q_true = np.column_stack([raw[c] for c in ("qw_true", "qx_true", "qy_true", "qz_true")])
    assert np.median(np.degrees(rotation_angle(q, q_true))) > 60.0


def test_plot_truth_without_frames_is_refused_until_they_are_declared(tmp_path):
    ok("simulate", tmp_path / "sim.parquet", "--scenario", "rocking", "--duration", 10)
    raw = read_table(tmp_path / "sim.parquet")
    bare = write_table(tmp_path / "ref.csv", {"t": raw["t"], **{c: raw[f"{c}_true"] for c in ("qw", "qx", "qy", "qz")}})
    ok("estimate", tmp_path / "sim.parquet", "-o", tmp_path / "att.parquet", "--body", "FLU")
    res = run("plot", tmp_path / "att.parquet", "--truth", bare, "--out", tmp_path / "fig")
    assert res.returncode == 1 and "--truth-frame" in res.stderr and "does not say" in res.stderr
    assert not (tmp_path / "fig").exists() or not list((tmp_path / "fig").iterdir())
    ok("plot", tmp_path / "att.parquet", "--truth", bare, "--truth-frame", "ENU", "--truth-body", "FLU", "--out",
       tmp_path / "fig")  # fmt: skip


def test_a_px4_logs_own_attitude_is_a_truth_for_plot(tmp_path):
    from conftest import rotation_angle
    from strapdown.io.pipelines.truth import align_truth

    ok("estimate", PX4_LOG, "-o", tmp_path / "att.csv")
    res = ok("plot", tmp_path / "att.csv", "--truth", PX4_LOG, "--out", tmp_path / "fig")
    assert "interpolated" in res.stderr and res.stdout.count("written:") >= 2
    aligned = align_truth(tmp_path / "att.csv", PX4_LOG)
    table = read_table(tmp_path / "att.csv")
    q = np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])[aligned.rows]
    late = table["t"][aligned.rows] > 2.0
    # the log's estimator and ours agree on the tilt at rest; the whole error (with heading) stays within degrees
    assert np.degrees(rotation_angle(q[late], aligned.q[aligned.rows][late])).max() < 10.0


def test_compare_runs_every_method_against_a_px4_logs_own_attitude():
    from strapdown import METHODS

    out = ok("compare", "--log", PX4_LOG).stdout
    rows = {line.split()[0]: line.split() for line in out.splitlines() if line and line.split()[0] in METHODS}
    assert set(rows) == set(METHODS)
    # the log's gyro integrated from its own first attitude stays near its estimator's attitude: a real gyro's bias
    # and noise over the log's seconds, so not zero, and well under a degree
    final = float(rows["exact"][1])
    assert 1e-3 < final < 1.0


def test_evaluate_grid_takes_degrees_with_the_unit_in_the_name(tmp_path):
    import scipy.io

    from strapdown.simulate import RandomMotion, sample

    data = sample(RandomMotion(duration=10.0, seed=3), 100.0, gyro="average", reference="ENU", body="FLU")
    movement = np.ones((len(data.q_true) - 1, 1), dtype=np.uint8)
    scipy.io.savemat(
        tmp_path / "01_trial.mat",
        {"imu_gyr": data.gyro, "imu_acc": data.acc, "imu_mag": data.mag, "opt_quat": data.q_true[1:],
         "movement": movement, "sampling_rate": np.array([[100.0]]), "opt_pos": np.zeros((len(movement), 3))},
    )  # fmt: skip
    deg = ok("evaluate", tmp_path, "-e", "tilt", "-g", "bias_limit_deg_s=1,4").stdout
    rad = ok("evaluate", tmp_path, "-e", "tilt", "-g", f"bias_limit={np.pi / 180!r},{4 * np.pi / 180!r}").stdout

    def numbers(text):
        return [float(x) for x in re.findall(r"\b\d+\.\d+\b", text)]

    assert numbers(deg) and numbers(deg) == pytest.approx(numbers(rad), rel=1e-9)
    assert "not an angle" in run("evaluate", tmp_path, "-g", "tau_acc_deg=1,2").stderr


def test_an_integration_of_a_px4_log_plots_against_its_own_attitude(tmp_path):
    # an integration's reference is its own start: no frames to check, but the truth is still put on its rows
    ok("integrate", PX4_LOG, "-o", tmp_path / "int.parquet", "--max-gap", "0")
    res = ok("plot", tmp_path / "int.parquet", "--truth", PX4_LOG, "--out", tmp_path / "fig")
    assert "not checked" in res.stderr and "interpolated" in res.stderr
    assert (tmp_path / "fig" / "int_errors.png").read_bytes()[:4] == b"\x89PNG"


def test_one_file_with_gyro_and_acc_beside_a_later_magnetometer_file(tmp_path):
    """An ArduPilot-style IMU table (gyro and accelerometer in one file) and a MAG file that starts 2 s later."""
    cols = still(600)
    write_table(tmp_path / "IMU.csv", {k: cols[k] for k in ("t", "gx", "gy", "gz", "ax", "ay", "az")})
    write_table(tmp_path / "MAG.csv", {"t": cols["t"][200::4], **{k: cols[k][200::4] for k in ("mx", "my", "mz")}})
    out = tmp_path / "att.parquet"
    ok("estimate", tmp_path / "IMU.csv", tmp_path / "MAG.csv", "-o", out, "--body", "FRD", "--frame", "NED")
    table = read_table(out)
    free = np.asarray(table["heading_free"], dtype=bool)
    # the heading is free up to the end of the block update (rows 1-b, b+1-2b, ... of b = ceil(100 Hz /
    # update_rate)) that first reads the field (row 200); it shows from the next row
    b = int(np.ceil(100.0 / AttitudeParams().update_rate))
    end = -(-200 // b) * b
    np.testing.assert_array_equal(free, np.arange(600) <= end)
    assert abs(signed(table["yaw_deg"][end + 1])) < 0.1  # facing north, once the field has been read
    # 6D: every row's heading is free
    ok("estimate", tmp_path / "IMU.csv", "-o", out, "--body", "FRD", "--frame", "NED")
    assert np.asarray(read_table(out)["heading_free"], dtype=bool).all()


def _phone(tmp_path, **acc_changes):
    cols = still(600)
    write_table(tmp_path / "Gyroscope.csv", {"time": cols["t"], "x": cols["gx"], "y": cols["gy"], "z": cols["gz"]})
    acc = {"time": cols["t"][::2], "x": cols["ax"][::2], "y": cols["ay"][::2].copy(), "z": cols["az"][::2]}
    acc.update(acc_changes)
    write_table(tmp_path / "Accelerometer.csv", acc)
    return run("estimate", tmp_path / "Gyroscope.csv", tmp_path / "Accelerometer.csv", "-o", tmp_path / "a.csv")


def test_a_problem_in_one_file_of_a_recording_names_that_file_and_its_line(tmp_path):
    y = still(600)["ay"][::2].copy()
    y[50] = np.nan
    res = _phone(tmp_path, y=y)
    # data row 50 of Accelerometer.csv is its line 52 (line 1 the header)
    assert res.returncode == 1 and f"{tmp_path / 'Accelerometer.csv'}: NaN or empty values at line 52" in res.stderr
    assert "Gyroscope.csv:" not in res.stderr
    cols = still(600)
    res = _phone(tmp_path, **{a: cols[f"a{a}"][::2] / G for a in "xyz"})  # in g, declared m/s2
    assert res.returncode == 1 and "Accelerometer.csv: |acc| is about 1 m/s2" in res.stderr
    assert "Gyroscope.csv:" not in res.stderr


def test_a_file_without_a_header_row_is_named_so_and_read_by_column_numbers(tmp_path):
    cols = still(600)
    rows = np.column_stack([cols[k] for k in ("t", "gx", "gy", "gz", "ax", "ay", "az")])
    np.savetxt(tmp_path / "vendor.csv", rows, delimiter=",", fmt="%.9f")
    res = run("estimate", tmp_path / "vendor.csv", "-o", tmp_path / "a.csv")
    assert res.returncode == 1 and "vendor.csv has no header row" in res.stderr and "--gyro 2,3,4" in res.stderr
    out = tmp_path / "a.parquet"
    numbers = ("--time", "1", "--gyro", "2,3,4", "--acc", "5,6,7", "--body", "FRD", "--frame", "NED")
    ok("estimate", tmp_path / "vendor.csv", "-o", out, *numbers)
    table = read_table(out)
    assert table["t"].size == 600 and abs(table["roll_deg"][-1]) < 0.1  # its first line is data, level
    # beside a headerless MAG file: FILE:COLS says which file holds what
    mag = np.column_stack([cols[k] for k in ("t", "mx", "my", "mz")])
    np.savetxt(tmp_path / "MAG.csv", mag, delimiter=",", fmt="%.9f")
    picks = ("--gyro", "vendor.csv:2,3,4", "--acc", "vendor.csv:5,6,7", "--mag", "MAG.csv:2,3,4", "--time", "1")
    ok("estimate", tmp_path / "vendor.csv", tmp_path / "MAG.csv", "-o", out, "--body", "FRD", "--frame", "NED", *picks)
    assert abs(signed(read_table(out)["yaw_deg"][-1])) < 0.1
    res = run("estimate", tmp_path / "vendor.csv", tmp_path / "MAG.csv", "--gyro", "other.csv:2,3,4")
    assert res.returncode == 1 and "other.csv is none of the inputs (vendor.csv, MAG.csv)" in res.stderr


def test_file_cols_picks_one_of_two_files_that_both_hold_a_sensor(tmp_path):
    cols = still(600)
    write_table(tmp_path / "IMU.csv", {k: cols[k] for k in ("t", "gx", "gy", "gz", "ax", "ay", "az")})
    # a second IMU table (a second instance): both hold gyro and accelerometer columns
    write_table(tmp_path / "IMU2.csv", {"t": cols["t"], "GyrX": cols["gx"], "GyrY": cols["gy"], "GyrZ": cols["gz"]})
    res = run("integrate", tmp_path / "IMU.csv", tmp_path / "IMU2.csv", "-o", tmp_path / "a.csv")
    assert res.returncode == 1 and "both hold gyro readings" in res.stderr and "--gyro IMU" in res.stderr
    ok(
        "integrate",
        tmp_path / "IMU.csv",
        tmp_path / "IMU2.csv",
        "-o",
        tmp_path / "a.csv",
        "--gyro",
        "IMU2.csv:GyrX,GyrY,GyrZ",
    )


def test_frd_data_read_in_the_default_flu_axes_is_warned_with_the_body_that_fits(tmp_path):
    src = write_table(tmp_path / "frd.csv", still(600))  # level FRD: gravity reads -z, up in FRD
    res = ok("estimate", src, "-o", tmp_path / "a.parquet")
    assert "warning:" in res.stderr and "reads gravity downward" in res.stderr and "pass --body FRD" in res.stderr
    assert abs(abs(signed(read_table(tmp_path / "a.parquet")["roll_deg"][-1])) - 180.0) < 0.5  # as warned
    res = ok("estimate", src, "-o", tmp_path / "a.parquet", "--body", "FRD")
    assert "warning:" not in res.stderr and abs(read_table(tmp_path / "a.parquet")["roll_deg"][-1]) < 0.1


def test_a_magnetometer_in_milligauss_is_caught_and_accepted(tmp_path):
    cols = still(600)
    for unit, factor in (("mG", 10.0), ("gauss", 0.01)):  # 1 uT = 10 mG = 0.01 gauss
        src = write_table(tmp_path / f"{unit}.csv", {**cols, **{f"m{a}": cols[f"m{a}"] * factor for a in "xyz"}})
        res = run("estimate", src, "--body", "FRD", "-o", tmp_path / "a.csv")
        assert res.returncode == 1 and f"look like {unit}" in res.stderr and f"--mag-unit {unit}" in res.stderr
        ok("estimate", src, "--body", "FRD", "--frame", "NED", "--mag-unit", unit, "-o", tmp_path / "a.parquet")
        assert abs(signed(read_table(tmp_path / "a.parquet")["yaw_deg"][-1])) < 0.1  # facing north


def test_a_gyro_in_deg_s_read_as_rad_s_is_caught_in_gentle_motion(tmp_path):
    t = np.arange(4000) / 100.0
    roll = np.radians(30.0) * np.sin(2 * np.pi * 0.15 * t)  # peak 28 deg/s: "28 rad/s" is within a gyro's range
    rate = np.radians(30.0) * 2 * np.pi * 0.15 * np.cos(2 * np.pi * 0.15 * t)
    cols = {"t": t, "gx": np.degrees(rate), "gy": 0 * t, "gz": 0 * t}
    cols.update(ax=0 * t, ay=G * np.sin(roll), az=G * np.cos(roll))  # FLU
    src = write_table(tmp_path / "deg.csv", cols)
    res = run("estimate", src, "-o", tmp_path / "a.csv")
    assert res.returncode == 1 and "the values look like deg/s" in res.stderr and "--gyro-unit deg/s" in res.stderr
    ok("estimate", src, "--gyro-unit", "deg/s", "-o", tmp_path / "a.parquet")
    np.testing.assert_allclose(
        read_table(tmp_path / "a.parquet")["roll_deg"][-1000:], np.degrees(roll[-1000:]), atol=0.5
    )


def test_an_ardupilot_imu_table_beside_its_mag_table_in_milligauss(tmp_path):
    """ArduPilot's IMU and MAG messages exported to CSV: TimeUS (µs since boot), GyrX.., AccX.., MagX.. in mG."""
    c = still(600)
    us = (c["t"] * 1e6).astype(np.int64) + 1234567
    imu = {
        "TimeUS": us,
        **{f"Gyr{a.upper()}": c[f"g{a}"] for a in "xyz"},
        **{f"Acc{a.upper()}": c[f"a{a}"] for a in "xyz"},
    }
    write_table(tmp_path / "IMU.csv", imu)
    write_table(
        tmp_path / "MAG.csv", {"TimeUS": us[100::5], **{f"Mag{a.upper()}": 10 * c[f"m{a}"][100::5] for a in "xyz"}}
    )
    files = (
        tmp_path / "IMU.csv",
        tmp_path / "MAG.csv",
        "--body",
        "FRD",
        "--frame",
        "NED",
        "-o",
        tmp_path / "a.parquet",
    )
    res = run("estimate", *files)
    assert res.returncode == 1 and "MAG.csv" in res.stderr and "--mag-unit mG" in res.stderr
    ok("estimate", *files, "--mag-unit", "mG")
    table = read_table(tmp_path / "a.parquet")
    np.testing.assert_allclose(table["t"][:3], [0.0, 0.01, 0.02], atol=1e-12)  # TimeUS read as µs
    assert abs(signed(table["yaw_deg"][-1])) < 0.1 and abs(table["roll_deg"][-1]) < 0.1
