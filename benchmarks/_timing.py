"""Timing helper shared by the benchmark scripts."""

import time


def best_time(func, repeat):
    """Shortest wall time of `repeat` calls of func (seconds)."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        func()
        times.append(time.perf_counter() - t0)
    return min(times)
