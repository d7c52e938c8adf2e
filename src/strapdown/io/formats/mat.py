"""MATLAB files: v7.3 (HDF5 underneath, streamed with h5py) and v4/v5 (scipy.io, loaded whole).

A v5 file is compressed per variable and cannot be read in parts, so it is loaded whole; a variable that
would expand past :data:`MAX_MAT_BYTES` is refused before it is decompressed (issue 14: 700 KB of zlib
expanded to 1 GB).  Save such data as v7.3 (``save -v7.3``), which is streamed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..._support.deps import need
from ..source import Source, _from_origin, check_chunk_rows
from .base import Format
from .hdf5 import Hdf5Source

__all__ = ["COLUMNS_VARIABLE", "MAX_MAT_BYTES", "MatSource", "MatV73Source", "expanded_size"]

#: Largest MATLAB v5 file content (all numeric variables, uncompressed) read into memory, bytes.
MAX_MAT_BYTES = 1 << 30


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
        size = expanded_size(path)
        if size > MAX_MAT_BYTES:
            raise ValueError(
                f"its variables expand to {size / 2**20:.0f} MiB in memory, past the {MAX_MAT_BYTES / 2**20:.0f} "
                "MiB that a MATLAB v5 file (loaded whole) may take; save it as v7.3 (save -v7.3), which is read in "
                "chunks, or raise strapdown.io.formats.mat.MAX_MAT_BYTES"
            )
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
        chunk_rows, names, stop = check_chunk_rows(chunk_rows), list(names), self._stop(names, stop)
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


def expanded_size(path) -> int:
    """The bytes a MATLAB v5 file's variables take once decompressed, from their element tags (v4: the file size).

    Each top-level element of a v5 file is a matrix (tag: type 14 and its byte count) or a zlib-compressed one
    (type 15) whose decompressed stream starts with that same tag; only those 8 bytes are decompressed, so the
    size is known before anything large is allocated.

    Parameters
    ----------
    path : path-like
        A MATLAB v4 or v5 file (v7.3 files are HDF5, and read in parts).

    Returns
    -------
    int
        Bytes.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile, scipy.io
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "z.mat"
    >>> scipy.io.savemat(path, {"x": np.zeros(1000)}, do_compression=True)
    >>> expanded_size(path) >= 8000 > path.stat().st_size
    True
    """
    import struct
    import zlib

    path = Path(path)
    with open(path, "rb") as f:
        header = f.read(128)
        if len(header) < 128 or not header.startswith(b"MATLAB 5.0"):
            return path.stat().st_size
        endian = "<" if header[126:128] == b"IM" else ">"
        total = 0
        while tag := f.read(8):
            if len(tag) < 8:
                break
            kind, nbytes = struct.unpack(endian + "II", tag)
            if kind >> 16:  # a small data element: 4 bytes of data in the tag itself
                continue
            if kind == 15:  # miCOMPRESSED
                inflate, inner, left = zlib.decompressobj(), b"", nbytes
                while len(inner) < 8 and left > 0:
                    piece = f.read(min(left, 4096))
                    if not piece:
                        break
                    left -= len(piece)
                    inner += inflate.decompress(piece, 8 - len(inner))
                    if inflate.unconsumed_tail:  # enough output already; the rest is skipped
                        break
                f.seek(left, 1)
                if len(inner) >= 8:
                    total += 8 + struct.unpack(endian + "II", inner[:8])[1]
            else:
                total += 8 + nbytes
                f.seek(nbytes + (-nbytes % 8), 1)
        return total


def _open(path, **options):
    path = Path(path)
    h5py = need("h5py", "reading MATLAB files")
    return MatV73Source(path) if h5py.is_hdf5(str(path)) else MatSource(path)


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format("mat", _open, suffixes=(".mat",), table=True, description="MATLAB v4/v5/v7.3")
