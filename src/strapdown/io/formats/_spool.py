"""Logs larger than memory: samples decoded a block at a time into spools, read back a chunk of rows at a time.

A log reader (ULog, DataFlash, bags) walks its file once, message by message or block by block, and appends each
sensor's samples (integer times and values) to a :class:`Spool`, which holds them in memory up to
:data:`SPOOL_BYTES` and in an unnamed temporary file past it.  :class:`SpooledSource` then serves the gyro's rows
chunk by chunk, and places the other sensors' samples on them as :func:`strapdown.io.merge.place_on_rows` does for
the whole log at once: a sample goes to its nearest gyro row, so the samples of one chunk of rows are those between
the midpoints to the neighbouring chunks' rows, and the result is the same row for row.  Memory stays bounded by
the chunk and the spools' caps, whatever the size of the log.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from ..merge import place_on_rows
from ..source import Source, TimeOrigin, check_chunk_rows

#: Bytes one spool keeps in memory before it moves its samples to a temporary file.
SPOOL_BYTES = 64 << 20
_INDEX_EVERY = 4096  # one time kept in memory per this many samples, to find a time in a spooled file
_PERIOD_ROWS = 1 << 21  # the gyro's period is the median step of at most this many first rows


class Spool:
    """One stream's samples in time order: int64 ticks and (n, k) float64 values, in memory or in a file.

    Parameters
    ----------
    width : int
        Values per sample.
    limit : int, optional
        Bytes kept in memory before the samples go to a temporary file.
    """

    def __init__(self, width: int, limit: int = SPOOL_BYTES):
        self.dtype = np.dtype([("t", "<i8"), ("v", "<f8", (width,))])
        self.width, self.limit, self.n = width, limit, 0
        self._blocks: list[np.ndarray] = []
        self._array: np.ndarray | None = None
        self._file = None
        self._index: list[int] = []  # the time of every _INDEX_EVERY-th sample
        self.first = self.last = None
        self.backwards = 0  # samples earlier than the one before them
        self.finite = np.zeros(width, dtype=np.int64)  # finite values of each column

    def append(self, t, values) -> None:
        """Add samples: ``t`` (m,) integer ticks, ``values`` (m, width)."""
        t = np.asarray(t, dtype=np.int64)
        if not t.size:
            return
        block = np.empty(t.size, self.dtype)
        block["t"] = t
        block["v"] = np.asarray(values, dtype=np.float64).reshape(t.size, self.width)
        if self.last is not None and t[0] < self.last:
            self.backwards += 1
        self.backwards += int(np.count_nonzero(t[1:] < t[:-1]))
        self.finite += np.isfinite(block["v"]).sum(axis=0)
        offset = (-self.n) % _INDEX_EVERY
        self._index.extend(t[offset::_INDEX_EVERY].tolist())
        self.first = int(t[0]) if self.first is None else self.first
        self.last = int(t[-1])
        self.n += t.size
        if self._file is None and self.n * self.dtype.itemsize > self.limit:
            self._file = tempfile.TemporaryFile(prefix="strapdown-spool-")
            for b in self._blocks:
                b.tofile(self._file)
            self._blocks = []
        if self._file is not None:
            block.tofile(self._file)
        else:
            self._blocks.append(block)

    def read(self, start: int, stop: int) -> np.ndarray:
        """Samples ``start`` to ``stop`` as a structured array (fields ``t`` and ``v``)."""
        start, stop = max(start, 0), min(stop, self.n)
        if stop <= start:
            return np.empty(0, self.dtype)
        if self._file is None:
            if self._array is None:
                self._array = np.concatenate(self._blocks) if self._blocks else np.empty(0, self.dtype)
                self._blocks = [self._array]
            return self._array[start:stop]
        self._file.seek(start * self.dtype.itemsize)
        return np.fromfile(self._file, self.dtype, stop - start)

    def times(self, start: int, stop: int) -> np.ndarray:
        """The ticks of samples ``start`` to ``stop``."""
        return self.read(start, stop)["t"]

    def find(self, ticks: int, twice: bool = False) -> int:
        """The first sample at or after ``ticks`` (``twice``: whose doubled time is at or after ``ticks``)."""
        scale = 2 if twice else 1
        index = np.asarray(self._index, dtype=np.int64) * scale
        block = max(int(np.searchsorted(index, ticks, side="left")) - 1, 0)
        a = block * _INDEX_EVERY
        t = self.times(a, a + 2 * _INDEX_EVERY) * scale
        return a + int(np.searchsorted(t, ticks, side="left"))

    def in_order(self, where) -> None:
        """Sort samples that came out of time order (in memory), or refuse when they are spooled to a file."""
        if not self.backwards:
            return
        if self._file is not None:
            raise ValueError(f"{where}: {self.backwards} samples go back in time, too many to sort in memory")
        block = self.read(0, self.n)
        self._array = block[np.argsort(block["t"], kind="stable")]
        self._blocks = [self._array]
        self._index = self._array["t"][::_INDEX_EVERY].tolist()
        self.first, self.last, self.backwards = int(self._array["t"][0]), int(self._array["t"][-1]), 0

    def close(self) -> None:
        """Drop the samples (and the temporary file)."""
        if self._file is not None:
            self._file.close()
            self._file = None
        self._blocks, self._array = [], None


class SpooledSource(Source):
    """A log's readings on the gyro's rows, served chunk by chunk from spools (see the module's description).

    Parameters
    ----------
    path : pathlib.Path
        The log.
    format : str
        Its format's name.
    rows : Spool
        The gyro's samples, with any sensor sampled in the same message (``sensor_combined``'s accelerometer).
    row_fields : dict of str to tuple of str
        The kind of each group of the rows' values (``{"gyro": (3 names), "acc": (3 names)}``), in order.
    placed : dict of str to (Spool, tuple of str)
        The other sensors' samples and their field names, placed on the nearest gyro rows.
    ticks_per_second : int
        The unit of the spools' times (1_000_000 for µs, 1_000_000_000 for ns).
    origin_kind : str
        What the clock counts from (``"boot"``, ``"epoch"``), for :class:`~strapdown.io.source.TimeOrigin`.
    units : dict of str to str
        The unit of each kind's values as the format documents it (``{"gyro": "rad/s", "mag": "gauss"}``).
    """

    def __init__(
        self,
        path,
        format: str,
        rows: Spool,
        row_fields: dict,
        placed: dict,
        ticks_per_second: int,
        origin_kind: str,
        units: dict,
    ):
        super().__init__(Path(path))
        if rows.n == 0:
            raise ValueError(f"{path}: the gyro's topic has no samples")
        self.format, self._rows, self._placed = format, rows, dict(placed)
        self._per_s = ticks_per_second
        self.rows = rows.n
        self.time_in_seconds = True
        self.fields = {"t": 1}
        self.presets = {"time": ("t",)}
        self._row_names: list[str] = []
        for kind, names in row_fields.items():
            self.presets[kind] = tuple(names)
            self._row_names.extend(names)
        for kind, (spool, names) in self._placed.items():
            spool.in_order(f"{path} ({kind})")
            self.presets[kind] = tuple(names)
        for kind, names in self.presets.items():
            self.fields.update(dict.fromkeys(names, 1))
            if kind in units:
                self.units.update(dict.fromkeys(names, units[kind]))
        self._t0 = int(rows.first)
        self.time_origin = TimeOrigin(self._t0, {1_000_000: "us", 1_000_000_000: "ns"}[ticks_per_second], origin_kind)
        steps = np.diff(rows.times(0, _PERIOD_ROWS))
        #: The gyro's sample period in ticks (the median step), beyond which a sample lands on no row.
        self.period_ticks = float(np.median(steps)) if steps.size else np.inf
        self._check_sparse(row_fields)

    def _check_sparse(self, row_fields: dict) -> None:
        """Mark the sensors that leave rows without a sample as sparse; refuse one that lands on no row at all."""
        kinds = {k: v[1] for k, v in self._placed.items()} | {k: v for k, v in row_fields.items() if k != "gyro"}
        empty = dict.fromkeys(kinds, 0)
        for _, cols in self._blocks(1 << 20, 0, self.rows, self._placed):
            for kind, names in kinds.items():
                empty[kind] += int(np.count_nonzero(np.isnan(cols[names[0]])))
        for kind, names in row_fields.items():
            if empty.get(kind):
                self.sparse.update(names)
        for kind, (spool, names) in self._placed.items():
            if empty[kind] == self.rows and spool.n:
                t = spool.times(0, 1)[0], spool.last
                raise ValueError(
                    f"{self.path}: none of the {spool.n} {kind} samples lies within a sample period of the gyro's "
                    f"rows: their times run {(t[0] - self._t0) / self._per_s:.6g} .. "
                    f"{(t[1] - self._t0) / self._per_s:.6g} s and the gyro's 0 .. "
                    f"{(self._rows.last - self._t0) / self._per_s:.6g} s from the gyro's first sample"
                )
            if empty[kind]:
                self.sparse.update(names)

    def chunks(self, names, chunk_rows, start=0, stop=None, relative=()):
        """Rows ``start`` to ``stop`` of the named fields, ``chunk_rows`` at a time."""
        chunk_rows = check_chunk_rows(chunk_rows)
        names = list(names)
        stop = self.rows if stop is None else min(stop, self.rows)
        wanted = {k: v for k, v in self._placed.items() if set(v[1]) & set(names)}
        for row, cols in self._blocks(chunk_rows, start, stop, wanted):
            yield row, {n: cols[n] for n in names}

    def _blocks(self, chunk_rows: int, start: int, stop: int, placed: dict):
        cursors = {kind: None for kind in placed}
        for a in range(start, stop, chunk_rows):
            b = min(a + chunk_rows, stop)
            block = self._rows.read(a, b)
            ticks = block["t"]
            cols = {"t": (ticks - self._t0) / self._per_s}
            for i, name in enumerate(self._row_names):
                cols[name] = block["v"][:, i]
            if placed:
                before = int(self._rows.times(a - 1, a)[0]) if a > 0 else None
                after = int(self._rows.times(b, b + 1)[0]) if b < self.rows else None
                for kind, (spool, names) in placed.items():
                    values, cursors[kind] = self._place(spool, ticks, before, after, cursors[kind])
                    for i, name in enumerate(names):
                        cols[name] = values[:, i]
            yield a, cols

    def _place(self, spool: Spool, ticks, before, after, cursor):
        """The samples nearest to these rows (between the midpoints to the neighbouring rows), on the rows."""
        # a sample at 2s >= before + ticks[0] is nearer the first row (a tie goes to the later row)
        lo = cursor if cursor is not None else (0 if before is None else spool.find(before + int(ticks[0]), True))
        hi = spool.n if after is None else spool.find(int(ticks[-1]) + after, True)
        samples = spool.read(lo, hi)
        return place_on_rows(ticks, samples["t"], samples["v"], period=self.period_ticks), hi

    def close(self) -> None:
        """Drop the spools."""
        self._rows.close()
        for spool, _ in self._placed.values():
            spool.close()
