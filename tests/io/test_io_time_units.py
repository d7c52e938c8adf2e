"""The silent failures of issue 12 and the reader-level resource checks of issue 14, each as a test.

Every file here is written by the test itself (simulated or synthetic values).
"""

import numpy as np
import pytest

from strapdown.io import (
    ImuColumns,
    ImuFile,
    open_source,
    read_imu,
    read_metadata,
    read_reference,
    read_table,
    write_table,
)
from strapdown.io.timebase import infer_time_unit

PER_S = {"ns": 1e9, "us": 1e6, "ms": 1e3}


def gyro_csv(path, times, rate_rad_s=0.1):
    rows = "".join(f"{t},0,0,{rate_rad_s}\n" for t in times)
    path.write_text("time,gx,gy,gz\n" + rows)
    return path


@pytest.mark.parametrize("unit", ["ns", "us", "ms"])
@pytest.mark.parametrize("epoch", [True, False])
def test_integer_times_get_their_unit_from_the_step(tmp_path, unit, epoch):
    # issue 12: epoch ns was taken as seconds (t up to 2e11 s); PX4's µs too ("4000 s sample period")
    period = {"ns": 0.01, "us": 0.004, "ms": 0.02}[unit]  # 100 Hz, 250 Hz, 50 Hz
    first = int(1_718_030_736.5 * PER_S[unit]) if epoch else int(20.3 * PER_S[unit])
    times = [first + round(k * period * PER_S[unit]) for k in range(300)]
    path = gyro_csv(tmp_path / "t.csv", times)
    imu = ImuFile(path)
    assert imu.units["time"] == unit
    assert imu.time_origin.value == first and imu.time_origin.kind == ("epoch" if epoch else "file")
    data = read_imu(path)
    np.testing.assert_allclose(data.t, np.arange(300) * period, atol=1e-9)
    # integrated over 3 s at 0.1 rad/s: 0.299 rad, not the 2e8 rad that seconds would make of epoch ns
    assert np.sum(np.diff(data.t) * data.gyro[:-1, 2]) == pytest.approx(0.1 * 299 * period)


def test_time_unit_overrides_the_inference_and_is_still_checked(tmp_path):
    path = gyro_csv(tmp_path / "t.csv", [1000 * k for k in range(50)])  # 1000 per step: ms (1 Hz) or us (1 kHz)
    assert ImuFile(path).units["time"] == "us"  # equally far from 100 Hz: the finer unit
    assert ImuFile(path, ImuColumns(time_unit="ms")).period == pytest.approx(1.0)
    with pytest.raises(ValueError, match=r"time column 'time' taken in ns .* it looks like"):
        ImuFile(path, ImuColumns(time_unit="ns"))  # 1 µs periods: no IMU


def test_a_float_time_with_an_implausible_period_names_the_column_and_the_guess(tmp_path):
    path = gyro_csv(tmp_path / "t.csv", [f"{4000.0 * k:.1f}" for k in range(20)])
    with pytest.raises(ValueError, match=r"t.csv: time column 'time' taken in s steps by 4000 s .* looks like us"):
        ImuFile(path)


def test_an_integer_step_no_unit_explains_is_refused(tmp_path):
    path = gyro_csv(tmp_path / "t.csv", [10**12 * k for k in range(20)])
    with pytest.raises(ValueError, match=r"integer time column 'time' steps by 1e\+12 .* --time-unit"):
        ImuFile(path)
    with pytest.raises(ValueError, match="steps by 1e"):
        infer_time_unit(1e12, 0, "time", "x")


def test_float_times_count_from_the_first_with_the_origin_kept(tmp_path):
    path = gyro_csv(tmp_path / "t.csv", [f"{1718030736.5 + 0.01 * k:.2f}" for k in range(10)])
    imu = ImuFile(path)
    assert imu.time_origin.kind == "epoch" and imu.time_origin.value == pytest.approx(1718030736.5)
    np.testing.assert_allclose(read_imu(path).t, np.arange(10) * 0.01, atol=1e-6)


def test_a_gravity_free_accelerometer_stream_is_refused(tmp_path):
    rng = np.random.default_rng(0)
    acc = rng.normal(0, 1.0, (500, 3))  # |a| about 1.6 m/s2, no gravity: phyphox's Linear Accelerometer
    cols = {"t": np.arange(500) * 0.01, "gx": np.zeros(500), "gy": np.zeros(500), "gz": np.zeros(500)}
    cols |= {"ax": acc[:, 0], "ay": acc[:, 1], "az": acc[:, 2]}
    from strapdown.io import write_table

    path = write_table(tmp_path / "lin.csv", cols)
    with pytest.raises(ValueError, match=r"lin.csv: \|acc\| is about 1.5\d m/s2 .*gravity-free.*columns ax,ay,az"):
        read_imu(path, optional=("acc",))
    # the same with gravity added reads
    cols["az"] = cols["az"] * 0.01 + 9.81
    read_imu(write_table(tmp_path / "ok.csv", cols), optional=("acc",))


def test_a_normalised_magnetometer_is_read_and_reported_as_normalised(tmp_path):
    from strapdown.io import write_table

    n = 200
    m = np.tile([0.4, 0.0, -0.9165], (n, 1))  # unit length: a normalised field
    cols = {"t": np.arange(n) * 0.01, "gx": np.zeros(n), "gy": np.zeros(n), "gz": np.zeros(n)}
    cols |= {"mx": m[:, 0], "my": m[:, 1], "mz": m[:, 2]}
    path = write_table(tmp_path / "norm.csv", cols)
    imu = ImuFile(path, optional=("mag",))
    assert imu.units["mag"] == "normalised" and "normalised" in imu.describe()
    np.testing.assert_array_equal(read_imu(path, optional=("mag",)).mag, m)


def test_blank_lines_comments_and_a_unit_row_keep_the_line_numbers(tmp_path):
    path = tmp_path / "b.csv"
    text = "\n# frame: NED\n\nt,gx,gy,gz\n\nms,deg/s,deg/s,deg/s\n0,0,0,90\n10,0,0,90\n"
    path.write_text(text)
    imu = ImuFile(path)
    assert imu.units == {"gyro": "deg/s", "time": "ms"} and read_metadata(path) == {"frame": "NED"}
    path.write_text(text + "20,0,0,x\n")
    with pytest.raises(ValueError, match=r"line 9, column 'gz': 'x' is not a number"):
        read_imu(path)


def test_csv_comment_lines_are_metadata_and_a_hash_header_is_a_header(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("# frame: NED\n# body: FRD\n# time_origin: 20309082\nt,qw,qx,qy,qz\n0.5,1,0,0,0\n0.6,1,0,0,0\n")
    assert read_metadata(path) == {"frame": "NED", "body": "FRD", "time_origin": "20309082"}
    assert list(read_table(path)) == ["t", "qw", "qx", "qy", "qz"]
    ref = read_reference(path)
    assert (ref.frame, ref.body) == ("NED", "FRD") and ref.t.tolist() == pytest.approx([0.0, 0.1])
    with open_source(path) as src:
        assert src.where(0) == "line 5"


# ---------------------------------------------------------------------------------------------------- issue 14
def test_hdf5_external_links_are_refused_not_followed(tmp_path):
    import h5py

    secret = tmp_path / "secret.h5"
    with h5py.File(secret, "w") as f:
        f["data"] = np.arange(10.0)
    path = tmp_path / "innocent.h5"
    with h5py.File(path, "w") as f:
        f["t"] = np.arange(10) * 0.01
        f["gx"] = h5py.ExternalLink(str(secret), "/data")
    with pytest.raises(ValueError, match=r"'gx' is an external link to '.*secret.h5' \(/data\)"):
        open_source(path)


def test_a_csv_header_of_100k_columns_is_checked_in_one_pass(tmp_path):
    names = [f"c{i}" for i in range(100_000)]
    path = tmp_path / "wide.csv"
    path.write_text(",".join(names) + "\n" + ",".join("1" for _ in names) + "\n")
    with open_source(path) as src:
        assert len(src.fields) == 100_000
    assert read_table(path, ["c99999"])["c99999"].tolist() == [1.0]
    with pytest.raises(ValueError, match=r"no gyro columns found .* c59 and 99940 more$"):
        ImuFile(path)  # the message lists a few names, not 100k
    dup = tmp_path / "dup.csv"
    dup.write_text(",".join([*names, "c5", "c7"]) + "\n")
    with pytest.raises(ValueError, match="'c5', 'c7' appear more than once"):
        open_source(dup)


def test_a_compressed_mat_file_that_would_expand_past_the_cap_is_refused(tmp_path, monkeypatch):
    import scipy.io

    from strapdown.io.formats import mat

    path = tmp_path / "bomb.mat"
    scipy.io.savemat(path, {"x": np.zeros((4_000_000,))}, do_compression=True)  # 32 MB of zeros, ~30 KB file
    assert path.stat().st_size < 100_000 and mat.expanded_size(path) >= 32_000_000
    monkeypatch.setattr(mat, "MAX_MAT_BYTES", 16 << 20)
    with pytest.raises(ValueError, match=r"bomb.mat .*expand to 31 MiB in memory, past the 16 MiB"):
        open_source(path)


def test_a_zip_member_cannot_escape_the_temporary_folder(tmp_path):
    import zipfile

    from strapdown.io.formats.multi import Unzipped

    path = tmp_path / "evil.zip"
    with zipfile.ZipFile(path, "w") as z:
        z.writestr("../../Gyroscope.csv", "time,seconds_elapsed,z,y,x\n")
    out = Unzipped(path, lambda name: name == "Gyroscope.csv")
    try:
        assert [p.name for p in out.folder.iterdir()] == ["Gyroscope.csv"]
        assert not (tmp_path.parent / "Gyroscope.csv").exists()
    finally:
        out.close()
    assert not out.folder.exists()


def test_a_zip_that_would_expand_past_the_cap_is_refused(tmp_path, monkeypatch):
    import zipfile

    from strapdown.io.formats import multi

    path = tmp_path / "big.zip"
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr("Gyroscope.csv", "time,seconds_elapsed,z,y,x\n" + "0" * 3_000_000)
    monkeypatch.setattr(multi, "MAX_UNZIPPED_BYTES", 1 << 20)
    with pytest.raises(ValueError, match=r"big.zip: its files would expand to 2.9 MiB, past the 1 MiB read from a zip"):
        open_source(path)


def test_a_new_format_is_one_registration(tmp_path):
    from strapdown.io.registry import Format, formats, register
    from strapdown.io.source import MemorySource

    def open_demo(path):
        values = np.loadtxt(path, ndmin=2)
        return MemorySource(
            path, {"t": values[:, 0], "gx": values[:, 1], "gy": values[:, 2], "gz": values[:, 3]}, "demo"
        )

    register(Format("demo", open_demo, suffixes=(".demo",)))
    try:
        path = tmp_path / "a.demo"
        path.write_text("0 0 0 1\n0.01 0 0 1\n0.02 0 0 1\n")
        assert read_imu(path).gyro[:, 2].tolist() == [1.0, 1.0, 1.0]
    finally:
        formats().pop("demo")


def test_a_gyro_in_deg_s_read_as_rad_s_at_rest_is_refused(tmp_path):
    # the accelerometer says gravity stays put; a 0.5 deg/s bias read as rad/s says the body tilts at 29 deg/s
    import sim_exports as sim
    from strapdown.io import write_table

    data = sim.phone_at_rest(duration=5.0)
    deg = np.degrees(data.gyro) + np.array([0.5, -0.4, 0.3])  # consumer bias plus this: about 1 deg/s
    cols = {"t": data.t[:-1], "gx": deg[:, 0], "gy": deg[:, 1], "gz": deg[:, 2]}
    cols |= {"ax": data.acc[:, 0], "ay": data.acc[:, 1], "az": data.acc[:, 2]}
    path = write_table(tmp_path / "deg.csv", cols)
    with pytest.raises(
        ValueError, match=r"turns the body at \d\.\d+ rad/s .* look like deg/s.*columns gx,gy,gz and ax"
    ):
        ImuFile(path, optional=("acc",))
    assert ImuFile(path, ImuColumns(gyro_unit="deg/s"), optional=("acc",)).units["gyro"] == "deg/s"
    # a turntable: 1 rad/s about the vertical with gravity steady in the body is no contradiction
    cols["gx"], cols["gy"], cols["gz"] = np.zeros(len(deg)), np.zeros(len(deg)), np.ones(len(deg))
    assert ImuFile(write_table(tmp_path / "turn.csv", cols), optional=("acc",)).units["gyro"] == "rad/s"


def test_a_reference_table_gets_its_time_unit_as_the_imu_does(tmp_path):
    """Epoch nanoseconds (integers) and a ``timestamp_ms`` column are turned into seconds; no time is an error."""
    ns = tmp_path / "ref_ns.csv"
    stamps = 1718030736872695300 + np.arange(5) * 10_000_000  # 100 Hz, past float64's 2**53
    ns.write_text("time,qw,qx,qy,qz\n" + "".join(f"{x},1,0,0,0\n" for x in stamps))
    ref = read_reference(ns)
    np.testing.assert_allclose(ref.t, np.arange(5) * 0.01, rtol=0, atol=1e-12)
    assert ref.time_origin.kind == "epoch" and ref.time_origin.value == int(stamps[0])
    ms = tmp_path / "ref_ms.csv"
    ms.write_text("timestamp_ms,qw,qx,qy,qz\n0,1,0,0,0\n10,1,0,0,0\n20,1,0,0,0\n")
    np.testing.assert_allclose(read_reference(ms).t, [0.0, 0.01, 0.02], rtol=0, atol=1e-15)
    slow = tmp_path / "ref_slow.csv"
    slow.write_text("t,qw,qx,qy,qz\n0.0,1,0,0,0\n4000.0,1,0,0,0\n8000.0,1,0,0,0\n")  # seconds: 4000 s steps
    with pytest.raises(ValueError, match=r"ref_slow.csv.*'t'"):
        read_reference(slow)
    none = tmp_path / "ref_none.csv"
    none.write_text("qw,qx,qy,qz\n1,0,0,0\n1,0,0,0\n")
    with pytest.raises(ValueError, match=r"ref_none.csv has attitudes .* but no time column"):
        read_reference(none)


def test_a_reference_with_date_times_keeps_their_epoch_origin(tmp_path):
    pa, pq = pytest.importorskip("pyarrow"), pytest.importorskip("pyarrow.parquet")
    stamps = np.datetime64("2024-06-10T14:45:36", "ns") + np.arange(5) * np.timedelta64(10, "ms")
    one, zero = np.ones(5), np.zeros(5)
    pq.write_table(
        pa.table({"time": pa.array(stamps), "qw": one, "qx": zero, "qy": zero, "qz": zero}), tmp_path / "r.pq"
    )
    ref = read_reference(tmp_path / "r.pq", format="parquet")
    np.testing.assert_allclose(ref.t, np.arange(5) * 0.01, rtol=0, atol=1e-12)
    assert ref.time_origin.kind == "epoch" and ref.time_origin.value == int(stamps[0].astype(np.int64))


def test_a_truth_table_in_epoch_ns_is_put_on_the_estimates_instants(tmp_path):
    """A motion-capture table stamped in epoch ns, starting 1 s before the estimate: the shift comes from the stamps."""
    from strapdown.io.pipelines.truth import align_truth

    rate, e0 = 0.5, 1718030736000000000  # rad/s about z; the truth's first stamp
    t_est = np.arange(300) * 0.01
    angle = rate * (t_est + 1.0)
    zero = np.zeros_like(angle)
    est = {"t": t_est, "qw": np.cos(angle / 2), "qx": zero, "qy": zero, "qz": np.sin(angle / 2)}
    origin = {"time_origin": str(e0 + 10**9), "time_origin_unit": "ns", "time_origin_kind": "epoch"}
    write_table(tmp_path / "est.csv", est, metadata={"frame": "NED", "body": "FRD", **origin})
    stamps = e0 + np.arange(500) * 10_000_000
    a = rate * (stamps - e0) * 1e-9
    cells = zip(stamps, np.cos(a / 2), np.sin(a / 2), strict=True)
    rows = "".join(f"{s},{float(w)!r},0,0,{float(z)!r}\n" for s, w, z in cells)
    (tmp_path / "truth.csv").write_text("# frame: NED\n# body: FRD\ntime,qw,qx,qy,qz\n" + rows)
    aligned = align_truth(tmp_path / "est.csv", tmp_path / "truth.csv")
    assert aligned.rows.all()
    np.testing.assert_allclose(aligned.q[:, [0, 3]], np.stack([est["qw"], est["qz"]], -1), rtol=0, atol=1e-12)
