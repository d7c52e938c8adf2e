"""Follow a CSV file through ``strapdown.io.estimate_file``: how often the work moves between modules.

Two measures, both from ``sys.setprofile`` on a warm second call (everything imported and compiled first):

* **the datum's walk**: the calls that carry one gyro sample, a value planted in the file (an argument holds it,
  or an array inside an argument, two levels deep); the strapdown modules they run in, in order;
* **the whole walk**: every call of a strapdown function during the command.

Calls on every thread count (the file commands read ahead on a thread of their own).

A *stay* is a run of consecutive calls in one module on one thread, a *room* a distinct module, and a *return* a
stay in a room that thread already visited.  Fewer returns means a reader follows the data through fewer
files and back.  It runs on any commit that has ``strapdown.io.estimate_file`` and ``write_table`` (release 0.1
too), so the figure before a change is measured with this script on the older checkout.

    python benchmarks/walk_estimate.py          # the counts
    python benchmarks/walk_estimate.py -v       # and the datum's calls, module by module
"""

import pathlib
import sys
import tempfile
import threading

import numpy as np

from strapdown.io import estimate_file, write_table

MARK = 0.012345678901234  # the planted gyro sample (rad/s)


def _log(folder: pathlib.Path) -> pathlib.Path:
    n = 2000
    rng = np.random.default_rng(0)
    cols = {"t": np.arange(n) * 0.01}
    for a in "xyz":
        cols["gyro_" + a] = 0.001 * rng.standard_normal(n)
    cols["gyro_x"][n // 3] = MARK
    for a in "xyz":
        cols["acc_" + a] = (9.81 if a == "z" else 0.0) + 0.05 * rng.standard_normal(n)
    for i, a in enumerate("xyz"):
        cols["mag_" + a] = np.array([20.0, 0.0, -40.0])[i] + 0.1 * rng.standard_normal(n)
    return write_table(folder / "log.csv", cols)


def _holds(x, depth=0) -> bool:
    if isinstance(x, np.ndarray):
        return x.dtype.kind == "f" and x.size > 0 and bool(np.any(x == MARK))
    if depth >= 2:
        return False
    if isinstance(x, dict):
        return any(_holds(v, depth + 1) for v in x.values())
    if isinstance(x, list | tuple):
        return any(_holds(v, depth + 1) for v in x[:64])
    d = getattr(x, "__dict__", None)
    if isinstance(d, dict) and type(x).__module__.startswith("strapdown"):
        return any(_holds(v, depth + 1) for v in d.values())
    return False


def walk(path: pathlib.Path, out: pathlib.Path) -> tuple[list, list]:
    """(every call, the calls carrying the datum), each a list of (thread, module, function)."""
    every, datum = [], []

    def profile(frame, event, arg):
        if event != "call":
            return
        module = frame.f_globals.get("__name__", "")
        if not module.startswith("strapdown"):
            return
        code = frame.f_code
        here = threading.get_ident()
        every.append((here, module, code.co_name))
        names = code.co_varnames[: code.co_argcount + code.co_kwonlyargcount]
        if any(_holds(frame.f_locals.get(v)) for v in names):
            datum.append((here, module, code.co_name))

    # every thread: the file commands read the next chunks on a thread of their own (io/_ahead.py)
    threading.setprofile(profile)
    sys.setprofile(profile)
    try:
        estimate_file(path, out)
    finally:
        sys.setprofile(None)
        threading.setprofile(None)
    return every, datum


def stays(calls: list) -> tuple[int, int, int]:
    """(stays, rooms, returns) of a list of (thread, module, function) calls.

    Each thread's calls are a walk of their own (the reading thread's interleave with the main thread's at
    random); the stays and returns are summed over the threads, the rooms counted once.
    """
    total, returns, rooms = 0, 0, set()
    for thread in dict.fromkeys(t for t, _, _ in calls):
        mine = [m for t, m, _ in calls if t == thread]
        runs = [m for i, m in enumerate(mine) if i == 0 or mine[i - 1] != m]
        total += len(runs)
        returns += len(runs) - len(set(runs))
        rooms |= set(runs)
    return total, len(rooms), returns


def main() -> None:
    folder = pathlib.Path(tempfile.mkdtemp())
    path = _log(folder)
    estimate_file(path, folder / "warm.csv")  # imports and compiles everything first
    every, datum = walk(path, folder / "out.csv")
    for name, calls in (("the datum's walk", datum), ("the whole walk", every)):
        s, r, ret = stays(calls)
        print(f"{name:<18} {len(calls):5d} calls  {s:4d} stays  {r:3d} rooms  {ret:4d} returns")
    if "-v" in sys.argv:
        main = datum[0][0] if datum else None
        for thread, module, function in datum:
            print(f"  {'' if thread == main else '[reader] '}{module}.{function}")


if __name__ == "__main__":
    main()
