"""Per-call cost of the command line: ``strapdown --help`` and ``strapdown estimate`` on a 200-row CSV.

    python benchmarks/bench_cli.py [--src PATH ...] [--runs 5] [--cold] [--no-pyc] [--json out.json]

Each measured call is a fresh ``python -m strapdown.cli`` process, timed from the outside (wall time, as a user
waits for it).  ``--src`` names a checkout's ``src`` folder to measure (repeatable; the first is this checkout's
by default), so that before and after come from the same run on the same machine: e.g. the branch point,
unpacked with ``git archive 0e1d9e9 src | tar -x -C /tmp/base``, then ``--src /tmp/base/src --src src``.  The
runs of the checkouts are interleaved (A, B, A, B, ...) so that a change of load hits them alike.  The machine
is shared and noisy: read the figures as medians next to each other, not as absolutes.

Warm cache: each checkout runs the command once, unmeasured, to fill its numba cache (``cache=True`` writes it
beside the sources) and Python's bytecode cache, then ``--runs`` times.  ``--cold`` also times one call of each
with an empty numba cache (``NUMBA_CACHE_DIR`` set to a fresh folder): what the first call after a fresh install
costs, when every kernel the command touches is compiled; and then ``python -m strapdown.apps.warmup`` on another
empty cache followed by one call (the documented warm-up step, and what the call costs after it).

Bytecode: ``pip install`` compiles every module to ``.pyc`` and Python writes them for a source checkout at
the first import, so a user's call reads bytecode.  Where ``PYTHONDONTWRITEBYTECODE`` is set (the development
machine sets it) every call would instead compile the package's sources again,
so the benchmark clears it for the measured processes.  ``--no-pyc`` measures that case: it deletes the
checkouts' own ``.pyc`` files (Python's bytecode cache of ``strapdown``, not numba's) and sets the variable, so
that every call compiles the package again while numpy, numba and the rest read their installed bytecode.

The floor: each run also times, with the last checkout, ``python -c "import numpy"`` and a process that imports
numba and loads one cached kernel (:data:`FLOORS`), with and without scipy importable: the part of every call
that is Python's, numpy's and numba's, to read the command's own share against.

The input: 200 rows at 100 Hz of a level, still IMU with gyro, accelerometer and magnetometer (t, gx..gz in
rad/s, ax..az in m/s², mx..mz in µT), written with numpy so that every checkout reads the same bytes.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent.parent


def write_csv(path: Path, n: int = 200) -> Path:
    rng = np.random.default_rng(0)
    t = np.arange(n) * 0.01
    gyro = rng.normal(0.0, 0.01, (n, 3))
    acc = rng.normal(0.0, 0.05, (n, 3)) + np.array([0.0, 0.0, 9.81])
    mag = np.tile([20.0, 0.0, -40.0], (n, 1)) + rng.normal(0.0, 0.5, (n, 3))
    header = "t,gx,gy,gz,ax,ay,az,mx,my,mz"
    np.savetxt(path, np.column_stack([t, gyro, acc, mag]), delimiter=",", header=header, comments="", fmt="%.9g")
    return path


#: The floor under any call, measured in the same run with the last checkout: what every ``strapdown estimate``
#: pays before it does anything of its own (Python with numpy; then numba imported and one cached kernel loaded,
#: the first of a process, which loads numba's registries), with garbage collection as the program has it
#: (paused while it starts, then what exists frozen: ``strapdown.cli._run.PausedCollection``).  "no scipy"
#: makes scipy unimportable in that process only, as for a user without it: numba then skips its BLAS check,
#: which imports scipy.linalg when it is there.  "gc as usual" is "numba" with the collector left alone: the
#: difference is the collections over numba's objects, while it loads and at the interpreter's exit.
_ONE_KERNEL = "import numpy as np; from strapdown import from_matrix; from_matrix(np.eye(3))"
FLOORS = {
    "numpy": "import numpy",
    "numba": f"import gc; gc.disable(); {_ONE_KERNEL}; gc.freeze(); gc.enable()",
    "no scipy": f"import gc, sys; sys.modules['scipy'] = None; gc.disable(); {_ONE_KERNEL}; gc.freeze(); gc.enable()",
    "gc usual": _ONE_KERNEL,
}


def timed(
    src: str, args: list[str], env_extra: dict | None = None, cwd: str | None = None, output: list | None = None
) -> tuple[float, float]:
    """(wall seconds, CPU seconds: user + system of the child) of one call of ``python *args``.

    ``output``, when given, receives the call's standard output.
    """
    env = dict(os.environ, PYTHONPATH=src, **(env_extra or {}))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    res = subprocess.run([sys.executable, *args], env=env, cwd=cwd, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if res.returncode != 0:
        raise SystemExit(f"python {' '.join(args)} failed with {src}:\n{res.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if output is not None:
        output.append(res.stdout)
    return seconds, cpu


def summary(runs: list[tuple[float, float]]) -> str:
    """Median, least and most wall time and median CPU time of some calls, as one line of the table."""
    wall, cpu = [w for w, _ in runs], [c for _, c in runs]
    return f"{statistics.median(wall):8.3f} {min(wall):6.3f} {max(wall):6.3f} {statistics.median(cpu):8.3f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--src", action="append", help="A checkout's src folder (repeatable; default: ./src).")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--cold", action="store_true", help="Also time one call with an empty numba cache.")
    parser.add_argument("--no-pyc", action="store_true", help="Compile the package every call (see above).")
    parser.add_argument("--json", help="Write the figures here.")
    a = parser.parse_args()
    if not a.no_pyc:  # the measured processes (children) inherit this environment
        os.environ.pop("PYTHONDONTWRITEBYTECODE", None)
    else:
        os.environ["PYTHONDONTWRITEBYTECODE"] = "1"
        for src in a.src or [str(HERE / "src")]:
            for pyc in (Path(src) / "strapdown").rglob("*.pyc"):
                pyc.unlink()
    load_start = os.getloadavg()[0]
    sources = [str(Path(s).resolve()) for s in (a.src or [str(HERE / "src")])]
    with tempfile.TemporaryDirectory() as tmp:
        log = write_csv(Path(tmp) / "log200.csv")
        cli = ["-m", "strapdown.cli"]
        calls = {
            "help": [*cli, "--help"],
            "estimate": [*cli, "estimate", str(log), "-o", str(Path(tmp) / "out.csv"), "-q"],
        }
        for src in sources:  # fill each checkout's numba cache
            timed(src, calls["estimate"])
        times = {src: {name: [] for name in calls} for src in sources}
        floors = {name: [] for name in FLOORS}
        for _ in range(a.runs):
            for name, args in calls.items():
                for src in sources:
                    times[src][name].append(timed(src, args))
            for name, code in FLOORS.items():
                floors[name].append(timed(sources[-1], ["-c", code]))
        cold, warmed, compiled = {}, {}, {}
        if a.cold:
            # numba says what it saves to the cache (NUMBA_DEBUG_CACHE): the kernels a call had to compile
            for src in sources:
                log = []
                with tempfile.TemporaryDirectory() as cache:
                    env = {"NUMBA_CACHE_DIR": cache, "NUMBA_DEBUG_CACHE": "1"}
                    cold[src] = timed(src, calls["estimate"], env, output=log)
                with tempfile.TemporaryDirectory() as cache:
                    step = timed(src, ["-m", "strapdown.apps.warmup", "--quiet"], {"NUMBA_CACHE_DIR": cache})
                    env = {"NUMBA_CACHE_DIR": cache, "NUMBA_DEBUG_CACHE": "1"}
                    warmed[src] = (step, timed(src, calls["estimate"], env, output=log))
                compiled[src] = [text.count("data saved") for text in log]  # cold, after the warm-up
    load = os.getloadavg()[0]
    bytecode = "compiled every call (--no-pyc)" if a.no_pyc else "read from .pyc, as after pip install"
    print(f"load average {load_start:.1f} at the start, {load:.1f} at the end, on {os.cpu_count()} cores")
    print(f"seconds of one call, {a.runs} runs each; the package's modules {bytecode}")
    print("wall: what a user waits (grows with the load); cpu: user + system time of the process (less so)")
    print(f"{'checkout':48} {'call':9} {'wall med':>8} {'min':>6} {'max':>6} {'cpu med':>8}")
    for src in sources:
        for name in calls:
            print(f"{src[-48:]:48} {name:9} {summary(times[src][name])}")
        if src in cold:
            step, after = warmed[src]
            for name, (w, c), what in (
                ("cold", cold[src], f"estimate, empty numba cache: {compiled[src][0]} kernels compiled"),
                ("warmup", step, "python -m strapdown.apps.warmup, empty numba cache"),
                ("after it", after, f"estimate after it: {compiled[src][1]} kernels compiled"),
            ):
                print(f"{src[-48:]:48} {name:9} {w:8.3f} {'':6} {'':6} {c:8.3f}   ({what})")
    print("the floor, with the last checkout: python -c ...")
    for name, what in (
        ("numpy", "import numpy"),
        ("numba", "and numba, one cached kernel"),
        ("no scipy", "the same, scipy unimportable"),
        ("gc usual", "the same, garbage collection as usual"),
    ):
        print(f"{what:48} {name:9} {summary(floors[name])}")
    if len(sources) > 1:
        base, new = sources[0], sources[-1]
        for name in calls:
            for k, what in ((0, "wall"), (1, "cpu")):
                b = statistics.median([x[k] for x in times[base][name]])
                n = statistics.median([x[k] for x in times[new][name]])
                print(f"{name} {what}: last / first checkout = {n / b:.2f}")
    if a.json:
        out = {"load": [load_start, load], "runs": a.runs, "pyc": not a.no_pyc, "times": times, "cold": cold}
        out.update(warmup=warmed, compiled_after_warmup=compiled, floors=floors)
        Path(a.json).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
