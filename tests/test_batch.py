"""Many files in parallel (local processes and a Dask cluster), and one integration split across workers."""

import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner

import strapdown as sd
from strapdown.batch import Job, expand, integrate_split, run_batch
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
    np.testing.assert_array_equal(read_table(split.output)["t"], t)
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
