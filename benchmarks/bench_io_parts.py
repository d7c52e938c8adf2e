"""The parts of the file pipeline's speed, each against what it replaced, interleaved in one process.

    python benchmarks/bench_io_parts.py [--rows 262144] [--close-rows 10000000] [--dir /tmp]

1. Output columns of 2^18 attitudes (``--rows``): ``as_euler`` plus two transposing copies (the old path)
   against the one-pass kernel ``io/_columns_numba.quat_euler_columns``, float64 and float32, and the kernel
   into a fresh block against a reused one (what ``io/_blocks.Blocks`` gives).  Best of 30 calls each, in ms.
2. Closing a Parquet file written into an empty file that was opened with truncation (what the writers did:
   ext4 flushes such a file on close) against one opened without (``writers._mode``), ``--close-rows`` rows
   of 8 float64 columns.

On a shared machine compare within a round; the noise between rounds is larger than most effects.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np


def best_ms(f, reps: int = 30) -> float:
    best = np.inf
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best * 1e3


def columns(rows: int) -> None:
    from strapdown import as_euler
    from strapdown.io.tables import OutputSpec, _attitude_block, _columns

    q = np.random.default_rng(0).normal(size=(rows, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    for dtype in (np.float64, np.float32):
        spec = OutputSpec(float32=dtype == np.float32)

        def old(dtype=dtype):
            euler = as_euler(q, "ZYX", True, yaw_range="positive", check=False)
            return _columns(q, dtype), _columns(euler, dtype)

        def fresh(spec=spec, dtype=dtype):
            return _attitude_block(q, spec, False, dtype)

        kept = np.empty((7, rows), dtype)

        def reused(spec=spec, dtype=dtype, kept=kept):
            return _attitude_block(q, spec, False, dtype, lambda shape, kind: kept)

        same = np.array_equal(np.concatenate(old()), fresh())
        figures = {"as_euler + transposes": best_ms(old), "kernel, fresh block": best_ms(fresh),
                   "kernel, reused block": best_ms(reused)}  # fmt: skip
        print(f"columns of {rows} attitudes, {np.dtype(dtype).name} (same values: {same}): "
              + ", ".join(f"{k} {v:.2f} ms" for k, v in figures.items()))  # fmt: skip


def close_times(rows: int, folder: Path) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    group = 1 << 18
    schema = pa.schema([(f"c{i}", pa.float64()) for i in range(8)])
    rng = np.random.default_rng(1)
    batch = pa.record_batch([pa.array(rng.uniform(-1, 1, group)) for _ in schema], schema=schema)
    path = folder / "close.parquet"
    for how in ("truncated", "not truncated", "truncated", "not truncated"):
        os.sync()
        os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))  # as atomic_path claims it
        sink = pa.OSFile(str(path), "a") if how == "not truncated" else str(path)
        writer = pq.ParquetWriter(sink, schema, compression="snappy", use_dictionary=False)
        t0 = time.perf_counter()
        for a in range(0, rows, group):
            writer.write_batch(batch.slice(0, min(group, rows - a)), row_group_size=group)
        t1 = time.perf_counter()
        writer.close()
        if how == "not truncated":
            sink.close()
        t2 = time.perf_counter()
        print(f"Parquet file of {rows} rows, the empty file {how}: writes {t1 - t0:.2f} s, close {t2 - t1:.3f} s")
        path.unlink()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", type=int, default=1 << 18)
    ap.add_argument("--close-rows", type=float, default=1e7)
    ap.add_argument("--dir", default=tempfile.gettempdir())
    args = ap.parse_args()
    folder = Path(tempfile.mkdtemp(prefix="strapdown-bench-parts-", dir=args.dir))
    try:
        columns(args.rows)
        close_times(int(args.close_rows), folder)
    finally:
        for p in folder.iterdir():
            p.unlink()
        folder.rmdir()
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
