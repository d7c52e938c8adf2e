"""`strapdown calibrate` and `estimate --calibration/--declination` on a simulated recording written as CSV (the
layout of strapdown's own files; the truth is exact)."""

import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from strapdown.cli import _build
from strapdown.evaluate.metrics import rmse_errors
from strapdown.io import read_metadata, read_table, write_table
from strapdown.simulate import ImuModel, MagneticField, RandomMotion, sample
from strapdown.simulate.imu import TriadModel

DECLINATION = 12.0


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """Two minutes of random turning with a strong hard and soft iron, 12° declination."""
    mag = TriadModel(
        bias=[40.0, -25.0, 30.0],
        soft_iron=[[1.15, 0.08, 0.0], [0.02, 0.9, -0.05], [0.0, 0.06, 1.05]],
        noise_density=0.03,
    )
    data = sample(
        RandomMotion(
            duration=120.0, seed=4, rate_scale=1.5, bandwidth=0.3, acceleration_scale=0.3
        ),  # 72 % of directions
        100.0,
        imu=ImuModel(mag=mag),
        magnetic_field=MagneticField(50.0, 64.0, DECLINATION),
        reference="ENU",
        body="FLU",
    )
    cols = {"t": data.t[:-1]}
    for name, x in (("g", data.gyro), ("a", data.acc), ("m", data.mag)):
        for i, axis in enumerate("xyz"):
            cols[name + axis] = x[:, i]
    path = tmp_path_factory.mktemp("cal") / "turning.csv"
    write_table(path, cols)
    return path, data


def run(args):
    result = CliRunner().invoke(_build(), [str(a) for a in args])
    assert result.exit_code == 0, result.output
    return result.output


def heading_error(path, data):
    q = read_table(path)
    est = np.column_stack([q[k] for k in ("qw", "qx", "qy", "qz")])
    late = slice(6000, None)
    return rmse_errors(est[late], data.q_true[1:][late], np.ones(len(est[late]), dtype=bool))["heading"]


def test_calibrate_mag_then_estimate_true_north(recording, tmp_path):
    path, data = recording
    cal = tmp_path / "cal.json"
    out = run(["calibrate", "mag", path, "-o", cal, "--field-strength", "50"])
    assert "written:" in out
    doc = json.loads(cal.read_text())
    entry = doc["calibrations"][0]
    assert entry["sensor"] == "mag" and entry["units"] == "uT"
    np.testing.assert_allclose(entry["offset"], [40.0, -25.0, 30.0], atol=0.2)

    raw = tmp_path / "raw.parquet"
    fixed = tmp_path / "fixed.parquet"
    run(["estimate", path, "-o", raw, "--declination", str(DECLINATION), "-q"])
    run(["estimate", path, "-o", fixed, "--calibration", cal, "--declination", str(DECLINATION), "-q"])
    meta = read_metadata(fixed)
    assert meta["heading"] == "true" and float(meta["declination_deg"]) == pytest.approx(DECLINATION)
    assert meta["calibration"] == "mag"
    # (CSV has no place for metadata: the outputs are Parquet)
    # uncorrected hard/soft iron bends the heading; calibrated and turned to true north it follows the truth
    assert heading_error(fixed, data) < 2.5 < 20 < heading_error(raw, data)  # tens of degrees uncorrected

    aligned = tmp_path / "aligned.json"
    run(["calibrate", "mag", path, "-o", aligned, "--field-strength", "50", "--align-gyro"])
    quality = json.loads(aligned.read_text())["calibrations"][0]["quality"]
    # the simulated magnetometer is not turned against the gyro: only the non-symmetric soft iron's rotation
    a = np.array([[1.15, 0.08, 0.0], [0.02, 0.9, -0.05], [0.0, 0.06, 1.05]])
    u, _, vt = np.linalg.svd(a)  # A = (U Vᵀ)(V S Vᵀ): its rotation part U Vᵀ is what the gyro sees
    expected = np.degrees(np.arccos((np.trace(u @ vt) - 1) / 2))
    assert quality["gyro_alignment_deg"] == pytest.approx(expected, abs=0.3)

    magnetic = tmp_path / "magnetic.parquet"
    run(["estimate", path, "-o", magnetic, "--calibration", cal, "-q"])
    assert read_metadata(magnetic)["heading"] == "magnetic"
    assert heading_error(magnetic, data) == pytest.approx(DECLINATION, abs=2.0)


def test_refusals_reach_the_command_line(recording, tmp_path):
    path, _ = recording
    result = CliRunner().invoke(_build(), ["calibrate", "acc", str(path), "-o", str(tmp_path / "a.json")])
    assert result.exit_code == 1 and "no rest found in acc: hold the sensor still" in result.output
    result = CliRunner().invoke(_build(), ["estimate", str(path), "--declination", "auto", "--lat", "52"])
    assert result.exit_code != 0 and "auto takes --lat, --lon and --date together" in result.output
    result = CliRunner().invoke(_build(), ["estimate", str(path), "--6d", "--declination", "3"])
    assert result.exit_code == 1 and "needs the magnetometer" in result.output


def test_calibrate_acc_gyro_and_allan_from_a_file(tmp_path):
    """Six faces, 4 s still on each with tumbles between: acc and gyro calibrations land in one file."""
    rng = np.random.default_rng(2)
    fs, bias_g, bias_a = 100.0, np.array([0.01, -0.02, 0.005]), np.array([0.2, -0.1, 0.15])
    faces = 9.80665 * np.vstack([np.eye(3), -np.eye(3)])
    acc, gyro = [], []
    for k, f in enumerate(faces):
        if k:
            acc.append(f + 3.0 * rng.standard_normal((150, 3)))
            gyro.append(bias_g + 2.0 * rng.standard_normal((150, 3)))
        acc.append(f * [1.01, 0.99, 1.0] + bias_a + 0.02 * rng.standard_normal((400, 3)))
        gyro.append(bias_g + 0.003 * rng.standard_normal((400, 3)))
    acc, gyro = np.concatenate(acc), np.concatenate(gyro)
    cols = {"t": np.arange(len(acc)) / fs}
    for name, x in (("g", gyro), ("a", acc)):
        for i, axis in enumerate("xyz"):
            cols[name + axis] = x[:, i]
    path = write_table(tmp_path / "faces.csv", cols)
    cal = tmp_path / "cal.json"
    run(["calibrate", "acc", path, "-o", cal])
    run(["calibrate", "gyro", path, "-o", cal])
    doc = {c["sensor"]: c for c in json.loads(cal.read_text())["calibrations"]}
    assert sorted(doc) == ["acc", "gyro"]
    np.testing.assert_allclose(doc["acc"]["offset"], bias_a, atol=0.01)
    np.testing.assert_allclose(doc["acc"]["quality"]["scale_factor"], [0.01, -0.01, 0.0], atol=1e-3)
    np.testing.assert_allclose(doc["gyro"]["offset"], bias_g, atol=5e-4)
    out = run(["calibrate", "allan", path])
    assert "ARW N" in out and "bias_noise_rest=" in out


def test_an_output_that_is_no_calibration_file_is_refused(recording, tmp_path):
    path, _ = recording
    other = tmp_path / "other.json"
    other.write_text('{"something": "else"}')
    result = CliRunner().invoke(_build(), ["calibrate", "mag", str(path), "-o", str(other)])
    assert result.exit_code == 1 and "not a strapdown calibration file" in result.output
    assert json.loads(other.read_text()) == {"something": "else"}  # left as it was


def test_a_calibration_fitted_in_other_axes_is_refused(recording, tmp_path):
    """The offset and matrix act on the components of the axes they were fitted in: a FRD calibration applied to
    readings declared FLU would correct the wrong components, so estimate refuses it and names both axes."""
    path, _ = recording
    cal = tmp_path / "cal.json"
    run(["calibrate", "mag", path, "-o", cal, "--field-strength", "50"])
    doc = json.loads(cal.read_text())
    doc["calibrations"][0]["frame"] = "FRD"
    cal.write_text(json.dumps(doc))
    result = CliRunner().invoke(
        _build(), ["estimate", str(path), "--body", "FLU", "-o", str(tmp_path / "x.parquet"), "--calibration", str(cal)]
    )
    assert result.exit_code == 1 and "fitted in FRD axes" in result.output and "FLU axes" in result.output
    assert not (tmp_path / "x.parquet").exists()
    # the same file with its axes declared as the calibration's goes through
    run(["estimate", path, "--body", "FRD", "-o", tmp_path / "y.parquet", "--calibration", cal, "-q"])


def test_calibrate_mag_takes_a_gap_with_a_warning_and_honours_on_gap_error(recording, tmp_path):
    path, _ = recording
    table = read_table(path)
    keep = np.ones(len(table["t"]), dtype=bool)
    keep[3000:3300] = False  # 3 s without samples: 301 periods
    gapped = write_table(tmp_path / "gapped.csv", {k: np.asarray(v)[keep] for k, v in table.items()})
    result = CliRunner().invoke(_build(), ["calibrate", "mag", str(gapped), "-o", str(tmp_path / "a.json")])
    assert result.exit_code == 0, result.output
    assert "warning:" in result.output and "1 gap(s)" in result.output
    entry = json.loads((tmp_path / "a.json").read_text())["calibrations"][0]
    np.testing.assert_allclose(entry["offset"], [40.0, -25.0, 30.0], atol=0.3)  # the samples on both sides
    strict = ["calibrate", "mag", str(gapped), "-o", str(tmp_path / "b.json"), "--on-gap", "error"]
    result = CliRunner().invoke(_build(), strict)
    assert result.exit_code == 1 and "a gap of 3.01 s" in result.output and not (tmp_path / "b.json").exists()


def test_calibrate_mag_on_a_ulog_takes_its_densest_magnetometer_topic():
    pytest.importorskip("pyulog")
    from pyulog import ULog

    from strapdown.cli.calibrate import _mag_topic

    log = Path(__file__).resolve().parents[1] / "data" / "px4" / "sample_log_small.ulg"
    counts = {d.name: len(d.data["timestamp"]) for d in ULog(str(log)).data_list if d.multi_id == 0}
    densest = max(("sensor_mag", "vehicle_magnetometer"), key=counts.get)
    assert _mag_topic(log, {}, ("mag",))["mag_topic"] == densest
    assert _mag_topic(log, {"mag_topic": "sensor_mag"}, ("mag",))["mag_topic"] == "sensor_mag"  # as given
