"""Bad input and impossible requests on the command line: one clear line, a non-zero exit, no traceback (issue 14)."""

import numpy as np
import pytest

from conftest import strapdown_cli
from strapdown.io import write_table

run = strapdown_cli


def refused(*args, code=None, cwd=None):
    res = run(*args, cwd=cwd)
    assert res.returncode != 0, res.stdout
    assert "Traceback" not in res.stderr, res.stderr
    if code is not None:
        assert res.returncode == code, res.stderr
    return res.stderr


def level(n=200, **changes):
    cols = {"t": np.arange(n) * 0.01, "gx": np.zeros(n), "gy": np.zeros(n), "gz": np.zeros(n)}
    cols.update(ax=np.zeros(n), ay=np.zeros(n), az=np.full(n, 9.81))
    for name, (row, value) in changes.items():
        cols[name][row] = value
    return cols


@pytest.fixture(scope="module")
def attitude_file(tmp_path_factory):
    folder = tmp_path_factory.mktemp("att")
    src = write_table(folder / "still.parquet", level())
    assert run("estimate", src, "-o", folder / "att.parquet", "-q").returncode == 0
    return folder / "att.parquet"


@pytest.fixture()
def not_a_folder(tmp_path):
    """A path under a regular file: no one can create a folder there (read-only folders do not stop root)."""
    blocker = tmp_path / "file.txt"
    blocker.write_text("x")
    return blocker / "sub"


def test_plot_max_points_zero(attitude_file):
    assert "--max-points" in refused("plot", attitude_file, "--max-points", "0", code=2)


def test_simulate_refuses_an_impossible_size_before_allocating(tmp_path):
    err = refused("simulate", tmp_path / "big.parquet", "--rate", "1e12", code=2)
    assert "rows" in err and "--rate" in err
    assert not (tmp_path / "big.parquet").exists()
    assert "--rate" in refused("simulate", tmp_path / "x.csv", "--rate", "nan", code=2)


def test_compare_and_demo_check_their_output_folder_before_computing(not_a_folder):
    assert "cannot write into" in refused("compare", "--out", not_a_folder, code=2)
    assert "cannot write into" in refused("demo", "--out", not_a_folder, code=2)


def test_evaluate_checks_the_csv_path_and_the_grid_values_first(tmp_path, not_a_folder):
    # an empty folder is enough: both are refused before any trial is read
    assert "--csv" in refused("evaluate", tmp_path, "--csv", not_a_folder / "rows.csv", code=2)
    err = refused("evaluate", tmp_path, "-g", "tau_acc=1,abc", code=2)
    assert "tau_acc takes numbers" in err and "'abc'" in err


def test_convert_refuses_infinite_zero_and_absurd_input_naming_the_line(tmp_path):
    lines = ["t,qw,qx,qy,qz", "0,1,0,0,0", "0.1,nan,nan,nan,nan", "0.2,inf,0,0,0", "0.3,0,0,0,0"]
    src = tmp_path / "q.csv"
    src.write_text("\n".join(lines) + "\n")
    err = refused("convert", src, "--to", "euler", "-o", tmp_path / "e.csv")
    assert "q.csv: line 4" in err and "infinite" in err  # the NaN row (line 3) is an unknown attitude, kept
    src.write_text("\n".join(lines[:3] + lines[4:]) + "\n")
    err = refused("convert", src, "--to", "euler", "-o", tmp_path / "e.csv")
    assert "q.csv: line 4" in err and "zero quaternion" in err
    assert not (tmp_path / "e.csv").exists()
    assert "no digits are left" in refused("convert", "--from", "euler", "--degrees", "1e308", "0", "0", code=2)
    assert "zero quaternion" in refused("convert", "--from", "quat", "0", "0", "0", "0", code=2)


def test_huge_readings_are_named_by_file_and_line_not_by_internal_arrays(tmp_path):
    src = write_table(tmp_path / "huge.csv", level(gx=(98, 1e300)))
    err = refused("estimate", src, "--no-unit-check", "-o", tmp_path / "o.csv")
    assert "huge.csv" in err and "line 100" in err and "q[" not in err
    err = refused("integrate", src, "--no-unit-check", "-o", tmp_path / "o.csv")
    assert "huge.csv" in err and "line" in err


def test_batch_jobs_carry_absolute_paths(tmp_path):
    # a Dask worker runs in its own working folder: relative paths would name nothing there
    (tmp_path / "logs").mkdir()
    write_table(tmp_path / "logs" / "a.parquet", level())
    res = run("batch", "logs/*.parquet", "estimate", "-j", "1", "--out", "out", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    written = [line.split()[1] for line in res.stdout.splitlines() if line.startswith("written:")]
    assert written == [str(tmp_path / "out" / "a.estimate.parquet")]
