"""Delimited text: CSV, TSV, ``;``-separated files with decimal commas, and the headers instruments write.

Read with pyarrow's streaming CSV reader.  Besides a plain header line, the reader takes:

* comment lines before the header (``# frame: NED``), kept as metadata (:func:`strapdown.io.read_metadata`);
* a header that is itself a comment, as in ASL/EuRoC/TUM-VI files (``#timestamp [ns],w_RS_S_x [rad s^-1],...``);
* a second header row of units (``s,deg/s,deg/s,deg/s``), recorded in :attr:`Source.units`;
* ``;`` or tab separators with decimal commas (``0,25``), as spreadsheets in many locales save them.
"""

from __future__ import annotations

import csv
import re
from collections import Counter
from pathlib import Path

import numpy as np

from ..._support.deps import need
from ..source import Source, _arrow_to_numpy, _window, check_chunk_rows
from .base import Format, named_failure

__all__ = ["CsvSource", "open_csv"]

_INTEGER = re.compile(r"^[+-]?\d+$")
_DECIMAL_COMMA = re.compile(r"^[+-]?\d+,\d+([eE][+-]?\d+)?$")
_COMMENT_ITEM = re.compile(r"^#\s*([A-Za-z_][\w .-]*?)\s*[:=]\s*(.*)$")
#: Longest line read, bytes: a header of 100 000 columns fits; a line past it is a damaged file, refused before a
#: reader would hold it in memory (a 100 MB line without a newline took 2.3 GB).
MAX_LINE_BYTES = 16 << 20


class CsvSource(Source):
    """A delimited text file with a header line (pyarrow's streaming CSV reader)."""

    format = "csv"

    def __init__(self, path: Path):
        super().__init__(path)
        with open(path, newline="", encoding="utf-8-sig") as f:
            before, first = [], ""  # the blank and comment lines before the first other line
            for line in iter(lambda: self._line(f, len(before) + 1), ""):
                if line.strip() and not line.startswith("#"):
                    first = line
                    break
                before.append(line)
            rest = [self._line(f, len(before) + 2 + i) for i in range(64)]
        marks = [i for i, line in enumerate(before) if line.startswith("#")]
        comments = [before[i] for i in marks]
        if marks and (not first.strip() or self._is_data(first, before[marks[-1]])):
            # the header is the last comment (EuRoC's "#timestamp [ns],..."); the first other line is data
            head, n_skip, lines = comments.pop()[1:], marks[-1] + 1, [first, *rest]
        else:
            head, n_skip, lines = first, len(before) + 1, rest
        self.metadata = {m.group(1): m.group(2).strip() for c in comments if (m := _COMMENT_ITEM.match(c.strip()))}
        if not head.strip():
            raise ValueError("it is empty; a CSV file needs a header line with the column names")
        counts = {d: head.count(d) for d in (",", ";", "\t", "|")}
        self.delimiter = max(counts, key=counts.get) if max(counts.values()) else ","
        self.header = [h.strip() for h in next(csv.reader([head], delimiter=self.delimiter))]
        #: no header row (the first line is numbers, as some sensor vendors export): the columns are named by
        #: their numbers, "1" the first, and that line is data
        self.headerless = (
            head is first and any(self.header) and all(_is_number(h.replace(",", ".")) for h in self.header if h)
        )
        if self.headerless:
            self.header = [str(i + 1) for i in range(len(self.header))]
            n_skip, lines = len(before), [first, *rest]
        # one pass (Counter), not header.count per name: a 40k-column header took 32 s that way
        dup = sorted(h for h, n in Counter(self.header).items() if n > 1)
        if dup:
            shown = ", ".join(map(repr, dup[:10])) + (f" and {len(dup) - 10} more" if len(dup) > 10 else "")
            raise ValueError(f"the column name(s) {shown} appear more than once in the header")
        self._index = {h: i for i, h in enumerate(self.header)}
        if self.header == ["time", "seconds_elapsed", "z", "y", "x"]:
            self.frame, self.body = "ENU", "RFU"  # a Sensor Logger file: Android's axes (formats.sensorlogger)
        self.fields = {h: 1 for h in self.header}
        blank = next((i for i, line in enumerate(lines) if line.strip()), len(lines))
        if blank < len(lines) and self._is_unit_row(lines[blank]):
            units = next(csv.reader(lines[blank : blank + 1], delimiter=self.delimiter))
            self.units = {h: u.strip() for h, u in zip(self.header, units, strict=False) if u.strip()}
            lines, n_skip = lines[blank + 1 :], n_skip + blank + 1
        lines = [s for s in lines if s.strip()]
        self._skip = n_skip  # lines before the first data row
        self.decimal = (
            "," if self.delimiter != "," and any(_DECIMAL_COMMA.match(c.strip()) for c in self._cells(lines)) else "."
        )
        with open(path, "rb") as f:
            for _ in range(self._skip):
                f.readline()
            self._header_bytes = f.tell()
        if not lines and not self._has_data():
            self.rows = 0  # known now: Arrow would fail with "Empty CSV file", naming neither file nor problem
        self._first_values = next(csv.reader(lines[:1], delimiter=self.delimiter), [])
        self.integers = {h for h, v in zip(self.header, self._first_values, strict=False) if _INTEGER.match(v.strip())}
        self._bytes_per_row = max(8, sum(len(s) for s in lines) // max(len(lines), 1))

    def _line(self, f, number: int) -> str:
        """The next line of a text file, refused when longer than :data:`MAX_LINE_BYTES`."""
        line = f.readline(MAX_LINE_BYTES + 1)
        if len(line) > MAX_LINE_BYTES:
            raise ValueError(f"{self.path}: line {number} is longer than {MAX_LINE_BYTES >> 20} MiB: no CSV line is")
        return line

    def _cells(self, lines):
        for values in csv.reader(lines[:8], delimiter=self.delimiter):
            yield from values

    def _is_data(self, line: str, comment: str) -> bool:
        """Whether ``line`` is a data row whose fields the comment line before it names (EuRoC's header)."""
        for d in (",", ";", "\t"):
            n = comment.count(d)
            if n and line.count(d) == n:
                return all(
                    _is_number(c.strip().replace(",", ".")) or not c.strip()
                    for c in next(csv.reader([line], delimiter=d))
                )
        return False

    def _is_unit_row(self, line: str) -> bool:
        """A second header row of units: no number in it, and at least one cell a unit we know."""
        from ..units import UNITS, parse_unit

        cells = [c.strip() for c in next(csv.reader([line], delimiter=self.delimiter))]
        if len(cells) != len(self.header) or any(_is_number(c.replace(",", ".")) for c in cells if c):
            return False
        return any(parse_unit(k, c.strip("[]()"), strict=False) for c in cells if c for k in UNITS)

    def _has_data(self) -> bool:
        """Whether anything but blank lines follows the header."""
        with open(self.path, "rb") as f:
            f.seek(self._header_bytes)
            while block := f.read(1 << 20):
                if block.strip():
                    return True
        return False

    def where(self, row: int) -> str:
        """The line number of data row ``row`` (line 1 is the file's first)."""
        return f"line {row + 1 + self._skip}"

    def count_rows(self) -> int:
        """Count the data rows: the lines after the header (one pass at disk speed)."""
        if self.rows is None:
            n, last = 0, b"\n"
            with open(self.path, "rb") as f:
                f.seek(self._header_bytes)
                while block := f.read(1 << 24):
                    n += block.count(b"\n")
                    last = block[-1:]
            self.rows = n + (last != b"\n")
        return self.rows

    def _row_offset(self, target: int) -> int:
        """The byte offset where data row ``target`` starts (counting newlines; one row per line)."""
        with open(self.path, "rb") as f:
            f.seek(self._header_bytes)
            pos, row = f.tell(), 0
            while row < target:
                block = f.read(1 << 24)
                if not block:
                    return pos
                count = block.count(b"\n")
                if row + count < target:
                    row, pos = row + count, pos + len(block)
                    continue
                at = -1
                for _ in range(target - row):
                    at = block.index(b"\n", at + 1)
                return pos + at + 1
            return pos

    def is_timestamp(self, name: str) -> bool:
        """Whether a column holds ISO date-times (judged by its first value)."""
        pa = need("pyarrow", "reading CSV files")
        return self._types([name])[name] != pa.float64()

    def _first(self, name: str) -> str | None:
        i = self._index[name]
        return self._first_values[i].strip().rstrip("Z") if i < len(self._first_values) else None

    def _types(self, names, relative=()):
        pa = need("pyarrow", "reading CSV files")
        types = {}
        for n in names:
            i = self._index[n]
            first = self._first_values[i].strip() if i < len(self._first_values) else ""
            types[n] = pa.float64()
            if first and not _is_number(first) and _is_timestamp(first):
                # Arrow takes a trailing Z (UTC) only into a zoned type; cast to naive UTC in _arrow_to_numpy
                types[n] = pa.timestamp("ns", tz="UTC") if first.endswith("Z") else pa.timestamp("ns")
            elif n in relative and n in self.integers and abs(int(first)) > 2**53:
                types[n] = pa.int64()  # float64 would round the values before their first is subtracted
        return types

    def chunks(self, names, chunk_rows, start=0, stop=None, relative=()):
        """Rows ``start`` to ``stop`` of the named columns, about ``chunk_rows`` at a time."""
        pc = need("pyarrow.csv", "reading CSV files")
        pa = need("pyarrow", "reading CSV files")
        chunk_rows = check_chunk_rows(chunk_rows)
        names = list(names)
        if self.rows == 0:
            return
        offset = self._header_bytes if start == 0 else self._row_offset(start)
        block = int(min(max(chunk_rows * self._bytes_per_row, 1 << 16), MAX_LINE_BYTES))
        read = pc.ReadOptions(column_names=self.header, block_size=block)
        parse = pc.ParseOptions(delimiter=self.delimiter)
        types = self._types(names, relative)
        convert = pc.ConvertOptions(
            column_types=types, include_columns=names, strings_can_be_null=True, decimal_point=self.decimal
        )
        origins = {n: self._origin(n, self._first(n)) for n in names if self.is_timestamp(n)}
        for n in set(relative) & self.integers & set(names):
            origins[n] = self._int_origin(n, self._first(n))
        with open(self.path, "rb") as f:
            f.seek(offset)
            try:
                reader = pc.open_csv(f, read_options=read, parse_options=parse, convert_options=convert)
                for row, batch in _window(reader, start, stop, start):
                    cols = {}
                    for n in names:
                        if types[n] == pa.float64() and origins.get(n) is not None:
                            # below 2**53 integers are exact in float64, and so is their difference
                            cols[n] = _arrow_to_numpy(batch.column(n)) - float(origins[n])
                        else:
                            cols[n] = _arrow_to_numpy(batch.column(n), origins.get(n))
                    yield row, cols
            except pa.ArrowInvalid as exc:
                raise ValueError(self._explain(names, start, str(exc), types)) from None

    def _explain(self, names, start: int, arrow_message: str, types: dict) -> str:
        """Find the first value that is not a number (Arrow does not say where it is)."""
        index = {n: self._index[n] for n in names}
        with open(self.path, "rb") as f:
            f.seek(self._header_bytes)
            for row, raw in enumerate(iter(lambda: f.readline(MAX_LINE_BYTES + 1), b"")):
                if len(raw) > MAX_LINE_BYTES:  # read in bounded pieces: a line without end is never held whole
                    return f"{self.path}: {self.where(row)} is longer than {MAX_LINE_BYTES >> 20} MiB: no CSV line is"
                if row < start:
                    continue
                values = next(csv.reader([raw.decode("utf-8", errors="replace")], delimiter=self.delimiter), [])
                if not values:
                    continue
                if len(values) != len(self.header):
                    return (
                        f"{self.path}: {self.where(row)} has {len(values)} fields but the header has {len(self.header)}"
                    )
                for n, i in index.items():
                    v = values[i].strip()
                    if v and not _is_number(v.replace(self.decimal, ".")) and not _is_timestamp(v):
                        return f"{self.path}: {self.where(row)}, column {n!r}: {v!r} is not a number"
                    if v and str(types[n]) == "int64" and not _INTEGER.match(v):
                        return f"{self.path}: {self.where(row)}, column {n!r}: {v!r} is not an integer like the first"
        return f"{self.path}: {arrow_message}"


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _is_timestamp(text: str) -> bool:
    if not re.match(r"^\d{4}-\d\d-\d\d[T ]\d\d:\d\d", text):
        return False
    try:
        np.datetime64(text.rstrip("Z"))
    except ValueError:
        return False
    return True


def _open(path, **options):
    return CsvSource(Path(path))


def open_csv(path) -> CsvSource:
    r"""A CSV file as a Source, a failure named as :func:`strapdown.io.open_source` names it (the files of an export).

    Parameters
    ----------
    path : path-like
        A CSV file with a header row.

    Returns
    -------
    CsvSource
        Its fields and chunks.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io.formats.csv import open_csv
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "a.csv"
    >>> _ = path.write_text("t,x\n0,1\n")
    >>> with open_csv(path) as src:
    ...     src.fields
    {'t': 1, 'x': 1}
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    return named_failure(path, "csv", lambda: CsvSource(path))


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format("csv", _open, suffixes=(".csv", ".txt", ".tsv"), table=True, description="delimited text")
