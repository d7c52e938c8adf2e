"""Faults leave nothing but the old output (issue 14): signals, kill -9, a full disk, for every output format.

And corrupted, truncated and hostile input files never pass silently (issue 28): see the last section.

Each test runs the CLI as ``python -m strapdown.cli`` in a child process with an existing output in place,
injects the fault, and then lists the folder: the old output must be there, unchanged, and nothing else of
ours.  A full disk is simulated with RLIMIT_FSIZE (writes past the limit fail with EFBIG, SIGXFSZ ignored), which
needs no root and no mount; the HDF5 writer used to segfault there.
"""

import contextlib
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals and resource limits")

OLD = b"old output\n"


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A 300 000-sample gyro recording (about 3 s to integrate and write as CSV), and a small one."""
    from strapdown.io import write_table

    folder = tmp_path_factory.mktemp("faults")
    rng = np.random.default_rng(7)
    files = {}
    for name, n in (("big", 300_000), ("small", 2_000)):
        t = np.arange(n) * 0.005
        gyro = 0.3 * rng.standard_normal((n, 3))
        acc = np.tile([0.0, 0.0, 9.81], (n, 1)) + 0.05 * rng.standard_normal((n, 3))
        cols = {"t": t, "gx": gyro[:, 0], "gy": gyro[:, 1], "gz": gyro[:, 2]}
        cols.update({"ax": acc[:, 0], "ay": acc[:, 1], "az": acc[:, 2]})
        files[name] = write_table(folder / f"{name}.parquet", cols)
    return files


def _cli(*args):
    return [sys.executable, "-m", "strapdown.cli", *map(str, args)]


@pytest.fixture
def spawn():
    """Popen in a new session; afterwards whatever is left of that session (orphaned workers) is killed."""
    started = []

    def run(args, **kw):
        # A suite started under nohup ignores SIGHUP, and one started as a background job of a script ignores
        # SIGINT; children inherit that (the program, like Python itself, rightly keeps an inherited "ignore"):
        # the child starts with the default dispositions, as from a terminal.
        previous = {sig: signal.signal(sig, signal.SIG_DFL) for sig in (signal.SIGHUP, signal.SIGINT)}
        try:
            proc = subprocess.Popen(args, start_new_session=True, stderr=subprocess.PIPE, **kw)
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
        started.append(proc)
        return proc

    yield run
    for proc in started:
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(proc.pid, signal.SIGKILL)  # the session this test created, and only that
        proc.wait()


def _finish(proc, timeout=120):
    """Wait for the parent (not for stderr: an orphaned worker would hold the pipe open) and read its stderr."""
    proc.wait(timeout=timeout)
    time.sleep(0.5)
    os.set_blocking(proc.stderr.fileno(), False)
    return (proc.stderr.read() or b"").decode(errors="replace")


def _leftovers(folder, keep):
    return sorted(p.name for p in folder.iterdir() if p.name not in keep)


def _wait_for_temp(folder, proc, timeout=120):
    """Wait until the child has a temporary of ours in ``folder`` (then it is writing)."""
    for _ in range(int(timeout / 0.005)):  # polls, an upper bound on waiting, never a measured time
        if any(".strapdown-" in p.name for p in folder.iterdir()):
            return True
        if proc.poll() is not None:
            return False
        time.sleep(0.005)
    return False


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT], ids=lambda s: s.name)
@pytest.mark.parametrize("command", ["integrate", "estimate"])
def test_a_signal_while_writing_leaves_only_the_old_output(recording, tmp_path, sig, command, spawn):
    out = tmp_path / "out.csv"
    out.write_bytes(OLD)
    proc = spawn(_cli(command, recording["big"], "-o", out, "-q"))
    assert _wait_for_temp(tmp_path, proc), "the run never started writing"
    proc.send_signal(sig)
    err = _finish(proc)
    assert proc.returncode != 0, "the run finished before the signal arrived"
    assert _leftovers(tmp_path, {"out.csv"}) == [], err[-2000:]
    assert out.read_bytes() == OLD
    if sig != signal.SIGINT:  # the process still dies of the signal, as a shell or supervisor expects
        assert proc.returncode == -sig


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP], ids=lambda s: s.name)
def test_a_signal_during_a_parallel_batch_leaves_only_the_old_outputs(recording, tmp_path, sig, spawn):
    for i in range(3):
        (tmp_path / f"in{i}.parquet").write_bytes(recording["big"].read_bytes())
        (tmp_path / f"in{i}.integrate.parquet").write_bytes(OLD)
    inputs = {p.name for p in tmp_path.iterdir()}
    proc = spawn(_cli("batch", tmp_path / "in?.parquet", "integrate", "-j", "2", "-q"))
    assert _wait_for_temp(tmp_path, proc), "the batch never started writing"
    proc.send_signal(sig)
    err = _finish(proc)
    assert proc.returncode == 128 + sig, err[-2000:]  # a pool's parent exits through the interpreter's shutdown
    assert _leftovers(tmp_path, inputs) == [], err[-2000:]
    for i in range(3):
        assert (tmp_path / f"in{i}.integrate.parquet").read_bytes() == OLD
    assert "leaked semaphore" not in err


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT], ids=lambda s: s.name)
def test_a_signal_during_a_split_run_leaves_no_parts(recording, tmp_path, sig, spawn):
    out = tmp_path / "big.integrate.parquet"
    out.write_bytes(OLD)
    proc = spawn(_cli("batch", recording["big"], "integrate", "--split", "4", "-j", "2", "--out", tmp_path, "-q"))
    assert _wait_for_temp(tmp_path, proc), "the split run never started writing"
    proc.send_signal(sig)
    err = _finish(proc)
    assert proc.returncode != 0, "the run finished before the signal arrived"
    assert _leftovers(tmp_path, {out.name}) == [], err[-2000:]
    assert out.read_bytes() == OLD


def _dead_pid():
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_stale_temporaries_of_killed_runs_are_removed_by_the_next_run(recording, tmp_path, spawn):
    from strapdown._support.files import _host

    out = tmp_path / "out.csv"
    out.write_bytes(OLD)
    # a real kill -9 while writing leaves a temporary ...
    proc = spawn(_cli("integrate", recording["big"], "-o", out, "-q"))
    assert _wait_for_temp(tmp_path, proc)
    proc.kill()
    proc.wait()
    left = _leftovers(tmp_path, {"out.csv"})
    assert len(left) == 1 and re.fullmatch(
        rf"\.out\.csv\.strapdown-{re.escape(_host())}-\d+-[0-9a-f]{{8}}\.tmp", left[0]
    )
    # ... and so did a killed split run (a folder); a live process's temporary and files not of our naming stay
    dead = _dead_pid()
    (tmp_path / f".out.csv.strapdown-{_host()}-{dead}-0123abcd.parts").mkdir()
    (tmp_path / f".out.csv.strapdown-{_host()}-{dead}-0123abcd.parts" / "part00000.csv").write_bytes(b"x")
    live = tmp_path / f".out.csv.strapdown-{_host()}-{os.getpid()}-89abcdef.tmp"
    other_host = tmp_path / f".out.csv.strapdown-elsewhere-{dead}-89abcdef.tmp"
    foreign = tmp_path / ".out.csv.k3j4h5.tmp"  # the old mkstemp naming, or anyone's file: never ours to delete
    for p in (live, other_host, foreign):
        p.write_bytes(b"x")
    done = subprocess.run(_cli("integrate", recording["small"], "-o", out, "-q"), capture_output=True)
    assert done.returncode == 0, done.stderr.decode()
    assert _leftovers(tmp_path, {"out.csv"}) == sorted(p.name for p in (live, other_host, foreign))
    assert out.read_bytes() != OLD


def _limited(limit):
    def pre():
        import resource

        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG instead
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return pre


@pytest.mark.parametrize("fmt", ["csv", "parquet", "h5", "mat"])
@pytest.mark.parametrize("command", ["integrate", "estimate"])
def test_a_full_disk_leaves_nothing_and_names_the_output(recording, tmp_path, fmt, command):
    out = tmp_path / f"out.{fmt}"
    out.write_bytes(OLD)
    done = subprocess.run(
        _cli(command, recording["big"], "-o", out, "-q"), capture_output=True, text=True, preexec_fn=_limited(400_000)
    )
    assert done.returncode == 1, (done.returncode, done.stderr[-2000:])  # an error, not a crash (HDF5: SIGSEGV)
    assert f"cannot write {out}" in done.stderr and "file size limit" in done.stderr
    assert "Traceback" not in done.stderr
    assert _leftovers(tmp_path, {out.name}) == []
    assert out.read_bytes() == OLD


def test_a_full_disk_during_a_split_run_leaves_no_parts(recording, tmp_path):
    done = subprocess.run(
        _cli("batch", recording["big"], "integrate", "--split", "3", "-j", "1", "--out", tmp_path, "-q"),
        capture_output=True,
        text=True,
        preexec_fn=_limited(400_000),
    )
    assert done.returncode == 1, done.stderr[-2000:]
    assert "Traceback" not in done.stderr
    assert [p.name for p in tmp_path.iterdir()] == []


def test_a_killed_dask_worker_leaves_no_temporary(recording, tmp_path, spawn):
    """The task of a worker killed while writing runs again elsewhere; that run removes the dead one's temporary."""
    distributed = pytest.importorskip("distributed")
    for i in range(2):
        (tmp_path / f"in{i}.parquet").write_bytes(recording["big"].read_bytes())
    inputs = {p.name for p in tmp_path.iterdir()}
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            pids = set(client.run(os.getpid).values())
            proc = spawn(_cli("batch", tmp_path / "in?.parquet", "integrate", "--scheduler", cluster.scheduler_address))
            assert _wait_for_temp(tmp_path, proc), "the batch never started writing"
            temp = next(p for p in tmp_path.iterdir() if ".strapdown-" in p.name)
            victim = int(re.search(r"-(\d+)-[0-9a-f]{8}\.tmp$", temp.name).group(1))
            assert victim in pids
            os.kill(victim, signal.SIGKILL)  # a worker of the cluster this test started
            err = _finish(proc, timeout=300)
    assert proc.returncode == 0, err[-2000:]
    assert _leftovers(tmp_path, inputs) == ["in0.integrate.parquet", "in1.integrate.parquet"]


# ------------------------------------------------------------------------------------- corrupted files (issue 28)
# Corrupted, truncated and hostile variants of real logs: never a silent loss.  A reader either stops with a
# message that names the file and where it broke, and writes nothing, or reads on and warns with the samples lost
# and their time span.  Memory is measured as a child's peak RSS (a bound, never a time).
PX4 = Path(__file__).resolve().parents[1] / "data" / "px4" / "sample_logging_tagged_and_default_params.ulg"


def _run_measured(*args):
    """``strapdown ARGS`` in a child of a fresh interpreter: (returncode, stdout + stderr, the child's peak RSS, B)."""
    code = (
        "import resource, subprocess, sys\n"
        "r = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
        "sys.stdout.write(r.stdout + r.stderr)\n"
        "print('\\nPEAK_KIB', resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)\n"  # Linux: KiB
        "sys.exit(r.returncode)\n"
    )
    res = subprocess.run([sys.executable, "-c", code, *_cli(*args)], capture_output=True, text=True, timeout=600)
    text, _, peak = res.stdout.rpartition("PEAK_KIB")
    return res.returncode, text + res.stderr, int(peak) * 1024


def _ulog_messages(data: bytes, kind: bytes):
    """Offsets of the ULog messages of one type (``b"D"``): uint16 size, uint8 type, payload (PX4 ULog format)."""
    pos, found = 16, []  # after the 16-byte file header
    while pos + 3 <= len(data):
        size, typ = struct.unpack_from("<HB", data, pos)
        if typ == kind[0]:
            found.append(pos)
        pos += 3 + size
    return found


def _rows(path):
    from strapdown.io import read_table

    return len(read_table(path)["t"])


def _estimate(log, out):
    code, text, _ = _run_measured("estimate", log, "-o", out)
    return code, text


@pytest.fixture(scope="module")
def px4_rows(tmp_path_factory):
    out = tmp_path_factory.mktemp("px4") / "whole.csv"
    code, text = _estimate(PX4, out)
    assert code == 0, text
    return _rows(out)


def test_a_ulog_data_message_of_size_0xffff_is_skipped_and_warned_with_the_samples_lost(tmp_path, px4_rows):
    data = bytearray(PX4.read_bytes())
    at = _ulog_messages(data, b"D")[len(_ulog_messages(data, b"D")) // 3]
    struct.pack_into("<H", data, at, 0xFFFF)  # the size field of one data message
    log = tmp_path / "ffff.ulg"
    log.write_bytes(data)
    code, text = _estimate(log, tmp_path / "out.csv")
    assert code == 0, text
    said = (
        rf"warning: {re.escape(str(log))}: a data message of \d+ bytes .* at bytes (\d+) to (\d+), skipped: "
        r"(about (\d+)|no) gyro \(sensor_combined\) samples? lost.*\(t = ([\d.]+) s to ([\d.]+) s\)"
    )
    warning = re.search(said, text)
    assert warning, text
    assert int(warning.group(1)) == at
    lost = int(warning.group(4) or 0)
    # the count said is the count missing, up to one: it is told from the gap in the gyro's times, and this log
    # has such a gap of one period there already (PX4 logs drop a sample now and then)
    assert abs(px4_rows - _rows(tmp_path / "out.csv") - lost) <= 1
    assert float(warning.group(5)) < float(warning.group(6))
    assert "pyulog" not in text.lower()  # no third-party print on stdout


@pytest.mark.parametrize("bit", [0, 3, 9, 14])
def test_one_flipped_bit_in_a_ulog_size_field_loses_no_row_unsaid(tmp_path, px4_rows, bit):
    data = bytearray(PX4.read_bytes())
    offsets = _ulog_messages(data, b"D")
    at = offsets[len(offsets) // 2 + bit]
    data[at + bit // 8] ^= 1 << (bit % 8)
    log = tmp_path / "flip.ulg"
    log.write_bytes(data)
    code, text = _estimate(log, tmp_path / "out.csv")
    assert code == 0, text
    missing = px4_rows - _rows(tmp_path / "out.csv")
    warned = re.findall(r"about (\d+) gyro \(sensor_combined\) samples lost", text)
    assert f"warning: {log}" in text  # the break is said, whatever it cost
    assert abs(missing - sum(map(int, warned))) <= len(warned)  # each told from a gap in the times: about


def test_a_cut_ulog_warns_where_it_ends_and_one_cut_before_its_data_writes_nothing(tmp_path):
    data = PX4.read_bytes()
    cut = tmp_path / "cut.ulg"
    cut.write_bytes(data[: len(data) * 2 // 3])
    code, text = _estimate(cut, tmp_path / "out.csv")
    assert code == 0, text
    assert re.search(rf"warning: {re.escape(str(cut))}: the log is cut inside a message .* readings end there, at t = ",
                     text), text  # fmt: skip
    head = tmp_path / "head.ulg"
    head.write_bytes(data[: _ulog_messages(data, b"D")[0] - 40])  # inside the definitions: no data at all
    code, text = _estimate(head, tmp_path / "head.csv")
    assert code == 1 and str(head) in text and not (tmp_path / "head.csv").exists(), text


def test_a_dataflash_log_cut_or_overwritten_warns_with_the_samples_lost_and_when(tmp_path):
    import sim_exports as sim
    from strapdown.simulate import ImuModel, RandomMotion, sample

    data = sample(RandomMotion(6.0, seed=2), 200.0, gyro="rate", imu=ImuModel.consumer_mems(), seed=2)
    whole = sim.dataflash(tmp_path / "whole.bin", sim.dataflash_messages(data)).read_bytes()
    middle = len(whole) // 2
    (tmp_path / "cut.bin").write_bytes(whole[: middle + 7])
    garbled = bytearray(whole)
    garbled[middle : middle + 300] = bytes(range(256)) + bytes(44)
    (tmp_path / "garbled.bin").write_bytes(garbled)
    for name, said in (("cut", r"the log is cut inside a message .* readings end there, at t = [\d.]+ s"),
                       ("garbled", r"bytes that start no message at bytes \d+ to \d+, skipped: about (\d+) gyro "
                                   r"\(IMU:0\) samples lost \(t = [\d.]+ s to [\d.]+ s\)")):  # fmt: skip
        log = tmp_path / f"{name}.bin"
        code, text = _estimate(log, tmp_path / f"{name}.csv")
        assert code == 0, text
        found = re.search(rf"warning: {re.escape(str(log))}: {said}", text)
        assert found, text
        if name == "garbled":  # the count said is the count missing
            assert len(data.t) - 1 - _rows(tmp_path / "garbled.csv") == int(found.group(1))


def _mcap_records(data: bytes):
    """(offset, opcode, length) of an MCAP file's records: magic, then uint8 opcode, uint64 length (mcap.dev/spec)."""
    pos, found = 8, []
    while pos + 9 <= len(data):
        op, length = struct.unpack_from("<BQ", data, pos)
        found.append((pos, op, length))
        if op == 2:  # the Footer
            break
        pos += 9 + length
    return found


@pytest.mark.parametrize("fraction", [0.1, 0.5, 0.99])
def test_a_cut_mcap_is_refused_by_name_and_the_byte_it_breaks_at(tmp_path, fraction):
    import sim_exports as sim

    data = sim.phone_at_rest(body="FLU", duration=5.0)  # rosbags' own MCAP writer: the real layout
    mcap = next(sim.rosbag(tmp_path / "bag", data, storage="mcap").glob("*.mcap")).read_bytes()
    cut = mcap[: int(len(mcap) * fraction)]
    at = max(p for p, _, _ in _mcap_records(mcap) if p < len(cut))  # the record the cut falls in
    log = tmp_path / "cut.mcap"
    log.write_bytes(cut)
    code, text = _estimate(log, tmp_path / "cut.csv")
    assert code == 1 and not (tmp_path / "cut.csv").exists(), text
    assert re.search(
        rf"{re.escape(str(log))}: the file is cut inside a \w[\w ]* record that starts at byte {at} \(it declares "
        rf"\d+ bytes; the file ends at byte {len(cut)}\)",
        text,
    ), text


def test_a_damaged_mcap_chunk_is_warned_with_what_it_lost_and_where(tmp_path):
    import sim_exports as sim

    data = sim.phone_at_rest(body="FLU", duration=5.0)
    mcap = next(sim.rosbag(tmp_path / "bag", data, storage="mcap").glob("*.mcap")).read_bytes()
    zeroed = bytearray(mcap)
    zeroed[len(mcap) // 2 : len(mcap) // 2 + 64] = bytes(64)
    (tmp_path / "zeroed.mcap").write_bytes(zeroed)
    code, text = _estimate(tmp_path / "zeroed.mcap", tmp_path / "zeroed.csv")
    assert code == 0, text
    found = re.search(r"/imu/data: (\d+) of the (\d+) messages its index counts could be read, (\d+) lost after", text)
    assert found, text
    got, counted, lost = map(int, found.groups())
    assert counted == len(data.t) - 1 and lost == counted - got == counted - _rows(tmp_path / "zeroed.csv")
    chunk = next((p, 9 + n) for p, op, n in _mcap_records(mcap) if op == 6 and p < len(mcap) // 2 < p + 9 + n)
    where = re.search(rf"the Chunk at bytes {chunk[0]} to {sum(chunk)}, messages of [\d.]+ s to [\d.]+ s, is damaged: "
                      r"no record can start at byte \d+ of its records, byte (\d+) of the file", text)  # fmt: skip
    assert where, text
    assert len(mcap) // 2 <= int(where.group(1)) < len(mcap) // 2 + 64  # the first record header in the zeros


def test_a_zip_bomb_is_refused_before_it_is_unpacked_in_bounded_memory(tmp_path):
    import sim_exports as sim

    export = sim.sensor_logger(tmp_path / "export", sim.phone_at_rest(duration=3.0))
    bomb = tmp_path / "bomb.zip"
    with zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as z:
        for f in export.iterdir():
            if f.name != "Gyroscope.csv":
                z.write(f, f.name)
        with z.open("Gyroscope.csv", "w", force_zip64=True) as w:  # 1 GiB of digits, about 1 MB deflated
            w.write((export / "Gyroscope.csv").read_bytes())
            block = b"0" * (1 << 20)
            for _ in range(1024):
                w.write(block)
    assert bomb.stat().st_size < 8 << 20
    code, text, peak = _run_measured("estimate", bomb, "-o", tmp_path / "out.csv")
    assert code == 1 and re.search(rf"{re.escape(str(bomb))}: its files would expand to 10\d\d\.\d MiB, past", text)
    assert not (tmp_path / "out.csv").exists()
    assert not list(Path(tempfile.gettempdir()).glob(f"strapdown-unzip-*/{bomb.name}"))
    assert peak < 0.5e9, f"peak RSS {peak / 1e6:.0f} MB"


@pytest.mark.parametrize("as_zip", [False, True])
def test_a_100_mb_line_without_a_newline_is_refused_in_bounded_memory(tmp_path, as_zip):
    import sim_exports as sim

    export = sim.sensor_logger(tmp_path / "export", sim.phone_at_rest(duration=3.0))
    with open(export / "Gyroscope.csv", "ab") as f:
        block = b"1" * (1 << 20)
        for _ in range(100):
            f.write(block)
    given = Path(shutil.make_archive(str(export), "zip", export)) if as_zip else export
    code, text, peak = _run_measured("estimate", given, "-o", tmp_path / "out.csv")
    name = f"{given}: Gyroscope.csv" if as_zip else f"{export / 'Gyroscope.csv'}"
    assert code == 1 and re.search(rf"{re.escape(name)}: line \d+ is longer than 16 MiB", text), text
    assert not (tmp_path / "out.csv").exists()
    assert peak < 0.5e9, f"peak RSS {peak / 1e6:.0f} MB"


@pytest.mark.parametrize("suffix", [".h5", ".mat"])
def test_zeroed_4_kib_blocks_in_mat_and_hdf5_files_are_warned_with_count_and_span(tmp_path, suffix):
    from strapdown.io import write_table

    rng = np.random.default_rng(3)
    n = 20_000
    cols = {"t": np.arange(n) * 0.01}
    for axis, g, a in zip("xyz", (0.01, 0.02, -0.01), (0.3, -0.2, 9.8), strict=True):
        cols["g" + axis] = g + 0.001 * rng.standard_normal(n)
        cols["a" + axis] = a + 0.01 * rng.standard_normal(n)
    whole = write_table(tmp_path / f"whole{suffix}", cols).read_bytes()
    data = bytearray(whole)
    start = whole.find(cols["az"][:4].astype("<f8").tobytes())  # the az column, stored as it is
    block = (start // 4096 + 3) * 4096  # a 4 KiB page inside it: 512 values of az
    data[block : block + 4096] = bytes(4096)
    first = (block - start + 7) // 8  # the first whole value zeroed
    damaged = tmp_path / f"zeroed{suffix}"
    damaged.write_bytes(data)
    code, text = _estimate(damaged, tmp_path / "out.csv")
    assert code == 0, text
    found = re.search(rf"warning: {re.escape(str(damaged))}: (\d+) rows between t = ([\d.]+) and ([\d.]+) s", text)
    assert found, text
    assert int(found.group(1)) == 512 and float(found.group(2)) == pytest.approx(cols["t"][first])
    code, text = _estimate(tmp_path / f"whole{suffix}", tmp_path / "whole.csv")
    assert code == 0 and "zeroed block" not in text, text  # the intact file says nothing


def test_convert_refuses_a_non_unit_quaternion_and_says_the_nan_rows(tmp_path):
    from strapdown.io import write_table

    n = 1000
    q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))
    q[:, 3] = np.linspace(-0.5, 0.5, n)
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    t = np.arange(n) * 0.01
    for name, rows, value in (("huge", [200], [1e308, 0, 0, 0]), ("nan", slice(100, 110), np.nan)):
        bad = q.copy()
        bad[rows] = value
        path = write_table(
            tmp_path / f"{name}.parquet", dict(t=t, **{f"q{c}": bad[:, i] for i, c in enumerate("wxyz")})
        )
        out = tmp_path / f"{name}.csv"
        code, text, _ = _run_measured("convert", path, "--to", "euler", "--degrees", "-o", out)
        if name == "huge":  # 1e308 is no attitude; taken as the identity it would be a silent wrong answer
            assert code == 1 and f"{path}: row 200 (qw, qx, qy, qz) holds a quaternion of norm 1e+308" in text, text
            assert not out.exists()
        else:
            assert code == 0 and f"warning: {path}: 10 rows hold NaN (row 100 to row 109)" in text, text
            from strapdown.io import read_table

            angles = read_table(out)
            yaw = next(k for k in angles if k.startswith("yaw"))
            assert np.isnan(angles[yaw][100:110]).all() and not np.isnan(angles[yaw][:100]).any()


def test_parquet_errors_name_the_file(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    n = 50_000
    t = np.arange(n) * 0.01
    qx = np.round(np.sin(t), 2) / np.sqrt(1 + np.round(np.sin(t), 2) ** 2)
    good = tmp_path / "good.parquet"
    table = pa.table({"t": t, "qw": np.sqrt(1 - qx**2), "qx": qx, "qy": 0 * t, "qz": 0 * t})
    pq.write_table(table, good, compression="snappy", use_dictionary=False)
    data, column = good.read_bytes(), pq.ParquetFile(good).metadata.row_group(0).column(1)
    bad = tmp_path / "bad.parquet"
    for at in range(column.data_page_offset, column.data_page_offset + 2000, 8):  # the first bytes pyarrow refuses
        damaged = bytearray(data)
        damaged[at : at + 8] = b"\xff" * 8
        bad.write_bytes(damaged)
        try:
            pq.read_table(bad)
        except Exception:  # whatever pyarrow raises: the point is that ours names the file
            break
    else:
        pytest.fail("no damaged variant that pyarrow refuses")
    code, text, _ = _run_measured("convert", bad, "--to", "euler", "-o", tmp_path / "out.csv")
    assert code == 1 and f"{bad}: " in text and "the file is damaged" in text, text
    none = tmp_path / "none.parquet"
    pq.write_table(pa.table({"t": t, "a": t}), none)
    code, text, _ = _run_measured("convert", none, "--to", "euler", "-o", tmp_path / "out.csv")
    assert code == 1 and f"{none}: no quat columns found" in text, text
    assert not (tmp_path / "out.csv").exists()


def test_an_output_to_a_pipe_or_device_is_written_through_not_replaced(tmp_path):
    # `-o /dev/null` once renamed a temporary file onto /dev/null, which, run as root, left a regular file there
    # for the whole machine.  A FIFO stands in for the device here (no root needed): it must stay a FIFO and
    # receive the whole output
    import stat
    import threading

    from strapdown._support.files import atomic_path

    fifo = tmp_path / "out.csv"
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    with atomic_path(fifo) as tmp:
        tmp.write_bytes(b"t,qw\n0,1\n")
    reader.join(timeout=30)
    assert got == [b"t,qw\n0,1\n"]
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]  # no temporary left beside it
