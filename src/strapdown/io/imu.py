"""IMU readings from a file, in SI units and checked, a chunk of rows at a time.

:class:`ImuColumns` says where the readings are and in which units (everything it leaves out is detected from
the column names); :class:`ImuFile` resolves that against a file and yields :class:`ImuChunk` objects of
times (s), gyro (rad/s, or rad for increments), accelerometer (m/s²) and magnetometer (µT) readings.

Every chunk is checked before anything is computed from it, and a problem raises ``ValueError`` with what a
user needs to fix it: the file, the column and the line (CSV) or row:

* a column that is not there (the message lists those that are), arrays of different lengths (HDF5, .mat);
* NaN, empty or infinite values (the first line numbers);
* time that does not increase (where, and the two values), gaps longer than ``max_gap`` sample periods;
* magnitudes no sensor reads in any unit (:data:`strapdown.io.plausibility.LIMITS`: 1e4 rad/s, 1e7 m/s², 1e7 µT),
  the line and column named, in every chunk and whatever ``unit_check`` says;
* units that the magnitudes contradict (:func:`strapdown.io.plausibility.check_plausible`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np

from .columns import Pick, describe_fields, detect_rate, detect_time, detect_vector, no_header_row, pick_vector
from .formats.multi import kind_of_file
from .plausibility import ZEROED_RUN, check_chunk, probe, zeroed_rows
from .readers import Source, check_chunk_rows, open_source, require_rows
from .timebase import check_period, infer_time_unit, origin_of
from .units import (
    parse_unit,
    scale,
)

__all__ = ["ImuChunk", "ImuColumns", "ImuFile", "read_imu"]

_KINDS = ("gyro", "acc", "mag")
_LOOKED_FOR = {
    "gyro": "gx,gy,gz / gyr_x.. / gyro_x.. / wx.. / gyr, gyro, imu_gyr (N, 3)",
    "acc": "ax,ay,az / acc_x.. / accel_x.. / acc, imu_acc (N, 3)",
    "mag": "mx,my,mz / mag_x.. / mag, imu_mag (N, 3)",
}


@dataclass(frozen=True)
class ImuColumns:
    """Where the readings are in a file and their units; None means: detect from the names.

    Attributes
    ----------
    gyro, acc, mag : str, optional
        Three comma-separated columns (``"gx,gy,gz"``) or one (N, 3) array (``"imu_gyr"``); in a file without a
        header row, column numbers (``"2,3,4"``, 1 the first).  With several input files, ``FILE:COLS`` names
        the file too (``"imu.csv:AccX,AccY,AccZ"``; FILE as given or its name).
    time : str, optional
        The time column (``FILE:COL`` as above).  Times are counted from the first sample; integers (epoch
        nanoseconds, µs since boot) exactly, in integer arithmetic, with their unit inferred from the median
        step unless ``time_unit`` says it (:mod:`strapdown.io.timebase`).
    rate : float, optional
        Sample rate in Hz, for files without time (row k is at k / rate).
    gyro_unit, acc_unit, mag_unit, time_unit : str, optional
        Units (:data:`strapdown.io.units.UNITS`); by default the unit written in the column name, else
        rad/s, m/s2, uT and s.  For gyro increments rad/s means rad and deg/s means deg.
    extra : tuple of (str, str)
        Further inputs of an estimator: (keyword, columns), e.g. ``("known_acc", "kx,ky,kz")``; ``known_acc``
        is in the accelerometer's unit.
    max_gap : float
        Largest step allowed between two times, in nominal sample periods (0: no check).
    unit_check : bool
        Check that the magnitudes fit the units.  Magnitudes no sensor reads in any unit
        (:data:`strapdown.io.plausibility.LIMITS`) are refused either way: no estimator can use them.
    format : str, optional
        The input format when the layout or suffix does not tell it (:data:`strapdown.io.readers.INPUT_FORMATS`).
    topic : str, optional
        The IMU topic of a bag (``"/imu/data"``) or ULog (``"sensor_gyro"``); needed when there are several.
    mag_topic : str, optional
        The magnetometer topic of a bag (``sensor_msgs/MagneticField``) or ULog.
    """

    gyro: str | None = None
    acc: str | None = None
    mag: str | None = None
    time: str | None = None
    rate: float | None = None
    gyro_unit: str | None = None
    acc_unit: str | None = None
    mag_unit: str | None = None
    time_unit: str | None = None
    extra: tuple = ()
    max_gap: float = 10.0
    unit_check: bool = True
    format: str | None = None
    topic: str | None = None
    mag_topic: str | None = None

    def __post_init__(self):
        # NaN would switch the check off without a word, a negative limit would fail every file
        if not (isinstance(self.max_gap, int | float) and self.max_gap >= 0):
            raise ValueError(f"max_gap must be a number of sample periods >= 0 (0: no check), got {self.max_gap!r}")


@dataclass
class ImuChunk:
    """Rows ``row`` to ``row + len - 1`` of a file, in SI units.

    Attributes
    ----------
    row : int
        First row (0-based).
    t : numpy.ndarray, shape (n,)
        Times, s.
    gyro : numpy.ndarray, shape (n, 3)
        rad/s (rad for increments).
    acc, mag : numpy.ndarray of shape (n, 3), or None
        m/s² and µT, when read.
    extra : dict
        Estimator inputs by keyword.
    """

    row: int
    t: np.ndarray
    gyro: np.ndarray
    acc: np.ndarray | None = None
    mag: np.ndarray | None = None
    extra: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return self.t.shape[0]


def _file_picks(path, spec: ImuColumns) -> tuple[ImuColumns, dict]:
    """The ``FILE:COLS`` columns of ``spec`` as ``{Path: {kind: COLS}}`` for several files, and the spec without them.

    For one file, ``FILE:COLS`` naming that file is its ``COLS``; for several, a ``time`` without a file is
    every file's time column.
    """
    from dataclasses import replace
    from pathlib import Path

    paths = [Path(p) for p in path] if isinstance(path, list | tuple) else [Path(path)]
    picks: dict = {}
    changes = {}
    for kind in ("gyro", "acc", "mag", "time"):
        given = getattr(spec, kind)
        if given and kind == "time" and ":" not in given and len(paths) > 1:
            for p in paths:  # one time column name (or number) for every file
                picks.setdefault(p, {})["time"] = given
            changes["time"] = None
        if not given or ":" not in given:
            continue
        name, cols = given.rsplit(":", 1)
        match = [p for p in paths if str(p) == name or p.name == name]
        if not match:
            if len(paths) == 1:
                continue  # a column name with a colon in it
            shown = ", ".join(p.name for p in paths)
            raise ValueError(f"--{kind} {given}: {name} is none of the inputs ({shown})")
        if len(paths) == 1:
            changes[kind] = cols
        else:
            picks.setdefault(match[0], {})[kind] = cols
            changes[kind] = None
    return (replace(spec, **changes) if changes else spec), picks


class ImuFile:
    """A file of IMU readings: the columns resolved, units fixed, and checked chunks on demand.

    Parameters
    ----------
    path : path-like or sequence of path-like
        Any input :func:`strapdown.io.open_source` takes: a table, a ULog, a bag, an export folder or zip, or
        several files of one recording (one per sensor).
    columns : ImuColumns, optional
        Mapping and units (detected where left out).
    require : tuple of str
        Quantities that must be present (of "gyro", "acc", "mag").
    optional : tuple of str
        Quantities read when present.
    increments : bool
        The gyro holds angle increments (for the unit check).

    Attributes
    ----------
    source : Source
        The open file.
    picks : dict of str to Pick
        The fields of each quantity read.
    units : dict of str to str
        The unit of each quantity read.
    rows : int or None
        Number of rows when known without a pass over the file.
    rate : float or None
        Sample rate (Hz) when rows are timed by a rate, not a column.
    format : str
        The input format read.
    frame, body : str or None
        The reference frame and sensor axes the format documents (ULog NED/FRD, ROS ENU/FLU, Android phones
        ENU/RFU), None when the file does not say: defaults for the estimators' ``frame`` and the CLI's
        ``--frame``/``--body``.
    time_origin : TimeOrigin or None
        What t = 0 is: the first sample's time on the file's clock (epoch, boot, or the file's own); None for
        rows timed by a rate.
    period : float or None
        The median sample period, s (from the first rows).
    sparse : set of str
        The quantities ("acc", "mag") whose rows may be all NaN: no sample then (a slower sensor on the
        gyro's rows, :mod:`strapdown.io.merge`).
    notes : list of str
        What the checks found and accepted (a normalised magnetometer).

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import ImuFile, write_table
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "log.parquet"
    >>> _ = write_table(path, {"time": np.arange(3) * 0.01, "Gyro X [dps]": np.full(3, 90.0),
    ...                        "Gyro Y [dps]": np.zeros(3), "Gyro Z [dps]": np.zeros(3)})
    >>> imu = ImuFile(path)
    >>> print(imu.describe())
    gyro: Gyro X [dps],Gyro Y [dps],Gyro Z [dps] (deg/s); time: time (s)
    >>> next(imu.chunks(100)).gyro[0].round(6)
    array([1.570796, 0.      , 0.      ])
    """

    def __init__(
        self,
        path,
        columns: ImuColumns | None = None,
        *,
        require: tuple = ("gyro",),
        optional: tuple = (),
        increments: bool = False,
    ):
        self.spec = columns or ImuColumns()
        self.spec, picks = _file_picks(path, self.spec)
        options = {k: getattr(self.spec, k) for k in ("topic", "mag_topic", "time_unit") if getattr(self.spec, k)}
        if picks:
            options["picks"] = picks
        self.source: Source = open_source(path, self.spec.format, **options)
        self.path = self.source.path
        self.format = self.source.format
        self.frame, self.body = self.source.frame, self.source.body
        self.notes: list[str] = []
        try:
            self._resolve(require, optional, increments)
        except BaseException:
            self.source.close()
            raise

    # ------------------------------------------------------------------------------------------------
    def _resolve(self, require, optional, increments) -> None:
        spec, fields = self.spec, self.source.fields
        self.picks: dict[str, Pick] = {}
        self.units: dict[str, str] = {}
        for kind in (*require, *optional):
            given = getattr(spec, kind)
            if given:
                pick = pick_vector(given, fields, f"--{kind}")
            elif kind in self.source.presets:
                pick = Pick(tuple(self.source.presets[kind]))
            else:
                # bare x, y, z columns count for the sensor a file is named after (Gyroscope.csv)
                bare = self.source.format == "csv" and kind_of_file(self.path.name) == kind
                pick = detect_vector(kind, fields, units=self.source.units, bare=bare)
            if pick is None:
                if kind in require and getattr(self.source, "headerless", False):
                    raise no_header_row(self.path, fields, f"{kind} columns")
                if kind in require:
                    raise ValueError(
                        f"{self.path}: no {kind} columns found (looked for {_LOOKED_FOR[kind]}); name them with "
                        f"--{kind}.  The file has: {describe_fields(fields)}"
                    )
                continue
            self.picks[kind] = pick
            declared = getattr(spec, f"{kind}_unit")
            stated = next((self.source.units[f] for f in pick.fields if f in self.source.units), None)
            hint = pick.unit_hint or (parse_unit(kind, stated, strict=False) if stated else None)
            self.units[kind] = parse_unit(kind, declared) if declared else (hint or _SI[kind])
        self.extra: dict[str, Pick] = {}
        for name, cols in spec.extra:
            n_given = len([c for c in cols.split(",") if c.strip()])
            width = n_given if n_given > 1 else fields.get(cols.strip(), 1)
            self.extra[name] = pick_vector(cols, fields, f"--extra {name}", width=width)
        self.sparse = {k for k, p in self.picks.items() if k != "gyro" and set(p.fields) & self.source.sparse}
        self._resolve_time()
        self.increments = increments
        self.rows = self._check_lengths()
        # an output of no rows would look like a result; CSV, Parquet, HDF5 and .mat alike stop here
        require_rows(self.path, 0 if self.source.rows == 0 else self.rows)
        self._probe()

    def _resolve_time(self) -> None:
        spec, fields = self.spec, self.source.fields
        if spec.time and spec.rate:
            raise ValueError("give the time column (--time) or the sample rate (--rate), not both")
        self.time: Pick | None = None
        self.rate: float | None = None
        if spec.rate is not None:
            if not (np.isfinite(spec.rate) and spec.rate > 0):
                raise ValueError(f"--rate must be a positive number of Hz, got {spec.rate!r}")
            self.rate = float(spec.rate)
        elif spec.time:
            self.time = pick_vector(spec.time, fields, "--time", width=1)
        elif "time" in self.source.presets:
            self.time = Pick(tuple(self.source.presets["time"]))
        else:
            self.time = detect_time(fields)
            if self.time is None:
                self.rate = detect_rate(self.source.scalars)
            if self.time is None and self.rate is None and getattr(self.source, "headerless", False):
                raise no_header_row(self.path, fields, "time column")
            if self.time is None and self.rate is None:
                raise ValueError(
                    f"{self.path}: no time column found (looked for t, time, timestamp, ts, time_s, ...) and no "
                    f"sampling rate stored in the file; give --time COLUMN or --rate HZ.  The file has: "
                    f"{describe_fields(fields)}"
                )
        self._timestamps = self.time is not None and self.source.is_timestamp(self.time.fields[0])
        self.time_origin = None
        self.period = None if self.rate is None else 1.0 / self.rate
        self._t0 = 0.0
        if self.time is not None:
            # a decoded log's t is seconds already: a --time-unit was the reader's, for the files' own columns
            declared = "s" if self.source.time_in_seconds else self.spec.time_unit
            stated = self.source.units.get(self.time.fields[0])  # a unit row
            hint = self.time.unit_hint or (parse_unit("time", stated, strict=False) if stated else None)
            self.units["time"] = parse_unit("time", declared) if declared else (hint or "s")
            self._resolve_time_unit(declared is not None or hint is not None)

    def _resolve_time_unit(self, stated: bool) -> None:
        """Infer an integer column's unit from its steps, check the period, and find what t = 0 is."""
        name = self.time.fields[0]
        integer = name in self.source.integers and not self._timestamps
        relative = (name,) if integer else ()
        values = self._head(relative)[name]
        steps = np.diff(values[np.isfinite(values)])
        step = float(np.median(steps)) if steps.size else None
        if self._timestamps:
            first = self.source.origins.get(name)
            self.time_origin = (
                None if first is None else origin_of(int(np.datetime64(first, "ns").astype(np.int64)), "ns")
            )
            unit = "s"
        else:
            first = int(self.source.origins[name]) if integer and name in self.source.origins else None
            if first is None:
                first = float(values[0]) if values.size else 0.0
            if integer and not stated and step:
                unit, _ = infer_time_unit(step, first, name, str(self.path))
                self.units["time"] = unit
            unit = self.units["time"]
            if not integer:
                self._t0 = float(values[0]) if values.size else 0.0
            self.time_origin = self.source.time_origin or (origin_of(first, unit) if values.size else None)
        if step:
            check_period(step, unit, name, str(self.path))
            self.period = step * scale("time", unit)

    def _check_lengths(self) -> int | None:
        """The rows of the fields read (HDF5 and .mat store each field's length; they must agree)."""
        lengths = self.source.lengths
        if not lengths:
            return self.source.rows
        used = [(k, p) for k, p in self.picks.items()] + [(f"--extra {k}", p) for k, p in self.extra.items()]
        if self.time is not None:
            used.append(("time", self.time))
        sizes = [(k, f, lengths[f]) for k, p in used for f in p.fields]
        if len({s for _, _, s in sizes}) > 1:
            listing = ", ".join(f"{k} {f!r} has {s}" for k, f, s in sizes)
            raise ValueError(f"{self.path}: the readings have different lengths: {listing} rows; they must match")
        return sizes[0][2]

    # ------------------------------------------------------------------------------------------------
    def describe(self) -> str:
        """What is read from where, in which unit: one line."""
        parts = [f"{k}: {p.label} ({self.units[k]})" for k, p in self.picks.items()]
        parts += [f"{k}: {p.label}" for k, p in self.extra.items()]
        if self.time is None:
            parts.append(f"rate: {self.rate:g} Hz")
        elif self._timestamps:
            parts.append(f"time: {self.time.label} (date-times, in s from the first)")
        else:
            parts.append(f"time: {self.time.label} ({self.units['time']})")
        if self.time_origin is not None and self.time_origin.kind != "file":
            parts.append(f"t = 0 at {self.time_origin}")
        if self.sparse:
            parts.append(f"{' and '.join(sorted(self.sparse))} at lower rates (NaN rows: no sample)")
        if self.frame or self.body:
            parts.append(f"frames: {self.frame or '?'}/{self.body or '?'} ({self.format})")
        parts += self.notes
        return "; ".join(parts)

    def _head(self, relative=()) -> dict:
        """The first 4096 rows of the time, gyro, accelerometer and magnetometer fields, read once.

        One pass serves both the time-unit inference and the checks of :meth:`_probe`.
        """
        if getattr(self, "_head_cols", None) is None:
            names = list(self.time.fields) if self.time is not None else []
            names += [f for k in ("gyro", "acc", "mag") if k in self.picks for f in self.picks[k].fields]
            names = list(dict.fromkeys(names))
            empty = {n: np.zeros(0 if self.source.fields[n] == 1 else (0, self.source.fields[n])) for n in names}
            self._head_cols = next(iter(self.source.chunks(names, 4096, 0, 4096, relative=relative)), (0, empty))[1]
        return self._head_cols

    def _probe(self) -> None:
        """Checks on the first rows (:func:`strapdown.io.plausibility.probe`)."""
        if not self.spec.unit_check or not any(k in self.picks for k in ("acc", "mag")):
            return  # the gyro alone has nothing to be checked against
        cols = self._head()
        if len(next(iter(cols.values()))):
            probe(self, {kind: _assemble(cols, pick) for kind, pick in self.picks.items() if kind in _KINDS})

    def head(self, kind: str) -> np.ndarray | None:
        """The first rows (up to 4096) of a sensor's readings in SI units (rad/s for the gyro), or None."""
        if kind not in self.picks:
            return None
        values = _assemble(self._head(), self.picks[kind]) * scale(kind, self.units[kind])
        if kind == "gyro" and self.increments:
            values = values / self.period if self.period else np.full_like(values, np.nan)
        return values

    def gyro_noise(self) -> float:
        """The white noise of one gyro sample in the first rows, rad/s (:func:`strapdown.io.conventions.gyro_noise`)."""
        from .conventions import gyro_noise

        if getattr(self, "_noise", None) is None:
            self._noise = gyro_noise(self.head("gyro"))
        return self._noise

    def count_rows(self) -> int:
        """Number of rows (a pass over a CSV file)."""
        if self.rows is None:
            self.rows = self.source.count_rows()
        return self.rows

    def where(self, row: int) -> str:
        """Where a row is, for messages: ``"line 12"`` (CSV) or ``"row 10"``."""
        return self.source.where(row)

    def file_of(self, kind: str):
        """The file that holds a quantity's readings ("gyro", "acc", "mag", "time"), for messages.

        The input itself, except for several files of one recording, where each sensor names its own file.
        """
        pick = self.time if kind == "time" else self.picks.get(kind)
        located = getattr(self.source, "located", None) or {}
        field = pick.fields[0] if pick is not None else None
        return located[field][0] if field in located else self.path

    def locate(self, field: str, row: int) -> tuple:
        """(file, where) of a field's reading on a row: ``(Accelerometer.csv, "line 7")`` in a merged recording.

        A slower sensor's row of the merged table is its own sample's row in its own file; a row where it has no
        sample is told by the table's row.
        """
        located = getattr(self.source, "located", None) or {}
        if field not in located:
            return self.path, self.where(row)
        path, where, index = located[field]
        own = row if index is None else int(index[row])
        if where is None or own < 0:
            return path, f"row {row} of the merged table"
        return path, where(own)

    def close(self) -> None:
        """Release the file."""
        self.source.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def chunks(self, chunk_rows: int = 1 << 18, start: int = 0, stop: int | None = None) -> Iterator[ImuChunk]:
        """Checked chunks of rows ``start`` to ``stop`` in SI units.

        Parameters
        ----------
        chunk_rows : int
            Rows per chunk (about, for CSV); a positive integer.
        start, stop : int
            Row range; the whole file by default.

        Yields
        ------
        ImuChunk
            Times and readings; a ValueError at the first bad row.
        """
        names = [f for p in self.picks.values() for f in p.fields]
        names += [f for p in self.extra.values() for f in p.fields]
        if self.time is not None:
            names += list(self.time.fields)
        names = list(dict.fromkeys(names))
        chunk_rows = check_chunk_rows(chunk_rows)
        # integer times (epoch ns) count from the file's first, in integers: as float64 they would lose 0.2 µs
        relative = self.time.fields if self.time is not None and not self._timestamps else ()
        times = None  # the file's running time check, made by the first chunk's checks
        zeroed = [0, 0.0, 0.0]  # rows of a zeroed block: count, first and last time
        for row, cols in self.source.chunks(names, chunk_rows, start, stop, relative=relative):
            n = len(next(iter(cols.values()))) if cols else 0
            if self._timestamps:
                t = cols[self.time.fields[0]]  # already seconds
            elif self.time is not None:
                t = _in_si(cols[self.time.fields[0]] - self._t0, scale("time", self.units["time"]))
            else:
                t = (row + np.arange(n)) / self.rate
            raws = {kind: _assemble(cols, pick) for kind, pick in self.picks.items()}
            times = check_chunk(self, cols, raws, t, row, times)  # every check before any product can overflow
            zero = zeroed_rows(raws)
            if zero.any():
                zeroed = [zeroed[0] + int(zero.sum()), zeroed[1] if zeroed[0] else t[zero][0], t[zero][-1]]
            out = ImuChunk(row, t, gyro=None)
            for kind, raw in raws.items():
                factor = scale(kind, self.units[kind])
                # one field may be the reader's own (read-only) buffer: the product is then the copy to keep
                # (x * 1.0 is x: a value already in SI is not copied again)
                setattr(out, kind, raw if factor == 1.0 and len(self.picks[kind].fields) > 1 else raw * factor)
            for name, pick in self.extra.items():
                values = _assemble(cols, pick)
                if name == "known_acc" and "acc" in self.units:
                    values = values * scale("acc", self.units["acc"])
                out.extra[name] = values
            yield out
        if zeroed[0]:
            self.source.warnings.append(
                f"{self.path}: {zeroed[0]} rows between t = {zeroed[1]:.6g} and {zeroed[2]:.6g} s (file time) read "
                f"exactly 0 on an axis of the accelerometer or magnetometer for {ZEROED_RUN} rows or more in a "
                "row, which no sensor does: a zeroed block of a damaged file?"
            )


_SI = {"gyro": "rad/s", "acc": "m/s2", "mag": "uT"}


def _in_si(values: np.ndarray, factor: float) -> np.ndarray:
    """``values * factor``; the values themselves (a new array already) when already in SI: x * 1.0 is x."""
    return values if factor == 1.0 else values * factor


def _assemble(cols: dict, pick: Pick) -> np.ndarray:
    if len(pick.fields) == 1:
        v = cols[pick.fields[0]]
        return np.ascontiguousarray(v if v.ndim == 2 else v[:, None])
    return np.column_stack([cols[f] for f in pick.fields])


def read_imu(path, columns: ImuColumns | None = None, **kwargs) -> ImuChunk:
    """Read a whole IMU file into memory, converted to SI and checked (for files that fit in memory).

    Parameters
    ----------
    path : path-like
        A CSV, Parquet, HDF5 or MATLAB file.
    columns : ImuColumns, optional
        Mapping and units (detected where left out).
    **kwargs
        ``require``, ``optional``, ``increments``: see :class:`ImuFile`.

    Returns
    -------
    ImuChunk
        All rows.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import read_imu, write_table
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "log.csv"
    >>> _ = write_table(path, {"gx": np.zeros(4), "gy": np.zeros(4), "gz": np.ones(4),
    ...                        "ax": np.zeros(4), "ay": np.zeros(4), "az": np.ones(4)})
    >>> data = read_imu(path, columns=ImuColumns(rate=100.0, acc_unit="g"), optional=("acc",))
    >>> data.t, data.acc[0]
    (array([0.  , 0.01, 0.02, 0.03]), array([0.     , 0.     , 9.80665]))
    """
    with ImuFile(path, columns, **kwargs) as imu:
        parts = list(imu.chunks(1 << 22))
    if not parts:
        raise ValueError(f"{path}: no rows")

    def cat(name):
        values = [getattr(p, name) for p in parts]
        return None if values[0] is None else np.concatenate(values)

    extra = {k: np.concatenate([p.extra[k] for p in parts]) for k in parts[0].extra}
    return ImuChunk(0, cat("t"), cat("gyro"), cat("acc"), cat("mag"), extra)
