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
