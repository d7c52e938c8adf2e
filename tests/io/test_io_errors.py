"""Bad input: every problem gets a message that says what, where and how to fix it, and a non-zero exit."""

import numpy as np
import pytest
from click.testing import CliRunner

from strapdown.cli import _build
from strapdown.io import ImuColumns, write_table

N = 400


@pytest.fixture(scope="module")
def cli():
    return _build()


def invoke(cli, *args):
    res = CliRunner().invoke(cli, [str(a) for a in args])
    assert res.exception is None or isinstance(res.exception, SystemExit), res.exception
    return res


def imu(n=N, dt=0.01, acc=9.81, gyro=0.1):
    rng = np.random.default_rng(0)
    cols = {"t": np.arange(n) * dt}
    cols.update({f"g{a}": rng.normal(0, gyro, n) for a in "xyz"})
    cols.update({"ax": rng.normal(0, 0.05, n), "ay": rng.normal(0, 0.05, n), "az": np.full(n, acc)})
    return cols


def failure(cli, *args):
    res = invoke(cli, *args)
    assert res.exit_code != 0
    return res.output


def test_missing_column_lists_what_exists(cli, tmp_path):
    path = write_table(tmp_path / "a.csv", imu())
    out = failure(cli, "integrate", path, "--gyro", "wx,wy,wz")
    assert "no column 'wx' (--gyro); the file has: t, gx, gy, gz, ax, ay, az" in out
    cols = imu()
    del cols["gx"], cols["gy"], cols["gz"]
    out = failure(cli, "integrate", write_table(tmp_path / "b.parquet", cols))
    assert "no gyro columns found" in out and "--gyro" in out and "t, ax, ay, az" in out


def test_nan_rows_are_reported_by_line(cli, tmp_path):
    cols = imu()
    cols["gy"][[57, 58, 300]] = np.nan
    out = failure(cli, "integrate", write_table(tmp_path / "nan.csv", cols))
    assert "NaN or empty values at lines 59, 60, 302" in out and "'gy'" in out
    out = failure(cli, "integrate", write_table(tmp_path / "nan.parquet", cols))
    assert "at rows 57, 58, 300" in out


def test_time_going_backwards_says_where(cli, tmp_path):
    cols = imu()
    cols["t"][123] = cols["t"][122]
    out = failure(cli, "estimate", write_table(tmp_path / "t.csv", cols), "--chunk-rows", 50)
    assert "time (t) does not increase at line 125: 1.22 -> 1.22" in out


def test_gap_longer_than_allowed(cli, tmp_path):
    cols = imu()
    cols["t"][200:] += 5.0
    path = write_table(tmp_path / "gap.parquet", cols)
    out = failure(cli, "integrate", path, "--on-gap", "error")
    assert "a gap of 5.01 s (501.0 sample periods of 0.01 s) before row 200" in out
    # the message names every way to go on
    assert "--max-gap" in out and all(f"{w} (" in out for w in ("bridge", "restart", "split"))
    assert invoke(cli, "integrate", path, "--max-gap", "0", "-o", tmp_path / "o.csv").exit_code == 0


def test_gyro_in_degrees_declared_radians(cli, tmp_path):
    path = write_table(tmp_path / "deg.csv", imu(gyro=150.0))
    out = failure(cli, "integrate", path)
    assert "look like deg/s" in out and "--gyro-unit deg/s" in out
    assert invoke(cli, "integrate", path, "--gyro-unit", "deg/s", "-o", tmp_path / "o.csv").exit_code == 0


def test_accelerometer_in_g_declared_metres(cli, tmp_path):
    path = write_table(tmp_path / "g.csv", imu(acc=1.0))
    out = failure(cli, "estimate", path)
    assert "|acc| is about 1 m/s2" in out and "--acc-unit g" in out
    assert invoke(cli, "estimate", path, "--acc-unit", "g", "-o", tmp_path / "o.csv").exit_code == 0


def test_mismatched_lengths_in_a_mat_file(cli, tmp_path):
    import scipy.io

    path = tmp_path / "short.mat"
    scipy.io.savemat(path, {"imu_gyr": np.zeros((100, 3)), "imu_acc": np.zeros((99, 3)), "fs": 100.0})
    out = failure(cli, "estimate", path)
    assert "different lengths" in out and "'imu_gyr' has 100" in out and "'imu_acc' has 99" in out


def test_no_time_and_no_rate(cli, tmp_path):
    cols = imu()
    del cols["t"]
    path = write_table(tmp_path / "untimed.csv", cols)
    assert "give --time COLUMN or --rate HZ" in failure(cli, "integrate", path)
    assert "not both" in failure(cli, "integrate", write_table(tmp_path / "x.csv", imu()), "--rate", 100, "--time", "t")


def test_unknown_estimator_parameter_and_input(cli, tmp_path):
    path = write_table(tmp_path / "a.csv", imu())
    assert "attitude has no parameter beta; its parameters: tau_acc" in failure(cli, "estimate", path, "-p", "beta=1")
    out = failure(cli, "estimate", path, "-e", "mahony", "--extra", "known_acc=ax,ay,az")
    assert "mahony takes no input 'known_acc'" in out
    assert "does not take a magnetometer" in failure(cli, "estimate", path, "-e", "tilt", "--9d")


def test_text_in_a_number_column(cli, tmp_path):
    path = tmp_path / "text.csv"
    path.write_text("t,gx,gy,gz\n0,0,0,0\n0.01,0,zero,0\n")
    assert "line 3, column 'gy': 'zero' is not a number" in failure(cli, "integrate", path)


def test_corrupt_and_unknown_files(cli, tmp_path):
    bad = tmp_path / "broken.parquet"
    bad.write_bytes(b"PAR1 not really")
    assert f"{bad} is not a readable parquet file" in failure(cli, "integrate", bad)
    other = tmp_path / "data.xyz"
    other.write_text("1,2,3\n")
    assert "cannot tell the format of 'data.xyz'" in failure(cli, "integrate", other)


def test_output_may_not_overwrite_the_input(cli, tmp_path):
    path = write_table(tmp_path / "a.csv", imu())
    assert "is the input file" in failure(cli, "integrate", path, "-o", path)


def test_convert_values_count_and_garbage(cli):
    assert "--from euler takes 3 numbers, got 2" in failure(cli, "convert", "--from", "euler", "1", "2")
    assert "expected numbers or one input file" in failure(cli, "convert", "--from", "euler", "1", "x", "2")


def test_split_rejects_methods_that_read_neighbours(cli, tmp_path):
    path = write_table(tmp_path / "a.parquet", imu())
    out = failure(cli, "batch", path, "integrate", "--split", "2", "--method", "rk4", "-j", "1")
    assert "rk4" in out and "split" in out


@pytest.mark.parametrize("fmt", ["csv", "parquet", "h5", "mat"])
@pytest.mark.parametrize("out", ["csv", "parquet", "h5", "mat"])
def test_input_without_rows_is_named_and_nothing_is_written(cli, tmp_path, fmt, out):
    path = write_table(tmp_path / f"zero.{fmt}", {name: values[:0] for name, values in imu().items()})
    quat = write_table(tmp_path / f"q.{fmt}", {name: np.zeros(0) for name in ("t", "qw", "qx", "qy", "qz")})
    for command, source in (("integrate", path), ("estimate", path), ("convert", quat)):
        target = tmp_path / f"{command}.{out}"
        assert f"{source} has no data rows" in failure(cli, command, source, "-o", target)
        assert not target.exists()


def test_chunk_rows_must_be_positive(cli, tmp_path):
    from strapdown.io import convert_file, estimate_file, integrate_file, open_source

    path = write_table(tmp_path / "a.csv", imu())
    assert "chunk_rows must be a positive integer, got -5" in failure(cli, "integrate", path, "--chunk-rows", -5)
    for bad in (0, -1, 2.5):
        for run in (integrate_file, estimate_file, convert_file):
            with pytest.raises(ValueError, match="chunk_rows must be a positive integer"):
                run(path, tmp_path / "o.csv", chunk_rows=bad)
        for fmt in ("csv", "parquet", "h5", "mat"):
            with open_source(write_table(tmp_path / f"a.{fmt}", imu(n=3))) as src, pytest.raises(ValueError):
                next(src.chunks(["t"], bad))
    assert not (tmp_path / "o.csv").exists()


@pytest.mark.parametrize("value", ["-1", "nan"])
def test_max_gap_must_be_a_number_of_periods(cli, tmp_path, value):
    src = write_table(tmp_path / "g.csv", {"t": np.arange(10) * 0.01, **{f"g{a}": np.zeros(10) for a in "xyz"}})
    res = invoke(cli, "integrate", src, "--max-gap", value)
    assert res.exit_code == 2 and "--max-gap" in res.output and "sample periods >= 0" in res.output
    with pytest.raises(ValueError, match="max_gap must be a number of sample periods"):
        ImuColumns(max_gap=float(value))


def test_typed_numbers_must_be_finite(cli):
    res = invoke(cli, "convert", "--from", "quat", "nan", "0", "0", "0")
    assert res.exit_code == 2 and "the numbers must be finite" in res.output


def test_infinite_values_are_called_so(cli, tmp_path):
    cols = imu()
    cols["gy"][7] = np.inf
    msg = failure(cli, "integrate", write_table(tmp_path / "inf.csv", cols))
    assert "infinite values at line 9" in msg and "'gy'" in msg
