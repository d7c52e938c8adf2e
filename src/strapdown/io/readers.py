"""The reader registry's front door: open any input as a :class:`Source`, or read it whole.

Every input format is one module of :mod:`strapdown.io.formats` that registers itself
(:mod:`strapdown.io.registry`): the tables (CSV, Parquet, HDF5, MATLAB) and the logs and exports of the field
(PX4 ULog, ROS 1/2 bags, ASL/EuRoC, Sensor Logger, phyphox).  A format is chosen from the ``format`` given, a
folder's or zip's layout, the suffix, or the file's first bytes; several paths together are one recording
(one file per sensor), merged on the gyro's rows.

Every format is opened as a :class:`Source`: a set of named fields (1-D columns, or (N, k) arrays in HDF5 and
.mat files), the scalars stored beside them (a sampling rate), and :meth:`Source.chunks`, which yields the
wanted fields a block of rows at a time.  Memory stays bounded by the chunk for CSV, Parquet, HDF5 and
MATLAB v7.3 files; a MATLAB v5 file cannot be read in parts and is loaded whole (up to a size cap).

Rows are counted from 0; :meth:`Source.where` turns a row into what a user finds in the file: a line number
in a CSV file, a row index elsewhere.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .._support.deps import need
from .formats.base import named_failure
from .formats.csv import CsvSource
from .formats.hdf5 import Hdf5Source
from .formats.mat import COLUMNS_VARIABLE, MatSource, MatV73Source
from .formats.multi import open_files
from .formats.parquet import ParquetSource
from .registry import choose, formats
from .source import MemorySource, Source, TimeOrigin, check_chunk_rows, require_rows

__all__ = [
    "FORMATS",
    "INPUT_FORMATS",
    "Source",
    "format_of",
    "input_format",
    "open_source",
    "read_metadata",
    "read_table",
]

# re-exported: these lived here before the split into one module per format
_MOVED = (
    COLUMNS_VARIABLE,
    CsvSource,
    Hdf5Source,
    MatSource,
    MatV73Source,
    MemorySource,
    ParquetSource,
    TimeOrigin,
    check_chunk_rows,
    require_rows,
)

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
        ``"csv"``, ``"parquet"``, ``"hdf5"`` or ``"mat"``.

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
        Parquet schema metadata, HDF5 root attributes, MATLAB text variables, or the ``# key: value`` comment
        lines before a CSV header; empty for files that carry none.  For a log, bag or export (not a table):
        what its reader knows, ``format``, ``frame``, ``body`` and the ``time_origin`` items.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import read_metadata, write_table
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> path = write_table(folder / "a.parquet", {"x": np.zeros(2)}, metadata={"frame": "NED"})
    >>> read_metadata(path)
    {'frame': 'NED'}
    """
    if isinstance(path, list | tuple) or not choose(path, format).table:
        with open_source(path, format) as src:
            out = {"format": src.format, "frame": src.frame, "body": src.body}
            out = {k: v for k, v in out.items() if v}
            return out | (src.time_origin.metadata() if src.time_origin else {})
    fmt = format_of(path, format)
    out: dict[str, str] = {}
    if fmt == "csv":
        return dict(CsvSource(Path(path)).metadata)
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


#: Every input format's name (``--in-format``), tables first.
INPUT_FORMATS = tuple(sorted(formats(), key=lambda name: not formats()[name].table))


def input_format(path, format: str | None = None) -> str:
    """The input format of a path (file, folder or zip): named, from the layout, the suffix or the content.

    Parameters
    ----------
    path : path-like
        The input.
    format : str, optional
        One of :data:`INPUT_FORMATS`, which overrides the rest.

    Returns
    -------
    str
        The format's name.

    Examples
    --------
    >>> from strapdown.io.readers import input_format
    >>> input_format("flight.ulg"), input_format("run.bag"), input_format("imu.csv")
    ('ulog', 'rosbag', 'csv')
    """
    return choose(path, format).name


def open_source(path, format: str | None = None, **options) -> Source:
    r"""Open an input for reading in chunks: a table, a log, a bag, an export folder or zip, or several files.

    Parameters
    ----------
    path : path-like or sequence of path-like
        The input; several paths (one file per sensor: ``Gyroscope.csv``, ``Accelerometer.csv``, ...) are
        one recording, merged on the gyro's rows (:mod:`strapdown.io.formats.multi`).
    format : str, optional
        One of :data:`INPUT_FORMATS`; by default from the layout, suffix or content.
    **options
        The format's options: ``topic``, ``mag_topic`` (bags, ULog), ``time_unit`` (several files, exports:
        the unit of their integer time columns; tables take it in :class:`~strapdown.io.ImuFile`).

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
    if isinstance(path, list | tuple):
        if len(path) == 1:
            path = path[0]
        else:
            return open_files([Path(p) for p in path], format=format, opener=open_source, **options)
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no such file: {path}")
    fmt = choose(path, format)
    if "time_unit" not in fmt.options:
        options.pop("time_unit", None)  # a table's time column gets its unit in ImuFile
    unknown = set(options) - set(fmt.options)
    given = {k: v for k, v in options.items() if v is not None}
    if unknown & set(given):
        raise ValueError(f"{path}: the {fmt.name} reader takes no option {', '.join(sorted(unknown & set(given)))}")
    if path.is_dir() and fmt.table:
        raise ValueError(f"{path} is a folder, and no export layout (Sensor Logger, phyphox, EuRoC, ROS 2 bag) fits it")
    return named_failure(path, fmt.name, lambda: fmt.open(path, **{k: v for k, v in given.items() if k in fmt.options}))


def read_table(path, names: Sequence[str] | None = None, format: str | None = None, **options) -> dict:
    """Read whole fields of a file into memory (for files that fit; :func:`open_source` streams).

    Parameters
    ----------
    path : path-like or sequence of path-like
        Any input :func:`open_source` takes: a table, a log, a bag, an export folder or several files.
    names : sequence of str, optional
        The fields to read; all of them by default.
    format : str, optional
        When the suffix does not tell it.
    **options
        Passed to the format's reader (``topic=``).

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
    with open_source(path, format, **options) as src:
        wanted = list(src.fields) if names is None else list(names)
        missing = [n for n in wanted if n not in src.fields]
        if missing:
            raise ValueError(f"{path} has no field {', '.join(map(repr, missing))}; it has: {', '.join(src.fields)}")
        parts = [cols for _, cols in src.chunks(wanted, 1 << 22)]
    if not parts:
        return {n: np.zeros((0,) if src.fields[n] == 1 else (0, src.fields[n])) for n in wanted}
    return {n: np.concatenate([p[n] for p in parts]) for n in wanted}
