"""The base of every reader: :class:`Source`, a table read a chunk of rows at a time, and its helpers.

A format module (:mod:`strapdown.io.formats`) subclasses :class:`Source` for files it streams, or fills a
:class:`MemorySource` for formats whose readings must be decoded and merged first (ULog, bags, phone exports).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._support.deps import need
from ._arrow import to_numpy

__all__ = ["MemorySource", "Source", "TimeOrigin", "check_chunk_rows", "damaged", "require_rows"]


@dataclass(frozen=True)
class TimeOrigin:
    """The absolute instant of t = 0: ``value`` in ``unit`` on the clock ``kind``.

    Attributes
    ----------
    value : int or float
        The first sample's time as the file counts it (exact: an int for integer clocks).
    unit : {"s", "ms", "us", "ns"}
        Its unit.
    kind : {"epoch", "boot", "file"}
        ``"epoch"``: since 1970-01-01 UTC; ``"boot"``: since the device started (PX4); ``"file"``: the file's
        own clock, zero unknown.
    """

    value: int | float
    unit: str
    kind: str

    def __str__(self) -> str:
        where = {"epoch": "since the epoch (1970-01-01 UTC)", "boot": "since boot", "file": "on the file's clock"}
        return f"{self.value} {self.unit} {where.get(self.kind, self.kind)}"

    def metadata(self) -> dict[str, str]:
        """The origin as text items for an output's metadata."""
        return {"time_origin": str(self.value), "time_origin_unit": self.unit, "time_origin_kind": self.kind}

    @property
    def iso(self) -> str | None:
        """The origin as an ISO date-time (UTC) when it is an epoch time, else None."""
        if self.kind != "epoch":
            return None
        ns = {"s": 10**9, "ms": 10**6, "us": 10**3, "ns": 1}[self.unit]
        return str(np.datetime64(round(self.value * ns), "ns"))


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
    units : dict of str to str
        Units the file states apart from the field names (a CSV unit row, a format's documented units).
    sparse : set of str
        Fields in which a whole NaN row means "no sample then" (a slower sensor merged on the gyro's rows).
    frame, body : str or None
        The reference frame and sensor axes the format documents (``"NED"``, ``"FRD"``), None when unknown.
    time_origin : TimeOrigin or None
        The instant of t = 0 when the reader knows it (ULog boot time, epoch of a bag); else the time column's
        first value is taken (:class:`strapdown.io.imu.ImuFile`).
    upright : bool
        The format's vehicles start upright (a drone on the ground): an accelerometer reading gravity
        downwards at rest is then a sign error, not a pose.
    presets : dict of str to tuple of str
        The fields a format knows hold "gyro", "acc", "mag" or "time", used before any detection by name.
    time_in_seconds : bool
        The time field is already in seconds from the first sample (decoded and merged logs).
    warnings : list of str
        What went wrong reading the file that a user must hear about, each naming the file (a corrupt stretch of a
        log skipped, with the samples lost and when); the file commands print them as warnings.
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
        self.units: dict[str, str] = {}
        self.sparse: set[str] = set()
        self.frame: str | None = None
        self.body: str | None = None
        self.time_origin: TimeOrigin | None = None
        self.upright = False
        self.presets: dict[str, tuple] = {}  # kind -> the fields a format knows hold it (before name detection)
        self.time_in_seconds = False  # the time field is already seconds (decoded logs): no unit to infer
        self.warnings: list[str] = []

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

    def _stop(self, names, stop: int | None) -> int:
        """The end of a read of ``names`` (fields stored apart, HDF5 and .mat): the shortest's length at most."""
        n = min((self.lengths[name] for name in names), default=0)
        return n if stop is None else min(stop, n)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


@contextlib.contextmanager
def damaged(path, what: str):
    """Name ``path`` in any failure to read ``what`` of it (a reader library's "Corrupt snappy compressed data").

    Parameters
    ----------
    path : path-like
        The file.
    what : str
        What was being read ("rows 0 to 1023").

    Examples
    --------
    >>> from strapdown.io.source import damaged
    >>> with damaged("x.parquet", "rows 0 to 9"):
    ...     raise OSError("Corrupt snappy compressed data.")
    Traceback (most recent call last):
    ValueError: x.parquet: rows 0 to 9 cannot be read (Corrupt snappy compressed data.): the file is damaged
    """
    try:
        yield
    except ImportError:
        raise
    except Exception as exc:  # the libraries raise OSError, ArrowInvalid, KeyError, RuntimeError, ...
        if str(path) in str(exc):
            raise
        raise ValueError(f"{path}: {what} cannot be read ({exc}): the file is damaged") from None


def check_chunk_rows(chunk_rows) -> int:
    """``chunk_rows`` as an int, or a ValueError: zero or negative would read nothing, or loop forever."""
    if isinstance(chunk_rows, bool) or not isinstance(chunk_rows, int | np.integer) or chunk_rows < 1:
        raise ValueError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    return int(chunk_rows)


def require_rows(path, rows: int | None) -> None:
    """A ValueError naming ``path`` when it has no data rows (None: not known yet, no error)."""
    if rows == 0:
        raise ValueError(f"{path} has no data rows: there are no readings to process")


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
    return to_numpy(column)  # not Array.to_numpy, which imports pandas (0.2-0.3 s per call of the CLI; h-cli)


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


def _from_origin(block, origin: int | None) -> np.ndarray:
    """A numpy block as float64, less ``origin`` in integer arithmetic first when given."""
    block = np.asarray(block)
    if origin is not None:
        block = block.astype(np.int64) - np.int64(origin)
    return np.asarray(block, dtype=np.float64)


class MemorySource(Source):
    """Fields already decoded into memory (ULog topics, bag messages, merged per-sensor files).

    Parameters
    ----------
    path : pathlib.Path
        The file (or folder) the fields came from, for messages.
    columns : mapping of str to numpy.ndarray
        Equal-length arrays, (n,) or (n, k).
    format : str
        The format's name.
    """

    def __init__(self, path: Path, columns: Mapping[str, np.ndarray], format: str):
        super().__init__(Path(path))
        self.time_in_seconds = "t" in columns
        self.format = format
        self._columns = {k: np.asarray(v) for k, v in columns.items()}
        lengths = {v.shape[0] for v in self._columns.values()}
        if len(lengths) > 1:
            raise ValueError(f"{path}: fields of different lengths {sorted(lengths)}")
        self.rows = lengths.pop() if lengths else 0
        for name, v in self._columns.items():
            self.fields[name] = 1 if v.ndim == 1 else v.shape[1]
            if v.ndim == 1 and v.dtype.kind in "iu":
                self.integers.add(name)

    def chunks(self, names, chunk_rows, start=0, stop=None, relative=()):
        """Rows ``start`` to ``stop`` of the named fields, ``chunk_rows`` at a time."""
        chunk_rows = check_chunk_rows(chunk_rows)
        names = list(names)
        stop = self.rows if stop is None else min(stop, self.rows)
        origins = {}
        for name in set(relative) & self.integers & set(names):
            origins[name] = self._int_origin(name, self._columns[name][0] if self.rows else None)
        for a in range(start, stop, chunk_rows):
            b = min(a + chunk_rows, stop)
            yield a, {n: _from_origin(self._columns[n][a:b], origins.get(n)) for n in names}
