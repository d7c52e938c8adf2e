"""Aerobatic flights with exact truth: figures chained from segments of rotation about a body-fixed axis.

A :class:`Segment` turns the aircraft by an angle about an axis fixed in the body (FRD) with a rate that rises
from zero, holds and falls back to zero along a septic smoothstep, so the body rate is C³ across segment
boundaries.  Within a segment the attitude is ``q_start ⊗ exp(n θ(t)/2)`` with θ(t) in closed form, so the
attitude, the rate and the gyro increments are exact; so is the specific force, because the aircraft flies
along its body x axis at an airspeed that changes smoothly: ``f_b = ω × v_b + v̇_b - Cᵀ g``.

Rotations about one fixed axis commute, so the ``exact`` method fed exact increments reproduces any figure to
rounding, provided no sample straddles two segments with non-zero rate; at boundaries the rate and its first
three derivatives vanish, which leaves straddling samples an error far below 1e-12.

Figures (functions returning segment lists, all starting and ending in level flight unless stated):
:func:`level`, :func:`loop`, :func:`aileron_roll`, :func:`barrel_roll`, :func:`immelmann`, :func:`split_s`,
:func:`hammerhead`, :func:`spin`; scenarios: :func:`hammerhead_loop`, :func:`aerobatic_show`.  Every figure
takes its ``duration`` in seconds and the airspeed ``speed`` in m/s, constant through the figure unless its
docstring says otherwise; a scenario takes the airspeed of its level flight.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..rotations.quaternion import multiply, rotate
from ..rotations.rotvec import from_rotvec
from .trajectories import _G_NED, Trajectory, _positive, _times, _unit

__all__ = [
    "Flight",
    "Segment",
    "aerobatic_show",
    "aileron_roll",
    "barrel_roll",
    "hammerhead",
    "hammerhead_loop",
    "immelmann",
    "level",
    "loop",
    "spin",
    "split_s",
]


def _ramp(tau):
    """Septic smoothstep rate profile r(τ) = 140 ∫τ³(1-τ)³: 0 → 1 with three vanishing derivatives at both ends."""
    return tau**4 * (35 - 84 * tau + 70 * tau**2 - 20 * tau**3)


def _ramp_integral(tau):
    """∫_0^τ r = 7τ⁵ - 14τ⁶ + 10τ⁷ - 2.5τ⁸ (1/2 at τ = 1)."""
    return tau**5 * (7 - 14 * tau + 10 * tau**2 - 2.5 * tau**3)


def _smooth(tau):
    """Quintic smoothstep S(τ) = 6τ⁵ - 15τ⁴ + 10τ³ and its derivative, for airspeed changes."""
    return tau**3 * (10 - 15 * tau + 6 * tau**2), 30 * tau**2 * (1 - tau) ** 2


@dataclass(frozen=True)
class Segment:
    """A rotation by ``angle`` about the body axis ``axis`` over ``duration`` seconds.

    Attributes
    ----------
    axis : tuple of float
        Body (FRD) axis; normalised.  Ignored when angle is 0.
    angle : float
        Radians, right-handed about the axis.
    ramp : float
        Seconds the rate takes to rise and to fall (at most duration / 2).
    speed : tuple of float
        Airspeed along body x at the start and end, m/s; it changes along a quintic smoothstep.
    name : str
        For plots and tables.
    """

    axis: tuple = (1.0, 0.0, 0.0)
    angle: float = 0.0
    duration: float = 1.0
    ramp: float = 0.0
    speed: tuple = (60.0, 60.0)
    name: str = ""

    def __post_init__(self):
        _positive(self.duration, "duration")
        if not (0 <= self.ramp <= self.duration / 2):
            raise ValueError(f"ramp must be in [0, duration/2] = [0, {self.duration / 2:g}] s, got {self.ramp!r}")
        axis = np.asarray(self.axis, dtype=float)
        if axis.shape != (3,) or not np.isfinite(axis).all() or (self.angle != 0 and not np.linalg.norm(axis) > 0):
            raise ValueError(f"axis must be a non-zero 3-vector, got {self.axis!r}")
        if not np.isfinite(self.angle):
            raise ValueError(f"angle must be finite, got {self.angle!r}")
        if len(self.speed) != 2 or not all(np.isfinite(self.speed)) or min(self.speed) < 0:
            raise ValueError(f"speed must be two non-negative airspeeds (start, end), got {self.speed!r}")

    def theta(self, s: np.ndarray):
        """Angle, rate and rate derivative at times s (seconds since the segment started)."""
        big_t, tr = self.duration, self.ramp
        omega = self.angle / (big_t - tr)
        theta = np.empty_like(s)
        rate = np.empty_like(s)
        if tr > 0:
            up = s < tr
            down = s > big_t - tr
            mid = ~(up | down)
            tau = s[up] / tr
            theta[up] = omega * tr * _ramp_integral(tau)
            rate[up] = omega * _ramp(tau)
            tau = (big_t - s[down]) / tr
            theta[down] = self.angle - omega * tr * _ramp_integral(tau)
            rate[down] = omega * _ramp(tau)
        else:
            mid = np.ones(s.shape, dtype=bool)
        theta[mid] = omega * (tr / 2 + s[mid] - tr)
        rate[mid] = omega
        return theta, rate

    def airspeed(self, s: np.ndarray):
        """Airspeed and its rate of change at times s (seconds since the segment started)."""
        v0, v1 = self.speed
        shape, dshape = _smooth(np.clip(s / self.duration, 0.0, 1.0))
        return v0 + (v1 - v0) * shape, (v1 - v0) * dshape / self.duration


class Flight(Trajectory):
    """A chain of segments flown from the attitude ``q0`` (NED/FRD), with exact truth.

    Parameters
    ----------
    segments : sequence of Segment or of lists of Segment
        The figures in order (lists are flattened).
    q0 : array_like, shape (4,), optional
        Initial attitude; identity = level, heading north.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_euler
    >>> from strapdown.simulate import Flight, level, loop
    >>> flight = Flight([level(1.0), loop(4.0), level(1.0)])
    >>> flight.duration
    6.0
    >>> as_euler(flight.attitude([1.0, 3.0, 5.0]), degrees=True).round(6)   # entry, inverted at the top, exit
    array([[  0.,   0.,   0.],
           [180.,   0., 180.],
           [  0.,  -0.,   0.]])
    """

    def __init__(self, segments, q0=None):
        flat = []
        for item in segments:
            flat.extend(item if isinstance(item, list | tuple) else [item])
        if not flat or not all(isinstance(s, Segment) for s in flat):
            raise ValueError("segments must be a non-empty sequence of Segment (or lists of them)")
        self.segments = tuple(flat)
        durations = np.array([s.duration for s in flat])
        self.starts = np.concatenate([[0.0], np.cumsum(durations)])
        self.duration = float(self.starts[-1])
        self._axes = np.array([_axis(s) for s in flat])
        q = np.array([1.0, 0, 0, 0]) if q0 is None else _unit(q0, "q0")
        starts = [q]
        for s, n in zip(flat, self._axes, strict=True):
            q = multiply(q, from_rotvec(n * s.angle))
            starts.append(q / np.linalg.norm(q))
        self._q_start = np.array(starts)

    def _locate(self, t):
        t = _times(t, self.duration)
        idx = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, len(self.segments) - 1)
        return t, idx, t - self.starts[idx]

    def _per_segment(self, idx, s):
        theta = np.empty_like(s)
        rate = np.empty_like(s)
        v = np.empty_like(s)
        dv = np.empty_like(s)
        for j in np.unique(idx):
            m = idx == j
            theta[m], rate[m] = self.segments[j].theta(s[m])
            v[m], dv[m] = self.segments[j].airspeed(s[m])
        return theta, rate, v, dv

    def _motion(self, t):
        """Attitude, body rate, airspeed and its rate of change at times t."""
        t, idx, s = self._locate(t)
        theta, rate, v, dv = self._per_segment(idx, s)
        q = multiply(self._q_start[idx], from_rotvec(self._axes[idx] * theta[:, None]))
        return q, self._axes[idx] * rate[:, None], v, dv

    def attitude(self, t):
        """See :meth:`Trajectory.attitude`."""
        return self._motion(t)[0]

    def rate(self, t):
        """See :meth:`Trajectory.rate`."""
        t, idx, s = self._locate(t)
        _, rate, _, _ = self._per_segment(idx, s)
        return self._axes[idx] * rate[:, None]

    def increments(self, t):
        """Exact: each piece of an interval inside segment j contributes n_j (θ_j(b) - θ_j(a))."""
        t = _times(t, self.duration)
        out = np.zeros((t.size - 1, 3))
        for j, seg in enumerate(self.segments):
            lo, hi = self.starts[j], self.starts[j + 1]
            a = np.clip(t[:-1], lo, hi) - lo
            b = np.clip(t[1:], lo, hi) - lo
            touched = b > a
            if not touched.any() or seg.angle == 0:
                continue
            th_b, _ = seg.theta(b[touched])
            th_a, _ = seg.theta(a[touched])
            out[touched] += np.outer(th_b - th_a, self._axes[j])
        return out

    def specific_force(self, t):
        """``f_b = ω × v_b + v̇_b - Cᵀ g`` with ``v_b = (v, 0, 0)``: flight along the body x axis."""
        q, omega, v, dv = self._motion(t)
        g_body = rotate(q * [1.0, -1.0, -1.0, -1.0], np.broadcast_to(_G_NED, omega.shape))
        f = -g_body
        f[:, 0] += dv
        f[:, 1] += omega[:, 2] * v  # ω × (v, 0, 0) = (0, r v, -q v)
        f[:, 2] -= omega[:, 1] * v
        return f

    def acceleration(self, t):
        """See :meth:`Trajectory.acceleration`."""
        q, omega, v, dv = self._motion(t)
        a_body = np.stack([dv, omega[:, 2] * v, -omega[:, 1] * v], axis=-1)
        return rotate(q, a_body)

    def segment_at(self, t) -> list[str]:
        """Names of the segments flown at times t."""
        _, idx, _ = self._locate(t)
        return [self.segments[i].name for i in idx]


def _axis(seg: Segment) -> np.ndarray:
    axis = np.asarray(seg.axis, dtype=float)
    n = np.linalg.norm(axis)
    return axis / n if n > 0 else np.array([1.0, 0.0, 0.0])


_X, _Y, _Z = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)


def level(duration: float, speed: float = 60.0) -> list[Segment]:
    """Straight and level flight.

    Returns
    -------
    list of Segment
        One segment without rotation.

    Examples
    --------
    >>> from strapdown.simulate import level
    >>> level(2.0)[0].angle
    0.0
    """
    return [Segment(_X, 0.0, duration, 0.0, (speed, speed), "level")]


def loop(duration: float = 8.0, speed: float = 60.0) -> list[Segment]:
    """An inside loop: 360° of pitch, through the vertical climb, inverted at the top, the vertical dive.

    Returns
    -------
    list of Segment
        One segment: 2π about the body y axis, the rate ramping up and down over 15 % of the duration
        at each end.

    Examples
    --------
    >>> from strapdown.simulate import loop
    >>> round(loop(8.0)[0].angle, 6)
    6.283185
    """
    return [Segment(_Y, 2 * np.pi, duration, 0.15 * duration, (speed, speed), "loop")]


def aileron_roll(duration: float = 4.0, speed: float = 60.0) -> list[Segment]:
    """A 360° roll about the body x axis.

    Returns
    -------
    list of Segment
        One segment: 2π about the body x axis, with ramps of 20 % of the duration.

    Examples
    --------
    >>> from strapdown.simulate import aileron_roll
    >>> aileron_roll()[0].axis
    (1.0, 0.0, 0.0)
    """
    return [Segment(_X, 2 * np.pi, duration, 0.2 * duration, (speed, speed), "aileron roll")]


def barrel_roll(duration: float = 8.0, speed: float = 60.0, pitch_ratio: float = 0.6) -> list[Segment]:
    """A barrel roll: rolling and pitching at once, 360° about a body axis between x and y.

    Parameters
    ----------
    pitch_ratio : float
        Pitch rate / roll rate.

    Returns
    -------
    list of Segment
        One segment: 2π about the body axis ``(1, pitch_ratio, 0)``, with ramps of 15 % of the duration.

    Examples
    --------
    >>> from strapdown.simulate import barrel_roll
    >>> barrel_roll()[0].name
    'barrel roll'
    """
    return [Segment((1.0, pitch_ratio, 0.0), 2 * np.pi, duration, 0.15 * duration, (speed, speed), "barrel roll")]


def _half_loop(duration: float, v0: float, v1: float, figure: str) -> Segment:
    """The half loop of the Immelmann and the split-S: π about body y in 60 % of the figure's duration."""
    return Segment(_Y, np.pi, 0.6 * duration, 0.15 * duration, (v0, v1), f"{figure} half loop")


def _half_roll(duration: float, speed: float, figure: str) -> Segment:
    """Their half roll: π about body x in the other 40 %."""
    return Segment(_X, np.pi, 0.4 * duration, 0.1 * duration, (speed, speed), f"{figure} half roll")


def immelmann(duration: float = 8.0, speed: float = 60.0) -> list[Segment]:
    """A half loop up to inverted flight, then a half roll to upright: the heading reverses, altitude gained.

    The half loop is π about the body y axis in 60 % of the duration, the half roll π about x in the rest.

    Parameters
    ----------
    speed : float
        Airspeed at the start, m/s (it drops by a third in the climb).

    Returns
    -------
    list of Segment
        The half loop, then the half roll.

    Examples
    --------
    >>> from strapdown.simulate import immelmann
    >>> [s.name for s in immelmann()]
    ['Immelmann half loop', 'Immelmann half roll']
    """
    slow = speed * 2 / 3
    return [_half_loop(duration, speed, slow, "Immelmann"), _half_roll(duration, slow, "Immelmann")]


def split_s(duration: float = 8.0, speed: float = 45.0) -> list[Segment]:
    """A half roll to inverted flight, then a half loop down: the heading reverses, altitude lost.

    Parameters
    ----------
    speed : float
        Airspeed at the start, m/s (it grows by half in the dive).

    Returns
    -------
    list of Segment
        The half roll, then the half loop: the Immelmann's segments in the other order.

    Examples
    --------
    >>> from strapdown.simulate import split_s
    >>> len(split_s())
    2
    """
    return [_half_roll(duration, speed, "split-S"), _half_loop(duration, speed, 1.5 * speed, "split-S")]


def hammerhead(duration: float = 12.0, speed: float = 60.0) -> list[Segment]:
    """The stall turn: pull up to a vertical climb through pitch 90°, yaw over the top, dive, pull out.

    Parameters
    ----------
    speed : float
        Airspeed in level flight, m/s; it falls to 5 m/s at the top of the climb.

    Returns
    -------
    list of Segment
        Five segments: pull-up, vertical climb, yaw-over (180° about the body z axis, nose from straight up
        to straight down), vertical dive, pull-out.

    Examples
    --------
    >>> from strapdown.simulate import hammerhead
    >>> [s.name for s in hammerhead()][2]
    'hammerhead yaw-over'
    """
    d = duration
    top = 5.0
    return [
        Segment(_Y, np.pi / 2, 0.2 * d, 0.08 * d, (speed, 0.8 * speed), "hammerhead pull-up"),
        Segment(_X, 0.0, 0.2 * d, 0.0, (0.8 * speed, top), "hammerhead vertical climb"),
        Segment(_Z, np.pi, 0.2 * d, 0.08 * d, (top, top), "hammerhead yaw-over"),
        Segment(_X, 0.0, 0.2 * d, 0.0, (top, 0.8 * speed), "hammerhead vertical dive"),
        Segment(_Y, np.pi / 2, 0.2 * d, 0.08 * d, (0.8 * speed, speed), "hammerhead pull-out"),
    ]


def spin(turns: float = 2.0, duration: float = 10.0, speed: float = 30.0) -> list[Segment]:
    """A spin: stall and drop the nose to 60° below the horizon, autorotate about the vertical, recover.

    During the autorotation the attitude relative to the vertical is steady, so the rotation axis is fixed
    in the body: the vertical expressed in body axes, ``(-sin 60°, 0, cos 60°)`` in FRD.

    Parameters
    ----------
    turns : float
        Full turns of autorotation.

    Returns
    -------
    list of Segment
        Entry (the nose dropped 60° about the body y axis), the autorotation (60 % of the duration) and the
        recovery.

    Examples
    --------
    >>> from strapdown.simulate import spin
    >>> [s.name for s in spin()][1]
    'spin autorotation'
    """
    d = duration
    nose = np.pi / 3
    return [
        Segment(_Y, -nose, 0.2 * d, 0.08 * d, (speed, speed), "spin entry"),
        Segment(
            (-np.sin(nose), 0.0, np.cos(nose)), 2 * np.pi * turns, 0.6 * d, 0.1 * d, (speed, speed), "spin autorotation"
        ),
        Segment(_Y, nose, 0.2 * d, 0.08 * d, (speed, speed), "spin recovery"),
    ]


def hammerhead_loop(speed: float = 60.0) -> Flight:
    """Gajda's test sequence: level, hammerhead, level, loop, level (30 s), heading north at the start.

    Returns
    -------
    Flight
        The flight; it passes pitch ±90° four times.

    Examples
    --------
    >>> from strapdown.simulate import hammerhead_loop
    >>> hammerhead_loop().duration
    30.0
    """
    return Flight([level(2.0, speed), hammerhead(12.0, speed), level(3.0, speed), loop(10.0, speed), level(3.0, speed)])


def aerobatic_show(speed: float = 60.0) -> Flight:
    """Every figure in turn, joined by 2 s of level flight in which the airspeed changes smoothly (76 s).

    Returns
    -------
    Flight
        The flight.

    Examples
    --------
    >>> from strapdown.simulate import aerobatic_show
    >>> round(aerobatic_show().duration, 6)
    76.0
    """
    figures = [
        loop(8.0, speed),
        aileron_roll(4.0, speed),
        barrel_roll(8.0, speed),
        immelmann(8.0, speed),
        split_s(8.0, 0.75 * speed),
        hammerhead(12.0, speed),
        spin(2.0, 10.0, 0.5 * speed),
    ]
    segments = []
    previous = speed
    for fig in [*figures, level(2.0, speed)]:
        # a level gap carries the airspeed from the end of one figure to the start of the next
        segments.append(Segment(_X, 0.0, 2.0, 0.0, (previous, fig[0].speed[0]), "level"))
        segments.extend(fig)
        previous = fig[-1].speed[1]
    return Flight(segments)
