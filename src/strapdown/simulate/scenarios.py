"""Named scenarios for the command line and the demo."""

from __future__ import annotations

import numpy as np

from .aerobatics import aerobatic_show, hammerhead_loop
from .trajectories import Coning, RandomMotion, RockingPlatform, Trajectory

__all__ = ["SCENARIOS", "scenario"]

#: name -> (description, a function of the duration in seconds, or None for its own length).  The flight
#: figures have their own length; the others last as long as asked (their default in brackets).
SCENARIOS = {
    "hammerhead-loop": ("Gajda's test: level, hammerhead, level, loop, level (30 s)", lambda d: hammerhead_loop()),
    "aerobatic-show": (
        "loop, aileron roll, barrel roll, Immelmann, split-S, hammerhead, spin (76 s)",
        lambda d: aerobatic_show(),
    ),
    "coning": ("coning, half-angle 1°, 10 Hz (20 s)", lambda d: Coning(np.radians(1.0), 10.0, d or 20.0)),
    "random": ("random smooth motion with translation (60 s)", lambda d: RandomMotion(d or 60.0, seed=0)),
    "rocking": ("the patent's wheelchair: driving, turning, rocking (120 s)", lambda d: RockingPlatform(d or 120.0)),
}


def scenario(name: str, duration: float | None = None) -> Trajectory:
    """The trajectory of a named scenario.

    Parameters
    ----------
    name : str
        A key of :data:`SCENARIOS`.
    duration : float, optional
        Seconds: the random motion, the coning and the rocking platform last that long; a flight figure has its
        own length, and a longer duration is refused (never a shorter file than asked for, silently).

    Returns
    -------
    Trajectory
        A new trajectory at every call (the random motion's seed is fixed, so it is the same motion).

    Examples
    --------
    >>> from strapdown.simulate.scenarios import scenario
    >>> scenario("hammerhead-loop").duration
    30.0
    """
    if name not in SCENARIOS:
        raise ValueError(f"scenario must be one of {', '.join(SCENARIOS)}; got {name!r}")
    if duration is not None and not float(duration) > 0:
        raise ValueError(f"duration must be a number of seconds > 0, got {duration!r}")
    trajectory = SCENARIOS[name][1](duration)
    if duration is not None and duration > trajectory.duration * (1 + 1e-12):
        raise ValueError(
            f"duration={duration:g} s is longer than the {name} scenario ({trajectory.duration:g} s); give at most "
            f"{trajectory.duration:g} s, or a scenario of any length (coning, random, rocking)"
        )
    return trajectory
