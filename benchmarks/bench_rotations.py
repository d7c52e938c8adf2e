"""Speed of issue 16's rotations against scipy, and what the Attitude object costs, measured in one run.

    python benchmarks/bench_rotations.py [--n 1000000] [--repeat 7] [--json results.json]

Part 1, conversions: MRPs, Davenport angles, one- and two-axis Euler sequences and the rotation spline
(construction on n/100 knots, evaluation at n times) on the same data in strapdown and scipy.  strapdown's
times include its input validation; scipy's start from ready-made Rotation objects where scipy needs one (the
favourable case for scipy).  Ratio = strapdown / scipy; the goal is <= 1.

Part 2, the object: each Attitude operation against the plain array function it wraps, on the same n
attitudes.  Ratio = object / function; the goal is < 1.05 (the object adds less than 5 %).

Timings come in `repeat` back-to-back pairs (ours and the reference's, in alternating order) after a warm-up call
(which, for strapdown, also loads or compiles the numba kernels); the times shown are the best of each side and
the ratio is the median of the pairs' ratios, which a shared, noisy machine disturbs least.
Exit status 1 if a goal is missed.
"""

from __future__ import annotations

import argparse
import json
import platform
import sys

import numpy as np
import scipy
from scipy.spatial.transform import Rotation
from scipy.spatial.transform import RotationSpline as ScipySpline

import strapdown
from _timing import best_time
from strapdown import (
    Attitude,
    as_davenport,
    as_euler,
    as_mrp,
    from_davenport,
    from_euler,
    from_mrp,
    multiply,
    quaternion,
)
from strapdown.propagate.interpolate import RotationSpline

AXES = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 1.0]])  # n1 ⊥ n2 ⊥ n3, n1·n3 ≠ 0


def conversion_cases(n: int, rng):
    rot = Rotation.random(n, rng=rng)
    q = rot.as_quat(scalar_first=True)
    mrp = rot.as_mrp()
    angles = rng.uniform(-np.pi, np.pi, (n, 3))
    k = max(n // 100, 3)
    t_knots = np.cumsum(rng.uniform(0.5, 1.5, k))
    q_knots = Rotation.from_rotvec(np.cumsum(0.2 * rng.standard_normal((k, 3)), axis=0))
    ours_spline = RotationSpline(t_knots, q_knots.as_quat(scalar_first=True))
    scipy_spline = ScipySpline(t_knots, q_knots)
    t_eval = rng.uniform(t_knots[0], t_knots[-1], n)
    return [
        ("from_mrp", lambda: from_mrp(mrp), lambda: Rotation.from_mrp(mrp)),
        ("as_mrp", lambda: as_mrp(q), lambda: rot.as_mrp()),
        (
            "from_davenport",
            lambda: from_davenport(AXES, "e", angles),
            lambda: Rotation.from_davenport(AXES, "e", angles),
        ),
        ("as_davenport", lambda: as_davenport(q, AXES, "e"), lambda: rot.as_davenport(AXES, "e")),
        ("from_euler z", lambda: from_euler(angles[:, :1], "z"), lambda: Rotation.from_euler("z", angles[:, :1])),
        ("from_euler ZY", lambda: from_euler(angles[:, :2], "ZY"), lambda: Rotation.from_euler("ZY", angles[:, :2])),
        (
            f"spline build {k}",
            lambda: RotationSpline(t_knots, q_knots.as_quat(scalar_first=True)),
            lambda: ScipySpline(t_knots, q_knots),
        ),
        ("spline(t, 0)", lambda: ours_spline(t_eval), lambda: scipy_spline(t_eval)),
        ("spline(t, 1)", lambda: ours_spline(t_eval, 1), lambda: scipy_spline(t_eval, 1)),
        ("spline(t, 2)", lambda: ours_spline(t_eval, 2), lambda: scipy_spline(t_eval, 2)),
    ]


def object_cases(n: int, rng):
    q = Rotation.random(n, rng=rng).as_quat(scalar_first=True)
    q2 = Rotation.random(n, rng=rng).as_quat(scalar_first=True)
    angles = rng.uniform(-np.pi, np.pi, (n, 3))
    v = rng.standard_normal((n, 3))
    a = Attitude(q, reference="NED", body="FRD")
    b = Attitude(q2, reference="FRD", body="imu")
    return [
        (
            "from_euler",
            lambda: Attitude.from_euler(angles, "ZYX", reference="NED", body="FRD"),
            lambda: from_euler(angles, "ZYX"),
        ),
        ("as_euler", lambda: a.as_euler("ZYX"), lambda: as_euler(q, "ZYX")),
        ("a * b", lambda: a * b, lambda: multiply(q, q2)),
        ("apply", lambda: a.apply(v), lambda: quaternion.rotate(q, v)),
        ("inv", lambda: a.inv(), lambda: quaternion.conjugate(q)),
        ("from_mrp", lambda: Attitude.from_mrp(v, reference="NED", body="FRD"), lambda: from_mrp(v)),
        ("as_mrp", lambda: a.as_mrp(), lambda: as_mrp(q)),
    ]


def fixed_cost(rng, results: list) -> None:
    """What the object adds per call, in µs, measured on single attitudes (where nothing else costs much).

    At 10⁶ attitudes this fixed cost is all the object adds; divided by the operation's time it is the relative
    overhead, a steadier figure on a busy machine than the ratio of two 10 ms timings.
    """
    print("\nfixed cost of the object per call (single attitude, best of 2000)")
    for name, ours, theirs in object_cases(1, rng):
        ours()
        theirs()
        t_ours = min(best_time(ours, 1) for _ in range(2000))
        t_ref = min(best_time(theirs, 1) for _ in range(2000))
        results.append({"part": "fixed cost", "operation": name, "ours_s": t_ours, "reference_s": t_ref})
        print(f"{name:<20} {t_ours * 1e6:8.1f}µs {t_ref * 1e6:8.1f}µs   object adds {(t_ours - t_ref) * 1e6:6.1f}µs")


def run(cases, repeat: int, label: str, goal: float, results: list) -> float:
    print(f"\n{label}")
    print(f"{'operation':<20} {'ours':>10} {'reference':>10} {'ratio':>7}   (best times; ratio: median of pairs)")
    worst = 0.0
    for name, ours, theirs in cases:
        ours()
        theirs()
        # interleaved, and in alternating order, so that a change of load on a shared machine (or the allocator's
        # reuse of the memory the other side has just freed) favours neither side
        times = []
        for i in range(repeat):
            if i % 2:
                t_ref = best_time(theirs, 1)
                times.append((best_time(ours, 1), t_ref))
            else:
                times.append((best_time(ours, 1), best_time(theirs, 1)))
        t_ours = min(t for t, _ in times)
        t_ref = min(t for _, t in times)
        # the median of the back-to-back pairs' ratios: steadier under a changing load than the ratio of minima
        ratio = float(np.median([a / b for a, b in times]))
        worst = max(worst, ratio)
        results.append({"part": label, "operation": name, "ours_s": t_ours, "reference_s": t_ref, "ratio": ratio})
        flag = "" if ratio <= goal else "  <-- above goal"
        print(f"{name:<20} {t_ours * 1e3:8.2f}ms {t_ref * 1e3:8.2f}ms {ratio:7.3f}{flag}")
    print(f"worst ratio {worst:.3f} (goal <= {goal})")
    return worst


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=1_000_000, help="rotations per operation")
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--json", help="also write the results here")
    args = ap.parse_args(argv)
    rng = np.random.default_rng(0)
    print(
        f"strapdown {strapdown.__version__} vs scipy {scipy.__version__}, numpy {np.__version__}, "
        f"Python {platform.python_version()}, n = {args.n:,}, best of {args.repeat}"
    )
    results: list = []
    worst_conv = run(conversion_cases(args.n, rng), args.repeat, "conversions: strapdown / scipy", 1.0, results)
    worst_obj = run(object_cases(args.n, rng), args.repeat, "Attitude object / plain function", 1.05, results)
    fixed_cost(rng, results)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"n": args.n, "scipy": scipy.__version__, "results": results}, fh, indent=2)
    return 0 if worst_conv <= 1.0 and worst_obj <= 1.05 else 1


if __name__ == "__main__":
    sys.exit(main())
