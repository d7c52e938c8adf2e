"""HDF5 files (h5py): every numeric dataset of one or two dimensions is a field.

External links are refused, not followed: a link would make an input file read another file on the machine
into strapdown's output (issue 14).  Soft links inside the file are followed as datasets.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..._support.deps import need
from ..source import Source, _from_origin, check_chunk_rows, damaged
from .base import Format

__all__ = ["Hdf5Source"]


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
        for key in group:
            if key in self._skip:
                continue
            link = group.get(key, getlink=True)
            if isinstance(link, h5py.ExternalLink):
                raise ValueError(
                    f"{prefix}{key!r} is an external link to {link.filename!r} ({link.path}); strapdown does not "
                    "follow links out of an input file (they can point at any file on the machine): copy the data in"
                )
            obj = group.get(key)
            if isinstance(obj, h5py.Dataset) and (obj.external or obj.is_virtual):
                what = "stored in external files" if obj.external else "a virtual dataset mapping other files"
                raise ValueError(
                    f"{prefix}{key!r} is {what}; strapdown reads only data stored in the input file itself"
                )
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
        chunk_rows, names, stop = check_chunk_rows(chunk_rows), list(names), self._stop(names, stop)
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
                with damaged(self.path, f"rows {a} to {b - 1} of {name!r}"):  # h5py's errors name no file
                    block = ds[:, a:b].T if transposed else ds[a:b]
                out[name] = _from_origin(block, origins.get(name))
                if self.fields[name] == 1:
                    out[name] = out[name].reshape(-1)
            yield a, out

    def close(self):
        """Release the file."""
        self._file.close()


def _is_hdf5(path: Path) -> bool:
    with open(path, "rb") as f:
        return f.read(8) == b"\x89HDF\r\n\x1a\n"


def _open(path, **options):
    return Hdf5Source(Path(path))


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format("hdf5", _open, suffixes=(".h5", ".hdf5", ".hdf"), detect=_is_hdf5, table=True, description="HDF5")
