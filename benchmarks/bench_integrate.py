"""Gyro integration throughput and precision, with every reference measured in the same run.

    python benchmarks/bench_integrate.py [--n 10000000] [--repeat 5] [--json results.json]

Throughput: "exact" and "first-order" on n samples (random rates, dt = 10 ms), with the two-core scan (the
default for long single-body inputs) and with the sequential loop.  The reference is the memory traffic an ideal
integrator cannot avoid: np.copyto of an array of the input's bytes plus np.copyto of an array of the output's
bytes, timed here; the ratio is integrate time / copy time.  Anchors: a scipy Rotation composition loop and ahrs
AngularRate (closed form), both on 10^5 samples and scaled to n (pure-Python loops scale linearly).

Precision: the scan against the sequential loop over n random steps, and both against the closed form on a
constant-rate run of n steps (dt = 2^-10 s and a rate with few binary digits, so ω t is exact).
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import sys

import numba
import numpy as np

import strapdown
from _timing import best_time
from strapdown import integrate
from strapdown import quaternion as quat


def closed_form(q0, omega, t):
    v = [c * t / 2 for c in omega]
    a = math.sqrt(sum(c * c for c in v))
    s = math.sin(a) / a
    return quat.multiply(q0, [math.cos(a), v[0] * s, v[1] * s, v[2] * s])


def anchors(gyro, dt, n_scale):
    out = {}
    try:
        from scipy.spatial.transform import Rotation

        steps = Rotation.from_rotvec(gyro * dt)

        def scipy_loop():
            r = Rotation.identity()
            for k in range(len(steps)):
                r = r * steps[k]

        out["scipy Rotation loop"] = best_time(scipy_loop, 1) * n_scale
    except ImportError:
        pass
    try:
        from ahrs.filters import AngularRate

        out["ahrs AngularRate"] = best_time(lambda: AngularRate(gyr=gyro, frequency=1 / dt), 1) * n_scale
    except ImportError:
        pass
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=10_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--anchor-n", type=int, default=100_000)
    ap.add_argument("--goal", type=float, default=3.5, help="goal: integrate time / copy time")
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    n = args.n
    dt = 0.01
    gyro = np.random.default_rng(0).standard_normal((n, 3)) * 0.5
    print(
        f"strapdown {strapdown.__version__}, numpy {np.__version__}, numba {numba.__version__}, Python "
        f"{platform.python_version()}, {numba.get_num_threads()} threads, n = {n:,}, best of {args.repeat}"
    )

    in_buf = np.empty_like(gyro)
    out_src = np.ones((n + 1, 4))
    out_buf = np.empty_like(out_src)
    t_copy = best_time(lambda: np.copyto(in_buf, gyro), args.repeat) + best_time(
        lambda: np.copyto(out_buf, out_src), args.repeat
    )
    rows = [("np.copyto of input + output bytes", t_copy)]
    for method in ("exact", "first-order"):
        for parallel in (True, False):
            integrate(gyro[:1000], dt, method=method, parallel=parallel)  # compile / load the kernel
            t = best_time(lambda m=method, p=parallel: integrate(gyro, dt, method=m, parallel=p), args.repeat)
            rows.append((f"{method}, {'two-core scan' if parallel else 'sequential loop'}", t))
    for name, t in anchors(gyro[: args.anchor_n], dt, n / args.anchor_n).items():
        rows.append((f"{name} (10^5 samples, scaled)", t))

    print(f"\n{'':44s} {'time':>10s} {'M samples/s':>12s} {'/ copy':>8s}")
    results = []
    for name, t in rows:
        print(f"{name:44s} {t:9.3f}s {n / t / 1e6:12.2f} {t / t_copy:8.2f}")
        results.append({"what": name, "seconds": t, "msamples_per_s": n / t / 1e6, "ratio_to_copy": t / t_copy})

    # precision: scan vs sequential on random rates, and both vs the closed form at a constant rate
    seq = integrate(gyro, dt, parallel=False)
    par = integrate(gyro, dt, parallel=True)
    scan_vs_seq = float(quat.angle_between(par, seq, check=False).max())
    omega = [0.375, -0.625, 0.25]
    h = 2.0**-10
    q0 = strapdown.from_euler([0.3, -0.2, 0.1], "ZYX")
    const = np.tile(omega, (n, 1))
    truth = closed_form(q0, omega, n * h)
    err_seq = float(quat.angle_between(integrate(const, h, q0=q0, parallel=False)[-1], truth))
    err_par = float(quat.angle_between(integrate(const, h, q0=q0, parallel=True)[-1], truth))
    norm_err = float(np.abs(np.linalg.norm(par, axis=-1) - 1).max())
    print(
        f"\nscan vs sequential, {n:,} random steps: max {scan_vs_seq:.2e} rad; max ||q| - 1| of the scan {norm_err:.1e}"
    )
    print(f"constant rate, {n:,} steps: sequential {err_seq:.2e} rad, scan {err_par:.2e} rad from the closed form")

    exact_scan = next(r for r in results if r["what"] == "exact, two-core scan")
    ok = exact_scan["ratio_to_copy"] <= args.goal
    print(
        f"exact (scan) / copy = {exact_scan['ratio_to_copy']:.2f} (goal <= {args.goal}): {'met' if ok else 'NOT met'}"
    )
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(
                {
                    "n": n,
                    "threads": numba.get_num_threads(),
                    "results": results,
                    "scan_vs_sequential_rad": scan_vs_seq,
                    "constant_rate_error_rad": {"sequential": err_seq, "scan": err_par},
                },
                fh,
                indent=2,
            )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
