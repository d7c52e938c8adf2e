"""How many threads a parallel kernel gets: the policy that keeps threads from losing to one core (private).

A parallel prefix scan synchronises its threads once per tile of samples.  When the cores are busy with other
processes, a thread that the scheduler has set aside holds every other thread at the next barrier for a whole
time slice, and with numba's default OpenMP layer the waiting threads spin and so take that time from the busy
processes too: on the 2-core machine ``integrate`` on 10^7 samples ran at 4.9 M samples/s on two threads under
two busy processes, against 29.7 M/s on one (issue 15).  The policy below therefore decides per call, in this
order:

1. ``threads=`` given to the call (a positive int), else
2. the ``STRAPDOWN_THREADS`` environment variable (a positive int, or ``auto``), else
3. ``auto``: the cores this process may run on (``os.sched_getaffinity``) less the tasks that are running on
   them now (the instantaneous run-queue length, field 4 of ``/proc/loadavg``, read three times and the largest
   kept, less this thread), at least 1.  Where ``/proc/loadavg`` does not exist the one-minute load average
   (``os.getloadavg``) stands in; where neither does, every core counts as free.

The result is capped by ``numba.get_num_threads()`` (so ``numba.set_num_threads`` and ``NUMBA_NUM_THREADS``
still limit it) and by the size: each thread must get at least :data:`MIN_SAMPLES_PER_THREAD` samples, below
which waking it costs more than it saves.  One thread means the serial build of the same kernel: no thread
pool is touched at all.

4. A quick measure when the run queue says busy (auto mode only, :func:`run`): the run queue cannot tell
   whether more threads would still win, and on an oversubscribed machine they sometimes do (the scheduler
   shares time per thread), sometimes lose.  So a long call times its first :data:`PROBE_SAMPLES` samples
   on the count above and the next ones on every core, and finishes on every core only if that was clearly
   faster (:data:`PROBE_MARGIN`); a verdict serves later short calls for :data:`PROBE_VALID_S` seconds.  The
   worse setting costs at most one probe.  No probe runs where the scheduler's share of time could not give
   more threads that margin (two cores beside one or two busy processes: one thread, no probe).

Results never depend on the thread count: the kernels split the work into a fixed number of blocks (a
function of the size alone) and the threads only share out the blocks, so ``threads=1`` and ``threads=8``
give bit-identical attitudes.

Threading layer.  numba picks its layer at the first parallel launch (TBB if its library loads, else OpenMP,
else its own workqueue), and the choice is then fixed for the process.  Unless the user chose one
(``NUMBA_THREADING_LAYER``), :func:`prepare_layer` runs before strapdown's first parallel kernel and sets
``OMP_WAIT_POLICY=PASSIVE`` (unless already set): GNU OpenMP's workers then sleep between parallel regions
instead of spinning, which on a busy machine is time taken from other processes (and, at the barriers, from
our own threads).  TBB and OpenMP both stay safe when several Python threads call kernels at once, which
numba's workqueue layer is not; it is therefore not forced.  Only one strapdown parallel kernel runs at a
time in a process: a second Python thread that arrives meanwhile runs the serial build instead of
oversubscribing the cores.

Dask and process pools.  :func:`strapdown.batch.run_batch` runs one file per worker process; the parallelism
is across files, so each job runs with one numba thread (:func:`worker_default`) unless ``threads=`` or
``STRAPDOWN_THREADS`` says otherwise (set it in the workers' environment to change that).
"""

from __future__ import annotations

import math
import numbers
import os
import threading
import time
from contextlib import contextmanager

__all__ = [
    "ENV",
    "MIN_SAMPLES_PER_THREAD",
    "PROBE_MARGIN",
    "PROBE_SAMPLES",
    "choose",
    "claim",
    "free_cores",
    "parse",
    "prepare_layer",
    "run",
    "worker_default",
]

ENV = "STRAPDOWN_THREADS"

#: Samples below which one more thread cannot pay for its wake-up and the barrier per tile (a wake-up
#: on a sleeping OpenMP worker is tens of microseconds; 2^16 samples take about 1 ms on one core).
MIN_SAMPLES_PER_THREAD = 1 << 16

#: Samples in each probe of :func:`run` (four tiles of the scan: about 5 ms on one core).
PROBE_SAMPLES = 1 << 18
#: Seconds a probe's verdict is reused by calls too short to probe (the chunks of a file pipeline).
PROBE_VALID_S = 2.0
#: More threads win the probe only when they took less than this fraction of the time of the run-queue's
#: count.  A probe is a few milliseconds, about one time slice: it sees the larger share of CPU time that more
#: threads get from the scheduler (at most 1.5x for two threads against two busy processes on two cores), but
#: not what a long call then loses at the barriers when one of its threads is set aside.  On the 2-core
#: machine under two busy processes, 10^7 samples took 1.2x the one-thread time after a 2-thread verdict with
#: a margin of 0.8; with 0.6 more threads are taken only for a gain that a long call keeps.
PROBE_MARGIN = 0.6

_verdict = [1, -math.inf]  # threads, and the clock time until which that verdict stands
_LOCK = threading.Lock()  # held while a parallel kernel runs: one at a time per process
_local = threading.local()
_layer_ready = False


def parse(value, name: str = ENV) -> int | None:
    """A thread setting as a count, or None for ``auto``.

    Parameters
    ----------
    value : int, str or None
        A positive integer, ``"auto"`` (any case), None or ``""`` (auto).
    name : str
        What to name in the error message.

    Returns
    -------
    int or None
        The count, or None to let the policy decide.

    Examples
    --------
    >>> from strapdown._threads import parse
    >>> parse("4"), parse(" auto "), parse(None), parse(2)
    (4, None, None, 2)
    """
    if value is None:
        return None
    if isinstance(value, str):
        text = value.strip().lower()
        if text in ("", "auto"):
            return None
        try:
            value = int(text, 10)
        except ValueError:
            raise ValueError(f"{name} must be a positive integer or 'auto', got {value!r}") from None
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
        raise ValueError(f"{name} must be a positive integer or 'auto', got {value!r}")
    return int(value)


def _cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def _running_others() -> float | None:
    """Tasks running or runnable now besides this one, or None where the system does not say."""
    try:
        seen = 0
        for _ in range(3):  # a snapshot: a busy process may be between time slices in one of them
            with open("/proc/loadavg", "rb") as f:
                seen = max(seen, int(f.read().split()[3].split(b"/")[0]))
        return max(seen - 1, 0)
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):
        return None


def free_cores(cores: int | None = None, others: float | None = None) -> int:
    """Cores free for this process: ``cores - others`` rounded to the nearest integer, at least 1.

    Parameters
    ----------
    cores : int, optional
        Cores this process may use (default: its CPU affinity).
    others : float, optional
        Tasks running besides this one (default: read from the system, see the module notes).

    Returns
    -------
    int
        At least 1, at most ``cores``.

    Examples
    --------
    >>> from strapdown._threads import free_cores
    >>> free_cores(4, 1), free_cores(2, 2), free_cores(2, 0.0)
    (3, 1, 2)
    """
    cores = _cores() if cores is None else cores
    if others is None:
        others = _running_others()
    if others is None:
        return max(cores, 1)
    return int(min(max(round(cores - others), 1), cores))


def choose(n: int, threads=None, *, available: int | None = None) -> int:
    """Threads for a kernel on n samples: the module's policy.

    Parameters
    ----------
    n : int
        Samples the kernel will process.
    threads : int or str, optional
        The caller's ``threads=`` (a positive integer or ``"auto"``); None defers to ``STRAPDOWN_THREADS``.
    available : int, optional
        The thread count allowed before the size cap (default: :func:`free_cores` in auto mode, else the
        setting), capped by ``numba.get_num_threads()``.

    Returns
    -------
    int
        Between 1 and ``numba.get_num_threads()``.

    Examples
    --------
    >>> from strapdown._threads import MIN_SAMPLES_PER_THREAD, choose
    >>> choose(1000, 8), choose(10 * MIN_SAMPLES_PER_THREAD, 1)
    (1, 1)
    """
    count = _setting(threads)
    if available is None:
        available = free_cores() if count is None else count
    by_size = max(n // MIN_SAMPLES_PER_THREAD, 1)
    if min(available, by_size) <= 1:
        return 1  # decided without numba.get_num_threads(), which would start the thread pool for nothing
    import numba

    prepare_layer()  # numba.get_num_threads() starts the thread pool, and with it the layer
    return int(max(1, min(available, numba.get_num_threads(), by_size)))


def _setting(threads) -> int | None:
    """The thread count the caller, the environment or a batch worker asks for; None for the policy."""
    if threads is not None:
        return parse(threads, "threads")
    if os.environ.get(ENV, "").strip():
        return parse(os.environ[ENV])
    return getattr(_local, "default", None)  # a batch worker's default (worker_default), else auto


def run(n: int, threads, part, *, clock=time.perf_counter) -> None:
    """Process n samples as ``part(t, lo, hi)`` (t threads on samples lo..hi), the count chosen by the policy.

    With a setting (``threads=``, ``STRAPDOWN_THREADS``, a batch worker), or when the run queue shows every
    useful core free, this is one call with :func:`choose`'s count.  On a machine the run queue calls busy,
    auto mode measures instead of guessing: the first :data:`PROBE_SAMPLES` on :func:`choose`'s count (one
    thread), the next on every core, and the rest on every core only if those were clearly faster (the quick
    measure of the module notes); the verdict serves later calls too short to probe for :data:`PROBE_VALID_S`
    seconds.  The pieces start at multiples of PROBE_SAMPLES, a multiple of the scan's tile, so the result has
    the same bits as one call, whatever the verdict.

    Parameters
    ----------
    n : int
        Samples.
    threads : int, str or None
        The caller's ``threads=``.
    part : callable
        ``part(t, lo, hi)`` processes samples [lo, hi) on t threads, in order (each piece continues the last).
    clock : callable
        Seconds (for tests).
    """
    chosen = choose(n, threads)
    most = chosen
    if _setting(threads) is None and chosen < _cores() and n >= 2 * MIN_SAMPLES_PER_THREAD:
        import numba

        prepare_layer()
        most = max(1, min(_cores(), numba.get_num_threads(), n // MIN_SAMPLES_PER_THREAD))
    if most <= chosen:  # told, or every useful core is free: nothing to measure
        with claim(chosen) as t:
            part(t, 0, n)
        return
    now = clock()
    if n < 3 * PROBE_SAMPLES:  # too short to probe: the last verdict while it is fresh
        with claim(_verdict[0] if now < _verdict[1] else chosen) as t:
            part(t, 0, n)
        return
    if not _could_win(chosen, most):  # the probe would only cost
        with claim(chosen) as t:
            part(t, 0, n)
        return
    times = []
    for count, lo in ((chosen, 0), (most, PROBE_SAMPLES)):
        with claim(count) as t:
            start = clock()
            part(t, lo, lo + PROBE_SAMPLES)
            times.append((clock() - start, t))
    (t_few, few), (t_most, many) = times
    best = many if t_most < PROBE_MARGIN * t_few else few
    with claim(best) as t:
        part(t, 2 * PROBE_SAMPLES, n)
    _verdict[:] = [best, clock() + PROBE_VALID_S]  # from the end of this call


def _share(threads: int, others: float, cores: int) -> float:
    """Cores' worth of CPU time the scheduler gives `threads` threads beside `others` running tasks."""
    if threads + others <= cores:
        return float(threads)
    return cores * threads / (threads + others)


def _could_win(chosen: int, most: int) -> bool:
    """Whether `most` threads could win the probe against `chosen` (PROBE_MARGIN) by their share of CPU time.

    The scheduler shares the cores per task, so more threads get more time beside busy processes, but at most
    in the ratio of :func:`_share`; when even that cannot beat the margin, the probe would only cost.  On two
    cores beside one or two busy processes it cannot (1.33x, 1.5x), beside eight it can (1.8x).  Where the
    system does not say what runs, the probe decides.
    """
    others = _running_others()
    if others is None:
        return True
    cores = _cores()
    return _share(most, others, cores) * PROBE_MARGIN > _share(chosen, others, cores)


@contextmanager
def worker_default(count: int | None):
    """Within the block, on this thread: ``count`` threads where neither ``threads=`` nor the environment says.

    :mod:`strapdown.batch` runs each job in ``worker_default(1)``: with one file per worker the cores are
    already shared out across files, and numba threads in every worker would oversubscribe them.

    Examples
    --------
    >>> from strapdown._threads import choose, worker_default
    >>> with worker_default(1):
    ...     choose(10**8)
    1
    """
    previous = getattr(_local, "default", None)
    _local.default = parse(count, "count")
    try:
        yield
    finally:
        _local.default = previous


def prepare_layer() -> None:
    """Before the first parallel kernel: keep OpenMP's idle workers asleep unless the user chose a layer."""
    global _layer_ready
    if _layer_ready:
        return
    import numba

    if not os.environ.get("NUMBA_THREADING_LAYER") and numba.config.THREADING_LAYER == "default":
        os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    _layer_ready = True


class claim:
    """Context manager: ``with claim(t) as t:`` gives t threads, or 1 when another thread runs a parallel kernel.

    While held, ``numba.set_num_threads(t)`` is in force for this thread; the previous value comes back on exit.
    """

    def __init__(self, threads: int):
        self.threads = threads
        self._held = False
        self._previous = None

    def __enter__(self) -> int:
        import numba

        threads = min(self.threads, numba.config.NUMBA_NUM_THREADS)
        if threads <= 1 or not _LOCK.acquire(blocking=False):
            return 1
        self._held = True
        prepare_layer()
        self._previous = numba.get_num_threads()
        numba.set_num_threads(threads)
        return threads

    def __exit__(self, *exc) -> None:
        if self._held:
            import numba

            numba.set_num_threads(self._previous)
            _LOCK.release()
