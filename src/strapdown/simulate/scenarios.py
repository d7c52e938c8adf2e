"""Named scenarios for the command line and the demo."""

from __future__ import annotations

import numpy as np

from .aerobatics import aerobatic_show, hammerhead_loop
from .trajectories import Coning, RandomMotion, RockingPlatform, Trajectory

__all__ = ["SCENARIOS", "scenario"]

SCENARIOS = {
    "hammerhead-loop": ("Gajda's test: level, hammerhead, level, loop, level (30 s)", hammerhead_loop),
    "aerobatic-show": ("loop, aileron roll, barrel roll, Immelmann, split-S, hammerhead, spin (76 s)", aerobatic_show),
    "coning": ("coning, half-angle 1°, 10 Hz (20 s)", lambda: Coning(np.radians(1.0), 10.0, 20.0)),
    "random": ("random smooth motion with translation (60 s)", lambda: RandomMotion(60.0, seed=0)),
    "rocking": ("the patent's wheelchair: driving, turning, rocking (120 s)", lambda: RockingPlatform(120.0)),
}


def scenario(name: str) -> Trajectory:
    """The trajectory of a named scenario.

    Parameters
    ----------
    name : str
        A key of :data:`SCENARIOS`.

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
    return SCENARIOS[name][1]()
