"""A kernel run as plain Python while numba has not compiled it yet, and compiled meanwhile in the background (private).

numba compiles a kernel at its first call, for that call's argument types: the attitude estimator's takes about
12 s (docs/guide/performance.md), which a first ``update`` on a thousand samples would spend before computing for
a millisecond.  A numba kernel is a Python function (``dispatcher.py_func``) that numba translates; run as
written, with every kernel it calls run as written too, it computes the same numbers, only slower (23-40 µs a
sample for the estimator, against a few tens of nanoseconds compiled).  So :func:`call`, for a call whose
kernel is compiled neither in this process nor in the kernel cache (:mod:`.kernel_cache`), and whose uncompiled
run is short (under :data:`BUDGET_S`, from the caller's estimate), runs the Python *twin* instead and starts one
background process that compiles the kernel for these argument types into the cache; a later call, in this
process or another, loads it from there.  A long input is not worth running uncompiled: the kernel is compiled
at once, as before.

The twin is the same code, so it gives the same numbers: the tests compare the two on every estimator path
(they agree to the last bits but for the fused multiply-adds numba may contract).  Where the two languages
differ (Python raises on a division by zero or ``math.sqrt(-1)``, numba returns inf or nan; Python checks
indices), the twin's exception sends the call to the compiled kernel after restoring every array argument, so
that the result is always the compiled kernel's.

Two environment variables (read at each call):

* ``STRAPDOWN_UNCOMPILED``: ``auto`` (default, as above), ``never`` (always compile), or ``always`` (the twin
  whatever the cache holds: the tests' way of checking the twins);
* ``STRAPDOWN_BACKGROUND_COMPILE``: ``0`` starts no background process (the test suite's setting; then the first
  long call compiles).
"""

from __future__ import annotations

import base64
import hashlib
import os
import pickle
import subprocess
import sys
import time
import types
from pathlib import Path

import numpy as np

from . import kernel_cache

__all__ = ["BUDGET_S", "call", "compile_later", "fallbacks", "twin", "wait_for_background"]

#: The longest uncompiled run :func:`call` chooses over compiling (seconds, from the caller's estimate).
BUDGET_S = 2.0
_MODES = ("auto", "never", "always")
_STALE_LOCK_S = 600.0  # a background compile that has not finished in 10 minutes has died

_twins: dict[int, types.FunctionType] = {}
_globals_twins: dict[int, dict] = {}
_started: set[str] = set()
#: How many twin runs fell back to the compiled kernel in this process (the tests check it stays 0).
fallbacks = [0]


def _is_kernel(obj) -> bool:
    from numba.core.dispatcher import Dispatcher  # numba is imported by every kernel module already

    return isinstance(obj, Dispatcher)


def twin(kernel) -> types.FunctionType:
    """The kernel's Python function, calling the twins of the kernels it calls.

    Parameters
    ----------
    kernel : numba dispatcher
        A kernel (``@numba.njit``).

    Returns
    -------
    function
        Its ``py_func`` bound to a copy of its module's globals in which every kernel is replaced by its twin
        (made once per kernel and module).

    Examples
    --------
    >>> import numba, numpy as np
    >>> @numba.njit
    ... def square(x):
    ...     return x * x
    >>> @numba.njit
    ... def sum_squares(v):
    ...     return sum([square(x) for x in v])
    >>> twin(sum_squares)(np.arange(4.0)), sum_squares.signatures  # nothing compiled
    (np.float64(14.0), [])
    """
    key = id(kernel)
    if key not in _twins:
        f = kernel.py_func
        closure = f.__closure__
        if closure is not None:
            closure = tuple(types.CellType(_twin_of(c.cell_contents)) for c in closure)
        _twins[key] = types.FunctionType(f.__code__, _globals_of(f.__globals__), f.__name__, f.__defaults__, closure)
    return _twins[key]


def _twin_of(obj):
    return twin(obj) if _is_kernel(obj) else obj


def _globals_of(module_globals: dict) -> dict:
    key = id(module_globals)
    if key not in _globals_twins:
        new = dict(module_globals)
        _globals_twins[key] = new  # before the kernels' twins, which may come back to this module
        for name, value in module_globals.items():
            if _is_kernel(value):
                new[name] = twin(value)
    return _globals_twins[key]


def _signature(kernel, args) -> tuple:
    return tuple(kernel.typeof_pyval(a) for a in args)


def _compiled(kernel, sig) -> bool:
    """Whether numba would not compile for ``sig``: compiled in this process, or in the cache for this machine."""
    cache = getattr(kernel, "_cache", None)
    try:
        index = cache._cache_file._load_index()
        return cache._index_key(sig, kernel.targetctx.codegen()) in index
    except Exception:  # a kernel without a cache, or numba's internals changed: not known
        return cache is not None and type(cache).__name__ != "NullCache"  # unsure: let numba decide


def call(kernel, *args, python_seconds: float):
    """``kernel(*args)``, or its uncompiled twin (module notes) when the kernel is not compiled and the run is short.

    Parameters
    ----------
    kernel : numba dispatcher
        The kernel.
    *args
        Its arguments (positional, as the kernel takes them).
    python_seconds : float
        The caller's estimate of the uncompiled run's time, e.g. the samples times the twin's measured cost per
        sample.

    Returns
    -------
    object
        What the kernel returns.  Array arguments are written as the compiled kernel writes them.
    """
    mode = os.environ.get("STRAPDOWN_UNCOMPILED", "auto")
    if mode not in _MODES:
        raise ValueError(f"STRAPDOWN_UNCOMPILED must be one of {', '.join(_MODES)}; the environment says {mode!r}")
    if mode == "never":
        return kernel(*args)
    if mode != "always":
        # once compiled in this process for some types, numba's dispatch is the fast path (another type compiles)
        if kernel.overloads or python_seconds > BUDGET_S:
            return kernel(*args)
        sig = _signature(kernel, args)
        if _compiled(kernel, sig):
            return kernel(*args)
        _compile_in_background(kernel, sig)
    saved = [(a, a.copy()) for a in args if isinstance(a, np.ndarray) and a.flags.writeable]
    try:
        with np.errstate(all="ignore"):
            return twin(kernel)(*args)
    except Exception:  # Python's rules where numba's differ (module notes)
        fallbacks[0] += 1
        for a, before in saved:
            a[...] = before
        return kernel(*args)


def compile_later(kernel, *args) -> None:
    """Queue ``kernel`` for these arguments' types for the background worker, unless it is compiled or cached.

    For a kernel that this call did not need but the next may: the serial and parallel builds of a scan, of
    which the thread policy picks one by the load of the moment, so that a second process that picks the other
    does not compile it (benchmarks/bench_coldstart.py counts a second process's compilations).
    """
    if kernel.overloads or os.environ.get("STRAPDOWN_BACKGROUND_COMPILE", "1") == "0":
        return
    sig = _signature(kernel, args)
    if not _compiled(kernel, sig):
        _compile_in_background(kernel, sig)


# The background worker: compiles the queued kernels one after another (``*.job`` files, oldest first), then
# leaves; a job queued while it removes its lock is taken by the worker the next call starts.
_WORKER = """
import base64, importlib, os, pickle, sys, time
from pathlib import Path
if hasattr(os, "nice"):
    os.nice(19)  # the lowest priority: it yields the cores to the work at hand
where = Path(sys.argv[1])
lock = where / "worker.lock"
while True:
    jobs = sorted(where.glob("*.job"), key=lambda p: p.stat().st_mtime)
    if not jobs:
        break
    for job in jobs:
        try:
            module, name, sig = job.read_text().split()
            os.utime(lock)
            getattr(importlib.import_module(module), name).compile(pickle.loads(base64.b64decode(sig)))
        except Exception:
            pass
        finally:
            job.unlink(missing_ok=True)
lock.unlink(missing_ok=True)
"""


def _queue() -> Path:
    return kernel_cache.folder() / "compiling"


def _compile_in_background(kernel, sig) -> None:
    """Queue ``kernel`` for ``sig`` for the background worker, and start the worker unless one runs (module notes)."""
    if os.environ.get("STRAPDOWN_BACKGROUND_COMPILE", "1") == "0":
        return
    f = kernel.py_func
    blob = base64.b64encode(pickle.dumps(sig)).decode()
    key = hashlib.sha256(f"{f.__module__}.{f.__qualname__} {blob}".encode()).hexdigest()[:24]
    if key in _started:
        return
    _started.add(key)
    where = _queue()
    try:
        where.mkdir(parents=True, exist_ok=True)
        job = where / f"{key}.job"
        if not job.exists():
            tmp = where / f"{key}.{os.getpid()}.tmp"
            tmp.write_text(f"{f.__module__} {f.__name__} {blob}")
            os.replace(tmp, job)
        lock = where / "worker.lock"
        if lock.exists() and time.time() - lock.stat().st_mtime > _STALE_LOCK_S:
            lock.unlink(missing_ok=True)  # a worker that died
        os.close(os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except OSError:
        return  # a worker runs and will take the job, or the cache cannot be written (numba could not keep it)
    env = dict(os.environ)
    package_parent = str(Path(kernel_cache.PACKAGE).parent)  # the worker imports this very strapdown
    env["PYTHONPATH"] = os.pathsep.join([package_parent, *filter(None, [env.get("PYTHONPATH")])])
    try:
        subprocess.Popen(
            [sys.executable, "-c", _WORKER, str(where)],
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=os.name == "posix",  # it outlives a command that has finished before it
        )
    except OSError:
        lock.unlink(missing_ok=True)


def wait_for_background(timeout: float = 600.0) -> bool:
    """Wait until the background worker has compiled every queued kernel (benchmarks/bench_coldstart.py, the tests).

    Parameters
    ----------
    timeout : float
        Seconds to wait at most.

    Returns
    -------
    bool
        True when no job is queued and no worker runs.
    """
    end = time.monotonic() + timeout
    where = _queue()
    while any(where.glob("*.job")) or (where / "worker.lock").exists():
        if time.monotonic() > end:
            return False
        time.sleep(0.2)
    return True
