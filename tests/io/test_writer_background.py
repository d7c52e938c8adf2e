"""Parquet writing with gathered row groups and a background thread (io.writers, issue 15)."""

from __future__ import annotations

import numpy as np
import pyarrow.parquet as pq
import pytest

from strapdown.io import writers
from strapdown.io.writers import table_writer


@pytest.mark.parametrize("background", [False, True])
def test_small_chunks_gather_into_row_groups(tmp_path, monkeypatch, background):
    monkeypatch.setattr(writers, "ROW_GROUP_ROWS", 10)
    path = tmp_path / "t.parquet"
    sizes = [1, 5, 6, 3, 20, 2]  # groups close at >= 10 rows: 1+5+6, 3+20, 2 (the rest at close)
    start = 0
    with table_writer(path, background=background) as w:
        for n in sizes:
            w.write({"k": np.arange(start, start + n, dtype=np.float64), "x": np.full(n, 0.5)})
            start += n
    meta = pq.ParquetFile(path).metadata
    assert [meta.row_group(i).num_rows for i in range(meta.num_row_groups)] == [12, 23, 2]
    table = pq.read_table(path)
    np.testing.assert_array_equal(table["k"].to_numpy(), np.arange(sum(sizes), dtype=np.float64))


def test_background_write_error_surfaces_and_leaves_no_file(tmp_path, monkeypatch):
    monkeypatch.setattr(writers, "ROW_GROUP_ROWS", 1)  # every chunk goes to the thread at once
    path = tmp_path / "bad.parquet"
    with pytest.raises(Exception, match=r"(?i)schema|type|int64|double"):
        with table_writer(path, background=True) as w:
            w.write({"x": np.zeros(3)})
            w.write({"x": np.zeros(3, dtype=np.int64)})  # a type change the Parquet writer refuses
            for _ in range(5):  # the error comes back at a later write or at the close
                w.write({"x": np.zeros(3)})
    assert not path.exists()
    assert list(tmp_path.iterdir()) == []  # nor a temporary beside it


def test_error_in_the_block_stops_the_thread_and_writes_nothing(tmp_path):
    path = tmp_path / "x.parquet"
    with pytest.raises(RuntimeError, match="halfway"):
        with table_writer(path, background=True) as w:
            w.write({"x": np.arange(5.0)})
            raise RuntimeError("halfway")
    assert not path.exists()
    assert list(tmp_path.iterdir()) == []


def test_background_copies_so_the_caller_may_reuse_its_buffer(tmp_path, monkeypatch):
    monkeypatch.setattr(writers, "ROW_GROUP_ROWS", 4)
    path = tmp_path / "reuse.parquet"
    buf = np.empty((3, 2))
    with table_writer(path) as w:  # background by default
        for k in range(6):
            buf[:] = k
            w.write({"a": buf[:, 0], "b": buf[:, 1]})  # strided views of one reused buffer
    table = pq.read_table(path)
    np.testing.assert_array_equal(table["a"].to_numpy(), np.repeat(np.arange(6.0), 3))
    np.testing.assert_array_equal(table["b"].to_numpy(), np.repeat(np.arange(6.0), 3))
