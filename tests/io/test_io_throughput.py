"""What the file commands do for speed must not change what they write: float32 outputs (``--float32``) are the
float64 results rounded, and the read-ahead thread keeps the order of chunks and errors and stops with its block."""

import threading

import numpy as np
import pytest
from tests.conftest import strapdown_cli

from strapdown.io import OutputSpec, estimate_file, integrate_file, read_metadata, read_table, write_table
from strapdown.io._ahead import ReadAhead


def reader_threads():
    return [t for t in threading.enumerate() if t.name == "strapdown-reader"]


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    rng = np.random.default_rng(11)
    n = 1000
    t = np.arange(n) * 0.01 + rng.uniform(-1e-4, 1e-4, n)
    gyro = np.cumsum(rng.normal(0, 0.05, (n, 3)), axis=0)  # rad/s, a wandering motion through all angles
    columns = {"t": t, "gx": gyro[:, 0], "gy": gyro[:, 1], "gz": gyro[:, 2]}
    return write_table(tmp_path_factory.mktemp("log") / "log.parquet", columns)


@pytest.fixture(scope="module")
def still(tmp_path_factory):
    """A sensor at rest: gyro and accelerometer noise about zero and gravity."""
    rng = np.random.default_rng(12)
    n = 1000
    gyro = rng.normal(0, 0.01, (n, 3)) + np.array([0.002, -0.001, 0.003])
    acc = np.tile([0.0, 0.0, 9.81], (n, 1)) + rng.normal(0, 0.05, (n, 3))
    columns = {"t": np.arange(n) * 0.01, "gx": gyro[:, 0], "gy": gyro[:, 1], "gz": gyro[:, 2]}
    columns |= {"ax": acc[:, 0], "ay": acc[:, 1], "az": acc[:, 2]}
    return write_table(tmp_path_factory.mktemp("still") / "still.parquet", columns)


def test_the_read_ahead_yields_everything_in_order():
    with ReadAhead(iter(range(1000)), depth=3) as items:
        assert list(items) == list(range(1000))
    assert not reader_threads()


def test_an_error_of_the_producer_comes_after_the_items_before_it():
    def produce():
        yield from range(3)
        raise ValueError("row 3 is bad")

    got = []
    with pytest.raises(ValueError, match="row 3 is bad"), ReadAhead(produce()) as items:
        for item in items:
            got.append(item)
    assert got == [0, 1, 2]
    assert not reader_threads()


def test_an_error_of_the_consumer_stops_the_producer_and_runs_its_clean_up():
    made, closed = [], []

    def produce():
        try:
            for i in range(10**9):
                made.append(i)
                yield i
        finally:
            closed.append(True)

    with pytest.raises(KeyboardInterrupt), ReadAhead(produce(), depth=2) as items:
        for item in items:
            if item == 5:
                raise KeyboardInterrupt  # Ctrl-C in the consumer
    assert closed == [True]
    assert not reader_threads()
    assert len(made) <= 6 + 2 + 1  # at most the queue's depth and the item in hand beyond what was consumed


def test_a_bad_row_late_in_a_file_fails_the_run_with_no_output_and_no_thread_left(tmp_path):
    n = 6000  # past the 4096 rows that the reader looks at first: the bad row is found by the read-ahead thread
    table = {"t": np.arange(n) * 0.01, "gx": np.zeros(n), "gy": np.full(n, 0.1), "gz": np.zeros(n)}
    table["gy"][5000] = np.nan
    bad = write_table(tmp_path / "bad.parquet", table)
    with pytest.raises(ValueError, match=r"row 5000.*'gy'"):
        integrate_file(bad, tmp_path / "out.parquet", chunk_rows=64)
    assert not (tmp_path / "out.parquet").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.parquet"]  # no temporary either
    assert not reader_threads()


@pytest.mark.parametrize("fmt", ["parquet", "csv", "h5", "mat"])
def test_float32_integrate_is_the_float64_run_rounded(tmp_path, log, fmt):
    wide = read_table(integrate_file(log, tmp_path / f"64.{fmt}", chunk_rows=97).output)
    path = integrate_file(log, tmp_path / f"32.{fmt}", chunk_rows=97, out=OutputSpec(float32=True)).output
    narrow = read_table(path)
    assert list(narrow) == list(wide)
    np.testing.assert_array_equal(narrow["t"], wide["t"])  # time stays float64
    for name in ("qw", "qx", "qy", "qz", "yaw_deg", "pitch_deg", "roll_deg"):
        # each value is the nearest float32 to the float64 result (round to nearest, numpy's cast); CSV text is
        # the shortest decimal that reads back as that float32, which float64 parsing does not return exactly
        np.testing.assert_array_equal(narrow[name].astype(np.float32), wide[name].astype(np.float32))
        if fmt != "csv":
            np.testing.assert_array_equal(narrow[name], narrow[name].astype(np.float32))
        assert not np.array_equal(narrow[name], wide[name])  # and it really was rounded
    assert "float32" in read_metadata(path)["precision"]
    assert "precision" not in read_metadata(tmp_path / f"64.{fmt}")


def test_float32_columns_are_stored_as_float32(tmp_path, log):
    import pyarrow.parquet as pq

    path = integrate_file(log, tmp_path / "32.parquet", out=OutputSpec(float32=True)).output
    types = {f.name: str(f.type) for f in pq.read_schema(path)}
    angles = {"t": "double", **dict.fromkeys(["qw", "qx", "qy", "qz", "yaw_deg", "pitch_deg", "roll_deg"], "float")}
    assert types == {**angles, "gap": "bool", "segment": "int32"}  # the default on_gap's gap and segment columns
    wide = integrate_file(log, tmp_path / "64.parquet").output
    # 7 of the 8 columns halved: the file shrinks to about (1 + 7/2) / 8 of the float64 one
    assert path.stat().st_size < 0.7 * wide.stat().st_size


def test_float32_estimate_rounds_quaternions_angles_and_bias_but_not_flags(tmp_path, still):
    wide = read_table(estimate_file(still, tmp_path / "64.parquet", estimator="mahony", chunk_rows=128).output)
    out = OutputSpec(float32=True)
    path = estimate_file(still, tmp_path / "32.parquet", estimator="mahony", chunk_rows=128, out=out).output
    narrow = read_table(path)
    assert list(narrow) == list(wide)
    rounded = [n for n in wide if n.startswith(("q", "bias_", "yaw", "pitch", "roll"))]
    assert len(rounded) == 10
    for name in wide:
        expected = wide[name].astype(np.float32).astype(np.float64) if name in rounded else wide[name]
        np.testing.assert_array_equal(narrow[name], expected, err_msg=name)


def test_the_cli_float32_flag(tmp_path, log, still):
    import pyarrow.parquet as pq

    res = strapdown_cli("integrate", log, "-o", tmp_path / "a.parquet", "--float32", "-q")
    assert res.returncode == 0, res.stderr
    assert str(pq.read_schema(tmp_path / "a.parquet").field("qw").type) == "float"
    res = strapdown_cli("estimate", still, "-o", tmp_path / "e.csv", "--float32", "-e", "mahony", "-q")
    assert res.returncode == 0, res.stderr
    assert "float32" in read_metadata(tmp_path / "e.csv")["precision"]
    assert "--float32" in strapdown_cli("integrate", "--help").stdout


def awkward_quaternions():
    """Random unnormalised quaternions and the cases where Euler angles are delicate, each also negated."""
    from strapdown import from_euler

    rng = np.random.default_rng(13)
    special = [np.eye(4)[i] for i in range(4)]  # identity and 180° about each axis
    for seq in ("ZYX", "ZXZ", "xyz", "zxz"):  # at and next to gimbal lock, both limits
        for middle in (-90.0, 90.0, 0.0, 180.0, 89.9999999, 1e-9):
            special.append(from_euler([30.0, middle, -170.0], seq, degrees=True))
    q = np.concatenate([rng.normal(size=(600, 4)), np.array(special)])
    return np.concatenate([q, -q])


@pytest.mark.parametrize("float32", [False, True])
@pytest.mark.parametrize("degrees", [True, False])
def test_the_attitude_columns_are_as_euler_and_the_quaternion_rounded_to_the_output_type(degrees, float32):
    """One kernel pass writes the quaternion and angle columns: they must be the library's own conversion's."""
    from itertools import permutations, product

    from strapdown import as_euler
    from strapdown.io import Angles, attitude_columns

    q = awkward_quaternions()
    t = np.arange(len(q)) * 0.01
    dtype = np.float32 if float32 else np.float64
    tait_bryan = ["".join(p) for p in permutations("XYZ")]
    proper = [a + b + a for a, b in product("XYZ", repeat=2) if a != b]
    sequences = [s for s in tait_bryan + proper] + [s.lower() for s in tait_bryan + proper]
    assert len(sequences) == 24
    for seq, yaw_range in product(sequences, (None, "signed", "positive")):
        angles = Angles(seq, degrees=degrees, yaw_range=yaw_range)
        cols = attitude_columns(t, q, OutputSpec(angles=angles, float32=float32), check=False)
        expected = as_euler(q, seq, degrees, yaw_range=angles.range).astype(dtype)
        got = np.column_stack(list(cols.values())[5:])
        assert got.dtype == dtype and np.array_equal(got, expected), (seq, yaw_range)
        assert np.array_equal(np.column_stack(list(cols.values())[1:5]), q.astype(dtype))
        assert cols["t"].dtype == np.float64 and np.array_equal(cols["t"], t)


def test_the_attitude_columns_check_and_rescale_extreme_quaternions_as_as_euler_does():
    from strapdown import as_euler
    from strapdown.io import attitude_columns

    q = awkward_quaternions()[:50]
    scaled = q * np.where(np.arange(50) % 2, 1e200, 1e-300)[:, None]  # products of components overflow
    cols = attitude_columns(np.zeros(50), scaled)
    got = np.column_stack([cols["yaw_deg"], cols["pitch_deg"], cols["roll_deg"]])
    assert np.array_equal(got, as_euler(scaled, "ZYX", True, yaw_range="positive"))
    # the rotations of q (scaling by 1e200 rounds each component: the angles move by a few ulp)
    assert np.allclose(got, as_euler(q, "ZYX", True, yaw_range="positive"), rtol=0, atol=1e-9)
    assert np.array_equal(cols["qw"], scaled[:, 0])  # the quaternion as given
    with pytest.raises(ValueError, match="q"):
        attitude_columns([0.0], [[np.nan, 0.0, 0.0, 1.0]])
    assert list(attitude_columns([0.0], [[1.0, 0, 0, 0]], OutputSpec(euler=False))) == ["t", "qw", "qx", "qy", "qz"]


@pytest.mark.parametrize("fmt", ["parquet", "csv", "h5", "mat"])
def test_many_small_chunks_write_what_one_call_of_the_library_gives(tmp_path, log, fmt):
    """The columns of each chunk are handed to the writer without a copy (and the MATLAB writer keeps every chunk
    until the end): no row may change after it was handed on."""
    from strapdown import as_euler, integrate

    table = read_table(integrate_file(log, tmp_path / f"out.{fmt}", chunk_rows=61).output)
    data = read_table(log)
    t = data["t"]
    q = integrate(np.column_stack([data["gx"], data["gy"], data["gz"]])[:-1], t=t)
    got = np.column_stack([table[n] for n in ("qw", "qx", "qy", "qz")])
    angles = np.column_stack([table[n] for n in ("yaw_deg", "pitch_deg", "roll_deg")])
    np.testing.assert_allclose(table["t"], t - t[0], rtol=0, atol=1e-12)
    # one call and chunks of 61 rows associate the products differently: equal to rounding, not bit for bit
    assert np.max(np.abs(np.abs(np.sum(got * q, axis=1)) - 1)) < 1e-12
    expected = as_euler(q, "ZYX", degrees=True, yaw_range="positive")
    wrapped = (angles - expected + 180.0) % 360.0 - 180.0
    assert np.max(np.abs(wrapped)) < 1e-7


@pytest.mark.parametrize("fmt", ["parquet", "csv", "h5", "mat"])
def test_a_writer_opens_the_claimed_empty_file_without_truncating_and_any_other_file_afresh(tmp_path, fmt):
    """The empty temporary file of table_writer is written in place (truncating it made ext4 flush the whole
    output when it was closed); a TableWriter given a file with content still replaces all of it."""
    from strapdown.io.writers import TableWriter, _mode

    empty, used = tmp_path / f"empty.{fmt}", tmp_path / f"used.{fmt}"
    empty.touch()
    used.write_bytes(b"x" * 1_000_000)  # longer than the table: no byte of it may remain
    assert _mode(empty) == "r+b" and _mode(used) == "wb" and _mode(tmp_path / "absent") == "wb"
    columns = {"t": np.arange(5.0), "x": np.arange(5.0) ** 2}
    for path in (empty, used):
        w = TableWriter(path, "hdf5" if fmt == "h5" else fmt, {"frame": "NED"}, background=False)
        w.write(columns)
        w.close()
        table = read_table(path)
        np.testing.assert_array_equal(table["x"], columns["x"])
        assert read_metadata(path)["frame"] == "NED"
    if fmt != "h5":  # an HDF5 file's layout depends on how it was opened; the others must be the same bytes
        assert empty.read_bytes() == used.read_bytes()
