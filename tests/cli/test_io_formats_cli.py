"""The commands a user types on the field's files, with no options beyond --topic (issue 12).

The PX4 log is real (tests/data/px4); the bag, the phone exports and the CSV files are SIMULATED motion written
by tests/sim_exports.py in each tool's layout.
"""

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sim_exports as sim
from strapdown.evaluate.metrics import attitude_errors
from strapdown.io import read_metadata, read_reference, read_table

DATA = Path(__file__).resolve().parents[1] / "data"


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "strapdown.cli", *map(str, args)], capture_output=True, text=True, timeout=600
    )


def ok(*args):
    res = run(*args)
    assert res.returncode == 0, res.stderr
    return res


def quats(table):
    return np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])


def test_estimate_on_a_px4_log_shows_the_tilt_px4_logged(tmp_path):
    log = DATA / "px4" / "sample_logging_tagged_and_default_params.ulg"
    out = tmp_path / "px4.parquet"
    ok("estimate", log, "-o", out)
    table, ref = read_table(out), read_reference(log)
    keep = (ref.t > 2.0) & (ref.t <= table["t"][-1])
    rows = np.searchsorted(table["t"], ref.t[keep])
    incl = np.degrees(attitude_errors(quats(table)[rows], ref.q[keep])["inclination"])
    assert incl.max() < 1.0
    meta = read_metadata(out)
    assert meta.get("time_origin") == "284000" and meta.get("time_origin_kind") == "boot"


def test_estimate_on_a_bag_names_its_imu_topics_then_reads_the_chosen_one(tmp_path):
    data = sim.phone_at_rest(body="FLU", duration=8.0)
    bag = sim.rosbag(tmp_path / "run.bag", data, version=1, imu_topics=("/imu/data", "/imu/data_raw"))
    res = run("estimate", bag, "-o", tmp_path / "x.csv")
    assert res.returncode == 1 and "/imu/data, /imu/data_raw" in res.stderr and "--topic" in res.stderr
    out = tmp_path / "bag.csv"
    ok("estimate", bag, "--topic", "/imu/data", "-o", out)
    table = read_table(out)
    late = table["t"] > table["t"][-1] - 1.0
    assert np.abs(table["pitch_deg"][late]).max() < 2.0 and np.abs(table["roll_deg"][late]).max() < 2.0


@pytest.mark.parametrize("layout", ["zip", "folder"])
def test_estimate_on_a_phone_export_lying_flat(tmp_path, layout):
    folder = sim.sensor_logger(tmp_path / "export", sim.phone_at_rest(duration=10.0))
    if layout == "zip":
        inputs = [shutil.make_archive(str(tmp_path / "export"), "zip", folder)]
    else:
        inputs = [folder]
    out = tmp_path / "phone.csv"
    ok("estimate", *inputs, "-o", out)
    table = read_table(out)
    late = table["t"] > table["t"][-1] - 1.0
    assert np.abs(table["pitch_deg"][late]).max() < 2.0 and np.abs(table["roll_deg"][late]).max() < 2.0


def test_estimate_refuses_phyphox_linear_acceleration(tmp_path):
    data = sim.phone_at_rest(duration=5.0)
    data.acc[:] = data.acc + np.random.default_rng(3).normal(0, 1.2, data.acc.shape)
    folder = sim.phyphox(tmp_path / "linear", data, linear_only=True)
    res = run("estimate", folder, "-o", tmp_path / "x.csv")
    assert res.returncode == 1 and "gravity-free" in res.stderr and "Linear Accelerometer" in res.stderr
    assert not (tmp_path / "x.csv").exists()


def test_integrate_on_epoch_nanoseconds_counts_seconds(tmp_path):
    # issue 12: exit 0 with t up to 2e11 s; now the unit is inferred and t counts from the first sample
    path = tmp_path / "ns.csv"
    t0 = 1_718_030_736_872_695_300
    path.write_text("time,gx,gy,gz\n" + "".join(f"{t0 + k * 10_000_000},0,0,0.5\n" for k in range(201)))
    out = tmp_path / "ns.integrate.csv"
    ok("integrate", path, "-o", out)
    table = read_table(out)
    assert table["t"][-1] == pytest.approx(2.0)
    assert table["yaw_deg"][-1] == pytest.approx(np.degrees(0.5 * 2.0), abs=1e-6)
