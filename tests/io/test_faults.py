"""Faults leave nothing but the old output (issue 14): signals, kill -9, a full disk, for every output format.

Each test runs the CLI as ``python -m strapdown.cli`` in a child process with an existing output in place,
injects the fault, and then lists the folder: the old output must be there, unchanged, and nothing else of
ours.  A full disk is simulated with RLIMIT_FSIZE (writes past the limit fail with EFBIG, SIGXFSZ ignored), which
needs no root and no mount; the HDF5 writer used to segfault there.
"""

import contextlib
import os
import re
import signal
import subprocess
import sys
import time

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
