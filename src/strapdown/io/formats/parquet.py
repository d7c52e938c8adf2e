"""Parquet files (pyarrow), read by row groups and batches."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..._support.deps import need
from ..source import Source, _arrow_to_numpy, _arrow_width, _window, check_chunk_rows, damaged
from .base import Format

__all__ = ["ParquetSource"]


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
        with damaged(self.path, f"the first values of {', '.join(names)}"):
            batches = self._file.iter_batches(batch_size=chunk_rows, row_groups=groups, columns=names)
            origins = {n: self._origin(n, self._first(n)) for n in names if n in self._timestamps}
            origins |= {n: self._int_origin(n, self._first(n)) for n in names if n in relative and n in self.integers}
        window, row = _window(batches, start, stop, first), start
        while True:
            with damaged(self.path, f"the row group holding row {row} ({', '.join(names)})"):
                item = next(window, None)
                if item is None:
                    return
                row, batch = item
                cols = {n: _arrow_to_numpy(batch.column(n), origins.get(n)) for n in names}
            yield row, cols
            row += batch.num_rows

    def close(self):
        """Release the file."""
        self._file.close()


def _open(path, **options):
    return ParquetSource(Path(path))


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format("parquet", _open, suffixes=(".parquet", ".pq"), table=True, description="Apache Parquet")
