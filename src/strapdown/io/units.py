"""Units of IMU columns: names and aliases, conversion to SI, and the unit written in a column's name.

The library computes in SI (rad/s, m/s², seconds); the magnetometer only matters by direction but is still
converted to µT so that its plausibility can be checked (:mod:`strapdown.io.plausibility`, which also refuses a
declared unit that the data contradict).
"""

from __future__ import annotations

import math
import re

from .._support.moved import names

__all__ = ["GRAVITY", "UNITS", "parse_unit", "scale", "split_name"]

# the plausibility checks lived here in release 0.1
__getattr__ = names(
    __name__,
    dict.fromkeys(
        ("LIMITS", "check_gravity_sign", "check_gyro_at_rest", "check_magnitude", "check_plausible", "row_norms"),
        "strapdown.io.plausibility",
    ),
)

GRAVITY = 9.80665

#: Canonical unit names per quantity, with the factor that takes a value to SI (µT for the magnetometer).
UNITS: dict[str, dict[str, float]] = {
    "gyro": {"rad/s": 1.0, "deg/s": math.pi / 180},
    "acc": {"m/s2": 1.0, "g": GRAVITY, "mg": GRAVITY / 1000},
    # "normalised": a field scaled to |m| ~ 1 (direction only, which is all the estimators use)
    "mag": {"uT": 1.0, "gauss": 100.0, "mG": 0.1, "nT": 1e-3, "mT": 1000.0, "normalised": 1.0},
    "time": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9},
}

# spellings met in headers and on command lines, compared after _norm (lower case, letters and digits only)
_ALIASES: dict[str, dict[str, str]] = {
    "gyro": {
        "rads": "rad/s",
        "rads1": "rad/s",  # EuRoC's "rad s^-1"
        "radpers": "rad/s",
        "radsec": "rad/s",
        "rad": "rad/s",
        "degs": "deg/s",
        "degs1": "deg/s",
        "degpers": "deg/s",
        "degsec": "deg/s",
        "dps": "deg/s",
        "deg": "deg/s",
    },
    "acc": {"ms2": "m/s2", "mps2": "m/s2", "mss": "m/s2", "mpss": "m/s2", "g": "g", "mg": "mg"},
    "mag": {
        "ut": "uT",
        "microtesla": "uT",
        "microteslas": "uT",
        "gauss": "gauss",
        "g": "gauss",
        "ga": "gauss",  # PX4's magnetometer_ga
        "mg": "mG",  # milligauss (mT is "mt": the case is gone, the letters differ)
        "milligauss": "mG",
        "mgauss": "mG",
        "nt": "nT",
        "mt": "mT",
        "normalised": "normalised",
        "normalized": "normalised",
        "1": "normalised",
    },
    "time": {"s": "s", "sec": "s", "seconds": "s", "ms": "ms", "us": "us", "ns": "ns"},
}


def _norm(text: str) -> str:
    # the non-ASCII spellings of units: µT, m/s², °/s (a degree sign dropped would leave "/s", read as rad/s)
    text = text.lower().replace("µ", "u").replace("μ", "u").replace("²", "2").replace("°", "deg").replace("º", "deg")
    return "".join(c for c in text if c.isascii() and c.isalnum())


def parse_unit(kind: str, text: str, *, strict: bool = True) -> str | None:
    """The canonical name of a unit of ``kind`` ("gyro", "acc", "mag", "time") from any common spelling.

    Parameters
    ----------
    kind : {"gyro", "acc", "mag", "time"}
        The quantity.
    text : str
        The unit as written: ``"deg/s"``, ``"dps"``, ``"m/s^2"``, ``"µT"``, ``"G"``, ...
    strict : bool
        Raise ValueError for an unknown unit (else return None).

    Returns
    -------
    str or None
        A key of ``UNITS[kind]``.

    Examples
    --------
    >>> from strapdown.io.units import parse_unit
    >>> parse_unit("gyro", "dps"), parse_unit("acc", "m/s^2"), parse_unit("mag", "µT")
    ('deg/s', 'm/s2', 'uT')
    """
    found = _ALIASES[kind].get(_norm(text))
    if found is None and strict:
        raise ValueError(f"unknown {kind} unit {text!r}; use one of {', '.join(UNITS[kind])}")
    return found


def scale(kind: str, unit: str) -> float:
    """The factor taking values of ``unit`` to SI (µT for ``"mag"``).

    Parameters
    ----------
    kind : {"gyro", "acc", "mag", "time"}
        The quantity.
    unit : str
        Any spelling :func:`parse_unit` knows.

    Returns
    -------
    float
        Multiply the file's values by it.

    Examples
    --------
    >>> from strapdown.io.units import scale
    >>> scale("acc", "g"), scale("time", "ms")
    (9.80665, 0.001)
    """
    return UNITS[kind][parse_unit(kind, unit)]


_ALL = ("gyro", "acc", "mag", "time")  # the quantities whose units a column name may carry


def split_name(name: str, kind: str | None = None) -> tuple[str, str | None]:
    """A field name without its unit, in lower-case letters and digits, and the unit if one is written.

    Parameters
    ----------
    name : str
        The field's name as in the file (``"Gyro X [deg/s]"``, ``"timestamp_ns"``, ``"imu/gyr"``).
    kind : {"gyro", "acc", "mag", "time"}, optional
        The quantity whose units are looked for (all when None).

    Returns
    -------
    base : str
        The name without the unit: ``"gyrox"``, ``"timestamp"``.
    unit : str or None
        The canonical unit when one is written.

    Examples
    --------
    >>> from strapdown.io.units import split_name
    >>> split_name("Gyro X [deg/s]", "gyro"), split_name("timestamp_ns", "time"), split_name("ax", "acc")
    (('gyrox', 'deg/s'), ('timestamp', 'ns'), ('ax', None))
    """
    kinds = (kind,) if kind else ("gyro", "acc", "mag", "time")
    indexed = re.match(r"^(.*\S)\[([0-2])\]$", name)  # PX4's gyro_rad[0]: an index, x y z
    if indexed:
        base, unit = split_name(indexed.group(1), kind)
        return base + "xyz"[int(indexed.group(2))], unit
    unit = None
    bracket = re.search(r"[\[(]([^\])]*)[\])]", name)
    if bracket:
        text = bracket.group(1).strip()
        # a bracket that names no unit of these kinds is passed on as written: used as a unit it stops with
        # "unknown unit", where ignoring it would read "[°C]" or "[krpm]" silently as SI
        unit = _first_unit(kinds, text) or (text if kind and _first_unit(_ALL, text) is None else None)
        name = name[: bracket.start()] + name[bracket.end() :]
    slashed = re.search(r"[_ \-]?([a-zµμ°]+/[a-z0-9^²]+)$", name, re.IGNORECASE)  # gyro_x_deg/s, ax m/s^2
    if slashed and _first_unit(_ALL, slashed.group(1)):
        # a unit of any kind is cut off, so that "gyro_x_rad/sec" is not taken for an HDF5 path ending in "sec"
        unit = unit or _first_unit(kinds, slashed.group(1))
        name = name[: slashed.start()]
    name = name.split("/")[-1]  # an HDF5 path: the last segment names the field
    tokens = re.findall(r"[a-z0-9]+", name.lower())
    # a unit spelt as the last one or two tokens (gyro_x_rad_s, acc_x_g), when something is left before it
    for k in (2, 1):
        if unit is None and len(tokens) > k:
            found = _first_unit(kinds, "".join(tokens[-k:]))
            if found:
                unit, tokens = found, tokens[:-k]
    return "".join(tokens), unit


def _first_unit(kinds, text: str) -> str | None:
    for k in kinds:
        u = parse_unit(k, text, strict=False)
        if u:
            return u
    return None
