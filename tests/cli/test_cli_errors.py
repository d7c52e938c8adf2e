"""Bad input and impossible requests on the command line: one clear line, a non-zero exit, no traceback (issue 14)."""

import os
from pathlib import Path

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


@pytest.fixture()
def read_only(tmp_path):
    """A folder no one can create files in: /proc even for root (for whom os.access says yes), else a chmod 500."""
    import tempfile

    try:
        with tempfile.TemporaryFile(dir="/proc"):
            pass
    except OSError:
        return Path("/proc")
    if os.geteuid() == 0:
        pytest.skip("no folder here refuses root's writes")
    folder = tmp_path / "ro"
    folder.mkdir(mode=0o500)
    return folder


def test_outputs_in_a_read_only_folder_are_refused_before_computing(read_only, attitude_file, tmp_path):
    # these wrote after the whole computation, into a hidden temp file: a traceback naming the temp
    assert "cannot write into" in refused("compare", "--out", read_only / "cmp", code=2)
    assert "cannot write into" in refused("demo", "--out", read_only / "demo", code=2)
    assert "--csv" in refused("evaluate", tmp_path, "--csv", read_only / "rows.csv", code=2)
    assert "OUTPUT" in refused("simulate", read_only / "sim.csv", code=2)
    assert "--out" in refused("plot", attitude_file, "--out", read_only / "figs", code=2)
    src = write_table(tmp_path / "still.csv", level())
    for command in ("integrate", "estimate", "convert"):  # the message named the hidden temp file
        err = refused(command, src if command != "convert" else attitude_file, "-o", read_only / "o.csv", code=2)
        assert f"cannot write into {read_only}" in err and ".tmp" not in err


def test_plot_max_points_zero(attitude_file):
    assert "--max-points" in refused("plot", attitude_file, "--max-points", "0", code=2)
    assert "--euler" in refused("plot", attitude_file, "--euler", "QQQ", code=2)


def test_simulate_refuses_an_impossible_size_before_allocating(tmp_path):
    err = refused("simulate", tmp_path / "big.parquet", "--rate", "1e12", code=2)
    assert "--rate" in err and "3e+13 samples" in err  # the default scenario lasts 30 s
    err = refused("compare", "--rate", "1e12", code=2)
    assert "--rate" in err and "3e+13 samples" in err
    assert not (tmp_path / "big.parquet").exists()
    assert "--rate" in refused("simulate", tmp_path / "x.csv", "--rate", "nan", code=2)
    assert "holds no sample at 1e-300 Hz" in refused("compare", "--rate", "1e-300", code=2)
    # numpy's "expected non-negative integer" (a traceback in compare) named no option
    assert "--seed" in refused("compare", "--seed", "-1", code=2)
    assert "--seed" in refused("simulate", tmp_path / "x.csv", "--seed", "-1", code=2)


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


def test_convert_takes_quaternions_of_any_scale_and_names_refused_rows(tmp_path):
    # the norm of (1e300, 1e300, 0, 0) overflows and that of (1e-320, 0, 0, 0) underflows: they were called zero
    # quaternions; both are attitudes (a quarter turn about x, the identity), whatever their scale
    for numbers, roll in ((["1e300", "1e300", "0", "0"], 90.0), (["1e-320", "0", "0", "0"], 0.0)):
        res = run("convert", "--from", "quat", *numbers, "--to", "euler", "--degrees")
        assert res.returncode == 0, res.stderr
        np.testing.assert_allclose([float(x) for x in res.stdout.split()], [0.0, 0.0, roll], atol=1e-12)
    # a row the library refuses is named by the file's line, not by the library's array index ("c[0]")
    rows = ["1,0,0,0,1,0,0,0,1", "1,0,0,0,1,0,0,0,1", "1,0,0,0,1,0,0,0,2"]
    src = tmp_path / "m.csv"
    src.write_text("t," + ",".join(f"c{i}{j}" for i in range(1, 4) for j in range(1, 4)) + "\n")
    with src.open("a") as f:
        f.writelines(f"{k * 0.1},{r}\n" for k, r in enumerate(rows))
    err = refused("convert", src, "--from", "matrix", "--columns", "c11,c12,c13,c21,c22,c23,c31,c32,c33", "-o",
                  tmp_path / "q.csv")  # fmt: skip
    assert "m.csv: line 4" in err and "not a rotation matrix" in err and "c[" not in err
    src = tmp_path / "q.csv"
    src.write_text("t,qw,qx,qy,qz\n0,1,0,0,0\n0.1,0,1,0,0\n")
    err = refused("convert", src, "--to", "gibbs", "-o", tmp_path / "g.csv")
    assert "q.csv: line 3" in err and "Gibbs vector is infinite" in err


def test_huge_readings_are_named_by_file_and_line_not_by_internal_arrays(tmp_path):
    # one absurd reading passed the unit check (a percentile of the first rows) and failed later as "q[98, 0] is
    # NaN" or "the step rotations overflow"; now the reader refuses it in its chunk (with or without the unit
    # check: no unit makes 1e300 plausible), naming the file, the line or row, the column and the value
    def named(err, file, where, column):
        assert file in err and where in err and f"'{column}'" in err and "1e+300" in err, err
        assert "q[" not in err

    src = write_table(tmp_path / "huge.csv", level(gx=(98, 1e300)))
    named(refused("estimate", src, "--no-unit-check", "-o", tmp_path / "o.csv"), "huge.csv", "line 100", "gx")
    named(refused("integrate", src, "-o", tmp_path / "o.csv"), "huge.csv", "line 100", "gx")
    # turned axes (--body) and a split integration still name the file's own column and line
    err = refused("integrate", src, "--frame", "ENU", "--body", "FRD", "-o", tmp_path / "o.csv")
    named(err, "huge.csv", "line 100", "gx")
    src = write_table(tmp_path / "huge_y.csv", level(gy=(98, 1e300)))
    err = refused("integrate", src, "--frame", "ENU", "--body", "FRD", "-o", tmp_path / "o.csv")
    named(err, "huge_y.csv", "line 100", "gy")
    err = refused("batch", src, "integrate", "--split", "2", "-j", "1", "--no-unit-check", "--out", tmp_path / "s")
    named(err, "huge_y.csv", "line 100", "gy")
    src = write_table(tmp_path / "acc.parquet", level(ay=(150, 1e300)))
    named(
        refused("estimate", src, "-e", "tilt", "--no-unit-check", "-o", tmp_path / "o.csv"), "acc.parquet", "150", "ay"
    )
    assert not (tmp_path / "o.csv").exists()


def test_batch_jobs_carry_absolute_paths(tmp_path):
    # a Dask worker runs in its own working folder: relative paths would name nothing there
    (tmp_path / "logs").mkdir()
    write_table(tmp_path / "logs" / "a.parquet", level())
    res = run("batch", "logs/*.parquet", "estimate", "-j", "1", "--out", "out", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    written = [line.split()[1] for line in res.stdout.splitlines() if line.startswith("written:")]
    assert written == [str(tmp_path / "out" / "a.estimate.parquet")]


def broad_trial(folder, rate=100.0, quat=None, n=300):
    """A BROAD-layout trial of a level sensor at rest, with exact truth (the identity): simulated, not BROAD's."""
    import scipy.io

    folder.mkdir(parents=True, exist_ok=True)
    fields = {"imu_gyr": np.zeros((n, 3)), "imu_acc": np.tile([0.0, 0.0, 9.81], (n, 1))}
    fields.update(imu_mag=np.tile([20.0, 0.0, -40.0], (n, 1)), movement=np.ones((n, 1)), sampling_rate=rate)
    fields["opt_quat"] = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1)) if quat is None else quat
    scipy.io.savemat(folder / "t1.mat", fields)
    return folder


@pytest.mark.parametrize(
    ("rate", "trials_json", "words"),
    [
        (np.zeros((0, 1)), None, "sampling_rate must be one number of Hz, got []"),
        ("abc", None, "sampling_rate must be one number of Hz"),
        (-1.0, None, "sampling_rate must be a positive number of Hz, got -1.0"),
        (100.0, "[1, 2]", "trials.json must hold a JSON object"),
        (100.0, '{"trials": [1, 2]}', "'trials' must map each trial name"),
        (100.0, '{"trials": {"t1": {"groups": "fast"}}}', "the groups of trial 't1' must be a list"),
        (100.0, '{"groups": ["fast"]}', "'groups' must be a list of objects with a 'name'"),
        (100.0, "{", "trials.json is not valid JSON"),
    ],
)
def test_evaluate_names_a_bad_trial_file(tmp_path, rate, trials_json, words):
    folder = broad_trial(tmp_path / "broad", rate=rate)
    if trials_json is not None:
        (folder / "trials.json").write_text(trials_json)
    err = refused("evaluate", folder, code=2)
    assert words in err
    assert ("t1.mat" in err) != (trials_json is not None)  # the file at fault, by name


def test_evaluate_refuses_a_truth_that_scores_nan(tmp_path):
    from strapdown.evaluate.broad import load_trials
    from strapdown.evaluate.evaluation import evaluate

    # all-zero truth: every error would be NaN; the table printed NaN and the exit code was 0
    err = refused("evaluate", broad_trial(tmp_path / "zero", quat=np.zeros((300, 4))), code=2)
    assert "t1.mat: opt_quat row 1 of 300 is [0.0, 0.0, 0.0, 0.0]" in err
    # all truth occluded (NaN) on the movement samples: nothing to score
    err = refused("evaluate", broad_trial(tmp_path / "lost", quat=np.full((300, 4), np.nan)), code=2)
    assert "no movement sample has a true attitude" in err
    # one absurd gyro reading: the estimate was lost (NaN) and scored 0.000 (the errors skip NaN rows); now the
    # filter refuses the sample and evaluate names the trial and the sample
    folder = broad_trial(tmp_path / "huge")
    import scipy.io

    fields = scipy.io.loadmat(folder / "t1.mat")
    fields["imu_gyr"][98, 0] = 1e300
    scipy.io.savemat(folder / "t1.mat", fields)
    err = refused("evaluate", folder, code=2)
    assert "t1.mat: sample 99 of 300: gyro[98] = [1e+300, 0.0, 0.0] is beyond" in err
    # trials built in code bypass the loader: the evaluation itself refuses a NaN score
    trial = load_trials(broad_trial(tmp_path / "good"))[0]
    trial.quat[:] = 0.0
    with pytest.raises(ValueError, match=r"t1: the true attitude cannot be scored: q_ref\[0\] is a zero quaternion"):
        evaluate("tilt", [trial])


def test_scheduler_workers_find_relative_inputs(tmp_path):
    distributed = pytest.importorskip("distributed")
    (tmp_path / "logs").mkdir()
    write_table(tmp_path / "logs" / "a.parquet", level())
    # the workers run in this process, whose working folder is not the command's: relative paths name nothing there
    assert os.getcwd() != str(tmp_path)
    cluster = distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, protocol="tcp", host="127.0.0.1", dashboard_address=None
    )
    try:
        address = cluster.scheduler_address
        jobs = run("batch", "logs/*.parquet", "estimate", "--scheduler", address, "--out", "out", cwd=tmp_path)
        split = run("batch", "logs/a.parquet", "integrate", "--split", "2", "--scheduler", address, cwd=tmp_path)
    finally:
        cluster.close()
    assert jobs.returncode == 0, jobs.stderr
    assert split.returncode == 0, split.stderr
    assert (tmp_path / "out" / "a.estimate.parquet").is_file()
    assert (tmp_path / "logs" / "a.integrate.parquet").is_file()


def test_an_unknown_format_is_met_by_the_option_the_command_has(tmp_path, attitude_file):
    # the message said --format (the output's option) where the input's is --in-format; plot has neither
    src = tmp_path / "log.weird"
    src.write_text("a,b\n1,2\n")
    for command in ("estimate", "integrate", "convert"):
        err = refused(command, src, "-o", tmp_path / "o.csv")
        assert "cannot tell the format of 'log.weird'" in err and "--in-format" in err
        assert "--in-format" in run(command, "--help").stdout
    err = refused("plot", src)
    assert "give it one of those suffixes" in err and "--in-format" not in err
    assert "--in-format" not in run("plot", "--help").stdout
    err = refused("plot", attitude_file, "--truth", src)
    assert "log.weird" in err and "--in-format" not in err
