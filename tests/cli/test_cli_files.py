"""The file commands end to end: the CLI run as a subprocess on generated files in every format, its numbers
checked against the library functions on the same arrays."""

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import strapdown as sd
from strapdown.fusion import ESTIMATORS
from strapdown.io import read_table, write_table

FORMATS = ["csv", "parquet", "h5", "mat"]
QUAT = ["qw", "qx", "qy", "qz"]
TRUE = [f"{c}_true" for c in QUAT]


def run(*args, timeout=120):
    return subprocess.run(
        [sys.executable, "-m", "strapdown.cli", *map(str, args)], capture_output=True, text=True, timeout=timeout
    )


def ok(*args):
    res = run(*args)
    assert res.returncode == 0, res.stderr
    return res


def stack(table, names):
    return np.column_stack([table[n] for n in names])


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    """A consumer-grade aerobatic flight, simulated by the CLI into every format (6 s at 100 Hz)."""
    folder = tmp_path_factory.mktemp("logs")
    for fmt in FORMATS:
        ok("simulate", folder / f"show.{fmt}", "--scenario", "aerobatic-show", "--imu", "consumer", "--duration", 6)
    return folder


@pytest.mark.parametrize("fmt", FORMATS)
def test_simulate_writes_what_the_simulator_samples(logs, fmt):
    from strapdown.simulate import ImuModel, sample
    from strapdown.simulate.scenarios import scenario

    table = read_table(logs / f"show.{fmt}")
    data = sample(
        scenario("aerobatic-show"), 100.0, imu=ImuModel.consumer_mems(), reference="ENU", body="FLU", duration=6
    )
    np.testing.assert_array_equal(table["t"], data.t[:-1])
    np.testing.assert_array_equal(stack(table, ["gx", "gy", "gz"]), data.gyro)
    np.testing.assert_array_equal(stack(table, ["mx", "my", "mz"]), data.mag)
    np.testing.assert_array_equal(stack(table, TRUE), data.q_true[:-1])


@pytest.mark.parametrize("fmt", FORMATS)
def test_integrate_in_every_format_equals_the_library(logs, tmp_path, fmt):
    table = read_table(logs / f"show.{fmt}")
    q0 = stack(table, TRUE)[0]
    out = tmp_path / f"att.{'parquet' if fmt == 'parquet' else 'csv'}"
    ok("integrate", logs / f"show.{fmt}", "-o", out, "--q0", ",".join(repr(float(x)) for x in q0), "--method", "rk4")
    result = read_table(out)
    gyro = stack(table, ["gx", "gy", "gz"])
    expected = sd.integrate(gyro[:-1], t=table["t"], q0=q0, method="rk4")
    np.testing.assert_allclose(stack(result, QUAT), expected, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(result["t"], table["t"])
    angles = sd.as_euler(expected, "ZYX", degrees=True, yaw_range="positive")
    np.testing.assert_allclose(stack(result, ["yaw_deg", "pitch_deg", "roll_deg"]), angles, rtol=0, atol=1e-9)


@pytest.mark.parametrize("fmt", FORMATS)
def test_estimate_in_every_format_equals_the_streaming_object(logs, tmp_path, fmt):
    table = read_table(logs / f"show.{fmt}")
    gyro, acc, mag = (stack(table, [f"{p}{a}" for a in "xyz"]) for p in "gam")
    out = tmp_path / "est.parquet"
    ok("estimate", logs / f"show.{fmt}", "-o", out, "-e", "tilt", "-p", "tau_acc=1.5", "--chunk-rows", 97)
    result = read_table(out)
    cls, pcls, _ = ESTIMATORS["tilt"]
    ref = cls(pcls(tau_acc=1.5)).update(gyro, acc, t=table["t"])
    np.testing.assert_array_equal(stack(result, QUAT), ref.q)
    np.testing.assert_array_equal(stack(result, [f"bias_{a}_deg_s" for a in "xyz"]), np.degrees(ref.bias))
    np.testing.assert_array_equal(result["flags"], ref.flags)
    # with a magnetometer in the file, a 9D filter uses it; --6d leaves it out
    ok("estimate", logs / f"show.{fmt}", "-o", out, "-e", "madgwick", "--frame", "ned", "--radians")
    result = read_table(out)
    cls, pcls, _ = ESTIMATORS["madgwick"]
    ref = cls(pcls(), frame="NED").update(gyro, acc, mag, t=table["t"])
    np.testing.assert_array_equal(stack(result, QUAT), ref.q)
    ypr = sd.as_euler(ref.q, "ZYX", yaw_range="positive")  # Gajda's range by default
    np.testing.assert_allclose(stack(result, ["yaw_rad", "pitch_rad", "roll_rad"]), ypr, rtol=0, atol=1e-15)


def test_declared_units_give_the_same_estimate_as_si(logs, tmp_path):
    odd = tmp_path / "odd.parquet"
    ok("simulate", odd, "--scenario", "aerobatic-show", "--imu", "consumer", "--duration", 6)
    ok("simulate", tmp_path / "odd_units.csv", "--scenario", "aerobatic-show", "--imu", "consumer", "--duration", 6,
       "--gyro-unit", "deg/s", "--acc-unit", "g", "--mag-unit", "gauss")  # fmt: skip
    ok("estimate", odd, "-o", tmp_path / "si.csv", "-e", "mahony")
    ok("estimate", tmp_path / "odd_units.csv", "-o", tmp_path / "units.csv", "-e", "mahony",
       "--gyro-unit", "deg/s", "--acc-unit", "g", "--mag-unit", "gauss")  # fmt: skip
    a, b = read_table(tmp_path / "si.csv"), read_table(tmp_path / "units.csv")
    np.testing.assert_allclose(stack(a, QUAT), stack(b, QUAT), rtol=0, atol=1e-12)


def test_estimate_takes_the_rate_and_columns_of_a_broad_like_mat_file(tmp_path):
    import scipy.io

    rng = np.random.default_rng(3)
    n = 1500
    gyro = rng.normal(0, 0.2, (n, 3))
    acc = rng.normal(0, 0.2, (n, 3)) + np.array([0.0, 0.0, 9.81])
    mag = rng.normal(0, 0.5, (n, 3)) + np.array([15.0, 5.0, -40.0])
    path = tmp_path / "01_trial.mat"
    scipy.io.savemat(path, {"imu_gyr": gyro, "imu_acc": acc, "imu_mag": mag, "sampling_rate": 285.714})
    res = ok("estimate", path, "-e", "mahony", "--9d")
    assert "mahony 9D" in res.stderr
    result = read_table(tmp_path / "01_trial.estimate.csv")
    cls, pcls, _ = ESTIMATORS["mahony"]
    ref = cls(pcls()).update(gyro, acc, mag, dt=1 / 285.714)
    np.testing.assert_array_equal(stack(result, QUAT), ref.q)


def test_convert_on_the_command_line_equals_the_library():
    res = ok("convert", "--from", "euler", "--seq", "ZYX", "--degrees", "10", "20", "30", "--to", "quat")
    np.testing.assert_array_equal(np.array(res.stdout.split(), float), sd.from_euler([10, 20, 30], "ZYX", True))
    q = np.array([0.5, -0.5, 0.5, 0.5])
    res = ok("convert", "--from", "quat", *q, "--to", "rotvec")  # negative numbers are values, not options
    np.testing.assert_array_equal(np.array(res.stdout.split(), float), sd.as_rotvec(q))
    res = ok("convert", "--from", "quat", *q)
    rows = {line.split()[0]: np.array(line.split("(")[0].split()[1:], float) for line in res.stdout.splitlines()}
    np.testing.assert_array_equal(rows["matrix"], sd.as_matrix(q).ravel())
    np.testing.assert_array_equal(rows["gibbs"], sd.as_gibbs(q))
    np.testing.assert_array_equal(rows["compressed"], sd.as_compressed(q))
    u = sd.as_cayley_klein(q).ravel()
    np.testing.assert_array_equal(rows["cayley_klein"], np.column_stack([u.real, u.imag]).ravel())


@pytest.mark.parametrize(("target", "extra"), [("euler", ["--to-seq", "zxz"]), ("matrix", []), ("axis_angle", [])])
def test_convert_files_round_trip_and_equal_the_library(logs, tmp_path, target, extra):
    table = read_table(logs / "show.parquet")
    q = stack(table, TRUE)
    src = write_table(tmp_path / "q.parquet", {"t": table["t"], **dict(zip(QUAT, q.T, strict=True))})
    ok("convert", src, "-o", tmp_path / "to.csv", "--to", target, "--degrees", *extra)
    out = read_table(tmp_path / "to.csv")
    assert next(iter(out)) == "t"
    if target == "euler":
        expected = sd.as_euler(q, "zxz", degrees=True)
    elif target == "matrix":
        expected = sd.as_matrix(q).reshape(-1, 9)
    else:
        axis, angle = sd.as_axis_angle(q, degrees=True)
        expected = np.column_stack([axis, angle])
    np.testing.assert_allclose(stack(out, list(out)[1:]), expected, rtol=0, atol=1e-12)
    seq = ["--seq", "zxz"] if target == "euler" else []
    ok("convert", tmp_path / "to.csv", "-o", tmp_path / "back.parquet", "--from", target, "--to", "quat",
       "--degrees", *seq)  # fmt: skip
    back = stack(read_table(tmp_path / "back.parquet"), QUAT)
    np.testing.assert_allclose(sd.angle_between(back, q), 0, atol=1e-9)


def test_plot_writes_angle_error_and_bias_figures(logs, tmp_path):
    ok("estimate", logs / "show.parquet", "-o", tmp_path / "est.csv")
    res = ok("plot", tmp_path / "est.csv", "--truth", logs / "show.parquet", "--out", tmp_path / "fig")
    names = sorted(p.name for p in (tmp_path / "fig").iterdir())
    assert names == ["est_angles.png", "est_bias.png", "est_errors.png"]
    for name in names:
        assert (tmp_path / "fig" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert res.stdout.count("written:") == 3


def test_help_imports_nothing_heavy():
    # the whole of `strapdown --help`, in one process: no command module is imported for the listing
    code = (
        "import sys; from strapdown.cli import main\n"
        "try:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
        "heavy = [m for m in ('numba', 'pyarrow', 'h5py', 'scipy', 'matplotlib', 'distributed', 'tqdm', "
        "'strapdown.cli.estimate', 'strapdown.cli._options', 'strapdown.io') if m in sys.modules]\n"
        "assert not heavy, heavy"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr
    # How long it takes is measured in benchmarks/, never asserted here: a busy machine would fail it.
    assert run("--help").returncode == 0


@pytest.mark.parametrize("command", ["integrate", "estimate", "convert", "simulate", "plot", "batch", "demo"])
def test_every_command_has_examples_in_its_help(command):
    res = ok(command, "--help")
    examples = res.stdout.split("Examples:")[1]
    assert examples.count(f"strapdown {command}") >= 2


def test_a_bad_row_late_in_the_file_leaves_the_old_output_alone(tmp_path):
    n = 5000
    rng = np.random.default_rng(4)
    cols = {"t": np.arange(n) * 0.01, **{f"g{a}": rng.normal(0, 0.1, n) for a in "xyz"}}
    cols["gz"][4321] = np.nan
    src = write_table(tmp_path / "late.csv", cols)
    out = tmp_path / "att.parquet"
    out.write_bytes(b"the previous run")
    res = run("integrate", src, "-o", out, "--chunk-rows", 500)
    assert res.returncode == 1
    assert "line 4323" in res.stderr  # data row 4321 is on line 4323 (header on line 1)
    assert out.read_bytes() == b"the previous run"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["att.parquet", "late.csv"]


def test_a_killed_run_leaves_no_output(tmp_path):
    n = 3_000_000
    rng = np.random.default_rng(5)
    src = write_table(tmp_path / "big.parquet", {f"g{a}": rng.normal(0, 0.1, n) for a in "xyz"})
    out = tmp_path / "att.csv"  # CSV output: slow enough to be caught in the middle
    proc = subprocess.Popen(
        [sys.executable, "-m", "strapdown.cli", "integrate", src, "-o", out, "--rate", "100", "--chunk-rows", "20000"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        partial = []
        for _ in range(3000):  # polls 20 ms apart: about a minute at most, an upper bound, not a measurement
            if proc.poll() is not None:
                break
            partial = [p for p in tmp_path.iterdir() if p.name.startswith(".att.csv.") and p.stat().st_size > 0]
            if partial:
                break
            time.sleep(0.02)
        assert partial, "the run ended before it could be interrupted"
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == -signal.SIGKILL
    assert not out.exists()  # only the hidden temporary, never a partial att.csv


def test_simulated_units_are_named_and_read_back(tmp_path):
    # the help's own example: degrees, g and nT in an HDF5 file, read back without being told
    ok("simulate", tmp_path / "chair.h5", "--scenario", "rocking", "--reference", "NED", "--body", "FRD",
       "--gyro-unit", "deg/s", "--acc-unit", "g", "--mag-unit", "nT", "--duration", 5)  # fmt: skip
    table = read_table(tmp_path / "chair.h5")
    assert {"gx_dps", "ax_g", "mx_nT"} <= set(table)
    ok("integrate", tmp_path / "chair.h5", "-o", tmp_path / "att.csv")
    gyro = np.radians(stack(table, ["gx_dps", "gy_dps", "gz_dps"]))
    expected = sd.integrate(gyro[:-1], t=table["t"])
    np.testing.assert_allclose(stack(read_table(tmp_path / "att.csv"), QUAT), expected, atol=1e-12)


def test_convert_takes_the_angle_unit_from_the_names(tmp_path):
    rng = np.random.default_rng(7)
    q = sd.canonical(rng.normal(size=(40, 4)))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    e = sd.as_euler(q, "ZYX", degrees=True)
    src = write_table(tmp_path / "e.csv", {"yaw_deg": e[:, 0], "pitch_deg": e[:, 1], "roll_deg": e[:, 2]})
    for extra in ([], ["--columns", "yaw_deg,pitch_deg,roll_deg"], ["--degrees"]):
        ok("convert", src, "--from", "euler", "--to", "quat", "-o", tmp_path / "q.csv", *extra)
        back = stack(read_table(tmp_path / "q.csv"), QUAT)
        np.testing.assert_allclose(sd.angle_between(back, q), 0, atol=1e-12)
    res = run("convert", src, "--from", "euler", "--to", "quat", "--radians", "-o", tmp_path / "r.csv")
    assert res.returncode == 1 and "named in degrees, but the angles were declared in radians" in res.stderr
    assert not (tmp_path / "r.csv").exists()


def test_chunk_rows_zero_is_refused(tmp_path):
    src = write_table(tmp_path / "g.csv", {"t": np.arange(10) * 0.01, **{f"g{a}": np.zeros(10) for a in "xyz"}})
    res = run("integrate", src, "--chunk-rows", 0, "-o", tmp_path / "o.csv")
    assert res.returncode == 1 and "chunk_rows must be a positive integer, got 0" in res.stderr
