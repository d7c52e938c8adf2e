"""Speed of composition, this checkout against an older one, measured in the same run (issue 32).

    git worktree add /tmp/wt32-base 3db84d4
    python benchmarks/bench_composition.py --base /tmp/wt32-base [--rounds 5] [--repeat 7] [--json F]

Issue 32 made :class:`strapdown.Attitude`'s products unit again (one Newton step for 1/|q| in the kernel) and
summed the Hamilton product's terms in pairs; the goal is composition as fast as before, within 10 %.  Both
checkouts cannot be imported into one process, so each round starts one worker process per checkout (``src`` on
``PYTHONPATH``), in alternating order; a worker times ``Attitude * Attitude`` and ``quaternion.multiply`` for a
single attitude (the Python overhead), 1000 and 10⁶, best of ``--repeat`` after a warm-up call (which loads or
compiles the kernels).  The figure is new / base per operation, the median over the rounds; scipy's ``Rotation *
Rotation`` is timed in each worker as well, as a check that the two workers ran on an equally loaded machine (its
ratio should be near 1).  Exit status 1 if a ratio exceeds ``--max-ratio`` (default 1.10).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

SIZES = (1, 1000, 1_000_000)


def worker(repeat: int) -> dict:
    """Best times (s) of each operation and size in this process's strapdown."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    from _timing import best_time
    from strapdown import Attitude, multiply

    out = {}
    for n in SIZES:
        shape = None if n == 1 else n
        a, b = Attitude.random(shape, rng=0), Attitude.random(shape, rng=1)
        p, q = np.asarray(a.q), np.asarray(b.q)
        r, s = Rotation.from_quat(p, scalar_first=True), Rotation.from_quat(q, scalar_first=True)
        loops = max(1, 100_000 // n)  # small sizes: time a loop, so the clock's resolution does not count
        cases = {
            "Attitude * Attitude": lambda a=a, b=b: a * b,
            "quaternion.multiply": lambda p=p, q=q: multiply(p, q),
            "scipy Rotation * Rotation": lambda r=r, s=s: r * s,
        }
        for name, func in cases.items():

            def many(func=func, loops=loops):
                for _ in range(loops):
                    func()

            func()
            out[f"{name}, n={n:,}"] = best_time(many, repeat) / loops
    return out


def run_worker(checkout: Path, repeat: int) -> dict:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(checkout / "src"), str(Path(__file__).parent)]))
    done = subprocess.run(
        [sys.executable, __file__, "--worker", "--repeat", str(repeat)],
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode:
        raise SystemExit(f"the worker for {checkout} failed:\n{done.stderr}")
    return json.loads(done.stdout.splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--base", type=Path, help="the older checkout (a git worktree), compared with this one")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--max-ratio", type=float, default=1.10)
    ap.add_argument("--json", help="also write the results here")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(args.repeat)))
        return 0
    if args.base is None or not (args.base / "src" / "strapdown").is_dir():
        ap.error("--base must name a checkout of strapdown (with src/strapdown)")
    import numpy as np

    here = Path(__file__).resolve().parents[1]
    times: dict[str, dict[str, list]] = {"new": {}, "base": {}}
    for k in range(args.rounds):
        order = (("new", here), ("base", args.base)) if k % 2 == 0 else (("base", args.base), ("new", here))
        for label, checkout in order:
            for name, t in run_worker(checkout, args.repeat).items():
                times[label].setdefault(name, []).append(t)
    print(f"load average {os.getloadavg()[0]:.2f}; {args.rounds} rounds, best of {args.repeat} in each")
    print(f"{'operation':<40} {'base':>11} {'new':>11} {'new / base':>11}")
    rows, worst = {}, 0.0
    for name in times["new"]:
        ratios = np.array(times["new"][name]) / np.array(times["base"][name])
        ratio = float(np.median(ratios))
        base, new = (float(np.median(times[label][name])) for label in ("base", "new"))
        rows[name] = {"base_s": base, "new_s": new, "ratio": ratio}
        if not name.startswith("scipy"):
            worst = max(worst, ratio)
        print(f"{name:<40} {base * 1e6:>9.2f}µs {new * 1e6:>9.2f}µs {ratio:>11.3f}")
    print(f"largest ratio of strapdown's operations: {worst:.3f} (goal ≤ {args.max_ratio})")
    if args.json:
        Path(args.json).write_text(json.dumps({"rounds": args.rounds, "results": rows}, indent=1))
    return int(worst > args.max_ratio)


if __name__ == "__main__":
    sys.exit(main())
