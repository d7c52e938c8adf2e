"""Units of IMU columns: names and aliases, conversion to SI, and the checks that catch a wrong declaration.

The library computes in SI (rad/s, m/s², seconds); the magnetometer only matters by direction but is still
converted to µT so that its plausibility can be checked.  A declared unit that the data contradict (a gyro in
"rad/s" turning faster than any MEMS gyro can measure, an accelerometer in "m/s2" reading 1 at rest) is an
error with the fix in the message: silently integrating degrees as radians gives nonsense that looks fine.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["GRAVITY", "UNITS", "check_gravity_sign", "check_gyro_at_rest", "check_plausible", "parse_unit", "scale"]

GRAVITY = 9.80665

#: Canonical unit names per quantity, with the factor that takes a value to SI (µT for the magnetometer).
UNITS: dict[str, dict[str, float]] = {
    "gyro": {"rad/s": 1.0, "deg/s": math.pi / 180},
    "acc": {"m/s2": 1.0, "g": GRAVITY, "mg": GRAVITY / 1000},
    # "normalised": a field scaled to |m| ~ 1 (direction only, which is all the estimators use)
    "mag": {"uT": 1.0, "gauss": 100.0, "nT": 1e-3, "mT": 1000.0, "normalised": 1.0},
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


# A MEMS gyro's largest range is about ±2000°/s (35 rad/s); human and vehicle motion stays well below it.
_GYRO_MAX = 35.0
# Typical ranges of |value| in each declared unit, to say which unit a wrong declaration probably is.
# Past ±16 g (the largest range of consumer accelerometers) a median |a| is no accelerometer in that unit.
_ACC_MAX = 16 * GRAVITY
_ACC_AT_REST = {"m/s2": (6.0, 14.0), "g": (0.6, 1.4), "mg": (600.0, 1400.0)}
_EARTH_FIELD = {
    "uT": (15.0, 80.0),
    "gauss": (0.15, 0.8),
    "nT": (15e3, 80e3),
    "mT": (0.015, 0.08),
    "normalised": (0.5, 2.0),
}


def check_plausible(kind: str, raw: np.ndarray, unit: str, *, rate_hz: float | None = None) -> str | None:
    """A message when the magnitudes of ``raw`` (the file's values) contradict the declared ``unit``, else None.

    The gyro check flags rates beyond any MEMS gyro's range (±2000°/s) declared as rad/s; for increments
    give ``rate_hz`` and the increments are turned into rates.  The accelerometer and magnetometer checks
    compare the median magnitude with gravity and the Earth's field (15-80 µT) and name the unit it fits.

    Parameters
    ----------
    kind : {"gyro", "acc", "mag"}
        The quantity.
    raw : numpy.ndarray, shape (N, 3)
        Values as read (before conversion), finite.
    unit : str
        The declared unit (canonical name).
    rate_hz : float, optional
        Sample rate, for gyro increments.

    Returns
    -------
    str or None
        What looks wrong and how to say otherwise.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.units import check_plausible
    >>> check_plausible("acc", np.array([[0.0, 0.0, 1.0]] * 10), "m/s2")[:46]
    '|acc| is about 1 m/s2 (median), gravity is 9.8'
    >>> check_plausible("acc", np.array([[0.0, 0.0, 9.81]] * 10), "m/s2") is None
    True
    """
    if raw.shape[0] == 0:
        return None
    sub = raw[:: max(1, raw.shape[0] // 4096)]  # a few thousand rows tell the unit; the whole chunk costs more
    mags = np.sqrt(np.einsum("ij,ij->i", sub, sub))
    if kind == "gyro":
        if unit != "rad/s":
            return None
        rates = mags * rate_hz if rate_hz else mags
        high = float(np.percentile(rates, 99))
        if high > _GYRO_MAX:
            return (
                f"gyro magnitudes reach {high:.4g} rad/s, beyond the ±2000°/s range of any MEMS gyro: they look "
                "like deg/s.  Pass --gyro-unit deg/s, or --no-unit-check if they really are rad/s"
            )
        return None
    median = float(np.median(mags))
    table = _ACC_AT_REST if kind == "acc" else _EARTH_FIELD
    lo, hi = table[unit]
    if lo <= median <= hi:
        return None
    fits = [u for u, (a, b) in table.items() if u != unit and a <= median <= b]
    option = "--acc-unit" if kind == "acc" else "--mag-unit"
    if kind == "acc":
        si = median * UNITS["acc"][unit]
        # gravity keeps a fixed direction while the body moves little, so the mean vector is about as long as the
        # samples; with gravity removed the samples swing about zero and their mean vector is short
        steady = float(np.linalg.norm(sub.mean(axis=0))) / median if median > 0 else 0.0
        if fits and steady > 0.5:
            return (
                f"|acc| is about {median:.3g} {unit} (median), gravity is 9.81 m/s2: the values look like "
                f"{fits[0]}.  Pass {option} {fits[0]}, or --no-unit-check if {unit} is right"
            )
        if si < 0.5 * GRAVITY:
            return (
                f"|acc| is about {si:.3g} m/s2 (median) with a mean vector of {steady * si:.3g} m/s2, where an "
                "accelerometer reads gravity (9.81 m/s2) plus motion: this looks like a gravity-free 'linear "
                "acceleration' stream (phyphox's Linear Accelerometer, Sensor Logger's Accelerometer.csv), not the "
                "specific force the estimators need.  Use the file with gravity (phyphox Accelerometer, Sensor "
                "Logger TotalAcceleration.csv), or --no-unit-check"
            )
        if si < _ACC_MAX:
            return None  # sustained high g (aerobatics, a centrifuge): possible, and no unit fits better
        return (
            f"|acc| is about {median:.4g} {unit} (median) = {si:.4g} m/s2, far from gravity (9.81 m/s2) at any "
            f"unit ({', '.join(_ACC_AT_REST)}): raw sensor counts?  Scale them to a unit, or --no-unit-check"
        )
    if not fits:
        return None  # raw counts or an unusual field: the estimators use its direction only, so no complaint
    what = "the Earth's field is 25-65 uT"
    return (
        f"|{kind}| is about {median:.3g} {unit} (median), {what}: the values look like {fits[0]}.  "
        f"Pass {option} {fits[0]}, or --no-unit-check if {unit} is right"
    )


def check_gravity_sign(acc, body: str) -> str | None:
    """A message when an upright body's accelerometer reads gravity downwards at rest (a sign error), else None.

    At rest an accelerometer reads the specific force, +g along the body's up (``-z`` for FRD, ``+z`` for FLU
    or RFU).  A vehicle that starts upright (a drone on the ground) whose mean first reading points within 30°
    of the body's *down* is reporting acceleration with the opposite sign (or has its z axis flipped).

    Parameters
    ----------
    acc : numpy.ndarray, shape (N, 3)
        The first readings, m/s², finite.
    body : str
        The sensor axes (``"FRD"``, ``"FLU"``, ...).

    Returns
    -------
    str or None
        What looks wrong.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.units import check_gravity_sign
    >>> check_gravity_sign(np.tile([0.0, 0.0, -9.8], (50, 1)), "FRD") is None   # FRD at rest: up is -z
    True
    >>> check_gravity_sign(np.tile([0.0, 0.0, 9.8], (50, 1)), "FRD")[:40]
    'the accelerometer reads gravity downward'
    """
    if acc.shape[0] == 0 or body[2] not in "UD":
        return None
    mean = acc.mean(axis=0)
    norm = float(np.linalg.norm(mean))
    if not 0.5 * GRAVITY < norm < 1.5 * GRAVITY:
        return None  # moving, or a unit problem that check_plausible names
    up = np.array([0.0, 0.0, 1.0 if body[2] == "U" else -1.0])
    if float(mean @ up) / norm < -math.cos(math.radians(30)):
        return (
            f"the accelerometer reads gravity downward at the start ({np.round(mean, 2).tolist()} m/s2 in {body} "
            f"axes), where a body at rest reads +9.81 m/s2 upward: it looks like acceleration with the sign "
            f"flipped, or the log starts upside down.  Negate it, or pass --no-unit-check if it really is inverted"
        )
    return None


# A gyro that says the body tilts this fast while gravity stays put in the body contradicts the accelerometer:
# 0.2 rad/s (11°/s) is far past any MEMS gyro's bias (a few °/s at worst, uncalibrated).
_TILT_RATE_AT_REST = 0.2


def check_gyro_at_rest(gyro, acc, seconds: float, unit: str) -> str | None:
    """A message when the gyro turns the body about a horizontal axis while the accelerometer says it does not.

    At rest, or turning about the vertical only (a turntable), gravity keeps its direction in the body.  A mean
    rate of more than 0.2 rad/s about an axis perpendicular to gravity would turn that direction by 11° a
    second; if the accelerometer's direction stays within 3° over the window instead, the gyro's numbers are not
    rates in ``unit`` (deg/s values declared as rad/s read a 0.5°/s bias as 29°/s), or the two sensors' axes
    differ.

    Parameters
    ----------
    gyro, acc : numpy.ndarray, shape (N, 3)
        Rates (rad/s, converted with the declared unit) and specific force (m/s²) of the same rows, finite.
    seconds : float
        The span of the rows, s.
    unit : str
        The gyro's declared unit, for the message.

    Returns
    -------
    str or None
        What looks wrong.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.units import check_gyro_at_rest
    >>> acc = np.tile([0.0, 0.0, 9.81], (500, 1))
    >>> check_gyro_at_rest(np.tile([0.0, 0.0, 1.0], (500, 1)), acc, 5.0, "rad/s") is None   # a turntable
    True
    >>> check_gyro_at_rest(np.tile([0.5, -0.3, 0.2], (500, 1)), acc, 5.0, "rad/s")[:38]
    'the gyro turns the body at 0.583 rad/s'
    """
    n = acc.shape[0]
    if n < 20 or seconds < 1.0:
        return None
    k = max(1, n // 10)
    blocks = acc[: n - n % k].reshape(-1, k, 3).mean(axis=1)  # means of k rows: the accelerometer's noise out
    ref = blocks[0]
    g = float(np.linalg.norm(ref))
    if not 0.8 * GRAVITY < g < 1.2 * GRAVITY:
        return None
    cos = blocks @ ref / (np.linalg.norm(blocks, axis=1) * g)
    drift = float(np.degrees(np.arccos(np.clip(cos.min(), -1.0, 1.0))))
    up = ref / g
    w = gyro.mean(axis=0)
    across = float(np.linalg.norm(w - (w @ up) * up))
    if drift > 3.0 or across < _TILT_RATE_AT_REST:
        return None
    guess = "  The values look like deg/s: pass --gyro-unit deg/s" if unit == "rad/s" else ""
    return (
        f"the gyro turns the body at {across:.3g} rad/s about a horizontal axis ({np.degrees(across * seconds):.0f}° "
        f"in {seconds:.3g} s), but gravity stays within {drift:.1f}° in the accelerometer's axes: the gyro's numbers "
        f"are not rates in {unit}, or the two sensors' axes differ.{guess} (or --no-unit-check)"
    )
