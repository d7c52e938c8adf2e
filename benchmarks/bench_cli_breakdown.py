"""What one short ``strapdown estimate`` is made of: numba's fixed cost, each further kernel, the collector.

    python benchmarks/bench_cli_breakdown.py [--runs 7]

Each figure is the median over ``--runs`` fresh processes (wall and CPU milliseconds), the collector paused as
the ``strapdown`` program has it while a command starts:

* the phases of numba's fixed cost: ``import numpy``, ``import numba``, ``import strapdown``, and the first
  cached kernel of the process (``from_matrix``; numba's registries load then), as installed, with scipy made
  unimportable in that process (numba's BLAS check imports scipy.linalg when it is there), and with PyYAML
  also made unimportable (numba's configuration reads it when installed).  Nothing is hidden from the library:
  ``sys.modules[name] = None`` in the measuring process only, as for a user without the package;
* each further kernel of the 200-row estimate, loaded from the cache after that first one: ``multiply``,
  ``as_euler`` and the AttitudeEstimator's run kernel (its first ``update``, the module imported before);
* the time CPython's collector spends during a whole ``strapdown estimate`` run as the program, and with the
  collector left alone, by ``gc.callbacks``.

The numba cache of this checkout must be warm (run ``benchmarks/bench_cli.py`` or the estimate once first).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent

PHASES = r"""
import gc, json, sys, time
for name in sys.argv[1].split(",") if sys.argv[1] else []:
    sys.modules[name] = None  # this process only: as if the package were not installed
gc.disable()
marks = [(time.perf_counter(), time.process_time())]
import numpy as np
marks.append((time.perf_counter(), time.process_time()))
import numba
marks.append((time.perf_counter(), time.process_time()))
from strapdown import as_euler, from_matrix, multiply
from strapdown.fusion import AttitudeEstimator
import strapdown.rotations._matrix_numba, strapdown.rotations._quaternion_numba
import strapdown.rotations._euler_numba, strapdown.fusion._attitude_numba
marks.append((time.perf_counter(), time.process_time()))
from_matrix(np.eye(3))
marks.append((time.perf_counter(), time.process_time()))
multiply([1.0, 0, 0, 0], [1.0, 0, 0, 0])
marks.append((time.perf_counter(), time.process_time()))
as_euler(np.array([[1.0, 0, 0, 0]]), "ZYX")
marks.append((time.perf_counter(), time.process_time()))
n = 200
AttitudeEstimator().update(np.zeros((n, 3)), np.tile([0, 0, 9.81], (n, 1)), np.tile([20.0, 0, -40], (n, 1)),
                           t=np.arange(n) * 0.01)
marks.append((time.perf_counter(), time.process_time()))
print(json.dumps([[b[0] - a[0], b[1] - a[1]] for a, b in zip(marks, marks[1:])]))
"""
NAMES = ("import numpy", "import numba", "import strapdown", "first kernel", "multiply", "as_euler", "run kernel")

COLLECTOR = r"""
import gc, json, sys, time
spent, count, start = [0.0, 0.0, 0.0], [0, 0, 0], [0.0]
def watch(phase, info):
    if phase == "start":
        start[0] = time.perf_counter()
    else:
        spent[info["generation"]] += time.perf_counter() - start[0]
        count[info["generation"]] += 1
gc.callbacks.append(watch)
if sys.argv[1] == "usual":
    import strapdown.cli._options as options
    options.PausedCollection.__init__ = lambda self: setattr(self, "_paused", False)  # the collector left alone
from strapdown.cli import main
sys.argv = ["strapdown", "estimate", sys.argv[2], "-o", sys.argv[3], "-q"]
try:
    main()
except SystemExit:
    pass
print(json.dumps({"seconds": sum(spent), "collections": count}))
"""


def median_ms(runs, i, k):
    return 1000 * statistics.median(r[i][k] for r in runs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    a = parser.parse_args()
    env = dict(os.environ, PYTHONPATH=str(HERE / "src"))
    env.pop("PYTHONDONTWRITEBYTECODE", None)  # bytecode as after pip install (see bench_cli.py)
    cases = {"as installed": "", "no scipy": "scipy", "no scipy, no yaml": "scipy,yaml"}
    runs = {case: [] for case in cases}
    for _ in range(a.runs):
        for case, blocked in cases.items():
            out = subprocess.run([sys.executable, "-c", PHASES, blocked], env=env, capture_output=True, text=True)
            if out.returncode:
                raise SystemExit(out.stderr)
            runs[case].append(json.loads(out.stdout))
    print(f"load average {os.getloadavg()[0]:.1f}; median of {a.runs} processes, wall / CPU ms")
    print(f"{'':18}" + "".join(f"{n:>18}" for n in NAMES))
    for case, r in runs.items():
        print(f"{case:18}" + "".join(f"{median_ms(r, i, 0):>10.0f} /{median_ms(r, i, 1):>5.0f}" for i in range(7)))
    sys.path.insert(0, str(HERE / "benchmarks"))
    from bench_cli import write_csv

    with tempfile.TemporaryDirectory() as tmp:
        log = write_csv(Path(tmp) / "log200.csv")
        print("time in the garbage collector during one `strapdown estimate` (the program), median:")
        for mode in ("program", "usual"):
            seen = []
            for _ in range(a.runs):
                args = [sys.executable, "-c", COLLECTOR, mode, str(log), str(Path(tmp) / "out.csv")]
                out = subprocess.run(args, env=env, capture_output=True, text=True)
                if out.returncode:
                    raise SystemExit(out.stderr)
                seen.append(json.loads(out.stdout))
            ms = 1000 * statistics.median(s["seconds"] for s in seen)
            label = "as the program has it" if mode == "program" else "collector left alone"
            print(f"  {label:24} {ms:6.0f} ms, collections by generation {seen[0]['collections']}")


if __name__ == "__main__":
    main()
