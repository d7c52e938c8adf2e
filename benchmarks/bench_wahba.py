"""Speed of strapdown's Wahba solvers against scipy's Rotation.align_vectors in a Python loop, in the same run.

    python benchmarks/bench_wahba.py [--n 1000000] [--n-scipy 10000] [--repeat 5] [--json results.json]

Each epoch has 3 noisy unit vector observations (σ = 1 mrad) with random weights.  strapdown solves all n epochs
in one vectorised call (best of `repeat`, after one warm-up call that also loads or compiles the numba kernel;
that first-call time is shown separately), input validation included.  scipy has no batched solver, so
``align_vectors`` runs in a Python loop over the first `n-scipy` epochs (best of 3), and its time is scaled to n.
TRIAD is compared with align_vectors on its two vectors, the others with align_vectors on all three.  The ratio
is scipy / strapdown (above 1 means strapdown is faster); the accuracy column is the largest rotation angle
between strapdown's and scipy's answers on the looped epochs.  Exit status 1 if any ratio is below --min-ratio
(default 100, the issue's goal).
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time

import numpy as np
import scipy
from scipy.spatial.transform import Rotation

import strapdown
from _timing import best_time
from strapdown.rotations.wahba import davenport, olae, quest, triad


def first_call(func):
    t0 = time.perf_counter()
    func()
    return time.perf_counter() - t0


def angle(p, q):
    """Rotation angle between attitudes, sign-invariant (chordal form, accurate for tiny angles)."""
    d = np.minimum(np.linalg.norm(p - q, axis=-1), np.linalg.norm(p + q, axis=-1))
    return 4 * np.arcsin(np.minimum(d / 2, 1.0))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=1_000_000, help="epochs per strapdown call")
    ap.add_argument("--n-scipy", type=int, default=10_000, help="epochs in scipy's loop (scaled to n)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--min-ratio", type=float, default=100.0)
    ap.add_argument("--json", help="also write the results here")
    args = ap.parse_args(argv)
    n, n_scipy = args.n, min(args.n_scipy, args.n)

    rng = np.random.default_rng(0)
    truth = Rotation.random(n, rng=rng)
    body = rng.standard_normal((n, 3, 3))
    body /= np.linalg.norm(body, axis=-1, keepdims=True)
    reference = np.einsum("nij,nkj->nki", truth.as_matrix(), body) + 1e-3 * rng.standard_normal((n, 3, 3))
    reference /= np.linalg.norm(reference, axis=-1, keepdims=True)
    weights = rng.uniform(0.5, 1.5, (n, 3))
    b1, b2, r1, r2 = body[:, 0], body[:, 1], reference[:, 0], reference[:, 1]

    def scipy_loop(m):
        out = np.empty((n_scipy, 4))
        for i in range(n_scipy):
            rot, _ = Rotation.align_vectors(reference[i, :m], body[i, :m], weights=weights[i, :m])
            out[i] = rot.as_quat(scalar_first=True)
        return out

    scipy_q = {m: scipy_loop(m) for m in (2, 3)}
    scipy_time = {m: best_time(lambda m=m: scipy_loop(m), 3) * n / n_scipy for m in (2, 3)}

    cases = [
        ("triad", 2, lambda: triad(b1, b2, r1, r2)),
        ("davenport", 3, lambda: davenport(body, reference, weights)),
        ("quest", 3, lambda: quest(body, reference, weights)),
        ("olae", 3, lambda: olae(body, reference, weights)),
        ("davenport+cov", 3, lambda: davenport(body, reference, weights, return_covariance=True)[0]),
        ("quest+cov", 3, lambda: quest(body, reference, weights, return_covariance=True)[0]),
    ]
    print(
        f"strapdown {strapdown.__version__} vs scipy {scipy.__version__}, numpy {np.__version__}, "
        f"Python {platform.python_version()}, n = {n:,} epochs of 3 vectors, scipy looped over {n_scipy:,} "
        f"and scaled, best of {args.repeat}"
    )
    print(f"{'solver':<14} {'first call':>11} {'strapdown':>11} {'scipy loop':>11} {'ratio':>8} {'vs scipy':>10}")
    results = []
    for name, m, ours in cases:
        first = first_call(ours)
        t_ours = best_time(ours, args.repeat)
        ratio = scipy_time[m] / t_ours
        q = ours()[:n_scipy]
        diff = float(angle(q, scipy_q[m]).max())
        results.append(
            {
                "solver": name,
                "first_call_s": first,
                "strapdown_s": t_ours,
                "scipy_s": scipy_time[m],
                "ratio": ratio,
                "max_angle_vs_scipy_rad": diff,
            }
        )
        print(
            f"{name:<14} {first * 1e3:9.1f}ms {t_ours * 1e3:9.1f}ms {scipy_time[m]:10.2f}s {ratio:7.0f}x {diff:10.1e}"
        )
    print(
        "(vs scipy: max rotation angle in rad between the answers; TRIAD and OLAE are not Wahba-optimal, so theirs "
        "is the noise-level difference of their criteria)"
    )
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"n": n, "n_scipy": n_scipy, "scipy": scipy.__version__, "results": results}, fh, indent=2)
    worst = min(r["ratio"] for r in results)
    print(f"worst ratio {worst:.0f}x (goal >= {args.min_ratio:.0f}x)")
    return 0 if worst >= args.min_ratio else 1


if __name__ == "__main__":
    sys.exit(main())
