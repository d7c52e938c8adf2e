"""What the first call costs: a fresh install (empty numba cache) against a warm cache, in new processes.

    python benchmarks/bench_coldstart.py [--json out.json]

Each figure is one new Python process with ``NUMBA_CACHE_DIR`` pointing at a folder of this run, so that the
"cold" process finds no cache (as after ``pip install``) and the "warm" ones find what the cold one left.  Per
process: the time of ``import strapdown`` and of the first call of each of ``integrate`` on 10^3 samples (the
sequential loop), ``integrate`` on 10^6 samples (the scan, threads chosen by the policy) and ``as_euler`` on
10^3 quaternions, each in float64.  Then ``python -m strapdown.apps.warmup`` on another empty cache (what a warm-up
at install costs) and the same first calls after it.  The machine may be shared; the load average is printed.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

CHILD = r"""
import json, time
t0 = time.perf_counter()
import numpy as np
import strapdown
out = {"import strapdown": time.perf_counter() - t0}
g3 = np.random.default_rng(0).standard_normal((1000, 3))
g6 = np.random.default_rng(0).standard_normal((1_000_000, 3))
q = strapdown.from_rotvec(g3)
for name, call in (
    ("integrate 10^3 (loop)", lambda: strapdown.integrate(g3, 0.01)),
    ("integrate 10^6 (scan)", lambda: strapdown.integrate(g6, 0.01)),
    ("as_euler 10^3", lambda: strapdown.as_euler(q, "ZYX")),
):
    t0 = time.perf_counter()
    call()
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    call()
    out[name] = first
    out[name + ", second call"] = time.perf_counter() - t0
print(json.dumps(out))
"""


def child(cache: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-c", CHILD], env=env, capture_output=True, text=True, check=True)
    out = json.loads(res.stdout)
    out["process wall time"] = time.perf_counter() - t0
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}, {os.cpu_count()} CPUs")
    runs = {}
    with tempfile.TemporaryDirectory(prefix="strapdown-cold-") as root:
        cache = os.path.join(root, "cache")
        runs["cold (empty cache)"] = child(cache)
        runs["warm (cache of the cold run)"] = child(cache)
        warmed = os.path.join(root, "warmed")
        t0 = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "strapdown.apps.warmup", "--quiet"],
            env=dict(os.environ, NUMBA_CACHE_DIR=warmed),
            check=True,
        )
        warmup_seconds = time.perf_counter() - t0
        runs["after python -m strapdown.apps.warmup"] = child(warmed)
    names = list(next(iter(runs.values())))
    print(f"\n{'first call in a new process (s)':34s}" + "".join(f"{k:>34s}" for k in runs))
    for name in names:
        print(f"{name:34s}" + "".join(f"{r[name]:34.3f}" for r in runs.values()))
    print(f"\npython -m strapdown.apps.warmup on an empty cache: {warmup_seconds:.1f} s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"runs": runs, "warmup_seconds": warmup_seconds, "load": os.getloadavg()}, fh, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
