"""Handheld motion: a slow random motion with brief fast flicks and jolts, as a hand moves a phone or a tool."""

from __future__ import annotations

import numpy as np

from ..rotations.quaternion import conjugate, multiply, rotate
from ..rotations.rotvec import from_rotvec
from .trajectories import RandomMotion, Trajectory, _positive, _seed, _times

__all__ = ["Handheld"]


class Handheld(Trajectory):
    """A :class:`RandomMotion` with flicks: brief turns there and back about a random body axis, with a jolt.

    Every ``interval`` seconds (from ``interval`` on, with a random offset of up to a quarter of it) the body turns
    by an angle of ``amplitude`` (60-100 % of it) about a random body axis and back, in ``flick_time`` s
    (θ(τ) = A (1 - cos 2πτ/T) / 2, peak rate π A / T: 900°/s for the defaults), while it is jolted by a
    displacement there and back of 5 cm along a random direction in the same time (peak acceleration
    (2π/T)² 2.5 cm, 2.2 g).  ``q = q_base ⊗ q_flick``, so the body rate is ``q_flick* ω_base q_flick + θ' u``, exact.

    Parameters
    ----------
    duration : float
        Seconds.
    seed : int
        Seeds the base motion and the flicks (reproducible).
    interval : float
        Seconds between flicks.  Default 6.
    amplitude : float
        Largest flick angle, rad.  Default 90°.
    flick_time : float
        Seconds a flick lasts.  Default 0.3.
    rate_scale, acceleration_scale : float
        Of the base motion (:class:`RandomMotion`).  Defaults 1 rad/s and 1 m/s².

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.simulate.handheld import Handheld
    >>> hand = Handheld(30.0, seed=1)
    >>> t = np.arange(0.0, 30.0, 0.01)
    >>> bool(np.degrees(np.abs(hand.rate(t)).max()) > 500)
    True
    """

    def __init__(
        self,
        duration: float,
        seed: int = 0,
        interval: float = 6.0,
        amplitude: float = np.radians(90.0),
        flick_time: float = 0.3,
        rate_scale: float = 1.0,
        acceleration_scale: float = 1.0,
    ):
        self.duration = _positive(duration, "duration")
        self.interval = _positive(interval, "interval")
        self.flick_time = _positive(flick_time, "flick_time")
        if not flick_time < interval:
            raise ValueError(f"flick_time ({flick_time}) must be shorter than interval ({interval})")
        seed = _seed(seed)
        self._base = RandomMotion(duration, seed=seed, rate_scale=rate_scale, acceleration_scale=acceleration_scale)
        rng = np.random.default_rng(seed + 7919)
        n = max(int(duration / interval), 0)
        self._t0 = interval * np.arange(1, n + 1) + rng.uniform(0.0, 0.25 * interval, n)
        axes = rng.normal(size=(n, 3))
        self._axis = axes / np.linalg.norm(axes, axis=1, keepdims=True)
        self._angle = amplitude * rng.uniform(0.6, 1.0, n)
        jolt = rng.normal(size=(n, 3))
        self._jolt = 0.025 * jolt / np.linalg.norm(jolt, axis=1, keepdims=True)  # half the 5 cm there and back
        within = self._t0 + flick_time <= duration  # every flick ends within the motion
        self._t0, self._axis, self._angle, self._jolt = (
            x[within] for x in (self._t0, self._axis, self._angle, self._jolt)
        )

    def _flick(self, t):
        """Index of the flick under way at each time (-1: none) and its phase 2πτ/T."""
        i = np.searchsorted(self._t0, t, side="right") - 1
        tau = t - self._t0[np.maximum(i, 0)] if len(self._t0) else np.zeros_like(t)
        on = (i >= 0) & (tau < self.flick_time)
        return np.where(on, i, -1), 2.0 * np.pi * np.where(on, tau, 0.0) / self.flick_time

    def _flick_rotation(self, t):
        i, phase = self._flick(t)
        angle = np.where(i >= 0, 0.5 * self._angle[i] * (1.0 - np.cos(phase)), 0.0)
        rate = np.where(i >= 0, 0.5 * self._angle[i] * np.sin(phase) * 2.0 * np.pi / self.flick_time, 0.0)
        axis = self._axis[np.maximum(i, 0)] if len(self._t0) else np.zeros((t.size, 3))
        return from_rotvec(axis * angle[:, None]), axis * rate[:, None]

    def attitude(self, t):
        """See :meth:`Trajectory.attitude`."""
        t = _times(t, self.duration)
        return multiply(self._base.attitude(t), self._flick_rotation(t)[0])

    def rate(self, t):
        """See :meth:`Trajectory.rate`."""
        t = _times(t)
        q_f, w_f = self._flick_rotation(t)
        return rotate(conjugate(q_f), self._base.rate(t)) + w_f

    def acceleration(self, t):
        """See :meth:`Trajectory.acceleration`."""
        t = _times(t)
        i, phase = self._flick(t)
        k = (2.0 * np.pi / self.flick_time) ** 2
        jolt = self._jolt[np.maximum(i, 0)] if len(self._t0) else np.zeros((t.size, 3))
        return self._base.acceleration(t) + np.where(i >= 0, k * np.cos(phase), 0.0)[:, None] * jolt
