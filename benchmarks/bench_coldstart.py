"""What the first call costs: a fresh install (empty numba cache) against a warm cache, in new processes.

    python benchmarks/bench_coldstart.py [--against OLD/src] [--repeat 2] [--json out.json]

Each figure is one new Python process with ``NUMBA_CACHE_DIR`` pointing at a folder of this run, so that the
"cold" process finds no cache (as after ``pip install``) and the "warm" one finds what the cold one left.  Per
process, in float64: the time of ``import strapdown``, then the first (and a second) call of

* ``AttitudeEstimator().update`` on 1000 samples, 6D and then 9D;
* ``integrate`` on 10^3 samples (the sequential loop) and 10^6 samples (the scan, threads by the policy);
* ``as_euler`` on 10^3 quaternions;

and, in processes of their own, ``strapdown estimate`` on a simulated 3-minute, 200 Hz CSV (gyro, acc, mag:
the file of issue 30), cold and warm.  Every process counts the numba compilations of strapdown's kernels
(numba's compile events): a warm process must count none, which is the proof that the cache is reused across
processes.  Then ``strapdown warmup`` on another empty cache, and the first calls after it.

``--against`` runs the same processes with an older checkout's ``src`` first on ``PYTHONPATH``, alternating with
this one, so that before and after come from one run on one machine load.  The machine may be shared; the load
average is printed with every process.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = str(Path(__file__).resolve().parents[1] / "src")

# the counter of strapdown kernel compilations, started before the kernels are imported (older checkouts
# without it report no count)
COUNT = r"""
try:
    from strapdown._support.kernel_cache import count_compilations
    compiled = count_compilations()
except ImportError:
    compiled = None
"""

# the end of every child: the count, then (where the first calls ran kernels uncompiled) the wait for the
# background worker that compiles them, so that the next process finds them in the cache
END = r"""
if compiled is not None:
    out["kernels compiled"] = len(compiled)
try:
    from strapdown._support.uncompiled import wait_for_background
    t0 = time.perf_counter()
    wait_for_background()
    out["then waited for the background compile"] = time.perf_counter() - t0
except ImportError:
    pass
print(json.dumps(out))
"""

CALLS = (
    COUNT
    + r"""
import json, time
t0 = time.perf_counter()
import numpy as np
import strapdown
from strapdown.fusion import AttitudeEstimator
out = {"import strapdown": time.perf_counter() - t0}
rng = np.random.default_rng(0)
g3 = 0.01 * rng.standard_normal((1000, 3))
acc = np.tile([0.0, 0.0, 9.81], (1000, 1)) + 0.05 * rng.standard_normal((1000, 3))
mag = np.tile([20.0, 0.0, -40.0], (1000, 1))
g6 = rng.standard_normal((1_000_000, 3))
q = strapdown.from_rotvec(g3)
for name, call in (
    ("AttitudeEstimator().update 6D, 10^3", lambda: AttitudeEstimator().update(g3, acc, dt=0.01)),
    ("AttitudeEstimator().update 9D, 10^3", lambda: AttitudeEstimator().update(g3, acc, mag, dt=0.01)),
    ("integrate 10^3 (loop)", lambda: strapdown.integrate(g3, 0.01)),
    ("integrate 10^6 (scan)", lambda: strapdown.integrate(g6, 0.01)),
    ("as_euler 10^3", lambda: strapdown.as_euler(q, "ZYX")),
):
    t0 = time.perf_counter()
    call()
    out[name] = time.perf_counter() - t0
    t0 = time.perf_counter()
    call()
    out[name + ", second call"] = time.perf_counter() - t0
"""
    + END
)

ESTIMATE = (
    COUNT
    + r"""
import json, sys, time
t0 = time.perf_counter()
from strapdown.cli import main
try:
    main(["estimate", sys.argv[1], "-o", sys.argv[2], "-q"])
except SystemExit as exc:
    if exc.code:
        raise
out = {"strapdown estimate, 3 min at 200 Hz (in process)": time.perf_counter() - t0}
"""
    + END
)


def child(code: str, cache: str, src: str, *args: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=src)
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-c", code, *args], env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode:
        raise RuntimeError(f"child process failed:\n{res.stderr[-2000:]}")
    out = json.loads(res.stdout.strip().splitlines()[-1])
    # what the user waits for: the process less its wait for the background worker (which only the benchmark
    # does, so that the next process finds the cache filled)
    out["process wall time"] = wall - out.get("then waited for the background compile", 0.0)
    out["load average"] = os.getloadavg()[0]
    return out


def make_csv(path: str) -> None:
    subprocess.run(
        [
            sys.executable,
            "-m",
            "strapdown.cli",
            "simulate",
            path,
            *("--scenario", "random", "--imu", "consumer"),
            *("--rate", "200", "--duration", "180", "--no-truth", "-q"),
        ],
        env=dict(os.environ, PYTHONPATH=SRC),
        check=True,
    )


def one_tree(src: str, root: str, csv: str) -> dict[str, dict]:
    """The cold, warm and warmed-up processes of one source tree, each on caches of its own."""
    runs = {}
    cache = tempfile.mkdtemp(dir=root)
    runs["cold"] = child(CALLS, cache, src)
    runs["warm"] = child(CALLS, cache, src)
    cache = tempfile.mkdtemp(dir=root)
    out = os.path.join(root, "out.csv")
    for key in ("cold estimate", "warm estimate"):
        if os.path.exists(out):
            os.remove(out)
        runs[key] = child(ESTIMATE, cache, src, csv, out)
        runs[key]["strapdown estimate, process wall time"] = runs[key]["process wall time"]
    warmed = tempfile.mkdtemp(dir=root)
    t0 = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "strapdown.apps.warmup", "--quiet"],
        env=dict(os.environ, NUMBA_CACHE_DIR=warmed, PYTHONPATH=src),
        capture_output=True,
    )
    if done.returncode == 0:  # (the warm-up of some older checkouts fails: their figures leave it out)
        runs["after warmup"] = child(CALLS, warmed, src)
        runs["after warmup"]["warmup on an empty cache"] = time.perf_counter() - t0
    return runs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--against", help="an older checkout's src folder, measured alternately in the same run")
    ap.add_argument("--repeat", type=int, default=1, help="rounds (each tree once per round); medians reported")
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    print(f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}, {os.cpu_count()} CPUs")
    trees = {"this": SRC} if not args.against else {"this": SRC, "against": str(Path(args.against).resolve())}
    rounds: dict[str, list[dict]] = {k: [] for k in trees}
    with tempfile.TemporaryDirectory(prefix="strapdown-cold-") as root:
        csv = os.path.join(root, "log200.csv")
        make_csv(csv)
        for r in range(args.repeat):
            order = list(trees) if r % 2 == 0 else list(trees)[::-1]
            for name in order:
                rounds[name].append(one_tree(trees[name], root, csv))
                print(f"round {r + 1}, {name}: done (load {os.getloadavg()[0]:.2f})", flush=True)
    medians = {}
    for name, rs in rounds.items():
        medians[name] = {run: {key: statistics.median(r[run][key] for r in rs) for key in rs[0][run]} for run in rs[0]}
    for name, runs in medians.items():
        print(f"\n{name} ({trees[name]}), median of {args.repeat}")
        for run, figures in runs.items():
            print(f"  {run}")
            for key, value in figures.items():
                print(f"    {key:52s} {value:8.3f}")
    this = medians["this"]
    gap = (
        this["cold estimate"]["strapdown estimate, process wall time"]
        - this["warm estimate"]["strapdown estimate, process wall time"]
    )
    print(f"\nfirst strapdown estimate after a fresh install: {gap:.1f} s more than the warm call")
    print(
        f"kernels compiled by a second process: {this['warm']['kernels compiled']:.0f} (calls), "
        f"{this['warm estimate']['kernels compiled']:.0f} (estimate)"
    )
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"trees": trees, "rounds": rounds, "medians": medians}, fh, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
