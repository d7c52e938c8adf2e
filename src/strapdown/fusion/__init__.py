"""Sensor fusion: attitude from gyroscope, accelerometer and magnetometer.

Every filter is a streaming object (``update`` on chunks, state readable and settable with ``.state``) with a
batch function of the same name in lower case, a frozen parameter dataclass in physical units, and a private
numba kernel.  Conventions are those of :mod:`strapdown` (scalar-first quaternions, sensor to reference);
timing and frames are described in :mod:`strapdown.fusion._base`: sample k is applied over the interval that
ends at it, and outputs are in ``frame`` (ENU by default).

* :class:`AttitudeEstimator`: 6D/9D orientation with gyro bias and scale-factor estimation, magnetic
  disturbance rejection, and an offline mode (:func:`attitude_offline`);
* :class:`TiltEstimator`: the Rowe patent's tilt estimation with gyro-drift correction (6D, or inclinometer);
* :class:`Complementary`: a quaternion complementary filter (6D/9D);
* :class:`Mahony`: Mahony's filter with integral bias (6D/9D);
* :class:`Madgwick`: Madgwick's gradient-descent filter (6D/9D), with the original code's variant for
  reproducing published results.
"""

from ._base import (
    FLAG_ACC_REJECTED,
    FLAG_BIAS_AT_LIMIT,
    FLAG_INVERTED,
    FLAG_MAG_REJECTED,
    FLAG_REST,
    Estimate,
    initial_attitude,
)
from .attitude import AttitudeEstimator, AttitudeParams, attitude, attitude_offline
from .complementary import Complementary, ComplementaryParams, complementary
from .madgwick import Madgwick, MadgwickParams, madgwick
from .mahony import Mahony, MahonyParams, mahony
from .tilt import (
    TiltEstimator,
    TiltParams,
    tilt,
    tilt_from_pitch_roll,
    tilt_from_quaternion,
    tilt_from_up,
    tilt_rates,
)

__all__ = [
    "FLAG_ACC_REJECTED",
    "FLAG_BIAS_AT_LIMIT",
    "FLAG_INVERTED",
    "FLAG_MAG_REJECTED",
    "FLAG_REST",
    "AttitudeEstimator",
    "AttitudeParams",
    "Complementary",
    "ComplementaryParams",
    "Estimate",
    "Madgwick",
    "MadgwickParams",
    "Mahony",
    "MahonyParams",
    "TiltEstimator",
    "TiltParams",
    "attitude",
    "attitude_offline",
    "complementary",
    "initial_attitude",
    "madgwick",
    "mahony",
    "tilt",
    "tilt_from_pitch_roll",
    "tilt_from_quaternion",
    "tilt_from_up",
    "tilt_rates",
]
