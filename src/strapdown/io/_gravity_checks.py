"""Checks of the gyro and accelerometer against gravity: its sign in the body axes, and the gyro's tilt rate.

Public through :mod:`strapdown.io.plausibility`.
"""

from __future__ import annotations

import math

import numpy as np

from ._limits import _impossible, check_magnitude, row_norms
from .units import GRAVITY


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
        The message: the reading's direction and sign, in ``body`` axes.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.plausibility import check_gravity_sign
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
            f"axes), where a body at rest reads +9.81 m/s2 upward: it looks like axes whose z points the other "
            f"way (--body {flipped_body(body)}), acceleration with the sign flipped, or a log that starts upside "
            "down.  Pass the --body that fits, or --no-unit-check if it really is inverted"
        )
    return None


_OPPOSITE = {"F": "B", "B": "F", "L": "R", "R": "L", "U": "D", "D": "U", "N": "S", "S": "N", "E": "W", "W": "E"}


def flipped_body(body: str) -> str:
    """The axes turned 180° about x from ``body``: y and z the other way (FLU for FRD, FRD for FLU).

    Read in these axes, a reading that gives gravity downward in ``body`` gives it upward, and the axes stay
    right-handed: the ``--body`` to suggest for a sensor whose z points the other way.

    Examples
    --------
    >>> from strapdown.io.plausibility import flipped_body
    >>> flipped_body("FRD"), flipped_body("FLU"), flipped_body("RFU")
    ('FLU', 'FRD', 'RBD')
    """
    body = body.upper()
    return body[0] + _OPPOSITE.get(body[1], body[1]) + _OPPOSITE.get(body[2], body[2])


# deg/s read as rad/s turn gravity's direction 57 times further than the accelerometer sees it turn; a gyro in the
# right unit stays at a ratio of 1 or below (linear acceleration only adds to what the accelerometer shows).  Only
# a ratio around 57 is taken for deg/s: a coordinated turn keeps the apparent gravity along the body's z while the
# gyro tilts it, with any ratio at all, and the band keeps such flights out
_TILT_RATIOS = (20.0, 200.0)
# and only once the accelerometer has seen gravity turn by 10 degrees or more: motion to compare
_TILT_SEEN = math.radians(10.0)


def check_gyro_tilt(gyro, acc, t, unit: str, block: float = 0.25) -> str | None:
    """A message when the gyro tilts the body much further than the accelerometer sees it tilt, in motion too.

    Gravity's direction u in the body turns as du/dt = -ω × u, so over a block of time Δt the gyro turns it by
    ‖ω̄ × u‖ Δt (ω̄ the mean rate over the block), while the accelerometer's mean over consecutive blocks shows
    the angle it actually turned (plus what linear acceleration adds).  Summed over the blocks, a gyro tilt of 20
    to 200 times the accelerometer's, once that is 10° or more, is deg/s read as rad/s (57 times too far).
    :func:`check_gyro_at_rest` judges a still body; this one the first rows in motion (:func:`probe`).

    Parameters
    ----------
    gyro, acc : numpy.ndarray, shape (N, 3)
        Rates (rad/s, converted with the declared unit) and specific force (m/s²) of the same rows, finite.
    t : numpy.ndarray, shape (N,)
        Their times, s.
    unit : str
        The gyro's declared unit, for the message.
    block : float
        The length of a block, s.

    Returns
    -------
    str or None
        The message: both tilts, and the unit they point to (only for a gyro declared in rad/s).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.plausibility import check_gyro_tilt
    >>> t = np.arange(2000) * 0.01                                  # rolling 30° back and forth at 0.25 Hz
    >>> roll = np.radians(30) * np.sin(2 * np.pi * 0.25 * t)
    >>> rate = np.gradient(roll, t)
    >>> acc = 9.81 * np.column_stack([0 * t, np.sin(roll), np.cos(roll)])   # FLU: gravity's up in the body
    >>> gyro = np.column_stack([rate, 0 * t, 0 * t])
    >>> check_gyro_tilt(gyro, acc, t, "rad/s") is None
    True
    >>> check_gyro_tilt(np.degrees(gyro), acc, t, "rad/s")[:35]      # deg/s declared as rad/s
    'the gyro tilts the body by 3.2e+04°'
    """
    n = acc.shape[0]
    if n < 8 or t[-1] - t[0] < 4 * block:
        return None
    size = float(np.abs(acc).max())
    if not 0.0 < size < math.inf:
        return None
    # blocks of rows about ``block`` long (irregular times: by time, not by count)
    edges = np.searchsorted(t, np.arange(t[0], t[-1], block))
    edges = np.unique(np.append(edges, n))
    counts = np.diff(edges)
    keep = counts > 0
    a = np.add.reduceat(acc / size, edges[:-1], axis=0)[keep] / counts[keep, None]
    w = np.add.reduceat(gyro, edges[:-1], axis=0)[keep] / counts[keep, None]
    mid = np.add.reduceat(t, edges[:-1])[keep] / counts[keep]
    lengths = row_norms(a)
    good = lengths > 0
    a, w, mid, lengths = a[good], w[good], mid[good], lengths[good]
    if a.shape[0] < 4:
        return None
    u = a / lengths[:, None]
    seen = np.arccos(np.clip(np.einsum("ij,ij->i", u[1:], u[:-1]), -1.0, 1.0))
    # the rate between two block centres: the mean of the two blocks' means
    w_mid = 0.5 * (w[1:] + w[:-1])
    turned = row_norms(np.cross(w_mid, u[:-1])) * np.diff(mid)
    total_seen, total_turned = float(seen.sum()), float(turned.sum())
    ratio = total_turned / total_seen if total_seen > 0 else math.inf
    if unit != "rad/s" or total_seen < _TILT_SEEN or not _TILT_RATIOS[0] <= ratio <= _TILT_RATIOS[1]:
        return None
    return (
        f"the gyro tilts the body by {np.degrees(total_turned):.2g}° in {t[-1] - t[0]:.3g} s where the "
        f"accelerometer sees gravity turn by {np.degrees(total_seen):.2g}°, {ratio:.0f} times less (deg/s read as "
        "rad/s tilt 57 times too far): the values look like deg/s.  Pass --gyro-unit deg/s, or --no-unit-check if "
        "they really are rad/s"
    )


# A gyro that says the body tilts this fast while gravity stays put in the body contradicts the accelerometer:
# 0.2 rad/s (11°/s) is far past any MEMS gyro's bias (a few °/s at worst, uncalibrated).
_TILT_RATE_AT_REST = 0.2


def check_gyro_at_rest(gyro, acc, seconds: float, unit: str) -> str | None:
    """A message when the gyro turns the body about a horizontal axis while the accelerometer says it does not.

    At rest, or turning about the vertical only (a turntable), gravity keeps its direction in the body.  A mean
    rate of more than 0.2 rad/s about an axis perpendicular to gravity would turn that direction by 11° a
    second; if the accelerometer's direction stays within 3° over the window instead, the gyro's numbers are not
    rates in ``unit`` (deg/s values declared as rad/s read a 0.5°/s bias as 29°/s), or the two sensors' axes
    differ.  A gyro reading past :data:`LIMITS` is named instead (row and component, :func:`check_magnitude`).

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
        The message: the rate across gravity against the accelerometer's drift, or a reading past the limits.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.plausibility import check_gyro_at_rest
    >>> acc = np.tile([0.0, 0.0, 9.81], (500, 1))
    >>> check_gyro_at_rest(np.tile([0.0, 0.0, 1.0], (500, 1)), acc, 5.0, "rad/s") is None   # a turntable
    True
    >>> check_gyro_at_rest(np.tile([0.5, -0.3, 0.2], (500, 1)), acc, 5.0, "rad/s")[:38]
    'the gyro turns the body at 0.583 rad/s'
    """
    n = acc.shape[0]
    if n < 20 or seconds < 1.0:
        return None
    # a rate no unit explains is not "deg/s declared as rad/s": name it (and keep it out of the sums below)
    hit = check_magnitude("gyro", gyro, unit, converted=True)
    if hit:
        return _impossible(hit, "the gyro rows checked")
    # the accelerometer only by direction, scaled by its largest reading: no sum or square can overflow
    size = float(np.abs(acc).max())
    if not 0.0 < size < math.inf:
        return None
    k = max(1, n // 10)
    blocks = (acc / size)[: n - n % k].reshape(-1, k, 3).mean(axis=1)  # means of k rows: the noise out
    lengths = row_norms(blocks)
    ref = blocks[0]
    g = float(lengths[0]) * size
    if not 0.8 * GRAVITY < g < 1.2 * GRAVITY:
        return None
    up = ref / lengths[0]
    cos = blocks @ up / np.where(lengths > 0, lengths, 1.0)  # a zero block: cos 0, a drift of 90°
    drift = float(np.degrees(np.arccos(np.clip(cos.min(), -1.0, 1.0))))
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
