"""A function over items on a local process pool, inline, or on a Dask cluster (private).

Used by the batch runs of :mod:`strapdown.apps.batch` and the split integration of
:mod:`strapdown.io.pipelines.split`.  A call that raises gives its exception as its result: a batch reports each
item's failure and goes on with the others.
"""

from __future__ import annotations

import functools
import os
from collections.abc import Iterator, Sequence


# ----------------------------------------------------------------------------------------------------------
class Runner:
    """Runs a function over items on a local process pool, inline, or on a Dask cluster."""

    def __init__(self, scheduler: str | None = None, workers: int | None = None):
        self.scheduler = scheduler
        self.workers = workers
        self._client = None
        self._pool = None

    def __enter__(self):
        from .files import guard_signals

        guard_signals()  # SIGTERM/SIGHUP: stop the workers, which remove their temporaries (_files.py)
        if self.scheduler:
            from .deps import need

            distributed = need("distributed", "running on a Dask cluster")
            try:
                self._client = distributed.Client(self.scheduler, timeout="20s")
            except OSError as exc:
                raise ValueError(f"cannot reach the Dask scheduler at {self.scheduler}: {exc}") from None
        return self

    def __exit__(self, *exc):
        if self._client is not None:
            self._client.close()
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)

    def map(self, fn, items: Sequence) -> Iterator[tuple[int, object]]:
        """Yield (index, result) as results come in; a result is an exception when the call raised."""
        items = list(items)
        workers = min(self.workers or os.cpu_count() or 1, len(items))
        if self._client is not None or workers > 1:
            fn = functools.partial(one_thread, fn)  # the parallelism is across files (strapdown._support.threads)
        if self._client is not None:
            from distributed import as_completed

            futures = self._client.map(fn, items, pure=False)
            index = {f.key: i for i, f in enumerate(futures)}
            for fut in as_completed(futures):
                try:
                    yield index[fut.key], fut.result()
                except Exception as exc:  # a lost worker: the item failed, the others go on
                    yield index[fut.key], exc
            return
        if workers <= 1:
            for i, item in enumerate(items):
                try:
                    yield i, fn(item)
                except Exception as exc:
                    yield i, exc
            return
        if self._pool is None or self._pool._max_workers < workers:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            if self._pool is not None:
                self._pool.shutdown()
            # spawn: a forked child would inherit the parent's Arrow and numba thread pools mid-use
            self._pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
        from concurrent.futures import as_completed

        futures = {self._pool.submit(fn, item): i for i, item in enumerate(items)}
        for fut in as_completed(futures):
            try:
                yield futures[fut], fut.result()
            except Exception as exc:
                yield futures[fut], exc


def one_thread(fn, item):
    """fn(item) with one numba thread unless ``threads=`` or ``STRAPDOWN_THREADS`` says otherwise."""
    from .threads import worker_default

    with worker_default(1):
        return fn(item)


def gather(results: Iterator[tuple[int, object]], n: int) -> list:
    out: list = [None] * n
    for i, r in results:
        if isinstance(r, BaseException):
            raise r
        out[i] = r
    return out
