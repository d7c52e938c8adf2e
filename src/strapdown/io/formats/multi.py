"""Several files of one recording, merged on the gyro's rows without resampling it.

Each file is read whole (phone and lab exports are small), its sensor told by its name (``Gyroscope.csv``,
``accel.csv``, ``Magnetometer.csv``, ...) or else its sensors by their columns (one file may hold several:
an ArduPilot ``IMU`` table's ``GyrX..GyrZ`` and ``AccX..AccZ`` beside a ``MAG`` file), or as given per file
(``--acc imu.csv:AccX,AccY,AccZ``), its time column by name (``time``, ``Time (s)``, ``timestamp``).  Times
are put on one clock exactly: integer columns count from their own first value in integers, and the offsets
between the files' first values are integers too.  Then the accelerometer and magnetometer samples go to the
nearest gyro rows (:mod:`strapdown.io.merge`); the rows they miss are NaN.
"""

from __future__ import annotations

import os
import re
import shutil
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..columns import describe_fields, detect_time, detect_vector, no_header_row, pick_vector
from ..merge import place_on_rows
from ..source import MemorySource, Source, TimeOrigin
from ..timebase import check_period, infer_time_unit, origin_of
from ..units import UNITS, parse_unit

__all__ = ["Stream", "kind_of_file", "merge_streams", "open_files", "read_stream"]

_NAMES = {
    "gyro": re.compile(r"gyr|rotationrate|angular", re.IGNORECASE),
    "acc": re.compile(r"acc|specificforce", re.IGNORECASE),
    "mag": re.compile(r"magnet|(^|[^a-z])mag|compass", re.IGNORECASE),  # not "Image"
}
_PER_S = UNITS["time"]  # s per unit
#: Largest total size of the files taken out of one zip, bytes: a zip bomb (1 GiB from 5 MB) is refused from the
#: sizes the zip declares, before anything is unpacked, and a zip that lies about them when the bytes pass this.
#: Well below memory: the files are then read whole (an export of an hour at 100 Hz is some 100 MB).
MAX_UNZIPPED_BYTES = 512 << 20
#: Longest first line read from an export's file to recognise it (a header is a few hundred bytes).
MAX_HEADER_BYTES = 1 << 16


def kind_of_file(name: str) -> str | None:
    """The sensor a file holds by its name, or None (``"Gyroscope.csv"`` -> ``"gyro"``).

    Parameters
    ----------
    name : str
        The file name.

    Returns
    -------
    str or None
        ``"gyro"``, ``"acc"`` or ``"mag"``.

    Examples
    --------
    >>> from strapdown.io.formats.multi import kind_of_file
    >>> kind_of_file("Gyroscope.csv"), kind_of_file("TotalAcceleration.csv"), kind_of_file("imu_mag.csv")
    ('gyro', 'acc', 'mag')
    >>> kind_of_file("UncalibratedMagnetometer.csv"), kind_of_file("Image.csv"), kind_of_file("notes.csv")
    ('mag', None, None)
    """
    found = [k for k, pattern in _NAMES.items() if pattern.search(Path(name).stem)]
    return found[0] if len(found) == 1 else None


@dataclass
class Stream:
    """One sensor's samples from one file: times on the file's clock and (n, 3) values as read.

    Attributes
    ----------
    path : pathlib.Path
        The file.
    kind : str
        ``"gyro"``, ``"acc"`` or ``"mag"``.
    fields : tuple of str
        The three columns read.
    unit : str or None
        Their unit when the file states it.
    time_field : str
        The time column.
    t : numpy.ndarray
        Times from the file's first one, in its unit (float64; exact for integers).
    first : int or float
        The first time value as written.
    integer : bool
        The time column holds integers.
    values : numpy.ndarray, shape (n, 3)
        The samples.
    qualified : bool
        The field names already say where they come from (a bag's ``topic/field``); else the file's name is
        put in front.
    """

    path: Path
    kind: str
    fields: tuple
    unit: str | None
    time_field: str
    t: np.ndarray
    first: int | float
    integer: bool
    values: np.ndarray
    qualified: bool = False
    where: object = None


def read_stream(src: Source, kind: str | None = None, time: str | None = None) -> Stream:
    r"""One sensor's samples from an open table that holds one sensor (``time, x, y, z`` and the like).

    Parameters
    ----------
    src : Source
        The open file.
    kind : {"gyro", "acc", "mag"}, optional
        Its sensor; by default from the file name, else from the columns.
    time : str, optional
        The time column; by default detected (``time`` is preferred when several look like time).

    Returns
    -------
    Stream
        The samples (the first sensor found, when the file holds several: :func:`read_streams`).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io import open_source
    >>> from strapdown.io.formats.multi import read_stream
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "Gyroscope.csv"
    >>> _ = path.write_text("time,z,y,x\n1700000000000000000,0.3,0.2,0.1\n1700000000010000000,0.3,0.2,0.1\n")
    >>> s = read_stream(open_source(path))
    >>> s.kind, s.fields, s.t, s.values[0]
    ('gyro', ('x', 'y', 'z'), array([       0., 10000000.]), array([0.1, 0.2, 0.3]))
    """
    return read_streams(src, kind, time)[0]


def _no_columns(src: Source, kind: str | None) -> ValueError:
    what = kind or "gyro, accelerometer or magnetometer"
    if getattr(src, "headerless", False):
        return no_header_row(src.path, src.fields, f"{what} columns")
    return ValueError(
        f"{src.path}: cannot tell which columns hold the {what} readings (looked for x,y,z and names like "
        f"gyro_x); it has: {describe_fields(src.fields)}; name them with --gyro/--acc/--mag {src.path.name}:COLS"
    )


def read_streams(src: Source, kind: str | None = None, time: str | None = None, picks: dict | None = None) -> list:
    r"""Every sensor's samples in an open table: one file may hold the gyro, the accelerometer and more.

    Parameters
    ----------
    src : Source
        The open file.
    kind : {"gyro", "acc", "mag"}, optional
        Its only sensor; by default the one its name says (``Gyroscope.csv``: its bare ``x, y, z`` columns),
        else every sensor whose columns its names show (``GyrX..GyrZ`` and ``AccX..AccZ``).
    time : str, optional
        The time column; by default detected (``time`` is preferred when several look like time).
    picks : dict of str to str, optional
        Columns given for a sensor (``{"acc": "AccX,AccY,AccZ"}``, or by number in a file without a header:
        ``"5,6,7"``), used instead of any detection; then only the sensors named are read.

    Returns
    -------
    list of Stream
        One per sensor, gyro first, sharing the file's time column.

    Examples
    --------
    An ArduPilot IMU table exported to CSV holds the gyro and the accelerometer:

    >>> import pathlib, tempfile
    >>> from strapdown.io import open_source
    >>> from strapdown.io.formats.multi import read_streams
    >>> rows = "TimeUS,GyrX,GyrY,GyrZ,AccX,AccY,AccZ\n1000,0,0,0.1,0,0,-9.8\n3500,0,0,0.1,0,0,-9.8\n"
    >>> (path := pathlib.Path(tempfile.mkdtemp()) / "IMU.csv").write_text(rows) > 0
    True
    >>> with open_source(path) as src:
    ...     print([(s.kind, s.fields) for s in read_streams(src)])
    [('gyro', ('GyrX', 'GyrY', 'GyrZ')), ('acc', ('AccX', 'AccY', 'AccZ'))]
    """
    fields = src.fields
    found = {}
    picks = dict(picks or {})
    if "time" in picks:
        given = picks.pop("time")
        time = pick_vector(given, fields, f"--time {src.path.name}:{given}", width=1).fields[0]
    if picks:
        for k, spec in picks.items():
            found[k] = pick_vector(spec, fields, f"--{k} {src.path.name}:{spec}")
    else:
        kind = kind or kind_of_file(src.path.name)
        for k in (kind,) if kind else ("gyro", "acc", "mag"):
            pick = detect_vector(k, fields, units=src.units, bare=kind is not None)
            if pick is not None:
                found[k] = pick
    if not found:
        raise _no_columns(src, kind)
    if time is None:
        times = [n for n in fields if n.strip().lower() == "time"]
        time = times[0] if times else None
    if time is None:
        detected = detect_time(fields)
        if detected is None:
            if getattr(src, "headerless", False):
                raise no_header_row(src.path, fields, "time column")
            raise ValueError(
                f"{src.path}: no time column (looked for time, t, timestamp, ...); it has: {describe_fields(fields)}"
            )
        time = detected.fields[0]
    integer = time in src.integers and not src.is_timestamp(time)
    names = list(dict.fromkeys([time, *(f for p in found.values() for f in p.fields)]))
    parts = list(src.chunks(names, 1 << 20, relative=(time,) if integer else ()))
    cat = {n: np.concatenate([p[n] for _, p in parts]) if parts else np.zeros(0) for n in names}
    t = cat[time]
    first = int(src.origins[time]) if integer and time in src.origins else (float(t[0]) if t.size else 0.0)
    if not integer and t.size:
        t = t - t[0]
    streams = []
    for k in sorted(found, key=("gyro", "acc", "mag").index):
        pick = found[k]
        unit = pick.unit_hint or next((src.units[f] for f in pick.fields if f in src.units), None)
        unit = parse_unit(k, unit, strict=False) if unit else None
        values = np.column_stack([cat[f] for f in pick.fields])
        streams.append(Stream(src.path, k, pick.fields, unit, time, t, first, integer, values, where=src.where))
    return streams


def _time_unit(stream: Stream, declared: str | None, time_hint: str | None) -> tuple[str, str | None]:
    steps = np.diff(stream.t[: 1 << 14])
    step = float(np.median(steps)) if steps.size else 0.0
    if declared:
        unit = parse_unit("time", declared)
    elif time_hint:
        unit = time_hint
    elif stream.integer and step:
        unit = infer_time_unit(step, stream.first, stream.time_field, str(stream.path))[0]
    else:
        unit = "s"
    if step:
        check_period(step, unit, stream.time_field, str(stream.path))
    return unit, None


def merge_streams(
    label: Path, streams: dict, format: str, time_unit: str | None = None, origin_kind: str | None = None
) -> MemorySource:
    """One table on the gyro's rows from one stream per sensor (:func:`read_stream`).

    Parameters
    ----------
    label : pathlib.Path
        What the recording is called in messages (the folder, zip or first file).
    streams : dict of str to Stream
        ``"gyro"`` (required), ``"acc"``, ``"mag"``.
    format : str
        The format's name.
    time_unit : str, optional
        The unit of the files' time columns (else read from the header, or inferred for integers).
    origin_kind : str, optional
        What the clock is (``"epoch"``), when the format documents it.

    Returns
    -------
    MemorySource
        Fields ``t`` (s from the first gyro sample) and the sensors' columns, named ``file/column``.

    Examples
    --------
    >>> import numpy as np, pathlib
    >>> from strapdown.io.formats.multi import Stream, merge_streams
    >>> g = Stream(pathlib.Path("g.csv"), "gyro", ("x", "y", "z"), "rad/s", "t", np.arange(4) * 0.01, 0.0,
    ...            False, np.zeros((4, 3)))
    >>> m = Stream(pathlib.Path("m.csv"), "mag", ("x", "y", "z"), "uT", "t", np.array([0.011]), 0.0, False,
    ...            np.ones((1, 3)))
    >>> src = merge_streams(pathlib.Path("rec"), {"gyro": g, "mag": m}, "files")
    >>> src.presets["mag"], src.sparse == {"m.csv/x", "m.csv/y", "m.csv/z"}
    (('m.csv/x', 'm.csv/y', 'm.csv/z'), True)
    """
    if "gyro" not in streams:
        have = ", ".join(f"{s.path.name} ({k})" for k, s in streams.items()) or "no sensor files"
        raise ValueError(f"{label}: no gyroscope file among {have}; strapdown needs the gyro")
    gyro = streams["gyro"]
    hint = next((u for u in (_hint(gyro.time_field),) if u), None)
    unit, _ = _time_unit(gyro, time_unit, hint)
    per_s = _PER_S[unit]
    cols: dict[str, np.ndarray] = {"t": gyro.t * per_s}
    src_presets, sparse, units, located = {"time": ("t",)}, set(), {}, {}
    for kind, stream in streams.items():
        names = stream.fields if stream.qualified else tuple(f"{stream.path.name}/{f}" for f in stream.fields)
        if kind == "gyro":
            values = stream.values
        else:
            # an integer clock beside a float one (a first time written "0") is compared in float: clocks that differ
            # leave no sample near a gyro row, which is refused below
            rows, times, clock = _common_clock(gyro, unit, stream, time_unit)
            values, index = place_on_rows(rows, times, stream.values, index=True)
            # a sensor vanishing is no answer (a file of empty cells is the reader's checks' business)
            if rows.size and np.isnan(values).all() and not np.isnan(stream.values).all():
                raise ValueError(
                    f"{stream.path}: none of its {stream.t.size} samples lies within a sample period of the gyro's "
                    f"rows ({gyro.path.name}): its times run {float(times[0]):.6g} .. {float(times[-1]):.6g} and "
                    f"the gyro's 0 .. {float(rows[-1]):.6g} ({clock} from the gyro's first sample); the files do "
                    "not share a clock"
                )
            if np.isnan(values).all(axis=1).any():
                sparse.update(names)
        for i, n in enumerate(names):
            cols[n] = values[:, i]
            if stream.unit:
                units[n] = stream.unit
            # where a reading is in its own file, for messages: the gyro's rows are the table's, another
            # sensor's sample on row r is its row index[r]
            located[n] = (stream.path, stream.where, None if kind == "gyro" else index)
        src_presets[kind] = names
    src = MemorySource(label, cols, format)
    src.presets, src.sparse, src.units, src.located = src_presets, sparse, units, located
    src.located["t"] = (gyro.path, gyro.where, None)
    kind = origin_kind or origin_of(gyro.first, unit).kind
    src.time_origin = TimeOrigin(gyro.first, unit, kind)
    return src


_NS = {"ns": 1, "us": 1_000, "ms": 1_000_000, "s": 1_000_000_000}  # integer factors: exact for integer clocks


def _common_clock(gyro: Stream, unit: str, stream: Stream, declared: str | None):
    """The gyro's and another stream's times in one unit (returned third), from the gyro's first sample.

    A file whose time column names its own unit (``time_us`` beside a gyro's ``time_ns``) is converted: taken
    in the gyro's unit, none of its samples would land near a gyro row and the sensor would silently vanish.
    """
    own = unit if declared else (_hint(stream.time_field) or unit)
    if own == unit:
        return gyro.t, stream.t + (stream.first - gyro.first), unit  # exact for integers: both are Python ints
    factor = _NS if stream.integer else _PER_S
    offset = stream.first * factor[own] - gyro.first * factor[unit]  # Python ints for integer clocks
    return gyro.t * factor[unit], stream.t * factor[own] + offset, "ns" if stream.integer else "s"


def _hint(name: str) -> str | None:
    from ..columns import split_name

    return split_name(name, "time")[1]


def open_streams(paths, kinds: dict | None = None, opener=None, picks: dict | None = None) -> dict:
    """The sensor streams of several files: ``{"gyro": Stream, ...}``, each sensor from one of them.

    Parameters
    ----------
    paths : sequence of pathlib.Path
        The files; each may hold one sensor or several (:func:`read_streams`).
    kinds : dict of pathlib.Path to str, optional
        The sensor of a file when its name does not tell it.
    opener : callable, optional
        ``opener(path) -> Source`` for each file; by default the CSV reader (a phone export's files are CSV).
    picks : dict of pathlib.Path to dict, optional
        Columns given per file and sensor (``{Path("imu.csv"): {"acc": "AccX,AccY,AccZ"}}``): a file named here
        gives only the sensors named, and those from no other file.

    Returns
    -------
    dict of str to Stream
        By sensor.

    Examples
    --------
    >>> from strapdown.io.formats.multi import open_streams
    >>> open_streams([])
    {}
    """
    if opener is None:
        from .csv import open_csv as opener

    picks = picks or {}
    given = {k for chosen in picks.values() for k in chosen if k != "time"}
    streams = {}
    for p in paths:
        with opener(p) as src:
            found = read_streams(src, (kinds or {}).get(p), picks=picks.get(p))
        for s in found:
            if s.kind in given and s.kind not in picks.get(p, {}):
                continue  # that sensor is named in another file
            if s.kind in streams:
                raise ValueError(
                    f"{p} and {streams[s.kind].path} both hold {s.kind} readings; give one file per sensor, or name "
                    f"the one to use: --{s.kind} {p.name}:{','.join(s.fields)}"
                )
            streams[s.kind] = s
    return streams


def open_files(
    paths, format: str | None = None, time_unit: str | None = None, *, opener=None, picks=None, **options
) -> MemorySource:
    r"""Several files of one recording as one table (see the module's description).

    Parameters
    ----------
    paths : sequence of pathlib.Path
        The files (one per sensor), in any order.
    format : str, optional
        ``"files"`` or None (the other formats take one path).
    time_unit : str, optional
        The unit of the files' time columns.
    opener : callable, optional
        ``opener(path) -> Source`` for each file (:func:`strapdown.io.open_source` when the files may be of
        any format); CSV by default.
    picks : dict of pathlib.Path to dict, optional
        Columns given per file and sensor (:func:`open_streams`).
    **options
        None accepted.

    Returns
    -------
    MemorySource
        The merged readings.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io import open_source
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "gyr.csv").write_text("t,x,y,z\n0.00,0,0,0\n0.01,0,0,0\n0.02,0,0,0\n")
    >>> _ = (folder / "acc.csv").write_text("t,x,y,z\n0.012,0,0,9.8\n")
    >>> src = open_source([folder / "gyr.csv", folder / "acc.csv"])
    >>> src.rows, src.sparse == {"acc.csv/x", "acc.csv/y", "acc.csv/z"}
    (3, True)
    """
    if format not in (None, "files"):
        raise ValueError(f"several input files are read as one recording (format 'files'), not as {format!r}")
    given = {k: v for k, v in options.items() if v is not None}
    if given:
        raise ValueError(f"several input files take no option {', '.join(sorted(given))}")
    for p in paths:
        if not p.is_file():
            raise FileNotFoundError(f"no such file: {p}")
    streams = open_streams(paths, opener=opener, picks=picks)
    src = merge_streams(paths[0], streams, "files", time_unit=time_unit)
    if all(first_line(p.parent, p.name).startswith("time,seconds_elapsed,z,y,x") for p in paths):
        src.frame, src.body = "ENU", "RFU"  # Sensor Logger's files given one by one: Android's axes
    return src


class Unzipped:
    """The members of a zip taken out into a temporary folder (removed on :meth:`close`), by base name only.

    Only regular files are taken, under their base names (no ``../`` or absolute paths can escape), and their
    declared sizes must stay under :data:`MAX_UNZIPPED_BYTES` together.
    """

    def __init__(self, path: Path, wanted):
        self.folder = Path(tempfile.mkdtemp(prefix="strapdown-unzip-"))
        try:
            with zipfile.ZipFile(path) as z:
                infos = [i for i in z.infolist() if not i.is_dir() and wanted(Path(i.filename).name)]
                total = sum(i.file_size for i in infos)
                if total > MAX_UNZIPPED_BYTES:
                    raise ValueError(
                        f"{path}: its files would expand to {total / 2**20:.1f} MiB, past the "
                        f"{MAX_UNZIPPED_BYTES / 2**20:.0f} MiB read from a zip; unpack it and give the folder"
                    )
                left = MAX_UNZIPPED_BYTES
                for info in infos:
                    target = self.folder / Path(info.filename).name
                    with z.open(info) as f, open(target, "wb") as out:
                        while block := f.read(min(1 << 20, left + 1)):
                            left -= len(block)
                            if left < 0:  # more than its sizes said: a lying zip, stopped here
                                raise ValueError(
                                    f"{path}: {info.filename} expands past the "
                                    f"{MAX_UNZIPPED_BYTES / 2**20:.0f} MiB read from a zip (it declares "
                                    f"{info.file_size} bytes); unpack it and give the folder"
                                )
                            out.write(block)
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Remove the temporary folder."""
        shutil.rmtree(self.folder, ignore_errors=True)


def zip_names(path: Path) -> list[str]:
    """The base names of a zip's files (empty for a file that is no zip)."""
    try:
        with zipfile.ZipFile(path) as z:
            return [Path(i.filename).name for i in z.infolist() if not i.is_dir()]
    except zipfile.BadZipFile:
        return []


def first_line(path: Path, name: str) -> str:
    """The first line of the file ``name`` in a folder (or one of its subfolders) or a zip; "" if absent."""
    if path.is_dir():
        found = find_in_folder(path, name)
        if found is None:
            return ""
        with open(found, encoding="utf-8-sig", errors="replace") as f:
            return f.readline(MAX_HEADER_BYTES)
    if zipfile.is_zipfile(path):
        with zipfile.ZipFile(path) as z:
            for info in z.infolist():
                if Path(info.filename).name == name and not info.is_dir():
                    with z.open(info) as f:
                        return f.readline(MAX_HEADER_BYTES).decode("utf-8-sig", errors="replace")
    return ""


def find_in_folder(folder: Path, name: str) -> Path | None:
    """``folder/name``, or ``folder/*/name`` when the export sits one folder down."""
    direct = folder / name
    if direct.is_file():
        return direct
    return next((p for p in sorted(folder.glob(f"*/{name}")) if p.is_file()), None)


class Export:
    """The files of an export folder or zip, by name: :meth:`get` gives a readable path or None."""

    def __init__(self, path: Path, names):
        self.path = path
        self._unzipped = Unzipped(path, lambda n: n in set(names)) if path.is_file() else None
        self._folder = self._unzipped.folder if self._unzipped else path

    def get(self, name: str) -> Path | None:
        """The file ``name`` of the export, or None."""
        return find_in_folder(self._folder, name)

    def sensor_files(self, preferences: dict) -> dict:
        """The first present of each sensor's file names, as ``{path: kind}``."""
        chosen = {}
        for kind, names in preferences.items():
            found = next((p for p in map(self.get, names) if p is not None), None)
            if found is not None:
                chosen[found] = kind
        return chosen

    def close(self) -> None:
        """Remove what was unzipped."""
        if self._unzipped is not None:
            self._unzipped.close()

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        self.close()
        # a member's error names the temporary folder it was unpacked to: name the zip and the member instead
        if self._unzipped is not None and isinstance(exc, ValueError) and str(self._folder) in str(exc):
            raise ValueError(str(exc).replace(f"{self._folder}{os.sep}", f"{self.path}: ")) from None
