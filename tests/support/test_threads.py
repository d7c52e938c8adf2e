"""The parallel policy's decisions (strapdown._support.threads): settings, free cores, the size threshold, and results
that do not depend on the thread count.  Decisions only: no elapsed time is measured here."""

from __future__ import annotations

import itertools
import math

import numba
import numpy as np
import pytest

from strapdown import AttitudeIntegrator, integrate
from strapdown._support import threads as th


@pytest.mark.parametrize(
    ("value", "expected"),
    [(None, None), ("", None), ("auto", None), (" AUTO ", None), ("1", 1), (" 12 ", 12), (3, 3), (np.int64(2), 2)],
)
def test_parse_accepts(value, expected):
    assert th.parse(value) == expected


@pytest.mark.parametrize("value", ["0", "-2", "two", "1.5", "4 threads", 0, -1, 2.0, True])
def test_parse_rejects_naming_the_setting(value):
    with pytest.raises(ValueError, match=r"STRAPDOWN_THREADS must be a positive integer or 'auto', got"):
        th.parse(value)


def test_bad_environment_variable_is_an_error_naming_it(monkeypatch):
    monkeypatch.setenv("STRAPDOWN_THREADS", "lots")
    with pytest.raises(ValueError, match=r"STRAPDOWN_THREADS.*'lots'"):
        th.choose(10**7)


def test_bad_threads_argument_is_refused_at_construction():
    with pytest.raises(ValueError, match="threads must be a positive integer or 'auto', got 0"):
        AttitudeIntegrator("exact", threads=0)


@pytest.mark.parametrize(
    ("cores", "others", "free"), [(2, 0, 2), (2, 1, 1), (2, 2, 1), (2, 7, 1), (8, 2.4, 6), (8, 2.6, 5), (4, 0.0, 4)]
)
def test_free_cores_is_cores_less_running_tasks_at_least_one(cores, others, free):
    assert th.free_cores(cores, others) == free


def test_free_cores_without_load_information_counts_every_core(monkeypatch):
    monkeypatch.setattr(th, "_running_others", lambda: None)
    assert th.free_cores(6) == 6


def test_running_others_excludes_this_task(monkeypatch, tmp_path):
    fake = tmp_path / "loadavg"
    fake.write_text("0.50 0.40 0.30 3/120 4242\n")
    real_open = open
    monkeypatch.setattr("builtins.open", lambda p, *a, **k: real_open(fake if p == "/proc/loadavg" else p, *a, **k))
    assert th._running_others() == 2  # three running, one of them us


def test_size_threshold_and_caps(monkeypatch):
    monkeypatch.delenv("STRAPDOWN_THREADS", raising=False)
    limit = numba.get_num_threads()
    per = th.MIN_SAMPLES_PER_THREAD
    assert th.choose(per - 1, 64) == 1  # too short for a second thread whatever was asked
    assert th.choose(2 * per, 64) == min(2, limit)
    assert th.choose(100 * per, 64) == limit  # never more than numba's thread count
    assert th.choose(100 * per, available=1) == 1  # a busy machine: one thread
    assert th.choose(100 * per, 1) == 1


def test_environment_variable_sets_the_count_and_argument_overrides_it(monkeypatch):
    per = th.MIN_SAMPLES_PER_THREAD
    monkeypatch.setattr(numba, "get_num_threads", lambda: 16)
    monkeypatch.setattr(th, "free_cores", lambda: 16)
    monkeypatch.setenv("STRAPDOWN_THREADS", "3")
    assert th.choose(100 * per) == 3
    assert th.choose(100 * per, 5) == 5
    assert th.choose(100 * per, "auto") == 16  # an explicit "auto" ignores the environment
    monkeypatch.setenv("STRAPDOWN_THREADS", "auto")
    monkeypatch.setattr(th, "free_cores", lambda: 4)
    assert th.choose(100 * per) == 4


def test_claim_gives_one_thread_while_another_kernel_runs():
    with th.claim(2) as first:
        with th.claim(2) as second:
            assert second == 1  # the second caller runs the serial build instead of oversubscribing
    assert first == min(2, numba.config.NUMBA_NUM_THREADS)
    with th.claim(1) as only:
        assert only == 1


@pytest.mark.parametrize("method", ["exact", "first-order", "cayley"])
def test_threads_one_is_bit_identical_to_threads_n(method, rng):
    # long enough for several tiles and for two threads to be chosen
    n = 5 * th.MIN_SAMPLES_PER_THREAD + 12345
    g = rng.standard_normal((n, 3))
    one = integrate(g, 0.005, method=method, threads=1)
    many = integrate(g, 0.005, method=method, threads=2)
    assert one.tobytes() == many.tobytes()
    seq = integrate(g, 0.005, method=method, parallel=False)
    # and both are the sequential loop's attitudes to rounding (an independent computation)
    dots = np.abs(np.sum(one * seq, axis=-1))
    assert (1 - dots).max() < 1e-12


def test_batch_jobs_default_to_one_thread_unless_told(monkeypatch):
    from strapdown._support.pool import one_thread as _one_thread

    monkeypatch.delenv("STRAPDOWN_THREADS", raising=False)
    monkeypatch.setattr(numba, "get_num_threads", lambda: 8)
    monkeypatch.setattr(th, "free_cores", lambda: 8)
    n = 100 * th.MIN_SAMPLES_PER_THREAD
    assert th.choose(n) == 8  # outside a batch job: every free core
    assert _one_thread(lambda _: th.choose(n), None) == 1  # a job in a worker: one thread
    assert _one_thread(lambda _: th.choose(n, 4), None) == 4  # threads= still wins
    monkeypatch.setenv("STRAPDOWN_THREADS", "3")
    assert _one_thread(lambda _: th.choose(n), None) == 3  # and so does the environment
    assert th.choose(n) == 3


def test_concurrent_calls_from_python_threads_agree_bit_for_bit(rng):
    from concurrent.futures import ThreadPoolExecutor

    n = 4 * th.MIN_SAMPLES_PER_THREAD + 777
    gyros = [rng.standard_normal((n, 3)) for _ in range(4)]
    alone = [integrate(g, 0.005, threads=1) for g in gyros]
    with ThreadPoolExecutor(4) as pool:  # one may hold the parallel kernel, the others run the serial build
        together = list(pool.map(lambda g: integrate(g, 0.005, threads=2), gyros))
    for a, b in zip(alone, together, strict=True):
        assert a.tobytes() == b.tobytes()


class _Machine:
    """A fake run: part() advances a fake clock by the cost per sample of the thread count it was given."""

    def __init__(self, cost):
        self.cost = cost  # {threads: seconds per sample}
        self.now = 0.0
        self.calls = []

    def clock(self):
        return self.now

    def part(self, t, lo, hi):
        self.calls.append((t, lo, hi))
        self.now += self.cost[t] * (hi - lo)


@pytest.fixture
def busy_two_cores(monkeypatch):
    """Two cores, the run queue full (auto chooses 1), a fresh verdict, claim granting what is asked."""
    from contextlib import contextmanager

    monkeypatch.delenv("STRAPDOWN_THREADS", raising=False)
    monkeypatch.setattr(th, "_cores", lambda: 2)
    monkeypatch.setattr(th, "_running_others", lambda: 3)
    monkeypatch.setattr(numba, "get_num_threads", lambda: 2)
    monkeypatch.setattr(th, "_verdict", [1, -np.inf, 1.0, th.RECHECK_PIECES, 0, 0])

    @contextmanager
    def grant(t):
        yield t

    monkeypatch.setattr(th, "claim", grant)


@pytest.fixture
def busy_eight_cores(busy_two_cores, monkeypatch):
    """Eight cores and six other tasks running: auto chooses 2, and 8 threads could get 2.3x their time."""
    monkeypatch.setattr(th, "_cores", lambda: 8)
    monkeypatch.setattr(th, "_running_others", lambda: 6)
    monkeypatch.setattr(numba, "get_num_threads", lambda: 8)


def _pieces_cover(calls, n):
    """The pieces are contiguous, cover [0, n) and start on multiples of PIECE_SAMPLES (tile edges)."""
    from strapdown.propagate._integrate_numba import SCAN_TILE

    assert th.PIECE_SAMPLES % SCAN_TILE == 0  # a piece edge is a tile edge: the same bits as one call
    assert calls[0][1] == 0 and calls[-1][2] == n
    for (_, _, hi), (_, lo, _) in itertools.pairwise(calls):
        assert hi == lo and lo % th.PIECE_SAMPLES == 0


@pytest.mark.parametrize(("cost", "faster"), [({2: 3e-8, 8: 1e-8}, 8), ({2: 1e-8, 8: 3e-8}, 2)])
def test_busy_machine_measures_and_keeps_the_faster(busy_eight_cores, cost, faster):
    """Seconds per sample as on a real machine (10-30 ns), so that a verdict is still fresh for the next call."""
    m = _Machine(cost)
    p = th.PIECE_SAMPLES
    n = 40 * p + 5
    th.run(n, None, m.part, clock=m.clock)
    _pieces_cover(m.calls, n)
    counts = [t for t, _, _ in m.calls]
    assert counts[:2] == [2, 8]  # the run queue's count first, then every core
    # every core is taken only once it has won WINS_NEEDED timings running, each after a piece on two threads
    decided = 1 if faster == 2 else 2 * th.WINS_NEEDED - 1
    assert counts[: decided + 1] == [2, 8] * ((decided + 1) // 2)
    # the faster from then on; the other timed again after RECHECK_PIECES pieces, then after gaps that double
    slower = 2 if faster == 8 else 8
    first = counts
    checks = [k for k, t in enumerate(first) if t == slower and k > decided]
    gaps = [b - a for a, b in itertools.pairwise([decided, *checks])]
    assert gaps == [th.RECHECK_PIECES * 2**i for i in range(len(gaps))] and len(checks) >= 2
    # the time is within the rechecks' share of running on the faster count alone
    alone = cost[faster] * n
    assert m.now <= alone * (1 + 3.0 / th.RECHECK_PIECES) + th.WINS_NEEDED * cost[slower] * p
    # a short call soon after reuses the verdict; once it is stale, the run queue decides again (two threads)
    m.calls.clear()
    th.run(p, None, m.part, clock=m.clock)
    assert m.calls == [(faster, 0, p)]
    # a long call while the verdict stands starts on it, without timing both counts first, and continues the
    # first call's schedule: the gaps between rechecks go on doubling across the two calls, up to the longest
    m.calls.clear()
    th.run(4 * n, None, m.part, clock=m.clock)
    second = [t for t, _, _ in m.calls]
    assert second[0] == faster
    checks = [k for k, t in enumerate(first + second) if t == slower and k > decided]
    gaps = [b - a for a, b in itertools.pairwise([decided, *checks])]
    assert gaps == [min(th.RECHECK_PIECES * 2**i, th.RECHECK_MAX_PIECES) for i in range(len(gaps))]
    assert gaps[-2:] == [th.RECHECK_MAX_PIECES] * 2  # the longest gap is reached and held
    m.now += th.VERDICT_VALID_S + 1.0
    m.calls.clear()
    th.run(p, None, m.part, clock=m.clock)
    assert m.calls == [(2, 0, p)]


def test_a_call_that_finds_the_cores_free_ends_the_verdict(busy_two_cores, monkeypatch):
    """The verdict belongs to the load it was measured under: once a call sees every core free, a short call
    under a new load takes the run queue's count again, not the old verdict."""
    m = _Machine({1: 2e-8, 2: 1e-8})
    p = th.PIECE_SAMPLES
    th.run(10 * p, None, m.part, clock=m.clock)
    m.calls.clear()
    th.run(p, None, m.part, clock=m.clock)
    assert m.calls == [(2, 0, p)]  # the verdict (two threads) serves a short call
    monkeypatch.setattr(th, "_running_others", lambda: 0)
    th.run(p, None, m.part, clock=m.clock)  # the cores are free: two threads, and the verdict ends
    monkeypatch.setattr(th, "_running_others", lambda: 3)
    m.calls.clear()
    th.run(p, None, m.part, clock=m.clock)
    assert m.calls == [(1, 0, p)]  # the run queue's count, although VERDICT_VALID_S has not passed
    assert m.now < th.VERDICT_VALID_S


def test_a_recheck_due_when_a_call_starts_follows_its_first_piece(busy_two_cores, monkeypatch):
    """The first piece of a call that starts on a verdict runs on the verdict's count, so that the other count's
    assumed rate has a piece of this call to be scaled by; a recheck that was due comes second."""
    monkeypatch.setattr(th, "_verdict", [1, np.inf, 2.0, th.RECHECK_PIECES, th.RECHECK_PIECES - 1, 0])
    m = _Machine({1: 1.0, 2: 2.0})
    th.run(4 * th.PIECE_SAMPLES, None, m.part, clock=m.clock)
    assert [t for t, _, _ in m.calls] == [1, 2, 1, 1]
    assert th._verdict[0] == 1 and th._verdict[2] == pytest.approx(2.0)


def test_one_lucky_timing_does_not_move_a_call_to_more_threads(busy_two_cores):
    """Under contention one piece's time varies 1.5-2x from the next: two threads that are as fast as one on
    average, but by turns half and one and a half times its time, are timed only as rechecks, and a lucky one
    is timed again at once instead of being taken."""

    class Noisy(_Machine):
        def part(self, t, lo, hi):
            if t == 2:
                self.cost[2] = 1.5 if self.cost[2] == 0.5 else 0.5
            super().part(t, lo, hi)

    m = Noisy({1: 1.0, 2: 1.5})  # the first timing of two threads is the lucky one
    n = 100 * th.PIECE_SAMPLES
    th.run(n, None, m.part, clock=m.clock)
    counts = [t for t, _, _ in m.calls]
    assert counts[:4] == [1, 2, 1, 2]  # a win, timed again after one piece on one thread: a loss
    assert not any(a == b == 2 for a, b in itertools.pairwise(counts))  # never taken
    assert counts.count(2) <= 2 * (1 + math.log2(len(counts)))  # the rechecks, at gaps that double
    assert th._verdict[0] == 1


def test_more_threads_are_kept_only_when_clearly_faster(busy_eight_cores):
    m = _Machine({2: 1.0, 8: 0.5 * (1 + th.PIECE_MARGIN)})  # faster, but within the margin
    n = 10 * th.PIECE_SAMPLES
    th.run(n, None, m.part, clock=m.clock)
    counts = [t for t, _, _ in m.calls]
    assert len(counts) == 10 and counts.count(8) == 2  # the first timing, and one recheck after RECHECK_PIECES
    assert counts[1] == counts[1 + th.RECHECK_PIECES] == 8


def test_the_choice_follows_a_change_of_load(busy_two_cores):
    """Two threads win until the load changes halfway; their own pieces then show it, and the call goes back to
    one thread, timing two again only as single rechecks."""
    p = th.PIECE_SAMPLES
    n = 64 * p

    class Changing(_Machine):
        def part(self, t, lo, hi):
            self.cost = {1: 1.0, 2: 0.5} if lo < n // 2 else {1: 1.0, 2: 2.0}
            super().part(t, lo, hi)

    m = Changing({})
    th.run(n, None, m.part, clock=m.clock)
    _pieces_cover(m.calls, n)
    first, second = [[t for t, lo, _ in m.calls if (lo < n // 2) == half] for half in (True, False)]
    assert first.count(2) >= len(first) - 1 - len(first) // th.RECHECK_PIECES
    # after the first piece that shows one thread faster, two threads run only as single rechecks
    after = second[second.index(1) :]
    assert all(not (a == 2 and b == 2) for a, b in itertools.pairwise(after))
    assert after.count(2) <= len(after) // th.RECHECK_PIECES + 1


def test_a_moment_of_load_is_looked_at_twice(busy_two_cores, monkeypatch):
    """A task seen once in the run queue and gone a moment later (a kernel thread) does not make a long call
    measure in pieces: the second look finds the cores free, and the call runs on both at once."""
    reads = iter([3, 0])
    monkeypatch.setattr(th, "_running_others", lambda: next(reads))
    m = _Machine({1: 1.0, 2: 1.0})
    n = 10 * th.PIECE_SAMPLES
    th.run(n, None, m.part, clock=m.clock)
    assert m.calls == [(2, 0, n)]


def test_the_second_look_keeps_the_core(busy_two_cores, monkeypatch):
    """The pause before the second look does not sleep: a sleeping thread on a busy machine hands its core to
    the busy processes (module notes, _second_look)."""
    import time

    def no_sleep(seconds):
        raise AssertionError(f"slept {seconds} s")

    monkeypatch.setattr(time, "sleep", no_sleep)
    reads = []
    monkeypatch.setattr(th, "_running_others", lambda: reads.append(1) or 3)
    m = _Machine({1: 1.0, 2: 1.0})
    th.run(4 * th.PIECE_SAMPLES, None, m.part, clock=m.clock)
    assert len(reads) == 2  # looked twice, without sleeping in between


def test_no_short_last_piece(busy_two_cores):
    m = _Machine({1: 1.0, 2: 1.0})
    p = th.PIECE_SAMPLES
    n = 3 * p + p // 4  # the quarter piece joins the third
    th.run(n, None, m.part, clock=m.clock)
    assert [(lo, hi) for _, lo, hi in m.calls] == [(0, p), (p, 2 * p), (2 * p, n)]


@pytest.mark.parametrize("threads", [1, 2])
def test_a_setting_is_never_second_guessed(busy_two_cores, threads):
    m = _Machine({1: 1.0, 2: 1.0})
    n = 10 * th.PIECE_SAMPLES
    th.run(n, threads, m.part, clock=m.clock)
    assert m.calls == [(threads, 0, n)]


def test_free_machine_runs_in_one_call_on_every_core(busy_two_cores, monkeypatch):
    monkeypatch.setattr(th, "_running_others", lambda: 0)
    m = _Machine({1: 1.0, 2: 1.0})
    n = 10 * th.PIECE_SAMPLES
    th.run(n, None, m.part, clock=m.clock)
    assert m.calls == [(2, 0, n)]


def test_auto_measuring_in_pieces_gives_the_bits_of_one_thread(rng, monkeypatch):
    monkeypatch.delenv("STRAPDOWN_THREADS", raising=False)
    monkeypatch.setattr(th, "_running_others", lambda: 8)  # busy: the call runs in timed pieces
    n = 2 * th.PIECE_SAMPLES + 4321
    g = rng.standard_normal((n, 3))
    dt = rng.uniform(0.001, 0.01, n)  # per-step durations: the pieces slice them too
    assert integrate(g, dt).tobytes() == integrate(g, dt, threads=1).tobytes()


@pytest.mark.parametrize("kind", [0, 1, 3])  # exact, first-order, cayley
def test_interleaved_chains_give_the_bits_of_one_chain_at_a_time(kind, rng):
    """The scan runs four blocks' chains in one loop (_local4) for speed: that reorders only independent
    operations, so each block must come out as when it is chained alone (_local1), large steps included."""
    from strapdown.propagate import _integrate_numba as k

    n = 4 * 3000 + 3  # blocks of unequal length: the longer ones finish alone
    g = rng.standard_normal((n, 3)) * 0.3
    g[[17, 5000, 9001]] = [40.0, -30.0, 25.0]  # steps past the series' limit, taken with sin and cos
    h = np.array([0.01])
    bounds = np.array([0, n // 4, n // 2, 3 * n // 4, n])
    assert len(set(np.diff(bounds))) == 2
    chain_norm = k.NORM_EXACT if kind == k.KIND_FIRST else k.NORM_NONE
    four, one = np.full((4, 4, k.SCAN_COLS), np.nan), np.full((4, 4, k.SCAN_COLS), np.nan)  # block scratch
    ends4, ends1 = np.empty((4, 4)), np.empty((4, 4))
    k._local4(g, h, 0, 1.0, kind, chain_norm, bounds, 0, four, ends4)
    for blk in range(4):
        k._local1(g, h, 0, 1.0, kind, chain_norm, bounds, blk, one, ends1)
    for blk, size in enumerate(np.diff(bounds)):
        assert not np.isnan(four[blk, :, :size]).any()  # every sample of the block written, in its columns
        assert four[blk, :, :size].tobytes() == one[blk, :, :size].tobytes()
        assert four[blk, :, size - 1].tobytes() == ends4[blk].tobytes()  # the end is the last sample
    assert ends4.tobytes() == ends1.tobytes()


def test_scan_bits_do_not_depend_on_how_the_blocks_are_shared(rng):
    """Any number of parts (threads) gives the same bits: 1, 2, 3 and 8 parts through the serial build of a part."""
    from strapdown.propagate import _integrate_numba as k

    n = 3 * k.SCAN_TILE + 1000
    g = rng.standard_normal((n, 3)) * 0.5
    h = np.array([0.01])
    results = []
    for n_parts in (1, 2, 3, 8):
        q = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
        out = np.empty((n, 4))
        prev_b, cur_b = np.zeros(k.SCAN_BLOCKS + 2, np.int64), np.zeros(k.SCAN_BLOCKS + 2, np.int64)
        prev, cur = np.zeros((2 * k.SCAN_BLOCKS, 4)), np.zeros((2 * k.SCAN_BLOCKS, 4))
        prev_c, cur_c = (np.empty((k.SCAN_BLOCKS, 4, k.SCAN_COLS)) for _ in range(2))
        for start in range(0, n + k.SCAN_TILE, k.SCAN_TILE):
            k._tile_record(start, min(start + k.SCAN_TILE, n), cur_b)
            for part in reversed(range(n_parts)):  # any order: the parts are independent within a region
                k._scan_part(
                    g, h, 0, 1.0, k.KIND_EXACT, True, part, n_parts, prev_b, prev, prev_c, cur_b, cur, cur_c, out
                )
            if cur_b[0] > 0:
                k._scan_offsets(True, k.KIND_EXACT, q, cur_b, cur)
            prev_b, cur_b, prev, cur, prev_c, cur_c = cur_b, prev_b, cur, prev, cur_c, prev_c
        results.append(out)
        assert q.tobytes() == out[-1].tobytes()  # the carried attitude is the last output, bit for bit
    q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
    serial = np.empty((n, 4))
    k.scan_serial(g, h, 0, 1.0, k.KIND_EXACT, True, q0.copy(), serial)
    for out in results:
        assert out.tobytes() == results[0].tobytes()
    assert results[0].tobytes() == serial.tobytes()
    # and it is the sequential loop to rounding (an independent computation)
    seq = np.empty((1, n, 4))
    k.sequential(g[None], h, 0, 1.0, k.KIND_EXACT, k.NORM_NONE, 1, 0, q0[None].copy(), seq)
    assert (1 - np.abs(np.sum(serial * seq[0], axis=-1))).max() < 1e-12
