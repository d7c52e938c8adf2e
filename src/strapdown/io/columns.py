"""Which columns of a file hold the gyro, accelerometer, magnetometer and time: explicit or detected.

A vector quantity comes from three 1-D columns (``gx,gy,gz``) or one (N, 3) array (``imu_gyr`` in a .mat or
HDF5 file).  Without an explicit mapping the names are matched, case and punctuation aside, against the usual
spellings: a stem (``gyr``, ``gyro``, ``g``, ``w``, ``omega``, ``acc``, ``accel``, ``a``, ``mag``, ``m``, ...), an
optional ``imu`` in front and an axis letter after, with a unit at the end or in brackets (``gyro_x_dps``,
``Acc X [g]``).  A unit found in a header is used when none is given on the command line.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass

from .units import parse_unit, split_name

__all__ = [
    "Pick",
    "describe_fields",
    "detect_rate",
    "detect_time",
    "detect_vector",
    "no_header_row",
    "pick_vector",
    "split_name",
]

_STEMS = {
    # wrss / arss: ASL/EuRoC/TUM-VI's w_RS_S and a_RS_S (of sensor S relative to R, in S)
    "gyro": (
        "gyr",
        "gyro",
        "gyros",
        "gyroscope",
        "g",
        "w",
        "omega",
        "angvel",
        "angularvelocity",
        "angularrate",
        "wrss",
        "rotationrate",
    ),
    "acc": (
        "acc",
        "accel",
        "accelerometer",
        "acceleration",
        "a",
        "f",
        "specificforce",
        "linearacceleration",
        "arss",
    ),
    "mag": ("mag", "magnetometer", "m", "b", "magneticfield", "field"),
}
_TIME = ("t", "time", "times", "timestamp", "timestamps", "ts", "sec", "seconds", "timesec", "stamp")
# a unit glued to the name without a separator: ArduPilot's TimeUS (and TimeMS of older logs)
_GLUED_TIME = {"timeus": "us", "timems": "ms"}
_RATE = ("rate", "samplingrate", "samplerate", "fs", "frequency", "freq", "ratehz", "samplingfrequency", "hz")
_AXES = "xyz"
_KINDS = ("gyro", "acc", "mag", "time")


@dataclass(frozen=True)
class Pick:
    """Where a quantity is: the fields read and how to assemble them.

    Attributes
    ----------
    fields : tuple of str
        Three 1-D fields (x, y, z), or one (N, k) field.
    unit_hint : str or None
        A unit read from the header, if any.
    """

    fields: tuple
    unit_hint: str | None = None

    @property
    def label(self) -> str:
        """The fields as written on a command line."""
        return ",".join(self.fields)


def no_header_row(path, fields: Mapping[str, int], what: str) -> ValueError:
    """The error for a file without a header row (its columns are named "1", "2", ...) whose ``what`` is not given.

    Parameters
    ----------
    path : pathlib.Path
        The file.
    fields : mapping of str to int
        Its columns.
    what : str
        What could not be found ("gyro columns", "time column").

    Returns
    -------
    ValueError
        Saying so, with the options that give the columns by number.

    Examples
    --------
    >>> from pathlib import Path
    >>> from strapdown.io.columns import no_header_row
    >>> str(no_header_row(Path("imu.csv"), {"1": 1, "2": 1}, "gyro columns"))[:60]
    'imu.csv has no header row (its first line is numbers), so no'
    """
    return ValueError(
        f"{path} has no header row (its first line is numbers), so no column name tells the {what}: give the "
        f"columns by number, 1 the first, e.g. --time 1 --gyro 2,3,4 --acc 5,6,7 (or --gyro {path.name}:2,3,4 "
        f"when several files are given); it has {len(fields)} columns"
    )


def describe_fields(fields: Mapping[str, int]) -> str:
    """The fields of a file for an error message: names, with (N, k) for arrays.

    Parameters
    ----------
    fields : mapping of str to int
        Field name to its width (1 for a column).

    Returns
    -------
    str
        Comma-separated.

    Examples
    --------
    >>> from strapdown.io.columns import describe_fields
    >>> describe_fields({"t": 1, "imu_gyr": 3})
    't, imu_gyr (N, 3)'
    """
    shown = [f"{n} (N, {w})" if w > 1 else n for n, w in itertools.islice(fields.items(), _SHOWN)]
    more = f" and {len(fields) - _SHOWN} more" if len(fields) > _SHOWN else ""  # a 100k-column header stays readable
    return ", ".join(shown) + more if shown else "(none)"


_SHOWN = 60


def _missing(name: str, option: str, fields: Mapping[str, int]) -> ValueError:
    return ValueError(f"no column {name!r} ({option}); the file has: {describe_fields(fields)}")


def pick_vector(spec: str, fields: Mapping[str, int], option: str, width: int = 3) -> Pick:
    """The fields named by a command-line spec: ``"gx,gy,gz"`` or one (N, 3) field ``"imu_gyr"``.

    Parameters
    ----------
    spec : str
        Comma-separated names.
    fields : mapping of str to int
        The file's fields and their widths.
    option : str
        The option that gave ``spec``, for messages.
    width : int
        Components wanted.

    Returns
    -------
    Pick
        One field of width ``width``, or ``width`` scalar fields in the order given.

    Examples
    --------
    >>> from strapdown.io.columns import pick_vector
    >>> pick_vector("wx, wy, wz", {"t": 1, "wx": 1, "wy": 1, "wz": 1}, "--gyro").fields
    ('wx', 'wy', 'wz')
    """
    names = tuple(s.strip() for s in spec.split(",") if s.strip())
    for n in names:
        if n not in fields:
            raise _missing(n, option, fields)
    if len(names) == 1 and fields[names[0]] == width:
        return Pick(names)
    if len(names) == width and all(fields[n] == 1 for n in names):
        return Pick(names)
    raise ValueError(
        f"{option} {spec!r} must name {width} columns or one (N, {width}) array; the file has: "
        f"{describe_fields(fields)}"
    )


def detect_vector(
    kind: str, fields: Mapping[str, int], width: int = 3, units: Mapping[str, str] | None = None, bare: bool = False
) -> Pick | None:
    """The fields holding ``kind`` ("gyro", "acc", "mag") by their names, or None when there are none.

    Parameters
    ----------
    kind : {"gyro", "acc", "mag"}
        The quantity.
    fields : mapping of str to int
        The file's fields and their widths.
    width : int
        Components wanted.
    units : mapping of str to str, optional
        Units stated apart from the names (a CSV unit row), by field.
    bare : bool
        Also take columns named by their axis alone (``x, y, z``, ``X (rad/s)``) as ``kind``: for a file that
        holds one sensor.  Without it such columns count only when their unit is one of ``kind``'s.

    Returns
    -------
    Pick or None
        The fields, with a unit read from their names.

    Raises
    ------
    ValueError
        When several sets of fields match (name one with an option).

    Examples
    --------
    >>> from strapdown.io.columns import detect_vector
    >>> detect_vector("gyro", {"time": 1, "Gyro X (dps)": 1, "Gyro Y (dps)": 1, "Gyro Z (dps)": 1})
    Pick(fields=('Gyro X (dps)', 'Gyro Y (dps)', 'Gyro Z (dps)'), unit_hint='deg/s')
    >>> detect_vector("acc", {"imu_gyr": 3, "imu_acc": 3}).fields
    ('imu_acc',)
    """
    stems = _STEMS[kind]
    units = units or {}
    whole, parts = [], {}
    for name, w in fields.items():
        base, unit = split_name(name, kind)
        if unit is None and name in units:
            unit = parse_unit(kind, units[name], strict=False)
        stem = base[3:] if base.startswith("imu") and base[3:] else base
        if w == width and stem in stems:
            whole.append(Pick((name,), unit))
        elif w == 1 and len(stem) > 1 and stem[-1] in _AXES and stem[:-1] in stems:
            parts.setdefault(stem[:-1], {})[stem[-1]] = (name, unit)
        elif w == 1 and len(stem) == 1 and stem in _AXES and (bare or unit is not None):
            parts.setdefault("", {})[stem] = (name, unit)
    found = list(whole)
    for by_axis in parts.values():
        if len(by_axis) == width:
            names = tuple(by_axis[a][0] for a in _AXES[:width])
            axis_units = {by_axis[a][1] for a in _AXES[:width]}
            found.append(Pick(names, axis_units.pop() if len(axis_units) == 1 else None))
    if len(found) > 1:
        option = {"gyro": "--gyro", "acc": "--acc", "mag": "--mag"}[kind]
        choices = "; ".join(p.label for p in found)
        raise ValueError(f"several column sets look like {kind}: {choices}; choose one with {option}")
    return found[0] if found else None


def detect_time(fields: Mapping[str, int]) -> Pick | None:
    """The time column by its name (``t``, ``time``, ``timestamp``, ``time_s``, ``timestamp_ns``, ...), or None.

    Parameters
    ----------
    fields : mapping of str to int
        The file's fields and their widths.

    Returns
    -------
    Pick or None
        The column, with a unit read from its name.

    Examples
    --------
    >>> from strapdown.io.columns import detect_time
    >>> detect_time({"timestamp_ms": 1, "gx": 1})
    Pick(fields=('timestamp_ms',), unit_hint='ms')
    >>> detect_time({"TimeUS": 1, "GyrX": 1})                   # ArduPilot's
    Pick(fields=('TimeUS',), unit_hint='us')
    """
    found = []
    for name, w in fields.items():
        base, unit = split_name(name, "time")
        if w == 1 and base in _GLUED_TIME and unit is None:
            found.append(Pick((name,), _GLUED_TIME[base]))
        elif w == 1 and base in _TIME:
            found.append(Pick((name,), unit))
    if len(found) > 1:
        raise ValueError(f"several columns look like time: {', '.join(p.label for p in found)}; choose with --time")
    return found[0] if found else None


def detect_rate(scalars: Mapping[str, float]) -> float | None:
    """A sampling rate stored as a scalar in the file (``sampling_rate``, ``fs``, ...), or None.

    Parameters
    ----------
    scalars : mapping of str to float
        The file's scalar values (.mat variables, HDF5 scalars and attributes).

    Returns
    -------
    float or None
        Hz.

    Examples
    --------
    >>> from strapdown.io.columns import detect_rate
    >>> detect_rate({"sampling_rate": 285.714})
    285.714
    """
    for name, value in scalars.items():
        if split_name(name)[0] in _RATE and value > 0:
            return float(value)
    return None
