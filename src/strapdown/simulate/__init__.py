"""Motion and IMU simulation with exact truth.

* :mod:`~strapdown.simulate.trajectories`: constant rotation, coning, random smooth motion, rocking platform;
* :mod:`~strapdown.simulate.aerobatics`: aerobatic flights chained from figures;
* :mod:`~strapdown.simulate.handheld`: handheld motion, slow with brief fast flicks and jolts;
* :mod:`~strapdown.simulate.imu`: datasheet-style sensor error models;
* :mod:`~strapdown.simulate.sampling`: sampling a trajectory into IMU readings;
* :mod:`~strapdown.simulate.recorded`: IMU readings for a recorded motion (motion capture) through the C² spline.

Internally the simulator uses NED reference axes and FRD body axes; :func:`sample` re-expresses its output.
"""

from .aerobatics import (
    Flight,
    Segment,
    aerobatic_show,
    aileron_roll,
    barrel_roll,
    hammerhead,
    hammerhead_loop,
    immelmann,
    level,
    loop,
    spin,
    split_s,
)
from .handheld import Handheld
from .models import ClockModel, ImuModel, TriadModel
from .recorded import RecordedMotion, sample_recorded
from .sampling import ImuData, MagneticDisturbance, MagneticField, sample
from .trajectories import GRAVITY, Coning, ConstantRotation, RandomMotion, RockingPlatform, Trajectory

__all__ = [
    "GRAVITY",
    "ClockModel",
    "Coning",
    "ConstantRotation",
    "Flight",
    "Handheld",
    "ImuData",
    "ImuModel",
    "MagneticDisturbance",
    "MagneticField",
    "RandomMotion",
    "RecordedMotion",
    "RockingPlatform",
    "Segment",
    "Trajectory",
    "TriadModel",
    "aerobatic_show",
    "aileron_roll",
    "barrel_roll",
    "hammerhead",
    "hammerhead_loop",
    "immelmann",
    "level",
    "loop",
    "sample",
    "sample_recorded",
    "spin",
    "split_s",
]
