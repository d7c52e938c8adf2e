"""File I/O at scale: a 10^8-sample Parquet log integrated end to end by the CLI in constant memory.

    python benchmarks/bench_io.py [--n 100000000] [--dir /tmp] [--reference-n N] [--keep] [--json out.json]

1. Writes a gyro log (t, gx, gy, gz as float64; smooth random rates, 1 kHz with jittered timestamps) to a
   Parquet file in row groups of 2^20, with constant memory.
2. Runs ``strapdown integrate LOG -o OUT.parquet`` as a subprocess (time, quaternion and ZYX Euler angles out,
   progress bar off) and reads its wall time and its peak resident memory from ``wait4`` (the same figure as
   ``/usr/bin/time -v``); the better of two runs.  The claim: peak RSS below 1 GiB whatever the
   file size.
2b. The floor, in the same run, right after each CLI run (in a process of its own): what pyarrow alone takes to
   read the log in the same batches (to numpy) plus to write a Parquet table of the output's rows, column
   types, row groups and compression (random values, as incompressible as attitudes); best of two.  The goal:
   streaming time <= 1.5 x the floor (issue 15).  The CLI's time includes starting Python and loading numba's
   cached kernels (about a second), the floor's does not.  Every timed phase starts with no writes pending (the
   previous output deleted, then ``os.sync()``): see :func:`rounds`.
2c. The same with ``--float32`` (quaternion and angles as float32, time float64) against its own floor: the
   write of a table of those types.
3. The reference, in the same run: ``strapdown.integrate(gyro, t=t)`` on the same samples held in memory (the
   arrays are loaded first and not timed; best of two calls), so the ratio says what streaming from and to
   files costs against the library alone.  ``--reference-n`` integrates only the first N samples in memory
   when the whole file would not fit (the figure is then samples/s on N); by default all n.
4. Checks that the file's last attitude equals the in-memory one (angle < 1e-9 rad) when both cover all n.

Also reports ``strapdown --help`` wall time (best of 5).  Big files go under ``--dir`` and are deleted at the
end unless ``--keep``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

GIB = 1 << 30


def write_log(path: Path, n: int, seed: int = 0) -> float:
    """A 1 kHz gyro log in row groups of 2^20 rows; returns seconds taken.

    The rates are sums of four sinusoids per axis (0.05-2 Hz, up to about 3 rad/s) plus white noise: smooth
    motion that stays within a gyro's range however long the file.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    amp = rng.uniform(0.2, 0.8, (4, 3))
    freq = 2 * np.pi * rng.uniform(0.05, 2.0, (4, 3))
    phase = rng.uniform(0, 2 * np.pi, (4, 3))
    schema = pa.schema([(name, pa.float64()) for name in ("t", "gx", "gy", "gz")])
    block = 1 << 20
    with pq.ParquetWriter(path, schema, compression="snappy", use_dictionary=False) as w:
        for a in range(0, n, block):
            m = min(block, n - a)
            t = (a + np.arange(m)) * 1e-3
            rates = rng.normal(0.0, 0.01, (m, 3))
            for j in range(4):
                rates += amp[j] * np.sin(freq[j] * t[:, None] + phase[j])
            t += rng.uniform(-2e-5, 2e-5, m)  # timestamp jitter: the times are read, not assumed
            w.write_batch(pa.record_batch([t, rates[:, 0], rates[:, 1], rates[:, 2]], schema=schema))
    return time.perf_counter() - t0


def run_cli(args: list[str]) -> tuple[float, int, int]:
    """Wall time, peak RSS (bytes) and exit code of one strapdown CLI run."""
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "strapdown.cli", *args], stdout=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    sys.stdout.write(proc.stdout.read().decode())
    return seconds, usage.ru_maxrss * 1024, proc.returncode


def rounds(args: list[str], log: Path, out: Path, scratch: Path) -> tuple[float, int, float, float, dict]:
    """Two rounds of a CLI run and the floor of its output right after it, under the same conditions.

    Returns the better CLI time, the larger peak RSS, the better floor read and write (a busy machine's
    noise is larger than the effects measured), and the output's layout (:func:`layout`, with its last
    attitude).  Each floor runs in a process of its own: a child's ru_maxrss from ``wait4`` includes the
    parent's peak RSS when it starts (Linux keeps the pre-exec figure), and reading the log grows a process by
    gigabytes (pyarrow's memory pool), which the next CLI run would report as its own.

    Every timed phase starts with no writes pending: the previous phase's output is deleted (its dirty pages
    are dropped, not written) and ``os.sync()`` waits for whatever else is in flight.  Otherwise a phase pays
    for the previous one's writeback: the disk here sustains about 100 MB/s once the kernel's dirty limit (a
    few GiB) is reached, so a floor run right after a CLI run that left 5.9 GiB in the page cache took several
    times as long as on its own, and the ratio said more about the order than about the code.
    """
    best, peak, reads, writes = np.inf, 0, [], []
    for i in range(2):
        os.sync()
        seconds, rss, code = run_cli(args if i == 0 or "-q" in args else [*args, "-q"])
        if code != 0:
            raise SystemExit(f"strapdown {' '.join(args)} failed with exit code {code}")
        best, peak = min(best, seconds), max(peak, rss)
        load = os.getloadavg()[0]
        shape = layout(out)
        out.unlink()
        os.sync()
        child = [sys.executable, __file__, "--floor", str(log), json.dumps(shape), str(scratch)]
        read, write = json.loads(subprocess.run(child, capture_output=True, text=True, check=True).stdout)
        reads.append(read)
        writes.append(write)
        print(f"  round {i + 1}: CLI {seconds:.1f} s (peak RSS {rss / GIB:.3f} GiB, load {load:.1f}), floor read "
              f"{read:.1f} s + write {write:.1f} s = {read + write:.1f} s: ratio {seconds / (read + write):.2f}",
              flush=True)  # fmt: skip
    return best, peak, min(reads), min(writes), shape


def layout(out: Path) -> dict:
    """What the floor copies from an output file (rows, row groups, codec, columns and types), and its size."""
    import pyarrow.parquet as pq

    f = pq.ParquetFile(out)
    meta = f.metadata
    group = max((meta.row_group(i).num_rows for i in range(meta.num_row_groups)), default=1 << 18)
    codec = meta.row_group(0).column(0).compression.lower() if meta.num_row_groups else "snappy"
    columns = [(field.name, str(field.type)) for field in f.schema_arrow]
    return {"rows": meta.num_rows, "group": group, "codec": codec, "columns": columns,
            "bytes": out.stat().st_size, "last": last_attitude(out).tolist()}  # fmt: skip


def load(path: Path, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The first n rows of the log in memory: times (n,) and rates (n, 3)."""
    import pyarrow.parquet as pq

    f = pq.ParquetFile(path, pre_buffer=False)
    t = np.empty(n)
    gyro = np.empty((n, 3))
    row = 0
    for batch in f.iter_batches(batch_size=1 << 20, columns=["t", "gx", "gy", "gz"]):
        m = min(batch.num_rows, n - row)
        t[row : row + m] = batch.column(0).to_numpy()[:m]
        for i in range(3):
            gyro[row : row + m, i] = batch.column(i + 1).to_numpy()[:m]
        row += m
        if row == n:
            break
    return t, gyro


def last_attitude(path: Path) -> np.ndarray:
    import pyarrow.parquet as pq

    f = pq.ParquetFile(path)
    last = f.read_row_group(f.metadata.num_row_groups - 1, columns=["qw", "qx", "qy", "qz"])
    return np.array([last.column(i)[-1].as_py() for i in range(4)])


def floor(log: Path, shape: dict, scratch: Path, chunk_rows: int) -> tuple[float, float]:
    """What pyarrow alone takes: reading the log and writing a table like the output (seconds for each).

    The read takes every column of the log in batches of ``chunk_rows`` rows and makes numpy arrays of them, as
    the CLI does.  The write produces a Parquet file of the output's rows, column names, types, compression and
    row groups (``shape``, from :func:`layout`), filled with random values of the output's magnitude (as
    incompressible as attitudes), written batch by batch from arrays made beforehand (not timed).
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    t0 = time.perf_counter()
    # pre_buffer=False as the CLI's reader: pyarrow 26's default (True) reads each row group whole first and
    # took 17.5 s instead of 3.5 s for the 10^8-row log here (a floor above what pyarrow allows)
    f = pq.ParquetFile(log, pre_buffer=False)
    for batch in f.iter_batches(batch_size=chunk_rows):
        for col in batch.columns:
            col.to_numpy()
    read = time.perf_counter() - t0

    schema = pa.schema([(name, pa.type_for_alias(kind)) for name, kind in shape["columns"]])
    rows, group, codec = shape["rows"], shape["group"], shape["codec"]
    rng = np.random.default_rng(1)
    batch = pa.record_batch(
        [pa.array(rng.uniform(-1, 1, group).astype(field.type.to_pandas_dtype())) for field in schema],
        schema=schema,
    )
    t0 = time.perf_counter()
    with pq.ParquetWriter(scratch, schema, compression=codec, use_dictionary=False) as w:
        for a in range(0, rows, group):
            w.write_batch(batch.slice(0, min(group, rows - a)), row_group_size=group)
    write = time.perf_counter() - t0
    scratch.unlink()
    return read, write


def help_time() -> float:
    best = np.inf
    for _ in range(5):
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "strapdown.cli", "--help"], capture_output=True, check=True)
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=float, default=1e8, help="samples in the log")
    ap.add_argument("--dir", default=tempfile.gettempdir(), help="where the big files go")
    ap.add_argument("--reference-n", type=float, default=None, help="samples integrated in memory (default: n)")
    ap.add_argument("--keep", action="store_true", help="keep the files")
    ap.add_argument("--json", default=None)
    ap.add_argument("--floor", nargs=3, metavar=("LOG", "SHAPE", "SCRATCH"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.floor:  # one floor measure, in a process of its own (see rounds)
        import pyarrow.parquet as pq

        for col in next(pq.ParquetFile(args.floor[0], pre_buffer=False).iter_batches(batch_size=1)).columns:
            col.to_numpy()  # pyarrow's first use (to_numpy imports pandas), not timed
        log, shape, scratch = args.floor
        print(json.dumps(floor(Path(log), json.loads(shape), Path(scratch), 1 << 18)))
        return
    n = int(args.n)
    n_ref = n if args.reference_n is None else int(args.reference_n)
    work = Path(tempfile.mkdtemp(prefix="strapdown-bench-io-", dir=args.dir))
    log, out = work / "gyro.parquet", work / "attitude.parquet"
    results: dict = {
        "load_average_start": os.getloadavg(),
        "n": n,
        "reference_n": n_ref,
        "python": platform.python_version(),
        "cpus": os.cpu_count(),
    }
    try:
        print(f"writing {n:.3g} samples to {log} ...", flush=True)
        results["write_seconds"] = write_log(log, n)
        results["log_bytes"] = log.stat().st_size
        os.sync()  # the log on disk before anything is timed (see rounds)
        print(f"  {results['log_bytes'] / GIB:.2f} GiB in {results['write_seconds']:.1f} s", flush=True)

        print("strapdown integrate (streaming, subprocess) ...", flush=True)
        # first a tiny file, so that numba's cache is warm and only the file work is timed below
        write_log(work / "warm.parquet", 1000)
        run_cli(["integrate", str(work / "warm.parquet"), "-o", str(work / "warm.csv"), "-q"])
        # the fixed cost of one CLI run (Python, imports, loading the cached kernels): a 1000-row Parquet file
        tiny = min(run_cli(["integrate", str(work / "warm.parquet"), "-o", str(work / "tiny.parquet"), "-q"])[0]
                   for _ in range(2))  # fmt: skip
        results["cli_fixed_seconds"] = tiny
        print("strapdown integrate, then the pyarrow floor: read the log, write a table like the output ...")
        seconds, rss, read, write, shape = rounds(
            ["integrate", str(log), "-o", str(out)], log, out, work / "floor.parquet"
        )
        results.update(stream_seconds=seconds, stream_peak_rss=rss, out_bytes=shape["bytes"])
        results["stream_samples_per_s"] = n / seconds
        results["_last"] = np.array(shape["last"])
        results.update(floor_read_seconds=read, floor_write_seconds=write, floor_seconds=read + write)
        results["stream_over_floor"] = seconds / (read + write)
        print("strapdown integrate --float32, then its floor ...", flush=True)
        out32 = work / "attitude32.parquet"
        seconds32, rss32, read32, write32, shape32 = rounds(
            ["integrate", str(log), "-o", str(out32), "--float32", "-q"], log, out32, work / "floor.parquet"
        )
        results.update(stream32_seconds=seconds32, stream32_peak_rss=rss32, out32_bytes=shape32["bytes"])
        results.update(floor32_read_seconds=read32, floor32_write_seconds=write32, floor32_seconds=read32 + write32)
        results["stream32_over_floor32"] = seconds32 / (read32 + write32)

        print(f"in-memory reference: strapdown.integrate on {n_ref:.3g} samples ...", flush=True)
        import strapdown as sd

        t, gyro = load(log, n_ref)
        sd.integrate(gyro[:1000], t=t[:1001])  # numba kernels loaded
        # best of two: the first call also pays the kernel's first touch of its output pages
        best = np.inf
        for _ in range(2):
            q = None
            t0 = time.perf_counter()
            q = sd.integrate(gyro[:-1], t=t)
            best = min(best, time.perf_counter() - t0)
        results["memory_seconds"] = best
        results["memory_samples_per_s"] = (n_ref - 1) / results["memory_seconds"]
        if n_ref == n:
            results["last_attitude_angle_rad"] = float(sd.angle_between(q[-1], results.pop("_last")))
        del t, gyro, q
        results["help_seconds"] = help_time()
    finally:
        if not args.keep:
            for p in work.iterdir():
                p.unlink()
            work.rmdir()

    ratio = results["stream_samples_per_s"] / results["memory_samples_per_s"]
    print()
    print(f"file I/O benchmark: {n:.3g} samples, {results['cpus']} CPUs, Python {results['python']}")
    print(f"  log (t, gx, gy, gz float64, snappy)        {results['log_bytes'] / GIB:8.2f} GiB")
    print(f"  output (t, q, yaw/pitch/roll, snappy)      {results['out_bytes'] / GIB:8.2f} GiB")
    print(f"  strapdown integrate, streaming             {results['stream_seconds']:8.1f} s   "
          f"{results['stream_samples_per_s'] / 1e6:8.2f} M samples/s")  # fmt: skip
    print(f"    peak RSS                                 {rss / GIB:8.3f} GiB   (limit 1 GiB: "
          f"{'met' if rss < GIB else 'MISSED'})")  # fmt: skip
    print(f"  pyarrow floor: read {results['floor_read_seconds']:.1f} s + write "
          f"{results['floor_write_seconds']:.1f} s  {results['floor_seconds']:8.1f} s")  # fmt: skip
    print(f"  streaming / floor                          {results['stream_over_floor']:8.2f}     (goal <= 1.5)")
    results["variable_over_floor"] = (results["stream_seconds"] - results["cli_fixed_seconds"]) / results[
        "floor_seconds"
    ]
    print(f"  --float32 output (t float64)               {results['out32_bytes'] / GIB:8.2f} GiB")
    print(f"  strapdown integrate --float32              {results['stream32_seconds']:8.1f} s   peak RSS "
          f"{results['stream32_peak_rss'] / GIB:.3f} GiB")  # fmt: skip
    print(f"  pyarrow floor (float32 output): read {results['floor32_read_seconds']:.1f} s + write "
          f"{results['floor32_write_seconds']:.1f} s  {results['floor32_seconds']:8.1f} s")  # fmt: skip
    print(f"  streaming / floor, --float32               {results['stream32_over_floor32']:8.2f}     (goal <= 1.5)")
    print(f"  CLI fixed cost (1000-row file)             {results['cli_fixed_seconds']:8.1f} s;  (streaming - fixed) "
          f"/ floor {results['variable_over_floor']:6.2f}")  # fmt: skip
    print(f"  strapdown.integrate in memory ({n_ref:.3g})    {results['memory_seconds']:8.1f} s   "
          f"{results['memory_samples_per_s'] / 1e6:8.2f} M samples/s")  # fmt: skip
    print(f"  streaming / in-memory throughput           {ratio:8.3f}")
    if "last_attitude_angle_rad" in results:
        print(f"  last attitude, file vs memory              {results['last_attitude_angle_rad']:8.1e} rad")
    print(f"  strapdown --help                           {results['help_seconds']:8.3f} s")
    results["ratio"] = ratio
    results["load_average_end"] = os.getloadavg()
    print(f"  load average at start / end                {results['load_average_start'][0]:.1f} / "
          f"{results['load_average_end'][0]:.1f}")  # fmt: skip
    results.pop("_last", None)
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
