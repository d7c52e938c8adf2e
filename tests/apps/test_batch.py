"""Many files in parallel (local processes and a Dask cluster), and one integration split across workers."""

import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner

import strapdown as sd
import strapdown.fusion  # sd.fusion below: a subpackage is an attribute once imported
from strapdown.apps.batch import Job, expand, integrate_split, run_batch
from strapdown.io import ImuColumns, integrate_file, read_table, write_table

QUAT = ["qw", "qx", "qy", "qz"]


def quats(path):
    table = read_table(path)
    return np.column_stack([table[c] for c in QUAT])


def rotation_angle(p, q):
    """Angle between attitudes without the library's product: 4 asin(min(|p - q|, |p + q|) / 2)."""
    d = np.minimum(np.linalg.norm(p - q, axis=-1), np.linalg.norm(p + q, axis=-1))
    return 4 * np.arcsin(np.minimum(d / 2, 1))


@pytest.fixture(scope="module")
def long_log(tmp_path_factory):
    """200 000 samples of a lively random motion with jittery timestamps, in four row groups."""
    rng = np.random.default_rng(11)
    n = 200_000
    t = np.cumsum(rng.uniform(0.0045, 0.0055, n))
    gyro = np.cumsum(rng.normal(0, 0.01, (n, 3)), axis=0)  # a random walk: rates of a few rad/s
    path = tmp_path_factory.mktemp("split") / "long.parquet"
    cols = {"t": t, "gx": gyro[:, 0], "gy": gyro[:, 1], "gz": gyro[:, 2]}
    import pyarrow as pa
    import pyarrow.parquet as pq

    pq.write_table(pa.table(cols), path, row_group_size=50_000)
    return path, t, gyro


@pytest.mark.parametrize(
    ("method", "kind", "frame", "parts"),
    [("exact", "rate", "body", 7), ("cayley", "average", "body", 3), ("exact", "increment", "reference", 5)],
)
def test_split_integration_equals_the_sequential_one(long_log, tmp_path, method, kind, frame, parts):
    path, t, gyro = long_log
    if kind == "increment":
        gyro = gyro * 0.005
    q0 = sd.from_euler([10.0, -20.0, 30.0], degrees=True)
    common = {"method": method, "input": kind, "rate_frame": frame, "q0": q0}
    if kind == "increment":
        src = write_table(tmp_path / "inc.parquet", {"t": t, "gx": gyro[:, 0], "gy": gyro[:, 1], "gz": gyro[:, 2]})
    else:
        src = path
    split = integrate_split(src, tmp_path / "split.parquet", parts=parts, workers=2, chunk_rows=30_000, **common)
    assert split.rows == len(t)
    whole = integrate_file(src, tmp_path / "whole.parquet", **common)
    if kind == "increment":
        library = sd.integrate(gyro[:-1], q0=q0, method=method, input=kind, rate_frame=frame)
    else:
        library = sd.integrate(gyro[:-1], t=t, q0=q0, method=method, input=kind, rate_frame=frame)
    q_split = quats(split.output)
    assert rotation_angle(q_split, quats(whole.output)).max() < 1e-12
    assert rotation_angle(q_split, library).max() < 1e-12
    np.testing.assert_array_equal(read_table(split.output)["t"], t - t[0])  # seconds from the first sample
    # the parts were really different: from the identity, the second part's attitudes are not the final ones
    assert rotation_angle(library[-1], q0) > 0.1


def test_split_through_the_cli_matches_integrate(long_log, tmp_path):
    path, t, gyro = long_log
    res = CliRunner().invoke(
        __import__("strapdown.cli", fromlist=["_build"])._build(),
        ["batch", str(path), "integrate", "--split", "4", "-j", "1", "--out", str(tmp_path), "--no-euler"],
    )
    assert res.exit_code == 0, res.output
    out = tmp_path / "long.integrate.parquet"
    assert list(read_table(out)) == ["t", *QUAT]
    assert rotation_angle(quats(out), sd.integrate(gyro[:-1], t=t)).max() < 1e-12


def test_expand_skips_earlier_outputs_and_keeps_layout(tmp_path):
    (tmp_path / "a" / "b").mkdir(parents=True)
    for name in ("a/x.csv", "a/b/y.csv", "a/x.estimate.csv", "a/b/notes.txt"):
        (tmp_path / name).write_text("t\n0\n")
    files, root = expand(str(tmp_path / "a" / "**" / "*.csv"))
    assert [f.relative_to(tmp_path).as_posix() for f in files] == ["a/b/y.csv", "a/x.csv"]
    assert root == tmp_path / "a"


def _flights(folder, count):
    from strapdown.io import simulate_file

    paths = []
    for i in range(count):
        paths.append(simulate_file(folder / f"f{i:02d}.parquet", duration=3.0, imu="consumer", seed=i).output)
    return paths


def test_local_batch_reports_a_bad_file_and_writes_the_rest(tmp_path):
    paths = _flights(tmp_path, 3)
    (tmp_path / "f99.parquet").write_bytes(b"not parquet")
    jobs = [
        Job("estimate", str(p), str(p.with_suffix(".est.csv")), {"estimator": "mahony"})
        for p in [*paths, tmp_path / "f99.parquet"]
    ]
    results = run_batch(jobs, workers=2)
    assert [r.ok for r in results] == [True, True, True, False]
    assert "f99.parquet is not a readable parquet file" in results[-1].error
    for p, r in zip(paths, results, strict=False):
        table = read_table(p)
        cols = [np.column_stack([table[f"{s}{a}"] for a in "xyz"]) for s in "gam"]
        ref = sd.fusion.Mahony(sd.fusion.MahonyParams()).update(*cols, t=table["t"])
        np.testing.assert_array_equal(quats(r.output), ref.q)


def test_dask_batch_of_50_files_equals_50_sequential_calls(tmp_path):
    distributed = pytest.importorskip("distributed")
    logs = tmp_path / "logs"
    (logs / "sub").mkdir(parents=True)
    paths = _flights(logs, 25) + _flights(logs / "sub", 25)
    (logs / "sub" / "corrupt.parquet").write_bytes(b"PAR1" + bytes(100))

    # the reference: the estimate command called on each file in turn
    cli = __import__("strapdown.cli", fromlist=["_build"])._build()
    runner = CliRunner()
    for p in paths:
        res = runner.invoke(cli, ["estimate", str(p), "-o", str(tmp_path / "seq" / f"{p.parent.name}_{p.name}"), "-q"])
        assert res.exit_code == 0, res.output

    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, protocol="tcp", host="127.0.0.1", dashboard_address=None
    )
    try:
        res = subprocess.run(
            [sys.executable, "-m", "strapdown.cli", "batch", str(logs / "**" / "*.parquet"), "estimate",
             "--scheduler", cluster.scheduler_address, "--out", str(tmp_path / "out"), "-q"],
            capture_output=True, text=True, timeout=300,
        )  # fmt: skip
    finally:
        cluster.close()
    assert res.returncode == 1
    assert "corrupt.parquet" in res.stderr and "1 of 51 files failed" in res.stderr
    written = sorted((tmp_path / "out").rglob("*.parquet"))
    assert len(written) == 50
    for p in paths:
        rel = p.parent.relative_to(logs)
        batch_out = tmp_path / "out" / rel / f"{p.stem}.estimate.parquet"
        seq_out = tmp_path / "seq" / f"{p.parent.name}_{p.name}"
        a, b = read_table(batch_out), read_table(seq_out)
        assert list(a) == list(b)
        for name in a:
            np.testing.assert_array_equal(a[name], b[name])


def test_columns_spec_travels_to_workers_unchanged():
    import pickle

    spec = ImuColumns(gyro="a,b,c", rate=50.0, extra=(("known_acc", "x,y,z"),))
    assert pickle.loads(pickle.dumps(spec)) == spec


def _gyro_log(path, t, scale=0.5):
    """A random gyro log at times t: rates of about ``scale`` rad/s (or increments of about ``scale`` rad)."""
    gyro = np.random.default_rng(0).normal(0, scale, (len(t), 3))
    return write_table(path, {"t": t, "gx": gyro[:, 0], "gy": gyro[:, 1], "gz": gyro[:, 2]}), gyro


def test_split_refuses_a_default_method_it_cannot_split(tmp_path):
    from strapdown.apps.batch import SPLIT_METHODS

    path, _ = _gyro_log(tmp_path / "inc.parquet", np.arange(2000) * 0.01, scale=0.005)
    # plain integrate of increments defaults to coning2, which reads sample pairs across a cut
    assert sd.AttitudeIntegrator(input="increment").method == "coning2"
    with pytest.raises(ValueError, match="coning2") as err:
        integrate_split(path, tmp_path / "out.parquet", parts=4, workers=1, input="increment")
    assert all(m in str(err.value) for m in SPLIT_METHODS)
    assert not (tmp_path / "out.parquet").exists()
    from strapdown.apps.batch import check_split

    for method, kind in ((None, "increment"), ("coning2", "rate"), ("rk4", "average")):
        with pytest.raises(ValueError, match="method"):
            check_split(4, method, kind)
    with pytest.raises(ValueError, match="parts"):
        check_split(0, "exact", "rate")
    # where the plain default can be split it is kept: the same attitudes as plain integrate
    assert check_split(4, None, "rate") is None
    whole = integrate_file(path, tmp_path / "whole.parquet")
    split = integrate_split(path, tmp_path / "split.parquet", parts=4, workers=1)
    assert rotation_angle(quats(split.output), quats(whole.output)).max() < 1e-13


@pytest.mark.parametrize(
    ("name", "shift", "where"),
    [
        ("gap.parquet", {3800: 5.0}, "a gap of 5.01 s"),  # exactly where the third of four parts starts
        ("back.csv", {3800: -0.5}, "does not increase at line 3802"),  # line 1 is the header
        ("gaps.parquet", {3800: 5.0, 6000: 5.0}, "before row 3800"),  # the first gap in the file is reported
    ],
)
def test_split_checks_time_across_part_boundaries_as_integrate_does(tmp_path, name, shift, where):
    t = np.arange(7600) * 0.01
    for row, dt in shift.items():
        t[row:] += dt
    path, _ = _gyro_log(tmp_path / name, t)
    with pytest.raises(ValueError) as whole:
        integrate_file(path, tmp_path / "whole.csv", on_gap="error")  # a split run stops at gaps
    assert where in str(whole.value)
    with pytest.raises(ValueError) as split:
        integrate_split(path, tmp_path / "split.csv", parts=4, workers=1, chunk_rows=1000)
    assert str(split.value) == str(whole.value)
    assert not (tmp_path / "split.csv").exists()


def test_clashing_outputs_are_refused_before_anything_runs(tmp_path):
    from strapdown.apps.batch import batch_outputs

    t = np.arange(200) * 0.01
    for suffix in (".csv", ".h5", ".mat"):
        _gyro_log(tmp_path / f"x{suffix}", t)
    _gyro_log(tmp_path / "y.csv", t)
    files, root = expand(str(tmp_path / "*"))
    for out in (None, tmp_path / "res"):
        with pytest.raises(ValueError) as err:
            batch_outputs(files, "integrate", root, out)
        message = str(err.value)
        assert all(str(tmp_path / f"x{s}") in message for s in (".csv", ".h5", ".mat"))
        assert "x.integrate.csv" in message and "y.csv" not in message
    jobs = [Job("integrate", str(f), str(tmp_path / "same.csv")) for f in files[:2]]
    with pytest.raises(ValueError, match=r"same\.csv"):
        run_batch(jobs, workers=1)
    cli = __import__("strapdown.cli", fromlist=["_build"])._build()
    for extra in ([], ["--split", "2"]):
        res = CliRunner().invoke(cli, ["batch", str(tmp_path / "*"), "integrate", "-j", "1", *extra])
        assert res.exit_code == 2, res.output
        assert f"{tmp_path / 'x.mat'} -> {tmp_path / 'x.integrate.csv'}" in res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.csv", "x.h5", "x.mat", "y.csv"]


@pytest.mark.parametrize("method", [None, "cayley"])
def test_split_output_carries_the_metadata_of_integrate(tmp_path, method):
    import pyarrow.parquet as pq

    path, _ = _gyro_log(tmp_path / "g.parquet", np.arange(3000) * 0.01)
    common = {"method": method, "input": "average", "rate_frame": "reference"}
    # a split run stops at gaps: the metadata of integrate with on_gap="error" (no gap or segment column)
    whole = integrate_file(path, tmp_path / "whole.parquet", on_gap="error", **common)
    split = integrate_split(path, tmp_path / "split.parquet", parts=3, workers=1, **common)
    expected = pq.read_schema(whole.output).metadata
    assert expected[b"strapdown_command"] == b"integrate" and expected[b"input"] == b"average"
    assert pq.read_schema(split.output).metadata == expected


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--samples", "increment"], "integrates with method 'coning2' by default, which cannot be split"),
        (["-m", "coning2"], "method 'coning2' cannot be split"),
        (["--split", "0"], "--split takes a positive number of parts"),
    ],
)
def test_cli_refuses_a_split_it_cannot_do_before_reading_any_file(tmp_path, options, message):
    t = np.arange(400) * 0.01
    for name in ("a.parquet", "b.parquet"):
        _gyro_log(tmp_path / name, t, scale=0.005)
    cli = __import__("strapdown.cli", fromlist=["_build"])._build()
    args = ["batch", str(tmp_path / "*.parquet"), "integrate", "--split", "4", "-j", "1", *options]
    res = CliRunner().invoke(cli, args)
    assert res.exit_code == 2, res.output
    assert message in res.output and "FAILED" not in res.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.parquet", "b.parquet"]


def test_split_turns_the_axes_and_counts_time_as_integrate_does(long_log, tmp_path):
    path, t, gyro = long_log
    common = {"method": "exact", "body": "FRD", "out_body": "FLU"}
    split = integrate_split(path, tmp_path / "split.parquet", parts=3, workers=1, chunk_rows=40_000, **common)
    whole = integrate_file(path, tmp_path / "whole.parquet", **common)
    assert rotation_angle(quats(split.output), quats(whole.output)).max() < 1e-12
    # FRD -> FLU negates y and z: the same as integrating the negated rates in the library
    library = sd.integrate(gyro[:-1] * [1.0, -1.0, -1.0], t=t)
    assert rotation_angle(quats(split.output), library).max() < 1e-12
    from strapdown.io import read_metadata

    meta, ref = read_metadata(split.output), read_metadata(whole.output)
    assert meta["body"] == ref["body"] == "FLU" and meta["sensor_axes"] == "FRD"
    assert meta["time_origin"] == ref["time_origin"] == repr(float(t[0]))
