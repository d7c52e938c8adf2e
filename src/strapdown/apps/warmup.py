"""Compile strapdown's numba kernels now instead of at their first call: ``python -m strapdown.apps.warmup``.

numba compiles each kernel lazily, for the argument types of its first call, and caches the machine code on
disk (``cache=True``; one folder per version of the kernels, :mod:`strapdown._support.kernel_cache`).  The
first call of a function after an install therefore pays the compilation (seconds for the estimator;
docs/guide/performance.md has the measured figures) and every later process only loads the cache.  Running
this module once after installing moves that cost to the install: it calls the common entry points on a few
samples in float64 and float32, so that every kernel they use is compiled and cached.  The
cache is specific to the CPU and to the installed source files, so it is made on the machine that uses it (a
wheel cannot ship it).

    python -m strapdown.apps.warmup            # integrate, the conversions, the estimators, the file columns
    python -m strapdown.apps.warmup --quiet
    python -m strapdown.apps.warmup estimators conversions files    # what ``strapdown estimate`` uses
    strapdown warmup                      # the same from the command line (the ``cli`` extra)

``strapdown estimate`` needs the ``estimators``, ``conversions`` and ``files`` tasks (the filter's kernels, the
initial attitude's conversions, and the output's quaternion and Euler columns); ``strapdown integrate`` needs
``integrate`` and ``files``.
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable

import numpy as np

__all__ = ["FIRST_RUN", "TASKS", "compiling_notice", "warmup"]


def _integrate(dtype) -> None:
    from ..propagate.integrate import integrate

    rng = np.random.default_rng(0)
    g = rng.standard_normal((300, 3)).astype(dtype)
    for method in ("exact", "first-order", "rk4", "coning2"):
        integrate(g, 0.01, method=method, parallel=False)
    for threads in (1, 2):  # the scan's serial and parallel builds
        integrate(g, 0.01, parallel=True, threads=threads)


def _conversions(dtype) -> None:
    from ..rotations.euler import as_euler, from_euler
    from ..rotations.matrix import as_matrix, from_matrix
    from ..rotations.quaternion import multiply
    from ..rotations.rotvec import as_rotvec, from_rotvec

    q = np.random.default_rng(1).standard_normal((64, 4)).astype(dtype)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    for seq in ("ZYX", "ZXZ"):
        from_euler(as_euler(q, seq), seq)
    from_matrix(as_matrix(q))
    from_rotvec(as_rotvec(q))
    multiply(q, q)


def _estimators(dtype) -> None:
    from ..fusion.registry import ESTIMATORS

    n = 50
    t = np.arange(n) * 0.01
    gyro = np.zeros((n, 3), dtype)
    acc = np.tile(np.array([0.0, 0.0, 9.81], dtype), (n, 1))
    mag = np.tile(np.array([20.0, 0.0, -40.0], dtype), (n, 1))
    for cls, _, takes_mag in ESTIMATORS.values():
        try:
            est = cls()
            est.update(gyro, acc, mag if takes_mag else None, t=t)
        except (TypeError, ValueError):  # an estimator with other inputs: its kernels compile at first use
            continue


def _files(dtype) -> None:
    """The file commands' output columns (io.tables.attitude_columns' kernel), float64 and --float32 output."""
    from ..io.tables import OutputSpec, attitude_columns

    if dtype != np.float64:  # the pipeline's attitudes are float64 whatever the file holds
        return
    q = np.tile([1.0, 0.0, 0.0, 0.0], (8, 1))
    for float32 in (False, True):
        attitude_columns(np.arange(8.0), q, OutputSpec(float32=float32), check=False)


#: (name, function of the dtype) run by :func:`warmup`.
TASKS: list[tuple[str, Callable]] = [
    ("integrate", _integrate),
    ("conversions", _conversions),
    ("estimators", _estimators),
    ("files", _files),
]


def warmup(dtypes=(np.float64, np.float32), quiet: bool = True, tasks=None) -> dict[str, float]:
    """Compile (or load from the cache) the kernels of the common entry points.

    Parameters
    ----------
    dtypes : sequence of dtype
        The input types to compile for.
    quiet : bool
        Do not print each task's time.
    tasks : sequence of str, optional
        Names of :data:`TASKS` to run (default: all of them).

    Returns
    -------
    dict
        Seconds per task and dtype, e.g. ``{"integrate float64": 12.3, ...}``.
    """
    known = dict(TASKS)
    chosen = list(known) if tasks is None else list(tasks)
    unknown = [t for t in chosen if t not in known]
    if unknown:
        raise ValueError(f"unknown warm-up task(s) {', '.join(map(repr, unknown))}; the tasks: {', '.join(known)}")
    times = {}
    before = os.environ.get("STRAPDOWN_UNCOMPILED")
    os.environ["STRAPDOWN_UNCOMPILED"] = "never"  # compile here: no short call run uncompiled (_support/uncompiled)
    try:
        for name in chosen:
            task = known[name]
            for dtype in dtypes:
                t0 = time.perf_counter()
                task(dtype)
                key = f"{name} {np.dtype(dtype).name}"
                times[key] = time.perf_counter() - t0
                if not quiet:
                    print(f"{key:24s} {times[key]:7.2f} s", flush=True)
    finally:
        if before is None:
            os.environ.pop("STRAPDOWN_UNCOMPILED")
        else:
            os.environ["STRAPDOWN_UNCOMPILED"] = before
    return times


def main(argv=None) -> int:
    """Command-line entry: ``python -m strapdown.apps.warmup [TASK ...] [--quiet]``."""
    ap = argparse.ArgumentParser(prog="python -m strapdown.apps.warmup", description=__doc__.split("\n\n")[0])
    names = ", ".join(name for name, _ in TASKS)
    ap.add_argument("tasks", nargs="*", metavar="TASK", help=f"some of {names} (default: all)")
    ap.add_argument("--quiet", action="store_true", help="print nothing")
    args = ap.parse_args(argv)
    try:
        times = warmup(quiet=args.quiet, tasks=args.tasks or None)
    except ValueError as exc:
        ap.error(str(exc))
    if not args.quiet:
        print(f"{'total':24s} {sum(times.values()):7.2f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())


#: What the first run of a command compiles, by need: (what to call it, its kernels as (module file, function),
#: and the seconds its compilation took on the reference machine, an idle 2-core AMD EPYC VM; benchmarks/
#: bench_coldstart.py measures them).  The command line says so before it starts (:func:`compiling_notice`).
FIRST_RUN = {
    "estimator:attitude": ("the attitude estimator", [("fusion/_attitude_numba.py", "run")], 12),
    "estimator:tilt": ("the tilt estimator", [("fusion/_tilt_numba.py", "run")], 4),
    "estimator:mahony": ("the Mahony filter", [("fusion/_mahony_numba.py", "run")], 2),
    "estimator:madgwick": ("the Madgwick filter", [("fusion/_madgwick_numba.py", "run")], 2),
    "estimator:complementary": ("the complementary filter", [("fusion/_complementary_numba.py", "run")], 2),
    "integrate": (
        "the integrator",
        [("propagate/_integrate_numba.py", "sequential"), ("propagate/_integrate_numba.py", "scan_serial")],
        12,
    ),
    "files": ("the output columns", [("io/_columns_numba.py", "quat_euler_columns")], 2),
}


def compiling_notice(needs) -> str | None:
    """The line to say before a run that will compile kernels for this machine, or None when all are compiled.

    Parameters
    ----------
    needs : iterable of str
        Keys of :data:`FIRST_RUN` (``"estimator:attitude"``, ``"files"``).

    Returns
    -------
    str or None
        E.g. ``"compiling the attitude estimator for this machine, once: about 12 s, in the background ..."``.

    Examples
    --------
    >>> from strapdown.apps.warmup import compiling_notice
    >>> compiling_notice([]) is None
    True
    """
    from .._support import kernel_cache

    missing = [FIRST_RUN[key] for key in needs if not all(kernel_cache.cached(f, k) for f, k in FIRST_RUN[key][1])]
    if not missing:
        return None
    names = " and ".join(what for what, _, _ in missing)
    seconds = sum(s for _, _, s in missing)
    return (
        f"compiling {names} for this machine, once: about {seconds} s, in the background while a short input "
        "runs uncompiled (later runs start at once; `strapdown warmup` compiles every kernel ahead)"
    )
