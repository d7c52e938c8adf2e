"""A log read forward a block at a time, and what was found broken in it (private: the ULog and DataFlash readers).

Neither format carries checksums, so a flipped bit or a cut file shows only as a message that cannot be: a type
the format does not have, a length that disagrees with the message's declared layout.  The walk stops there, finds
the next offset where several valid messages follow one another, and goes on; every such break is kept as a
:class:`Break`, which the reader turns into a warning with the samples lost and their time span (a log that breaks
before its data section is refused).  A log that ends inside a message (cut at a power loss) is one more break.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Bytes read from a log at a time (a ULog message is at most 65 538 bytes long, a DataFlash one 255).
BLOCK_BYTES = 8 << 20
#: Most offsets one walk of a block records before its payloads are decoded.
BATCH = 1 << 18


@dataclass
class Break:
    """A stretch of a log that could not be read: bytes ``start`` to ``stop`` (``stop`` None: to the end).

    ``counts``: the samples of each wanted stream read before it, so that the reader can tell which samples are
    missing around it.
    """

    start: int
    stop: int | None
    what: str
    counts: dict


class Blocks:
    """A file read forward from ``start``: ``buf[:end]`` holds bytes ``base`` onwards; :meth:`fill` moves on."""

    def __init__(self, f, start: int, size: int = BLOCK_BYTES):
        self.f = f
        f.seek(start)
        self.base = start
        self.buf = np.empty(size, dtype=np.uint8)
        self.end = 0
        self.eof = False
        self.fill(0)

    def fill(self, pos: int) -> int:
        """Keep ``buf[pos:end]``, read on after it; the position of ``pos`` in the new buffer (0)."""
        tail = self.end - pos
        if tail and pos:
            self.buf[:tail] = self.buf[pos : self.end]
        self.base += pos
        view = memoryview(self.buf)[tail:]
        got = 0
        while got < len(view):  # readinto may return less than asked before the end
            n = self.f.readinto(view[got:])
            if not n:
                self.eof = True
                break
            got += n
        self.end = tail + got
        return 0


def describe_breaks(path, breaks, times, period_ticks: float, per_s: float, t0: int, stream: str) -> list[str]:
    """One warning per break: where it is, and the samples of ``stream`` lost around it and when.

    ``times(i)`` gives the ticks of sample ``i`` of the stream; the count lost is the gap in its times over its
    period, less one.
    """
    out = []
    for b in breaks:
        where = f"bytes {b.start} to {b.stop}" if b.stop is not None else f"bytes {b.start} to the end"
        i = b.counts.get(stream, 0)
        before, after = times(i - 1) if i > 0 else None, times(i)
        if before is not None and after is not None:
            lost = max(round((after - before) / period_ticks) - 1, 0) if period_ticks else 0
            span = f"t = {(before - t0) / per_s:.6g} s to {(after - t0) / per_s:.6g} s"
            count = f"about {lost} {stream} samples lost" if lost else f"no {stream} sample lost, only other messages"
            out.append(f"{path}: {b.what} at {where}, skipped: {count} ({span})")
        elif before is not None:
            out.append(
                f"{path}: {b.what} at {where}, skipped: the {stream} readings end there, at "
                f"t = {(before - t0) / per_s:.6g} s"
            )
        else:
            out.append(f"{path}: {b.what} at {where}, skipped: the {stream} readings start after it")
    return out
