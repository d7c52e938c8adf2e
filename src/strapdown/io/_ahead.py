"""Read ahead: an iterator run by a thread of its own, a few items ahead of its consumer (private).

A file command reads and checks chunk k+1 while the caller integrates chunk k and the writer's thread encodes
chunk k-1: pyarrow's decoding, numpy's checks and the numba kernels all release the GIL, so the three can use
different cores when there are free ones (and cost nothing when there are none: the queue is short).

Errors keep their place: the consumer gets every item before the one whose production failed, then that
exception.  Leaving the ``with`` block (an error of the consumer's, Ctrl-C) stops the thread and waits for it
before the block's caller goes on to close the file it reads; the thread is a daemon, so a signal that ends the
process never waits for it.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Iterator

_END = object()


class ReadAhead:
    """Iterate ``items`` in a thread, at most ``depth`` items ahead.  Use as a context manager.

    Examples
    --------
    >>> from strapdown.io._ahead import ReadAhead
    >>> with ReadAhead(iter(range(5))) as items:
    ...     list(items)
    [0, 1, 2, 3, 4]
    """

    def __init__(self, items: Iterator, depth: int = 2):
        self._items = items
        self._queue: queue.Queue = queue.Queue(depth)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="strapdown-reader", daemon=True)

    def __enter__(self) -> Iterator:
        self._thread.start()
        return self._consume()

    def __exit__(self, *exc) -> None:
        self._stop.set()
        while self._thread.is_alive():  # it may be in a read or waiting on a full queue: let it see the stop
            try:
                self._queue.get_nowait()
            except queue.Empty:
                pass
            self._thread.join(0.05)
        close = getattr(self._items, "close", None)
        if close is not None:  # a generator's own clean-up (finally blocks) runs here, in this thread
            close()

    def _run(self) -> None:
        try:
            for item in self._items:
                if not self._put(item):
                    return
        except BaseException as exc:  # handed to the consumer, which raises it in its own thread
            self._put(_Failed(exc))
            return
        self._put(_END)

    def _put(self, item) -> bool:
        """Queue an item, waiting for room; False once the consumer has stopped."""
        while not self._stop.is_set():
            try:
                self._queue.put(item, timeout=0.05)
                return True
            except queue.Full:
                continue
        return False

    def _consume(self) -> Iterator:
        while True:
            item = self._queue.get()
            if item is _END:
                return
            if isinstance(item, _Failed):
                raise item.exc
            yield item


class _Failed:
    def __init__(self, exc: BaseException):
        self.exc = exc


class InOrder:
    """Calls run by a thread of their own, each result handed to ``sink(key, result)`` in the order submitted.

    At most ``depth`` calls wait or run at a time (:meth:`submit` hands results on until fewer do), so memory
    stays bounded; :meth:`flush` hands on all of them.  The first error of a call is raised in the caller's
    thread, by the :meth:`submit` or :meth:`flush` that reaches it.  Leaving the ``with`` block waits for the
    thread: after an error the results still pending are dropped, never handed on.

    Examples
    --------
    >>> from strapdown.io._ahead import InOrder
    >>> got = []
    >>> with InOrder(lambda key, value: got.append((key, value))) as later:
    ...     for i in range(4):
    ...         later.submit(i, pow, i, 2)
    ...     later.flush()
    >>> got
    [(0, 0), (1, 1), (2, 4), (3, 9)]
    """

    def __init__(self, sink, depth: int = 2):
        from concurrent.futures import ThreadPoolExecutor

        self._sink = sink
        self._depth = depth
        self._pool = ThreadPoolExecutor(1, thread_name_prefix="strapdown-columns")
        self._pending: list = []

    def __enter__(self) -> InOrder:
        return self

    def __exit__(self, *exc) -> None:
        for _, future in self._pending:
            future.cancel()
        self._pending = []
        self._pool.shutdown(wait=True)

    def submit(self, key, fn, *args, **kwargs) -> None:
        """Run ``fn(*args, **kwargs)`` in the thread; its result goes to ``sink(key, result)`` in turn."""
        self._pending.append((key, self._pool.submit(fn, *args, **kwargs)))
        while len(self._pending) > self._depth:
            self._hand_on()

    def flush(self) -> None:
        """Hand on every pending result (waiting for them)."""
        while self._pending:
            self._hand_on()

    def _hand_on(self) -> None:
        key, future = self._pending[0]
        result = future.result()  # raises the call's error, here
        self._pending.pop(0)
        self._sink(key, result)
