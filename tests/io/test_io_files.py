"""Readers, writers and the streaming file functions, in-process: every format, chunking, atomic output."""

import itertools

import numpy as np
import pytest

import strapdown as sd
from strapdown.io import (
    ImuColumns,
    ImuFile,
    convert_file,
    estimate_file,
    integrate_file,
    open_source,
    read_imu,
    read_table,
    table_writer,
    write_table,
)
from strapdown.io.pipelines import integrate_stream

FORMATS = ["csv", "parquet", "h5", "mat"]


def quats(table, suffix=""):
    return np.column_stack([table[f"q{c}{suffix}"] for c in "wxyz"])


@pytest.fixture(scope="module")
def columns():
    rng = np.random.default_rng(7)
    n = 257
    t = np.cumsum(rng.uniform(0.009, 0.011, n))  # irregular sampling
    return {"t": t, "gx": rng.normal(size=n), "gy": rng.normal(size=n), "gz": rng.normal(size=n)}


@pytest.mark.parametrize("fmt", FORMATS)
def test_write_then_read_is_exact_in_every_format(tmp_path, columns, fmt):
    path = write_table(tmp_path / f"x.{fmt}", columns)
    back = read_table(path)
    assert list(back) == list(columns)
    for name, values in columns.items():
        np.testing.assert_array_equal(back[name], values)  # CSV too: shortest round-trip text


@pytest.mark.parametrize("fmt", FORMATS)
def test_row_ranges_in_chunks_equal_the_slice(tmp_path, columns, fmt):
    path = write_table(tmp_path / f"x.{fmt}", columns)
    with open_source(path) as src:
        assert src.count_rows() == 257
        pieces = list(src.chunks(["gy", "t"], 7, start=40, stop=201))
    assert pieces[0][0] == 40
    rows = [row for row, _ in pieces]
    assert rows == sorted(rows)
    gy = np.concatenate([c["gy"] for _, c in pieces])
    np.testing.assert_array_equal(gy, columns["gy"][40:201])


def test_matlab_v5_arrays_and_rate_like_broad(tmp_path):
    import scipy.io

    rng = np.random.default_rng(1)
    n = 600
    gyro, acc = rng.normal(0, 0.3, (n, 3)), rng.normal(0, 0.3, (n, 3)) + np.array([0, 0, 9.81])
    mag = rng.normal(0, 1, (n, 3)) + np.array([20, 0, -40])
    path = tmp_path / "trial.mat"
    scipy.io.savemat(path, {"imu_gyr": gyro, "imu_acc": acc, "imu_mag": mag, "sampling_rate": 285.714})
    data = read_imu(path, optional=("acc", "mag"))
    np.testing.assert_array_equal(data.gyro, gyro)
    np.testing.assert_allclose(data.t, np.arange(n) / 285.714, rtol=1e-15)
    # the estimate from the file equals the library on the same arrays (rate from the file)
    report = estimate_file(path, tmp_path / "est.csv", estimator="mahony")
    ref = sd.fusion.Mahony(sd.fusion.MahonyParams()).update(gyro, acc, mag, dt=1 / 285.714)
    np.testing.assert_array_equal(quats(read_table(report.output)), ref.q)


def test_matlab_v73_is_read_through_hdf5_with_column_major_arrays(tmp_path):
    import h5py

    rng = np.random.default_rng(2)
    gyro = rng.normal(size=(50, 3))
    path = tmp_path / "v73.mat"
    with h5py.File(path, "w", userblock_size=512) as f:  # MATLAB's 512-byte header, then HDF5
        f["imu_gyr"] = gyro.T  # MATLAB stores column-major: an (N, 3) array appears as (3, N)
        f["t"] = (np.arange(50) * 0.01)[None]
    data = read_imu(path)
    np.testing.assert_array_equal(data.gyro, gyro)
    np.testing.assert_array_equal(data.t, np.arange(50) * 0.01)


@pytest.mark.parametrize(
    ("method", "kind"),
    [("exact", "rate"), ("cayley", "average"), ("rk4", "rate"), ("coning3", "rate"), ("coning2", "increment")],
)
@pytest.mark.parametrize("timing", ["time", "rate"])
def test_stream_equals_the_library_for_any_chunking(columns, method, kind, timing):
    from strapdown.io.imu import ImuChunk

    t = columns["t"] if timing == "time" else np.arange(257) / 100.0
    gyro = np.column_stack([columns[c] for c in ("gx", "gy", "gz")]) * 0.3
    q0 = sd.from_euler([20.0, 5.0, -3.0], degrees=True)
    if kind == "increment":
        expected = sd.integrate(gyro[:-1], q0=q0, method=method, input=kind)
    elif timing == "time":
        expected = sd.integrate(gyro[:-1], t=t, q0=q0, method=method, input=kind)
    else:
        expected = sd.integrate(gyro[:-1], dt=0.01, q0=q0, method=method, input=kind)
    for cuts in ([257], [1, 256], [5, 5, 100, 147], [128, 1, 1, 127]):
        bounds = np.cumsum([0, *cuts])
        chunks = [ImuChunk(int(a), t[a:b], gyro[a:b]) for a, b in itertools.pairwise(bounds)]
        pieces = list(
            integrate_stream(chunks, method=method, input=kind, q0=q0, rate=None if timing == "time" else 100.0)
        )
        np.testing.assert_array_equal(np.concatenate([p[0] for p in pieces]), t)
        q = np.concatenate([p[1] for p in pieces])
        assert q.shape == (257, 4)
        np.testing.assert_allclose(q, expected, rtol=0, atol=1e-14)


def test_integrate_file_columns_match_library_conversions(tmp_path, columns):
    path = write_table(tmp_path / "g.parquet", columns)
    table = read_table(integrate_file(path, tmp_path / "out.csv", chunk_rows=50).output)
    gyro = np.column_stack([columns[c] for c in ("gx", "gy", "gz")])
    q = sd.integrate(gyro[:-1], t=columns["t"])
    np.testing.assert_allclose(quats(table), q, rtol=0, atol=1e-15)
    ypr = sd.as_euler(quats(table), "ZYX", degrees=True, yaw_range="positive")
    np.testing.assert_array_equal(np.column_stack([table["yaw_deg"], table["pitch_deg"], table["roll_deg"]]), ypr)
    assert ((table["yaw_deg"] >= 0) & (table["yaw_deg"] < 360)).all()


def test_csv_text_that_is_not_a_number_is_located(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("t,gx,gy,gz\n0,0,0,0\n0.01,0,1e-3,0\n0.02,0,n/a?,0\n")
    with pytest.raises(ValueError, match=r"line 4, column 'gy': 'n/a\?' is not a number"):
        read_imu(path)


def test_csv_with_semicolons_and_an_iso_time_column(tmp_path):
    path = tmp_path / "semi.csv"
    path.write_text(
        "time;gx;gy;gz\n2024-05-01T10:00:00.000;0;0;0.5\n2024-05-01T10:00:00.010;0;0;0.5\n"
        "2024-05-01T10:00:00.020;0;0;0.5\n"
    )
    with ImuFile(path) as imu:
        chunk = next(imu.chunks())
    np.testing.assert_allclose(np.diff(chunk.t), 0.01, atol=1e-9)
    np.testing.assert_array_equal(chunk.gyro[:, 2], 0.5)


def test_units_are_converted_to_si(tmp_path):
    n = 20
    deg = np.full(n, 90.0)
    path = write_table(
        tmp_path / "u.csv",
        {"time_ms": np.arange(n) * 10.0, "gx_dps": deg, "gy_dps": 0 * deg, "gz_dps": 0 * deg}
        | {"ax": np.zeros(n), "ay": np.zeros(n), "az": np.ones(n)},
    )
    data = read_imu(path, ImuColumns(acc_unit="g"), optional=("acc",))
    np.testing.assert_allclose(data.t, np.arange(n) * 0.01, rtol=1e-15)
    np.testing.assert_allclose(data.gyro[:, 0], np.pi / 2, rtol=1e-15)
    np.testing.assert_array_equal(data.acc[:, 2], 9.80665)


def test_a_failed_write_leaves_the_old_file_and_no_temporaries(tmp_path):
    target = tmp_path / "out.parquet"
    target.write_bytes(b"previous results")
    with pytest.raises(RuntimeError, match="boom"), table_writer(target) as w:
        w.write({"a": np.arange(3.0)})
        raise RuntimeError("boom")
    assert target.read_bytes() == b"previous results"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.parquet"]


def test_output_has_ordinary_permissions(tmp_path):
    import os
    import stat

    path = write_table(tmp_path / "p.csv", {"a": np.zeros(1)})
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask


@pytest.mark.parametrize(
    "module",
    [
        "io.units",
        "io.columns",
        "io.readers",
        "io.writers",
        "io.imu",
        "io.tables",
        "io.pipelines",
        "io.pipelines.plot",
        "evaluate.figures",
        "rotations.values",
        "apps.batch",
        "io.registry",
        "io.reference",
        "io.timebase",
        "io.merge",
        "io.formats.mat",
        "io.formats.multi",
        "io.formats.ulog",
        "io.formats.rosbag",
        "io.formats.euroc",
        "io.formats.sensorlogger",
        "io.formats.phyphox",
    ],
)
def test_public_functions_have_numpy_docstrings_with_examples(module):
    import importlib
    import inspect

    mod = importlib.import_module(f"strapdown.{module}")
    for name in mod.__all__:
        obj = getattr(mod, name)
        if inspect.isfunction(obj):
            _check_numpy_docstring(f"{module}.{name}", obj)


def _check_numpy_docstring(name, fn):
    import inspect

    doc = fn.__doc__ or ""
    assert "Examples" in doc and ">>>" in doc, f"{name} has no example"
    assert "Returns" in doc or "Yields" in doc, f"{name}: numpy sections"
    # a function without parameters needs no "Parameters" section (nor one that says "None")
    assert "Parameters" in doc or not inspect.signature(fn).parameters, f"{name}: its parameters are not documented"


def test_the_docstring_check_wants_a_parameters_section_only_for_parameters():
    def documented():
        """Nothing to pass.

        Returns
        -------
        int

        Examples
        --------
        >>> 1
        1
        """

    def undocumented(x):
        """Something to pass.

        Returns
        -------
        int

        Examples
        --------
        >>> 1
        1
        """

    _check_numpy_docstring("documented", documented)
    with pytest.raises(AssertionError, match="parameters are not documented"):
        _check_numpy_docstring("undocumented", undocumented)


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_table_without_rows_is_written_with_its_columns(tmp_path, fmt):
    with table_writer(tmp_path / f"empty.{fmt}") as w:
        w.write({"t": np.zeros(0), "flag": np.zeros(0, dtype=np.uint8)})
    back = read_table(tmp_path / f"empty.{fmt}")
    assert list(back) == ["t", "flag"]
    assert all(v.shape == (0,) for v in back.values())
    # no chunk at all: no columns to write, so no file rather than one that no reader accepts
    with (
        pytest.raises(ValueError, match=r"nothing was written to .*none\.\w+: no columns"),
        table_writer(tmp_path / f"none.{fmt}"),
    ):
        pass
    assert not (tmp_path / f"none.{fmt}").exists()


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("n", [1, 2])
def test_one_and_two_row_tables_round_trip(tmp_path, fmt, n):
    cols = {"t": np.arange(n) * 0.01, "gx": np.full(n, 0.3), "gy": np.arange(n) - 0.5, "gz": np.zeros(n)}
    back = read_table(write_table(tmp_path / f"short.{fmt}", cols))
    assert list(back) == list(cols)
    for name, values in cols.items():
        np.testing.assert_array_equal(back[name], values)
    # and through the file commands: integrate to this format, then convert what was written
    out = integrate_file(write_table(tmp_path / "in.csv", cols), tmp_path / f"q.{fmt}").output
    q = quats(read_table(out))
    gyro = np.column_stack([cols[c] for c in ("gx", "gy", "gz")])
    np.testing.assert_allclose(q, np.vstack([[1.0, 0, 0, 0], sd.integrate(gyro[:-1], t=cols["t"])[1:]]), atol=1e-15)
    table = read_table(convert_file(out, tmp_path / "e.csv", target="rotvec").output)
    np.testing.assert_allclose(
        np.column_stack([table[f"rotvec_{a}_deg"] for a in "xyz"]), sd.as_rotvec(q, degrees=True), atol=1e-12
    )


@pytest.mark.parametrize("n", [1, 2, 3])
def test_matlab_v5_short_logs_keep_their_orientation(tmp_path, n):
    import scipy.io

    gyro = np.arange(3.0 * n).reshape(n, 3) / 10
    path = tmp_path / "short.mat"
    acc = gyro + np.array([0.0, 0.0, 9.5])  # |acc| near g: the unit check refuses |a| far from it (issue 12)
    scipy.io.savemat(path, {"imu_gyr": gyro, "imu_acc": acc, "sampling_rate": 50.0})  # BROAD's layout
    data = read_imu(path, optional=("acc",))
    np.testing.assert_array_equal(data.gyro, gyro)
    np.testing.assert_array_equal(data.acc, acc)
    np.testing.assert_array_equal(data.t, np.arange(n) / 50.0)
    if n > 1:  # a 1 x n time row beside n x 3 readings is a column (one row would be a scalar: MATLAB cannot tell)
        scipy.io.savemat(path, {"imu_gyr": gyro, "t": np.arange(n)[None] * 0.02})
        np.testing.assert_array_equal(read_imu(path).t, np.arange(n) * 0.02)


@pytest.mark.parametrize("fmt", FORMATS)
def test_integer_epoch_nanoseconds_count_from_the_first_exactly(tmp_path, fmt):
    ns = 1_700_000_000_000_000_000 + np.arange(6, dtype=np.int64) * 10_000_000 + np.array([0, 1, 2, 3, 7, 9])
    cols = {"timestamp_ns": ns, "gx": np.zeros(6), "gy": np.zeros(6), "gz": np.full(6, 0.1)}
    path = write_table(tmp_path / f"ns.{fmt}", cols)
    data = read_imu(path)
    # float64 holds 1.7e18 only to 256 ns: counting from the first in integers keeps every nanosecond
    expected = np.array([int(v) - int(ns[0]) for v in ns]) / 1e9
    np.testing.assert_allclose(data.t, expected, rtol=1e-15, atol=0)
    np.testing.assert_allclose(np.diff(data.t), np.diff(expected), rtol=1e-12, atol=0)
    # a plain read gives the nearest float64 (no Arrow range error), as every format does
    np.testing.assert_array_equal(read_table(path, ["timestamp_ns"])["timestamp_ns"], ns.astype(np.float64))


def test_iso_times_ending_in_z_equal_those_without(tmp_path):
    start = np.datetime64("2024-03-01T12:00:00", "ns")
    stamps = start + np.array([0, 10_000_001, 20_000_000, 30_000_123], dtype="timedelta64[ns]")
    rows = "".join(f"{s}Z,0,0,{i}\n" for i, s in enumerate(stamps))
    zulu, local = tmp_path / "z.csv", tmp_path / "local.csv"
    zulu.write_text("timestamp,gx,gy,gz\n" + rows)
    local.write_text("timestamp,gx,gy,gz\n" + rows.replace("Z", ""))
    t = read_imu(zulu).t
    np.testing.assert_array_equal(t, read_imu(local).t)
    np.testing.assert_array_equal(t, (stamps - start).astype(np.int64) / 1e9)


def test_a_short_hdf5_table_stays_small(tmp_path):
    # HDF5 stores whole chunks: 500 rows of 8 columns once took 4 MB in chunks of 65536 rows
    cols = {f"c{i}": np.arange(500.0) for i in range(8)}
    path = write_table(tmp_path / "short.h5", cols)
    assert path.stat().st_size < 8 * 1024 * 8 * 2  # at most a 1024-row chunk per column, and some overhead
    np.testing.assert_array_equal(read_table(path)["c7"], cols["c7"])


@pytest.mark.parametrize("fmt", ["parquet", "h5", "mat", "csv"])
def test_metadata_is_read_back_where_the_format_keeps_it(tmp_path, fmt):
    from strapdown.io import read_metadata

    meta = {"strapdown_command": "estimate", "frame": "NED"}
    path = write_table(tmp_path / f"a.{fmt}", {"x": np.arange(3.0)}, metadata=meta)
    assert read_metadata(path) == meta  # CSV: "# key: value" lines above the header


def test_a_truth_in_another_frame_is_re_expressed_for_the_error_plot(tmp_path):
    from strapdown.io.pipelines.plot import _truth_in_frame_of

    rng = np.random.default_rng(2)
    q_enu = rng.normal(size=(20, 4))
    q_enu /= np.linalg.norm(q_enu, axis=1, keepdims=True)
    q_ned = sd.change_frame(q_enu, ref_from="ENU", ref_to="NED")
    est = write_table(tmp_path / "est.parquet", dict(zip(["qw", "qx", "qy", "qz"], q_ned.T, strict=True)),
                      metadata={"frame": "NED"})  # fmt: skip
    truth = write_table(tmp_path / "sim.h5", {"x": np.zeros(20)}, metadata={"reference": "ENU"})
    moved, note = _truth_in_frame_of(est, truth, q_enu)
    np.testing.assert_allclose(sd.angle_between(moved, q_ned), 0.0, atol=1e-12)
    assert note == " (truth taken from ENU to NED)"
    unnamed = write_table(tmp_path / "sim.csv", {"x": np.zeros(20)})
    assert _truth_in_frame_of(est, unnamed, q_enu)[0] is q_enu  # nothing said, nothing changed
