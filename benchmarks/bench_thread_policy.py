"""What the parts of the thread policy cost on a busy machine: each variant against the one-thread call.

    python benchmarks/bench_thread_policy.py [--n 10000000] [--pairs 100] [--busy 2] [--only NAME ...]

Under ``--busy`` spinning processes on the same cores (as in bench_integrate.py), ``integrate(method="exact")``
on n samples, each variant paired with ``threads=1``: the two calls back to back, the order alternating, and
the median of the pairs' time ratios with a bootstrap 90 % interval (below 1: the variant is faster).  The
variants take apart what the default call does beyond one thread in one call (strapdown._support.threads.run):

- ``default``: the policy as shipped;
- ``pieces``: one thread, cut into the policy's timed pieces (PIECE_SAMPLES), without reading the run queue;
- ``sleep``: one thread in one call after a sleep of SECOND_LOOK_S (how the second look used to pause);
- ``spin``: one thread in one call after a spin of SECOND_LOOK_S (how it pauses now);
- ``two``: two threads forced, for scale;
- ``same``: ``threads=1`` itself, which shows the spread of the comparison when nothing differs.

Only the variant's own call is patched (the one-thread call of the pair runs the shipped code).  A variant
that costs nothing gives a median of 1 within its interval, as ``same`` does.
"""

from __future__ import annotations

import argparse
import json
import time

import numba
import numpy as np

import strapdown
from bench_integrate import median_interval, paired, start_busy, stop_busy
from strapdown import integrate
from strapdown._support import threads as _threads


def _one_thread_in_pieces(n, threads, part, **kw):
    for lo, hi in _threads._pieces(n):
        part(1, lo, hi)


def _after(pause):
    def run(n, threads, part, **kw):
        pause()
        part(1, 0, n)

    return run


VARIANTS = {
    "default": None,
    "pieces": _one_thread_in_pieces,
    "sleep": _after(lambda: time.sleep(_threads.SECOND_LOOK_S)),
    "spin": _after(lambda: _threads._pause(_threads.SECOND_LOOK_S)),
    "two": "two",
    "same": "same",
}


def variant_call(name, gyro, dt):
    """The variant's integrate call (strapdown._support.threads.run replaced for that call only)."""
    run = VARIANTS[name]
    if run is None:
        return lambda: integrate(gyro, dt)
    if run == "two":
        return lambda: integrate(gyro, dt, threads=max(numba.config.NUMBA_NUM_THREADS, 2))
    if run == "same":
        return lambda: integrate(gyro, dt, threads=1)

    def call():
        shipped = _threads.run
        _threads.run = run
        try:
            return integrate(gyro, dt)
        finally:
            _threads.run = shipped

    return call


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=10_000_000)
    ap.add_argument("--pairs", type=int, default=100)
    ap.add_argument("--busy", type=int, default=2)
    ap.add_argument("--only", nargs="*", choices=list(VARIANTS), help="variants to run (default: all)")
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    dt = 0.01
    gyro = np.random.default_rng(0).standard_normal((args.n, 3)) * 0.5
    for t in (1, 2, None):  # load the kernels
        integrate(gyro[: 1 << 18], dt, threads=t)
    print(
        f"strapdown {strapdown.__version__}, numba {numba.__version__}, threading layer {numba.threading_layer()}, "
        f"n = {args.n:,}, {args.busy} busy processes, {args.pairs} pairs per variant against threads=1"
    )
    one = lambda: integrate(gyro, dt, threads=1)  # noqa: E731
    results = {}
    procs = start_busy(args.busy)
    try:
        for name in args.only or VARIANTS:
            call = variant_call(name, gyro, dt)
            call(), one()  # not timed: the phase's first touch of the memory
            ratios = paired(call, one, args.pairs)
            median, lo, hi = median_interval(ratios)
            results[name] = {"median": median, "interval_90": [lo, hi], "ratios": ratios.tolist()}
            print(f"{name:8s} median time ratio to threads=1: {median:.3f} (90% interval {lo:.3f}-{hi:.3f})")
    finally:
        stop_busy(procs)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"n": args.n, "busy": args.busy, "results": results}, fh, indent=2)


if __name__ == "__main__":
    main()
