"""Tables from CSV, Parquet, HDF5 and MATLAB files, read in chunks of rows (pyarrow, h5py, scipy.io).

Every format is opened as a :class:`Source`: a set of named fields (1-D columns, or (N, k) arrays in HDF5 and
.mat files), the scalars stored beside them (a sampling rate), and :meth:`Source.chunks`, which yields the
wanted fields a block of rows at a time.  Memory stays bounded by the chunk for CSV, Parquet, HDF5 and
MATLAB v7.3 files; a MATLAB v5 file cannot be read in parts and is loaded whole.

Rows are counted from 0; :meth:`Source.where` turns a row into what a user finds in the file: a line number
in a CSV file (the header is line 1), a row index elsewhere.
"""

from __future__ import annotations

import csv
import re
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from ._arrow import to_numpy
from ._deps import need

__all__ = ["FORMATS", "Source", "format_of", "open_source", "read_metadata", "read_table"]

#: File suffixes and the format they mean.
FORMATS = {
    ".csv": "csv",
    ".txt": "csv",
    ".tsv": "csv",
    ".parquet": "parquet",
    ".pq": "parquet",
    ".h5": "hdf5",
    ".hdf5": "hdf5",
    ".hdf": "hdf5",
    ".mat": "mat",
}


def format_of(path, format: str | None = None) -> str:
    """The format of a file from ``format`` or its suffix.

    Parameters
    ----------
    path : path-like
        The file.
    format : {"csv", "parquet", "hdf5", "mat"}, optional
        Overrides the suffix.

    Returns
    -------
    str
        The format.

    Examples
    --------
    >>> from strapdown.io.readers import format_of
    >>> format_of("logs/flight.PQ"), format_of("x.dat", "csv")
    ('parquet', 'csv')
    """
    if format is not None:
        if format not in set(FORMATS.values()):
            raise ValueError(f"unknown format {format!r}; use csv, parquet, hdf5 or mat")
        return format
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise ValueError(
            f"cannot tell the format of {Path(path).name!r} from its suffix; use .csv, .parquet, .h5/.hdf5 or .mat "
            "(or --format)"
        )
    return FORMATS[suffix]


class Source:
    """A table in a file, read a chunk of rows at a time.  Use :func:`open_source`.

    Attributes
    ----------
    path : pathlib.Path
        The file.
    format : str
        ``"csv"``, ``"parquet"``, ``"hdf5"`` or ``"mat"``.
    fields : dict of str to int
        Field name to width: 1 for a column, k for an (N, k) array.
    lengths : dict of str to int
        Rows of each field, where the format stores them separately (HDF5, .mat); empty for tables.
    scalars : dict of str to float
        Scalar values stored in the file (HDF5 attributes and scalars, .mat scalars).
    rows : int or None
        Number of rows, None for CSV until counted (:meth:`count_rows`); 0 for a CSV file with only a header.
    integers : set of str
        Integer fields (CSV: those whose first value is an integer), which ``chunks(relative=...)`` counts from
        their first value.
    """

    format = ""

    def __init__(self, path: Path):
        self.path = path
        self.fields: dict[str, int] = {}
        self.lengths: dict[str, int] = {}
        self.scalars: dict[str, float] = {}
        self.rows: int | None = None
        self.origins: dict[str, str] = {}  # timestamp fields: the instant their seconds count from
        self.integers: set[str] = set()  # integer fields: counted from their first value when asked (``relative``)

    def _origin(self, name: str, first) -> int | None:
        """The first value of a timestamp field in ns since the epoch: one origin per file, whatever the rows read."""
        if first is None:
            return None
        value = np.datetime64(first, "ns")
        self.origins[name] = str(value)
        return int(value.astype(np.int64))

    def _int_origin(self, name: str, first) -> int | None:
        """The first value of an integer field, which the values of ``relative`` chunks count from."""
        if first is None:
            return None
        self.origins[name] = str(int(first))
        return int(first)

    def where(self, row: int) -> str:
        """Where row ``row`` (0-based) is in the file, as a user would look for it."""
        return f"row {row}"

    def is_timestamp(self, name: str) -> bool:
        """Whether a field holds date-times (read as seconds from the file's first one)."""
        return False

    def count_rows(self) -> int:
        """The number of rows (a pass over a CSV file; free elsewhere)."""
        return self.rows

    def chunks(
        self,
        names: Sequence[str],
        chunk_rows: int,
        start: int = 0,
        stop: int | None = None,
        relative: Sequence[str] = (),
    ) -> Iterator[tuple[int, dict]]:
        """Yield ``(first row, {name: array})`` for rows ``start`` to ``stop`` in blocks of about ``chunk_rows``.

        Arrays are float64: (n,) for columns, (n, k) for k-wide fields; missing values are NaN.  Integer fields
        named in ``relative`` count from the file's first value, subtracted in integer arithmetic: epoch
        nanoseconds (~1.7e18) are past float64's 2**53 and would lose up to 0.1 µs.
        """
        raise NotImplementedError

    def close(self) -> None:
        """Release the file."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def check_chunk_rows(chunk_rows) -> int:
    """``chunk_rows`` as an int, or a ValueError: zero or negative would read nothing, or loop forever."""
    if isinstance(chunk_rows, bool) or not isinstance(chunk_rows, int | np.integer) or chunk_rows < 1:
        raise ValueError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    return int(chunk_rows)


def require_rows(path, rows: int | None) -> None:
    """A ValueError naming ``path`` when it has no data rows (None: not known yet, no error)."""
    if rows == 0:
        raise ValueError(f"{path} has no data rows: there are no readings to process")


def read_metadata(path, format: str | None = None) -> dict[str, str]:
    """The text that strapdown stores with a table: the command, frame, units and so on.

    Parameters
    ----------
    path : path-like
        A file written by :func:`~strapdown.io.write_table` or a command.
    format : {"csv", "parquet", "hdf5", "mat"}, optional
        Overrides the suffix.

    Returns
    -------
    dict of str to str
        Parquet schema metadata, HDF5 root attributes or MATLAB text variables; empty for CSV, which has no
        place for it, and for files that carry none.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import read_metadata, write_table
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> path = write_table(folder / "a.parquet", {"x": np.zeros(2)}, metadata={"frame": "NED"})
    >>> read_metadata(path)
    {'frame': 'NED'}
    """
    fmt = format_of(path, format)
    out: dict[str, str] = {}
    if fmt == "parquet":
        pq = need("pyarrow.parquet", "reading Parquet files")
        for key, value in (pq.read_schema(str(path)).metadata or {}).items():
            if not key.startswith(b"ARROW:"):  # Arrow's own schema, not ours
                out[key.decode(errors="replace")] = value.decode(errors="replace")
    elif fmt == "hdf5":
        h5py = need("h5py", "reading HDF5 files")
        with h5py.File(str(path), "r") as f:
            for key, value in f.attrs.items():
                if isinstance(value, bytes | str):
                    out[key] = value.decode(errors="replace") if isinstance(value, bytes) else value
    elif fmt == "mat":
        sio = need("scipy.io", "reading MATLAB files")
        try:
            names = [name for name, _, kind in sio.whosmat(str(path)) if kind == "char"]
            data = sio.loadmat(str(path), variable_names=names) if names else {}
        except (NotImplementedError, ValueError):  # v7.3 is HDF5 underneath; this metadata is not written there
            return {}
        out = {n: str(np.asarray(data[n]).ravel()[0]) for n in names if np.asarray(data[n]).size}
    return out


def open_source(path, format: str | None = None) -> Source:
    r"""Open a CSV, Parquet, HDF5 or MATLAB file for reading in chunks.

    Parameters
    ----------
    path : path-like
        The file.
    format : {"csv", "parquet", "hdf5", "mat"}, optional
        Overrides the suffix.

    Returns
    -------
    Source
        Its fields, scalars, and row chunks.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io import open_source
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "log.csv"
    >>> _ = path.write_text("t,gx,gy,gz\n0,0.1,0,0\n0.01,0.2,0,0\n")
    >>> with open_source(path) as src:
    ...     print(src.fields, [(row, cols["gx"]) for row, cols in src.chunks(["gx"], 1000)])
    {'t': 1, 'gx': 1, 'gy': 1, 'gz': 1} [(0, array([0.1, 0.2]))]
    """
    path = Path(path)
    fmt = format_of(path, format)
    if not path.is_file():
        raise FileNotFoundError(f"no such file: {path}")
    cls = {"csv": CsvSource, "parquet": ParquetSource, "hdf5": Hdf5Source, "mat": None}[fmt]
    if fmt == "mat":
        h5py = need("h5py", "reading MATLAB files")
        cls = MatV73Source if h5py.is_hdf5(str(path)) else MatSource
    try:
        return cls(path)
    except ImportError:
        raise
    except Exception as exc:  # a corrupt file, or one without a header: named, with the reader's reason
        raise ValueError(f"{path} is not a readable {fmt} file: {exc}") from None


# --------------------------------------------------------------------------------------------------------
def _arrow_to_numpy(column, origin: int | None = None) -> np.ndarray:
    """An Arrow array as float64: fixed-size lists as (n, k), nulls as NaN, timestamps in seconds from an origin.

    ``origin`` is in ns since the epoch for timestamps (float64 seconds since 1970 would resolve only 0.2 µs),
    and in the column's own unit for integers; both are subtracted before the conversion to float64.
    """
    pa = need("pyarrow", "reading Arrow data")
    if hasattr(column, "combine_chunks"):
        column = column.combine_chunks()
    typ = column.type
    if pa.types.is_timestamp(typ):
        ns = column.cast(pa.timestamp("ns")).cast(pa.int64())
        return _int_minus(ns, origin) / 1e9
    if pa.types.is_integer(typ) and origin is not None:
        return _int_minus(column.cast(pa.int64()), origin)
    if pa.types.is_duration(typ):
        per_second = {"s": 1, "ms": 1e3, "us": 1e6, "ns": 1e9}[typ.unit]
        return column.cast(pa.int64()).cast(pa.float64()).to_numpy(zero_copy_only=False) / per_second
    if pa.types.is_fixed_size_list(typ):
        k = typ.list_size
        return to_numpy(column.flatten()).reshape(-1, k)
    # unchecked: integers past 2**53 round to the nearest float64, as in CSV and HDF5, instead of failing
    return to_numpy(column)  # not Array.to_numpy, which imports pandas (0.2-0.3 s per call of the CLI)


def _int_minus(ints, origin: int | None) -> np.ndarray:
    """An Arrow int64 array minus ``origin`` (exact), as float64 with nulls as NaN."""
    pc = need("pyarrow.compute", "reading Arrow data")
    values = ints.fill_null(0).to_numpy(zero_copy_only=False) if ints.null_count else ints.to_numpy(False)
    out = (values - np.int64(origin or 0)).astype(np.float64)
    if ints.null_count:
        out[pc.is_null(ints).to_numpy(zero_copy_only=False)] = np.nan
    return out


def _arrow_width(field) -> int | None:
    pa = need("pyarrow", "reading Arrow data")
    t = field.type
    if pa.types.is_integer(t) or pa.types.is_floating(t) or pa.types.is_timestamp(t) or pa.types.is_boolean(t):
        return 1
    if pa.types.is_duration(t):
        return 1
    if pa.types.is_fixed_size_list(t) and (pa.types.is_floating(t.value_type) or pa.types.is_integer(t.value_type)):
        return t.list_size
    return None


def _window(batches, start: int, stop: int | None, first: int) -> Iterator[tuple[int, object]]:
    """Batches (Arrow) starting at row ``first``, cut to rows [start, stop)."""
    row = first
    for batch in batches:
        n = batch.num_rows
        lo, hi = max(start - row, 0), n if stop is None else min(stop - row, n)
        if hi > lo:
            yield row + lo, batch.slice(lo, hi - lo) if (lo, hi) != (0, n) else batch
        row += n
        if stop is not None and row >= stop:
            return


class CsvSource(Source):
    """A delimited text file with a header line (pyarrow's streaming CSV reader)."""

    format = "csv"

    def __init__(self, path: Path):
        super().__init__(path)
        with open(path, newline="", encoding="utf-8-sig") as f:
            head = f.readline()
            sample = [f.readline() for _ in range(64)]
        if not head.strip():
            raise ValueError("it is empty; a CSV file needs a header line with the column names")
        counts = {d: head.count(d) for d in (",", ";", "\t", "|")}
        self.delimiter = max(counts, key=counts.get) if max(counts.values()) else ","
        self.header = next(csv.reader([head], delimiter=self.delimiter))
        self.header = [h.strip() for h in self.header]
        dup = sorted({h for h in self.header if self.header.count(h) > 1})
        if dup:
            raise ValueError(f"the column name(s) {', '.join(dup)} appear more than once in the header")
        self.fields = {h: 1 for h in self.header}
        lines = [s for s in sample if s.strip()]
        if not lines and not self._has_data():
            self.rows = 0  # known now: Arrow would fail with "Empty CSV file", naming neither file nor problem
        self._first_values = next(csv.reader(lines[:1], delimiter=self.delimiter), [])
        self.integers = {h for h, v in zip(self.header, self._first_values, strict=False) if _INTEGER.match(v.strip())}
        self._bytes_per_row = max(8, sum(len(s) for s in lines) // max(len(lines), 1))
        with open(path, "rb") as f:
            self._header_bytes = len(f.readline())

    def _has_data(self) -> bool:
        """Whether anything but blank lines follows the header."""
        with open(self.path, "rb") as f:
            f.readline()
            while block := f.read(1 << 20):
                if block.strip():
                    return True
        return False

    def where(self, row: int) -> str:
        """The line number of data row ``row`` (line 1 is the header)."""
        return f"line {row + 2}"

    def count_rows(self) -> int:
        """Count the data rows: the lines after the header (one pass at disk speed)."""
        if self.rows is None:
            n, last = 0, b"\n"
            with open(self.path, "rb") as f:
                f.readline()
                while block := f.read(1 << 24):
                    n += block.count(b"\n")
                    last = block[-1:]
            self.rows = n + (last != b"\n")
        return self.rows

    def _row_offset(self, target: int) -> int:
        """The byte offset where data row ``target`` starts (counting newlines; one row per line)."""
        with open(self.path, "rb") as f:
            f.readline()
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
        i = self.header.index(name)
        return self._first_values[i].strip().rstrip("Z") if i < len(self._first_values) else None

    def _types(self, names, relative=()):
        pa = need("pyarrow", "reading CSV files")
        types = {}
        for n in names:
            i = self.header.index(n)
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
        block = int(min(max(chunk_rows * self._bytes_per_row, 1 << 16), 1 << 28))
        read = pc.ReadOptions(column_names=self.header, block_size=block)
        parse = pc.ParseOptions(delimiter=self.delimiter)
        types = self._types(names, relative)
        convert = pc.ConvertOptions(column_types=types, include_columns=names, strings_can_be_null=True)
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
        index = {n: self.header.index(n) for n in names}
        with open(self.path, newline="", encoding="utf-8-sig") as f:
            rows = csv.reader(f, delimiter=self.delimiter)
            next(rows)
            for row, values in enumerate(rows):
                if row < start or not values:
                    continue
                if len(values) != len(self.header):
                    return (
                        f"{self.path}: {self.where(row)} has {len(values)} fields but the header has {len(self.header)}"
                    )
                for n, i in index.items():
                    v = values[i].strip()
                    if v and not _is_number(v) and not _is_timestamp(v):
                        return f"{self.path}: {self.where(row)}, column {n!r}: {v!r} is not a number"
                    if v and str(types[n]) == "int64" and not _INTEGER.match(v):
                        return f"{self.path}: {self.where(row)}, column {n!r}: {v!r} is not an integer like the first"
        return f"{self.path}: {arrow_message}"


_INTEGER = re.compile(r"^[+-]?\d+$")


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


class ParquetSource(Source):
    """A Parquet file (pyarrow), read by row groups and batches."""

    format = "parquet"

    def __init__(self, path: Path):
        super().__init__(path)
        pq = need("pyarrow.parquet", "reading Parquet files")
        # pre_buffer would read every requested row group up front: memory would grow with the file
        self._file = pq.ParquetFile(str(path), pre_buffer=False)
        schema = self._file.schema_arrow
        pa = need("pyarrow", "reading Parquet files")
        self._timestamps = {f.name for f in schema if pa.types.is_timestamp(f.type)}
        self.integers = {f.name for f in schema if pa.types.is_integer(f.type)}
        for field in schema:
            w = _arrow_width(field)
            if w:
                self.fields[field.name] = w
        meta = self._file.metadata
        self.rows = meta.num_rows
        self._group_rows = [meta.row_group(i).num_rows for i in range(meta.num_row_groups)]
        kv = schema.metadata or {}
        for key, value in kv.items():
            try:
                self.scalars[key.decode()] = float(value)
            except (ValueError, UnicodeDecodeError):
                pass

    def is_timestamp(self, name: str) -> bool:
        """Whether a column has an Arrow timestamp type."""
        return name in self._timestamps

    def _first(self, name: str):
        group = next((i for i, n in enumerate(self._group_rows) if n), None)
        if group is None:
            return None
        pa = need("pyarrow", "reading Parquet files")
        column = self._file.read_row_group(group, columns=[name]).column(0)
        if name in self._timestamps:  # as ns since the epoch: as_py() would make a datetime, with µs only
            column = column.cast(pa.timestamp("ns")).cast(pa.int64())
        return column[0].as_py() if column[0].is_valid else None

    def chunks(self, names, chunk_rows, start=0, stop=None, relative=()):
        """Rows ``start`` to ``stop`` of the named columns, about ``chunk_rows`` at a time."""
        chunk_rows = check_chunk_rows(chunk_rows)
        names = list(names)
        stop = self.rows if stop is None else min(stop, self.rows)
        ends = np.cumsum(self._group_rows)
        groups = [i for i in range(len(ends)) if ends[i] > start and ends[i] - self._group_rows[i] < stop]
        if not groups:
            return
        first = int(ends[groups[0]] - self._group_rows[groups[0]])
        batches = self._file.iter_batches(batch_size=chunk_rows, row_groups=groups, columns=names)
        origins = {n: self._origin(n, self._first(n)) for n in names if n in self._timestamps}
        origins |= {n: self._int_origin(n, self._first(n)) for n in names if n in relative and n in self.integers}
        for row, batch in _window(batches, start, stop, first):
            yield row, {n: _arrow_to_numpy(batch.column(n), origins.get(n)) for n in names}

    def close(self):
        """Release the file."""
        self._file.close()


class Hdf5Source(Source):
    """An HDF5 file (h5py): every numeric dataset of one or two dimensions is a field, named by its path.

    A 2-D dataset is taken with its longer axis as rows, so MATLAB's column-major (3, N) storage reads as
    (N, 3).
    """

    format = "hdf5"
    _skip = ()

    def __init__(self, path: Path):
        super().__init__(path)
        h5py = need("h5py", "reading HDF5 files")
        self._file = h5py.File(str(path), "r")
        self._datasets = {}
        self._walk(self._file, "")
        self._attrs(self._file.attrs)
        lengths = set(self.lengths.values())
        self.rows = lengths.pop() if len(lengths) == 1 else None

    def _attrs(self, attrs, prefix: str = "") -> None:
        for key, value in attrs.items():
            arr = np.asarray(value)
            if arr.size == 1 and arr.dtype.kind in "iuf":
                self.scalars[prefix + key] = float(arr.reshape(()))

    def _walk(self, group, prefix: str) -> None:
        """Every dataset below ``group``, in the file's order (creation order when tracked, else by name)."""
        h5py = need("h5py", "reading HDF5 files")
        for key, obj in group.items():
            if key in self._skip:
                continue
            if isinstance(obj, h5py.Group):
                self._walk(obj, f"{prefix}{key}/")
            elif isinstance(obj, h5py.Dataset):
                self._visit(prefix + key, obj)

    def _visit(self, name: str, obj) -> None:
        if obj.dtype.kind not in "iuf" or obj.ndim > 2:
            return
        # a 1-D dataset of one element is a one-row column (this package writes columns so); MATLAB stores
        # its scalars as (1, 1)
        if obj.ndim == 0 or (obj.ndim == 2 and obj.size == 1):
            self.scalars[name] = float(np.asarray(obj[()]).reshape(()))
            return
        if obj.ndim == 1:
            rows, width, transposed = obj.shape[0], 1, False
        elif obj.size == 0:  # (0, k) or MATLAB's (k, 0): no rows of k values
            a, b = obj.shape
            rows, width, transposed = 0, max(a, b, 1), a > b
        else:
            a, b = obj.shape
            rows, width, transposed = (a, b, False) if a >= b else (b, a, True)
        self.fields[name] = width
        self.lengths[name] = rows
        self._datasets[name] = (obj, transposed)
        if width == 1 and obj.dtype.kind in "iu":
            self.integers.add(name)

    def chunks(self, names, chunk_rows, start=0, stop=None, relative=()):
        """Rows ``start`` to ``stop`` of the named datasets, ``chunk_rows`` at a time."""
        chunk_rows = check_chunk_rows(chunk_rows)
        names = list(names)
        n = min(self.lengths[name] for name in names) if names else 0
        stop = n if stop is None else min(stop, n)
        origins = {}
        for name in set(relative) & self.integers & set(names):
            ds, _ = self._datasets[name]
            first = np.asarray(ds[(0,) * ds.ndim]) if self.lengths[name] else None
            origins[name] = self._int_origin(name, first)
        for a in range(start, stop, chunk_rows):
            b = min(a + chunk_rows, stop)
            out = {}
            for name in names:
                ds, transposed = self._datasets[name]
                block = ds[:, a:b].T if transposed else ds[a:b]
                out[name] = _from_origin(block, origins.get(name))
                if self.fields[name] == 1:
                    out[name] = out[name].reshape(-1)
            yield a, out

    def close(self):
        """Release the file."""
        self._file.close()


def _from_origin(block, origin: int | None) -> np.ndarray:
    """A numpy block as float64, less ``origin`` in integer arithmetic first when given."""
    block = np.asarray(block)
    if origin is not None:
        block = block.astype(np.int64) - np.int64(origin)
    return np.asarray(block, dtype=np.float64)


class MatV73Source(Hdf5Source):
    """A MATLAB v7.3 file: HDF5 underneath, read in chunks like one."""

    format = "mat"
    _skip = ("#refs#", "#subsystem#")


class MatSource(Source):
    """A MATLAB v4/v5 file (scipy.io): loaded whole, as the format cannot be read in parts.

    Variables of shape (N,), (N, 1) or (1, N) are columns, (N, k) arrays are fields of width k, scalars are
    scalars; struct fields are named ``struct.field``.  Arrays are loaded unsqueezed, so their MATLAB shape is
    known: a small array is taken as stored ((2, 3) is two rows of three), unless that makes its rows disagree
    with the other variables' ((1, 5) beside 5-row arrays is a column).  The variables that
    :func:`strapdown.io.write_table` lists in ``strapdown_columns`` are columns whatever their length.
    """

    format = "mat"

    def __init__(self, path: Path):
        super().__init__(path)
        sio = need("scipy.io", "reading MATLAB files")
        # squeezing would make a one-row column a scalar and a (1, 3) row a column of 3
        data = sio.loadmat(str(path), squeeze_me=False, struct_as_record=False)
        declared = set(_cell_strings(data.pop(COLUMNS_VARIABLE, None)))
        arrays = {}
        self._collect(data, "", arrays, declared)
        self._arrays = {}
        for name, (arr, rows) in _orient(arrays, declared).items():
            self._arrays[name] = arr
            self.fields[name] = 1 if arr.ndim == 1 else arr.shape[1]
            self.lengths[name] = rows
            if arr.ndim == 1 and arr.dtype.kind in "iu":
                self.integers.add(name)
        lengths = set(self.lengths.values())
        self.rows = lengths.pop() if len(lengths) == 1 else None

    def _collect(self, data: dict, prefix: str, arrays: dict, declared: set) -> None:
        sio = need("scipy.io", "reading MATLAB files")
        for key, value in data.items():
            if key.startswith("__"):
                continue
            name = prefix + key
            arr = np.asarray(value)
            if arr.dtype == object and arr.size == 1 and isinstance(arr.item(), sio.matlab.mat_struct):
                struct = arr.item()
                self._collect({k: getattr(struct, k) for k in struct._fieldnames}, name + ".", arrays, declared)
                continue
            if arr.dtype.kind not in "iufb" or arr.ndim > 2:
                continue
            if arr.size == 1 and name not in declared:
                self.scalars[name] = float(arr.reshape(()))
            else:
                arrays[name] = arr

    def chunks(self, names, chunk_rows, start=0, stop=None, relative=()):
        """Rows ``start`` to ``stop`` of the named variables, ``chunk_rows`` at a time."""
        chunk_rows = check_chunk_rows(chunk_rows)
        names = list(names)
        n = min(self.lengths[name] for name in names) if names else 0
        stop = n if stop is None else min(stop, n)
        origins = {}
        for name in set(relative) & self.integers & set(names):
            origins[name] = self._int_origin(name, self._arrays[name][0] if self.lengths[name] else None)
        for a in range(start, stop, chunk_rows):
            b = min(a + chunk_rows, stop)
            yield a, {name: _from_origin(self._arrays[name][a:b], origins.get(name)) for name in names}


#: The variable of a MATLAB file written by this package that lists its columns (a cell array of names).
COLUMNS_VARIABLE = "strapdown_columns"


def _cell_strings(value) -> list[str]:
    """The strings of a cell array (or of one char array) as loaded by scipy.io, unsqueezed."""
    if value is None:
        return []
    arr = np.asarray(value)
    if arr.dtype.kind == "U":
        return [str(s) for s in arr.reshape(-1)]
    return [str(np.asarray(item).reshape(-1)[0]) if np.asarray(item).size else "" for item in arr.reshape(-1)]


def _orient(arrays: dict, declared: set) -> dict:
    """Each (a, b) array as (rows, values): 1-D for columns, (rows, k) for fields of width k, and its row count.

    An array may be read as stored (a rows) or transposed (b rows); it takes the reading whose row count the
    most arrays prefer (ties: the one the most arrays can have), else its own preference.  Preferred: the
    longer axis as rows for vectors and wide arrays, as stored for arrays up to 4 wide (a quaternion), so
    that a short log's (2, 3) stays two rows of three; declared columns are columns.
    """
    options = {}
    for name, arr in arrays.items():
        a, b = arr.shape if arr.ndim == 2 else (arr.shape[0], 1)
        stored, transposed = (a, arr.reshape(a, b)), (b, arr.reshape(a, b).T)
        if arr.size == 0:
            choices = [(0, np.zeros((0, max(a, b, 1)), arr.dtype))]
        elif name in declared:
            choices = [stored if b == 1 else transposed]
        elif a == 1 or b == 1:
            column = stored if b == 1 else transposed
            row = transposed if b == 1 else stored
            choices = [column, row] if max(a, b) > 4 else [row, column]
        elif a >= b or b <= 4:
            choices = [stored, transposed]
        else:
            choices = [transposed, stored]
        options[name] = choices
    counts = {rows for choices in options.values() for rows, _ in choices}
    score = {
        n: (sum(c[0][0] == n for c in options.values()), sum(any(r == n for r, _ in c) for c in options.values()))
        for n in counts
    }
    best = max(score, key=score.get) if score else None
    out = {}
    for name, choices in options.items():
        rows, arr = next(((r, v) for r, v in choices if r == best), choices[0])
        out[name] = (arr[:, 0] if arr.shape[1] == 1 else arr, rows)
    return out


def read_table(path, names: Sequence[str] | None = None, format: str | None = None) -> dict:
    """Read whole fields of a file into memory (for files that fit; :func:`open_source` streams).

    Parameters
    ----------
    path : path-like
        A CSV, Parquet, HDF5 or MATLAB file.
    names : sequence of str, optional
        The fields to read; all of them by default.
    format : str, optional
        When the suffix does not tell it.

    Returns
    -------
    dict of str to numpy.ndarray
        float64 arrays in file order.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import read_table, write_table
    >>> path = write_table(pathlib.Path(tempfile.mkdtemp()) / "x.h5", {"a": np.arange(3.0), "b": np.ones(3)})
    >>> read_table(path, ["b"])
    {'b': array([1., 1., 1.])}
    """
    with open_source(path, format) as src:
        wanted = list(src.fields) if names is None else list(names)
        missing = [n for n in wanted if n not in src.fields]
        if missing:
            raise ValueError(f"{path} has no field {', '.join(map(repr, missing))}; it has: {', '.join(src.fields)}")
        parts = [cols for _, cols in src.chunks(wanted, 1 << 22)]
    if not parts:
        return {n: np.zeros((0,) if src.fields[n] == 1 else (0, src.fields[n])) for n in wanted}
    return {n: np.concatenate([p[n] for p in parts]) for n in wanted}
