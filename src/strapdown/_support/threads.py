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

4. Measuring as it goes when the run queue says busy (auto mode only, :func:`run`): the run queue cannot tell
   whether more threads would still win, and that depends on the machine.  On the first 2-core machine of
   issue 15 two threads beside two busy processes lost 1.2x to one thread over a long call; on a later one
   (another hypervisor) they won 1.4x.  So a long call runs in pieces of :data:`PIECE_SAMPLES`, times each
   piece, and keeps the faster count: the first piece on the run-queue's count, the second on every core,
   then the faster of the two (more threads only when clearly faster, :data:`PIECE_MARGIN`, in
   :data:`WINS_NEEDED` timings running, since one piece's time is noisy), with the other count timed again
   after :data:`RECHECK_PIECES` pieces, then after gaps that double while it stays slower, so that a change
   of load is followed and a count that does badly costs little.  A piece is several
   scheduler time slices long, and every piece updates its count's rate (:func:`_measured`), so a verdict
   rests on what the call itself gets, not on a few milliseconds' guess.  Before measuring, a call looks at
   the run queue a second time a millisecond later (:func:`_second_look`): a kernel thread that ran for a
   moment is gone by then, a busy process is not.  The verdict serves later calls too short to measure for
   :data:`VERDICT_VALID_S` seconds, and a long call that starts while it stands begins on it and continues
   its schedule of rechecks; a call that finds every core free ends it.

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

Dask and process pools.  :func:`strapdown.apps.batch.run_batch` runs one file per worker process; the parallelism
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
    "PIECE_MARGIN",
    "PIECE_SAMPLES",
    "RECHECK_MAX_PIECES",
    "RECHECK_PIECES",
    "VERDICT_VALID_S",
    "WINS_NEEDED",
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

#: Samples in each timed piece of a long call on a busy machine (16 tiles of the scan: 15-40 ms on a contended
#: core of the 2-core machine, several time slices of the scheduler).
PIECE_SAMPLES = 1 << 20
#: More threads are kept only when their pieces took less than this fraction of the time per sample of the
#: run-queue's count: when both are alike, fewer threads leave more of the machine to the other processes.
PIECE_MARGIN = 0.95
#: Pieces after which the count not chosen is timed again (the gap doubles each time it confirms the choice),
#: so that the choice follows a change of load; the worse count then costs at most that share of a call.
RECHECK_PIECES = 8
#: The longest gap between timings of the count not chosen: a change of load is followed within this many
#: pieces (about a second at 15 ns a sample), while a confirmed choice costs a recheck per 64 pieces.
RECHECK_MAX_PIECES = 64
#: Timings running that more threads must win, each against the pieces on fewer threads just before it, before
#: they are taken: one piece's time is too noisy under contention to move on (see _measured).
WINS_NEEDED = 2
#: Seconds between the two reads of the run queue before a long call is measured in pieces (_second_look).
SECOND_LOOK_S = 0.001
#: Seconds a verdict stands after the call that measured it: calls too short to measure (the chunks of a file
#: pipeline) take its count, and a long call continues its schedule of rechecks instead of timing both counts
#: again.  The load of a shared machine changes as processes start and end, over seconds to minutes; a long
#: call still follows a change within RECHECK_MAX_PIECES pieces.
VERDICT_VALID_S = 10.0

# the threads of the last verdict, the clock time until which it stands, the other count's time per sample over
# the verdict's (what a call that starts from the verdict assumes until it times the other count itself), and
# the recheck schedule to continue: the gap in pieces, the pieces run on the verdict's count since the last
# recheck, and the timings won running by more threads
_verdict = [1, -math.inf, 1.0, RECHECK_PIECES, 0, 0]
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
    >>> from strapdown._support.threads import parse
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
    >>> from strapdown._support.threads import free_cores
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
    >>> from strapdown._support.threads import MIN_SAMPLES_PER_THREAD, choose
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
    auto mode measures instead of guessing (module notes, item 4): pieces of :data:`PIECE_SAMPLES`, the first
    on :func:`choose`'s count, the second on every core (or the first on the last verdict while it stands),
    then the faster, the other rechecked at growing gaps (a call that starts on the verdict continues its
    gaps); calls shorter than two pieces take the last verdict while it is fresh (:data:`VERDICT_VALID_S`),
    and a call that finds every core free ends it.  The pieces start at multiples of PIECE_SAMPLES, a multiple
    of the scan's tile, so the result has the same bits as one call, whatever the counts.

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
    auto = _setting(threads) is None
    free = free_cores() if auto else None
    chosen = choose(n, threads, available=free)
    if auto and free >= _cores():
        _verdict[1] = -math.inf  # the load that the verdict was measured under has gone
    most = chosen
    if auto and chosen < _cores() and n >= 2 * MIN_SAMPLES_PER_THREAD:
        import numba

        prepare_layer()
        most = max(1, min(_cores(), numba.get_num_threads(), n // MIN_SAMPLES_PER_THREAD))
        if most > chosen and n >= 2 * PIECE_SAMPLES:
            chosen = _second_look(n, threads, chosen)
    if most <= chosen:  # told, or every useful core is free: nothing to measure
        with claim(chosen) as t:
            part(t, 0, n)
        return
    if n < 2 * PIECE_SAMPLES:  # too short to measure: the last verdict while it is fresh
        with claim(_verdict[0] if clock() < _verdict[1] else chosen) as t:
            part(t, 0, n)
        return
    best, ratio, gap, since, wins = _measured(n, chosen, most, part, clock)
    _verdict[:] = [best, clock() + VERDICT_VALID_S, ratio, gap, since, wins]


def _second_look(n: int, threads, chosen: int) -> int:
    """The run queue's count read again after :data:`SECOND_LOOK_S`, the larger of the two kept.

    A process that keeps a core busy is in the run queue at every read; a kernel thread that runs for a moment
    is not.  On the 2-core VM one idle call in ten, right after an earlier call had freed its output, read a
    busy run queue and so began its timed pieces on one thread.  The run queue does not say which task that
    was; a kernel worker is the likely one (freeing memory on this VM hands it back to the host).  Only calls
    long enough to measure look twice (2 x PIECE_SAMPLES samples take tens of milliseconds, against the pause
    of one millisecond).

    The pause spins instead of sleeping.  A thread that sleeps on a busy machine gives up its core: the
    scheduler fills it with one of the busy processes, and the thread wakes up to share a core where it may
    have had one to itself.  Beside two busy processes on the 2-core VM, one thread in one call after a sleep
    of a millisecond took 1.08x the time of the same call without it (median of 100 pairs, 90 % interval
    1.01-1.13, ``benchmarks/bench_thread_policy.py``; 1.17x in a first trial), after a spin 1.03x
    (0.98-1.12), and cut into the timed pieces 0.95x (0.91-1.00).
    """
    _pause(SECOND_LOOK_S)
    return max(chosen, choose(n, threads))


def _pause(seconds: float) -> None:
    """Wait `seconds` on this core, spinning: a sleep would hand the core to a busy process (_second_look)."""
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        pass


def _pieces(n: int):
    """The timed pieces of n samples as (lo, hi), each starting at a multiple of PIECE_SAMPLES.

    A short last piece joins the one before: it would be timed at a different cost per sample.
    """
    lo = 0
    while lo < n:
        hi = min(lo + PIECE_SAMPLES, n)
        if hi < n and n - hi < PIECE_SAMPLES // 2:
            hi = n
        yield lo, hi
        lo = hi


def _measured(n: int, few: int, many: int, part, clock) -> tuple[int, float, int, int, int]:
    """Run n samples in timed pieces on `few` or `many` threads, keeping the faster (:func:`run`).

    Each count's rate is the seconds per sample of its pieces, the latest weighted as much as all before it.
    One piece's time says little on its own: in a trace of the pieces under two busy processes on the 2-core
    VM the same count took 11 to 30 ns a sample from one piece to the next, as the scheduler moved the busy
    processes between the cores.
    So the two directions are not treated alike:

    - Fewer threads are taken back as soon as the rate of more threads' own pieces is no longer clearly
      below theirs (:data:`PIECE_MARGIN`).
    - More threads are taken only once they have won :data:`WINS_NEEDED` timings running, each piece against
      the rate of the pieces on fewer threads just before it (the same phase of the load); a win is timed
      again after one piece, and a run of wins starts more threads' rate afresh.  With a single lucky piece
      enough, beside two busy processes, where two threads are no faster than one on average but vary more,
      the default call went to two threads on a lucky piece and stayed while the one-thread rate it was
      compared with was an unlucky one: bench_integrate's paired calls put it at 1.05 and 1.16 of the
      one-thread call's time (exact, first order; commit 60eadcd).

    The count not chosen is timed again after :data:`RECHECK_PIECES` pieces, and after twice as many each
    time it confirms the choice (at most :data:`RECHECK_MAX_PIECES`), so that a count that does badly costs
    less and less; a change of choice starts the gaps again.  A call that begins while the last verdict
    stands starts on it, takes the other count's rate from it (as a ratio to its own first piece) and
    continues its schedule of rechecks, so that a stream of long calls times the other count as rarely as one
    long call would.  A count that the claim could not grant (another Python thread holds the kernels) is
    timed as the count it got.

    Returns the verdict: the faster count, the other's time per sample over it, and the state to continue
    from (the gap, the pieces run on the faster count since the other was last timed, the wins running).
    """
    fresh = clock() < _verdict[1] and _verdict[0] in (few, many)
    best = _verdict[0] if fresh else few
    rate: dict[int, float] = {}
    # pieces between timings of the count not chosen, pieces on `best` since the other was last timed, and the
    # timings that more threads have won running (they are taken at WINS_NEEDED)
    gap, since, wins = (int(_verdict[3]), int(_verdict[4]), int(_verdict[5])) if fresh else (RECHECK_PIECES, 0, 0)
    checked = fresh  # whether the other count has been timed (a first timing confirms nothing)
    for k, (lo, hi) in enumerate(_pieces(n)):
        other = many if best == few else few
        due = 1 if wins else gap - 1  # a win to confirm is timed again after one piece
        count = other if k > 0 and (other not in rate or since >= due) else best
        before = rate.get(few)  # fewer threads' rate over the pieces just before this one
        with claim(count) as t:
            start = clock()
            part(t, lo, hi)
            seconds = (clock() - start) / (hi - lo)
        rate[t] = seconds if t not in rate else 0.5 * (rate[t] + seconds)
        if k == 0 and fresh and t == best:
            rate.setdefault(other, _verdict[2] * seconds)
        if few in rate and many in rate:
            if count == best:
                since += 1
                if best == many and rate[many] >= PIECE_MARGIN * rate[few]:
                    best, gap, since = few, RECHECK_PIECES, 0  # more threads lose their place at once
            else:  # the other count was timed
                if best == few:
                    won = t == many and before is not None and seconds < PIECE_MARGIN * before
                    wins = wins + 1 if won else 0
                    if wins == 1:
                        rate[many] = seconds  # a run of wins starts the rate afresh: earlier losses are stale
                    if wins >= WINS_NEEDED:
                        best, gap, wins = many, RECHECK_PIECES, 0
                    elif not wins:  # a confirmation of fewer threads doubles the gap
                        gap = min(2 * gap, RECHECK_MAX_PIECES) if checked else RECHECK_PIECES
                elif rate[many] >= PIECE_MARGIN * rate[few]:
                    best, gap = few, RECHECK_PIECES
                else:
                    gap = min(2 * gap, RECHECK_MAX_PIECES) if checked else RECHECK_PIECES
                since, checked = 0, True
    other = many if best == few else few
    ratio = rate[other] / rate[best] if other in rate and rate.get(best, 0.0) > 0 else 1.0
    return best, ratio, gap, since, wins


@contextmanager
def worker_default(count: int | None):
    """Within the block, on this thread: ``count`` threads where neither ``threads=`` nor the environment says.

    :mod:`strapdown.apps.batch` runs each job in ``worker_default(1)``: with one file per worker the cores are
    already shared out across files, and numba threads in every worker would oversubscribe them.

    Examples
    --------
    >>> from strapdown._support.threads import choose, worker_default
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
