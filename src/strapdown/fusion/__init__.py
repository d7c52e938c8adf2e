"""Sensor fusion: attitude from gyroscope, accelerometer and magnetometer.

Every filter is a streaming object (``update`` on chunks, state readable and settable with ``.state``) with a
batch function of the same name in lower case, a frozen parameter dataclass in physical units, and a private
numba kernel.  Conventions are those of :mod:`strapdown` (scalar-first quaternions, sensor to reference);
timing and frames are described in :mod:`strapdown.fusion.estimate`: sample k is applied over the interval that
ends at it, and outputs are in ``frame`` (ENU by default).

* :class:`AttitudeEstimator`: 6D/9D orientation with gyro bias and scale-factor estimation, magnetic
  disturbance rejection, and an offline mode (:func:`attitude_offline`);
* :class:`TiltEstimator`: the Rowe patent's tilt estimation with gyro-drift correction (6D, or inclinometer);
* :class:`Complementary`: a quaternion complementary filter (6D/9D);
* :class:`Mahony`: Mahony's filter with integral bias (6D/9D);
* :class:`Madgwick`: Madgwick's gradient-descent filter (6D/9D), with the original code's variant for
  reproducing published results.

Conventions
-----------
Stated here once; the docstrings of the filters say only what differs.

* A filter class takes ``params`` (its parameter dataclass; the defaults when None) and the keywords ``q0``, the
  initial attitude (sensor to ``frame``; by default from the first sample: the tilt from the accelerometer, the
  heading from the magnetometer), and ``frame``, the reference frame of ``q0`` and of the outputs (any z-up or
  z-down frame of :mod:`strapdown.rotations.frames`).
* ``update(gyro, acc, mag=None, *, dt=None, t=None)`` takes (N, 3) arrays: the angular rate in rad/s, the
  specific force in m/s² (+g along body up at rest) and the magnetic field in any unit (only its direction is
  used; 9D when given); ``dt`` (seconds per sample, a scalar or one per sample) or ``t`` (the sample times).
* The batch function runs the class over whole arrays with the same arguments.
"""

import sys as _sys

from .._support.moved import install as _install_moved
from .attitude_estimator import AttitudeEstimator, AttitudeParams, attitude
from .complementary import Complementary, ComplementaryParams, complementary
from .estimate import (
    FLAG_ACC_REJECTED,
    FLAG_BIAS_AT_LIMIT,
    FLAG_INVERTED,
    FLAG_MAG_REJECTED,
    FLAG_REST,
    FLAG_SATURATED,
    Estimate,
)
from .initial import initial_attitude
from .madgwick import Madgwick, MadgwickParams, madgwick
from .mahony import Mahony, MahonyParams, mahony
from .offline import attitude_offline
from .registry import ESTIMATORS, EstimatorEntry, make_params
from .saturation import saturated
from .tilt import TiltEstimator, TiltParams, tilt, tilt_from_pitch_roll, tilt_from_quaternion, tilt_from_up, tilt_rates

# strapdown.fusion.attitude names the function here and, as a module path of release 0.1, the estimator's module
_install_moved({"strapdown.fusion.attitude": _sys.modules[__name__ + ".offline"]})

__all__ = [
    "ESTIMATORS",
    "FLAG_ACC_REJECTED",
    "FLAG_BIAS_AT_LIMIT",
    "FLAG_INVERTED",
    "FLAG_MAG_REJECTED",
    "FLAG_REST",
    "FLAG_SATURATED",
    "AttitudeEstimator",
    "AttitudeParams",
    "Complementary",
    "ComplementaryParams",
    "Estimate",
    "EstimatorEntry",
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
    "make_params",
    "saturated",
    "tilt",
    "tilt_from_pitch_roll",
    "tilt_from_quaternion",
    "tilt_from_up",
    "tilt_rates",
]
