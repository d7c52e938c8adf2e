"""A/B of the file pipeline's read-ahead thread and chunk size, in one process, interleaved, with the floor.

    python benchmarks/bench_io_ab.py LOG.parquet [--reps 2] [--chunk-rows 262144 1048576] [--out /tmp/x.parquet]

Runs ``strapdown.io.integrate_file(LOG, OUT)`` with the read-ahead thread (as shipped) and without it (the
chunks read in the calling thread), for each ``--chunk-rows``, in turn, ``--reps`` times, and after each round
the pyarrow floor of ``bench_io.py`` (read the log, write a table like the output).  On a shared machine the
noise between rounds is larger than most effects: compare within a round, and the best of each.  Make a log
with ``bench_io.write_log`` (``python -c "import bench_io; bench_io.write_log(Path('log.parquet'), 10**8)"``).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import resource
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

import bench_io


@contextlib.contextmanager
def _in_this_thread(items):
    yield items


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("log")
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("--chunk-rows", type=int, nargs="+", default=[1 << 18])
    ap.add_argument("--out", default=None, help="output file (default: beside the log)")
    args = ap.parse_args()
    from strapdown.io import integrate_file, pipeline

    log = Path(args.log)
    out = Path(args.out) if args.out else log.with_name("ab-out.parquet")
    shipped = pipeline.ReadAhead
    variants = [(f"{name} {rows}", ahead, rows) for rows in args.chunk_rows
                for name, ahead in (("read-ahead", shipped), ("plain", _in_this_thread))]  # fmt: skip
    best: dict[str, float] = {}
    try:
        for rep in range(args.reps):
            line = []
            for name, ahead, rows in variants:
                pipeline.ReadAhead = ahead
                t0 = time.perf_counter()
                integrate_file(log, out, chunk_rows=rows)
                seconds = time.perf_counter() - t0
                best[name] = min(best.get(name, float("inf")), seconds)
                line.append(f"{name} {seconds:.2f} s")
            pipeline.ReadAhead = shipped
            read, write = bench_io.floor(log, bench_io.layout(out), out.with_name("ab-floor.parquet"), 1 << 18)
            best["floor"] = min(best.get("floor", float("inf")), read + write)
            print(f"round {rep + 1}: " + ", ".join(line) + f"; floor {read:.2f} + {write:.2f} s; load "
                  f"{os.getloadavg()[0]:.1f}", flush=True)  # fmt: skip
    finally:
        pipeline.ReadAhead = shipped
        out.unlink(missing_ok=True)
    print("best: " + ", ".join(f"{k} {v:.2f} s" for k, v in best.items()))
    print(f"peak RSS of this process {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20:.3f} GiB")


if __name__ == "__main__":
    main()
