"""The output side of a file command: time from the first sample, gaps, one writer per segment file."""

from __future__ import annotations

from contextlib import ExitStack
from pathlib import Path

import numpy as np

from ..conventions import GapSplitter, time_metadata
from ..tables import OutputSpec
from ..writers import table_writer
from ._common import (
    slice_chunk,
)


class Segments:
    """The output side of a file command: relative time, gaps (``on_gap``), one writer per segment file."""

    def __init__(self, imu, output: Path, out: OutputSpec, max_gap: float, on_gap: str, meta: dict):
        self.imu, self.output, self.out, self.on_gap, self.meta = imu, Path(output), out, on_gap, meta
        self.splitter = GapSplitter(max_gap, getattr(imu, "period", None)) if on_gap != "error" else None
        self.t_first: float | None = None
        self.writers: dict[int, object] = {}
        self.outputs: list[Path] = []
        self.notes: list[str] = []
        self.rows = 0
        self.segment_of_estimator = -1
        self.current = None  # the chunk in flight, for messages
        self._stack = ExitStack()

    def __enter__(self):
        self._stack.__enter__()
        return self

    def __exit__(self, *exc):
        if exc[0] is None:
            if not self.writers:  # no rows: the reader said so already, but never leave without a file
                self._writer(0)
            if self.splitter is not None and self.splitter.gaps:
                listing = "; ".join(f"{a:.6g} s -> {b:.6g} s" for a, b in self.splitter.gaps[:5])
                more = f" and {len(self.splitter.gaps) - 5} more" if len(self.splitter.gaps) > 5 else ""
                how = "a file per segment" if self.on_gap == "split" else "started afresh after each gap"
                self.notes.append(f"{len(self.splitter.gaps)} gap(s) ({how}): {listing}{more}")
        return self._stack.__exit__(*exc)

    def t(self, chunk) -> np.ndarray:
        """Seconds from the first sample of the file."""
        self._start(chunk)
        return chunk.t - self.t_first

    def _start(self, chunk) -> None:
        """The time origin, from the first chunk."""
        if self.t_first is None:
            self.t_first = float(chunk.t[0]) if len(chunk) else 0.0
            self.meta.update(time_metadata(self.imu, self.t_first))
            self.meta["time_first_input_s"] = repr(self.t_first)

    def pieces(self, chunks):
        """(segment, chunk) in order, the chunks cut at the gaps."""
        seg = 0
        for chunk in chunks:
            if not len(chunk):
                continue
            self._start(chunk)
            cuts = [] if self.splitter is None else list(self.splitter(self.t(chunk)))
            start = 0
            for i in [*cuts, len(chunk)]:
                if i > start:
                    self.current = slice_chunk(chunk, start, i)
                    yield seg, self.current
                if i < len(chunk):
                    seg += 1
                start = i

    def _writer(self, seg: int):
        key = seg if self.on_gap == "split" else 0
        if key not in self.writers:
            name = f"{self.output.stem}-{key + 1}{self.output.suffix}"
            path = self.output if key == 0 else self.output.with_name(name)
            meta = dict(self.meta)
            if self.on_gap == "split":
                meta["segment"] = str(key)
            self.writers[key] = self._stack.enter_context(table_writer(path, self.out.format, meta))
            self.outputs.append(path)
        return self.writers[key]

    def write(self, seg: int, columns: dict) -> None:
        if self.on_gap == "restart":
            columns["segment"] = np.full(len(columns["t"]), seg, dtype=np.int32)
        w = self._writer(seg)
        # attitude_columns made new arrays for every chunk: no copy needed
        w.write(columns, copy=False)
        self.rows += len(columns["t"])
