"""`strapdown estimate --adapt-noise`: the noise model from a calibration file or the data's rests, in the metadata
(issue 29)."""

import numpy as np
from click.testing import CliRunner

from strapdown.calibrate import allan, gyroscope, save
from strapdown.cli import _build
from strapdown.io import read_metadata, write_table

FS = 100.0


def still(tmp_path, n=12000, seed=0):
    rng = np.random.default_rng(seed)
    gyro = np.radians([0.2, -0.1, 0.05]) + np.radians(0.01) * np.sqrt(FS) * rng.standard_normal((n, 3))
    acc = [0.0, 0.0, 9.81] + 0.002 * np.sqrt(FS) * rng.standard_normal((n, 3))
    cols = {"t": np.arange(n) / FS}
    for name, x in (("g", gyro), ("a", acc)):
        for i, axis in enumerate("xyz"):
            cols[name + axis] = x[:, i]
    return write_table(tmp_path / "still.csv", cols), gyro, acc


def estimate(*args):
    result = CliRunner().invoke(_build(), ["estimate", *[str(a) for a in args]])
    assert result.exit_code == 0, result.output
    return result


def test_noise_model_from_an_allan_calibration(tmp_path):
    path, gyro, _ = still(tmp_path)
    analysis = allan(gyro, FS)
    save(tmp_path / "allan.json", analysis.calibration())
    estimate(path, "--calibration", tmp_path / "allan.json", "--adapt-noise", "-o", tmp_path / "out.csv")
    meta = read_metadata(tmp_path / "out.csv")
    arw = float(np.sqrt(np.mean(analysis.arw**2)))
    assert meta["noise_source"] == "calibration"
    assert float(meta["noise_gyro_density_rad_s_sqrt_hz"]) == float(f"{arw:.6g}")
    assert f"bias_noise_rest={arw:.6g}" in meta["noise_params"]


def test_noise_model_from_a_gyro_calibration(tmp_path):
    path, gyro, acc = still(tmp_path)
    cal = gyroscope(gyro, fs=FS, acc=acc)
    save(tmp_path / "gyro.json", cal)
    estimate(path, "--calibration", tmp_path / "gyro.json", "--adapt-noise", "-o", tmp_path / "out.csv")
    meta = read_metadata(tmp_path / "out.csv")
    density = float(np.sqrt(np.mean(np.square(cal.quality["noise"]))) / np.sqrt(FS))
    assert meta["noise_source"] == "calibration"
    assert float(meta["noise_gyro_density_rad_s_sqrt_hz"]) == float(f"{density:.6g}")


def test_noise_model_from_the_rests_and_not_without_the_flag(tmp_path):
    path, _, _ = still(tmp_path)
    estimate(path, "--adapt-noise", "-o", tmp_path / "out.csv")
    meta = read_metadata(tmp_path / "out.csv")
    assert meta["noise_source"] == "allan"  # two minutes still: the Allan terms too
    assert abs(float(meta["noise_gyro_density_rad_s_sqrt_hz"]) / np.radians(0.01) - 1.0) < 0.1
    assert abs(float(meta["noise_acc_density_m_s2_sqrt_hz"]) / 0.002 - 1.0) < 0.1
    estimate(path, "-o", tmp_path / "plain.csv")
    assert not any(k.startswith("noise") for k in read_metadata(tmp_path / "plain.csv"))
