"""What every file command shares: its options, its output side, the report, and messages naming file rows.

The output side is time from the first sample, the gaps, and one writer per segment file.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import ExitStack
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from ..._support.version import VERSION
from ..conventions import GapSplitter, bridge_limit, time_metadata
from ..imu import ImuColumns
from ..readers import check_chunk_rows, format_of
from ..tables import OutputSpec
from ..writers import table_writer

CHUNK_ROWS = 1 << 18  # rows in flight: about 400 bytes of memory each, and no speed to gain beyond


#: What a file command may do at a time step over ``columns.max_gap`` sample periods (``auto`` first: the default).
ON_GAP = ("auto", "error", "split", "restart", "bridge")


@dataclass(frozen=True)
class FileOptions:
    """What every file command takes besides its input and output: how to read it and what to write.

    Attributes
    ----------
    columns : ImuColumns
        Column mapping and units (detected where left out), the gap limit ``max_gap``.
    out : OutputSpec
        Euler angles, bias, flags and format of the output.
    frame : str, optional
        Reference frame of the output (``"ENU"``, ``"NED"``, ``"NWU"``, ...); by default the input format's
        preset (a PX4 log is NED).
    body : str, optional
        Axes of the readings (``"FRD"``, ``"FLU"``, ...); by default the format's preset, else taken to be
        ``out_body``.  Readings are re-expressed in ``out_body`` before anything uses them.
    out_body : str, optional
        Body axes of the output attitudes; by default those that go with ``frame``
        (:func:`strapdown.io.conventions.natural_body`: FRD for NED, FLU for ENU and NWU), so that a level
        vehicle has zero roll and pitch.
    on_gap : {"auto", "error", "split", "restart", "bridge"}
        A time step over ``columns.max_gap`` sample periods.  ``"auto"`` (default): a gap no longer than
        ``bridge`` is bridged (the run carries on across it; a ``gap`` column marks the row after it), a longer
        one starts the run afresh after it (a ``segment`` column counts from 0), each with a warning.  For strict
        use: ``"error"`` stops with a ValueError; ``"split"`` writes a file per segment (``<stem>-2.csv`` ...),
        each started afresh; ``"restart"`` starts afresh after every gap (``segment`` column); ``"bridge"``
        bridges every gap (``gap`` column).
    bridge : float, optional
        The longest gap bridged under ``"auto"``, s; by default from the gyro's own errors
        (:func:`strapdown.io.conventions.bridge_limit`: about 2 s for a quiet consumer gyro, less when it is noisy).
    chunk_rows : int
        Rows per chunk: memory, not results (every chunking gives the same output).
    """

    columns: ImuColumns = ImuColumns()
    out: OutputSpec = OutputSpec()
    frame: str | None = None
    body: str | None = None
    out_body: str | None = None
    on_gap: str = "auto"
    bridge: float | None = None
    chunk_rows: int = CHUNK_ROWS

    def __post_init__(self):
        # None stands for the defaults (the command line passes what it was not given as None)
        if self.columns is None:
            object.__setattr__(self, "columns", ImuColumns())
        if self.out is None:
            object.__setattr__(self, "out", OutputSpec())
        if self.on_gap not in ON_GAP:
            raise ValueError(f"on_gap must be one of {', '.join(ON_GAP)}, got {self.on_gap!r}")
        if self.bridge is not None and not (isinstance(self.bridge, int | float) and self.bridge >= 0):
            raise ValueError(f"bridge must be a number of seconds >= 0, got {self.bridge!r}")
        object.__setattr__(self, "chunk_rows", check_chunk_rows(self.chunk_rows))


def options_of(cls, options, changes: dict, command: str):
    """``options`` (an instance of ``cls``, or None for the defaults) with the fields of ``changes`` replaced."""
    if options is None:
        options = cls()
    elif not isinstance(options, cls):
        raise TypeError(f"{command}'s options must be a {cls.__name__}, got {type(options).__name__}")
    names = {f.name for f in fields(cls)}
    unknown = sorted(set(changes) - names)
    if unknown:
        raise TypeError(f"{command} takes no option {', '.join(unknown)}; its options: {', '.join(sorted(names))}")
    return replace(options, **changes) if changes else options


#: Called after each chunk with (rows done, total rows or None).
Progress = Callable[[int, int | None], None]


@dataclass
class Report:
    """What a file command did.

    Attributes
    ----------
    input, output : pathlib.Path or None
        The files.
    rows : int
        Rows written.
    seconds : float
        Wall time.
    read : str
        Which columns were read, in which units.
    notes : list of str
        What a user should know: frames, gaps, warnings (lines starting with ``warning:``).
    outputs : list of pathlib.Path
        Every file written (several with ``on_gap="split"``).
    """

    input: Path | None
    output: Path
    rows: int
    seconds: float
    read: str = ""
    notes: list = field(default_factory=list)
    outputs: list = field(default_factory=list)


def default_output(input, command: str, format: str | None = None) -> Path:
    """The output beside ``input``: ``<stem>.<command>.<csv|parquet>`` (CSV unless the input is Parquet).

    Parameters
    ----------
    input : path-like
        The input file.
    command : str
        ``"integrate"``, ``"estimate"``, ``"convert"``.
    format : {"csv", "parquet", "hdf5", "mat"}, optional
        The output format.

    Returns
    -------
    pathlib.Path
        The output path.

    Examples
    --------
    >>> from strapdown.io.pipelines import default_output
    >>> str(default_output("logs/a.parquet", "estimate")), str(default_output("b.mat", "integrate"))
    ('logs/a.estimate.parquet', 'b.integrate.csv')
    """
    input = Path(input)
    if format is None:
        try:
            format = "parquet" if format_of(input) == "parquet" else "csv"
        except ValueError:
            format = "csv"
    suffix = {"csv": ".csv", "parquet": ".parquet", "hdf5": ".h5", "mat": ".mat"}[format]
    return input.with_name(f"{input.stem}.{command}{suffix}")


def metadata(command: str, **items) -> dict:
    meta = {"strapdown_version": VERSION, "strapdown_command": command}
    meta.update({k: str(v) for k, v in items.items() if v is not None})
    return meta


def with_progress(chunks: Iterator, total: int | None, progress: Progress | None):
    done = 0
    for chunk in chunks:
        yield chunk
        done += chunk.t.shape[0]
        if progress is not None:
            progress(done, total)


def input_paths(path) -> list[Path]:
    """The files of one recording: one path, or the list of several (one per sensor)."""
    return [Path(p) for p in path] if isinstance(path, list | tuple) else [Path(path)]


def output_path(path, output, command: str, format: str | None) -> Path:
    inputs = [] if path is None else input_paths(path)
    if output is not None:
        out = Path(output)
    elif len(inputs) > 1:  # one file per sensor: the output is named after their folder, beside them
        folder = inputs[0].parent
        out = default_output(folder / f"{folder.resolve().name or 'recording'}.csv", command, format)
    else:
        out = default_output(path, command, format)
    if any(out.resolve() == p.resolve() for p in inputs):
        raise ValueError(f"the output {out} is the input file; choose another output (-o)")
    return out


#: Readings of a common size in SI units, to find the one most out of scale: rad/s (or rad), m/s², µT.
_TYPICAL = {"gyro": 1.0, "acc": 9.81, "mag": 50.0}


_SI = {"gyro": "rad/s", "acc": "m/s²", "mag": "µT"}


def culprit(imu, chunk, row: int | None = None) -> str:
    """The reading of a chunk (or of one of its rows) most out of scale, by line and column, for messages.

    A non-finite reading comes first, then the largest relative to its quantity's usual size.  The unit check
    looks at a percentile of the first rows, so one absurd value further on gets through it and fails in the
    integrator or the filter, whose words name their own arrays: this names the file's line and column instead.
    """
    best = None
    for kind, typical in _TYPICAL.items():
        v = getattr(chunk, kind, None)
        if v is None or kind not in imu.picks or not len(v):
            continue
        part = v if row is None else v[row : row + 1]
        size = np.abs(part) / typical  # inf stays inf
        # NaN: no sample of a slower sensor on the gyro's rows (imu.sparse), otherwise a reading gone wrong
        size[np.isnan(size)] = 0.0 if kind in (getattr(imu, "sparse", None) or ()) else np.inf
        i, j = np.unravel_index(int(np.argmax(size)), size.shape)
        if best is None or size[i, j] > best[0]:
            best = (size[i, j], kind, i + (row or 0), j)
    if best is None:
        return "no reading"
    _, kind, i, j = best
    fields = imu.picks[kind].fields
    column = fields[j] if len(fields) == 3 else f"{fields[0]}[{j}]"
    unit = "rad" if kind == "gyro" and getattr(imu, "increments", False) else _SI[kind]
    if hasattr(imu, "locate"):
        path, where = imu.locate(fields[min(j, len(fields) - 1)], chunk.row + i)
        where = where if path == imu.path else f"{path}, {where}"
    else:
        where = imu.where(chunk.row + i)
    return f"{where}, column {column} = {getattr(chunk, kind)[i, j]:.4g} {unit}"


def rows_text(imu, chunk) -> str:
    """The rows of a chunk as a user finds them ("lines 2 to 201" in a CSV file), and its worst reading."""
    if chunk is None:
        return "its first rows"
    first, last = imu.where(chunk.row), imu.where(chunk.row + len(chunk) - 1)
    return (
        f"{first.split()[0]}s {first.split()[-1]} to {last.split()[-1]} (the reading most out of scale there: "
        f"{culprit(imu, chunk)})"
    )


def slice_chunk(chunk, a: int, b: int):
    from ..imu import ImuChunk

    part = ImuChunk(chunk.row + a, chunk.t[a:b], chunk.gyro[a:b])
    part.acc = None if chunk.acc is None else chunk.acc[a:b]
    part.mag = None if chunk.mag is None else chunk.mag[a:b]
    part.extra = {k: v[a:b] for k, v in chunk.extra.items()}
    return part


def read_columns(o: FileOptions) -> ImuColumns:
    """The reader's columns for a file command: its gap check only when gaps stop the run (``on_gap="error"``).

    Under any other policy the gaps are the output side's (:class:`Segments`), and the reader's check would stop
    the run first.
    """
    return o.columns if o.on_gap == "error" else replace(o.columns, max_gap=0)


def gap_bridge(o: FileOptions, imu) -> float:
    """The longest gap a run bridges, s.

    Every gap under ``"bridge"``, none under ``"restart"`` and ``"split"``; under ``"auto"`` ``o.bridge``, or the
    limit of the file's gyro (:func:`~strapdown.io.conventions.bridge_limit`).
    """
    if o.on_gap == "bridge":
        return float("inf")
    if o.on_gap != "auto":
        return 0.0
    return float(o.bridge) if o.bridge is not None else bridge_limit(imu.gyro_noise())


def _listing(gaps: list) -> str:
    shown = "; ".join(f"{a:.6g} s -> {b:.6g} s ({(b - a) * 1e3:.4g} ms)" for a, b in gaps[:5])
    return shown + (f" and {len(gaps) - 5} more" if len(gaps) > 5 else "")


class Segments:
    """The output side of a file command: relative time, gaps (``on_gap``), one writer per segment file.

    Under ``"auto"`` and ``"bridge"`` every output has a boolean ``gap`` column (True on the first row after a
    bridged gap), under ``"auto"`` and ``"restart"`` an integer ``segment`` column (0 before the first restart),
    so that a file's columns do not depend on what its rows hold.
    """

    def __init__(
        self, imu, output: Path, out: OutputSpec, max_gap: float, on_gap: str, meta: dict, bridge: float = 0.0
    ):
        self.imu, self.output, self.out, self.on_gap, self.meta = imu, Path(output), out, on_gap, meta
        period = getattr(imu, "period", None)
        self.splitter = GapSplitter(max_gap, period, bridge) if on_gap != "error" else None
        self.bridge = bridge
        self.max_gap = max_gap
        self.t_first: float | None = None
        self.writers: dict[int, object] = {}
        self.outputs: list[Path] = []
        self.notes: list[str] = []
        self.rows = 0
        self.segment_of_estimator = -1
        self.current = None  # the chunk in flight, for messages
        self._ends: list[float] = []  # the first times after bridged gaps not yet written
        self._stack = ExitStack()
        if on_gap in ("auto", "bridge"):
            meta["gap"] = "the gap column is True on the first row after a gap that was bridged"
        if on_gap in ("auto", "restart"):
            meta["segment"] = "the segment column counts the restarts after gaps (0 before the first)"

    def __enter__(self):
        self._stack.__enter__()
        return self

    def __exit__(self, *exc):
        if exc[0] is None:
            # what the reader could not read (a corrupt stretch skipped, zeroed rows): said even with -q
            self.notes[:0] = [f"warning: {w}" for w in getattr(getattr(self.imu, "source", None), "warnings", ())]
            if not self.writers:  # no rows: the reader said so already, but never leave without a file
                self._writer(0)
            self.notes.extend(self._gap_notes())
        return self._stack.__exit__(*exc)

    def _gap_notes(self) -> list[str]:
        """The warnings about the gaps met: how many, where, and what was done."""
        if self.splitter is None:
            return []
        notes = []
        steps = f"over {self.max_gap:g} sample periods"
        others = "--on-gap error, split, restart or bridge treat them otherwise"
        if self.splitter.bridged:
            within = "" if self.bridge == float("inf") else f" (each within {self.bridge:.3g} s, "
            within += "" if not within else "in which the gyro's own errors cost under 1 degree)"
            notes.append(
                f"warning: {len(self.splitter.bridged)} gap(s) {steps} bridged{within}, the gap column marks the "
                f"row after each: {_listing(self.splitter.bridged)}; {others}"
            )
        gaps = self.splitter.gaps
        if gaps:
            longer = f" longer than {self.bridge:.3g} s" if self.on_gap == "auto" else ""
            how = {"split": "a file per segment", "restart": "started afresh after each gap, segment column"}
            what = how.get(self.on_gap, "started afresh after each (segment column): the attitude before it is lost")
            notes.append(f"warning: {len(gaps)} gap(s) {steps}{longer} ({what}): {_listing(gaps)}; {others}")
        return notes

    def t(self, chunk) -> np.ndarray:
        """Seconds from the first sample of the file."""
        self._start(chunk)
        return chunk.t - self.t_first

    def _start(self, chunk) -> None:
        """The time origin, from the first chunk."""
        if self.t_first is None:
            self.t_first = float(chunk.t[0]) if chunk.t.size else 0.0
            self.meta.update(time_metadata(self.imu, self.t_first))
            self.meta["time_first_input_s"] = repr(self.t_first)

    def pieces(self, chunks):
        """(segment, chunk) in order, the chunks cut at the gaps that restart the run."""
        seg = 0
        for chunk in chunks:
            n = chunk.t.shape[0]
            if not n:
                continue
            self._start(chunk)
            if self.splitter is None:
                cuts = []
            else:
                t = self.t(chunk)
                found, bridged = self.splitter.split(t)
                cuts = list(found)
                self._ends.extend(t[bridged].tolist())
            start = 0
            for i in [*cuts, n]:
                if i > start:
                    self.current = chunk if (start, i) == (0, n) else slice_chunk(chunk, start, i)
                    yield seg, self.current
                if i < n:
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
        """Write the output columns of rows of segment ``seg`` (with the ``gap`` and ``segment`` columns)."""
        n = len(columns["t"])
        if self.on_gap in ("auto", "bridge"):
            gap = np.zeros(n, dtype=bool)
            if self._ends:
                ends = np.asarray(self._ends)
                gap = np.isin(columns["t"], ends)
                if n:  # the ends written are done with; those after this block wait for theirs
                    self._ends = ends[ends > columns["t"][-1]].tolist()
            columns["gap"] = gap
        if self.on_gap in ("auto", "restart"):
            columns["segment"] = np.full(n, seg, dtype=np.int32)
        w = self._writer(seg)
        # attitude_columns made new arrays for every chunk: no copy needed
        w.write(columns, copy=False)
        self.rows += n
