"""Sensor calibration and true north: fits from recordings, Allan analysis, magnetic declination.

* :func:`magnetometer`: hard and soft iron from a recording that turns the sensor (robust ellipsoid fit);
* :func:`accelerometer`: offsets, scale factors and cross-axis coupling from static poses;
* :func:`gyroscope`: bias from rests, scale and cross-axis coupling from a reference rate or attitude;
* :func:`allan`: angle random walk, bias instability and rate random walk read off the Allan curve;
* :func:`find_rests`: the still intervals of a recording;
* :func:`declination` and :func:`field`: the Earth's field from position and date (World Magnetic Model,
  the ``geomag`` extra), and :func:`to_true_north` to turn a magnetic heading into a true one.

Each fit returns a :class:`Calibration` (``calibrated = matrix @ (reading - offset)``) with its uncertainty and
quality figures, saved and loaded as JSON (:func:`save`, :func:`load`).  A fit refuses input that cannot
determine it (:class:`InsufficientMotionError`, a ``ValueError``) and says which motion is missing.
"""

from ._accelerometer import GRAVITY, accelerometer
from ._allan import AllanAnalysis, allan
from ._calibration import SENSORS, Calibration, load, save
from ._declination import GeomagneticField, declination, field, to_true_north
from ._gyroscope import gyroscope, rates_from_attitude
from ._magnetometer import InsufficientMotionError, magnetometer
from ._rests import find_rests

__all__ = [
    "GRAVITY",
    "SENSORS",
    "AllanAnalysis",
    "Calibration",
    "GeomagneticField",
    "InsufficientMotionError",
    "accelerometer",
    "allan",
    "declination",
    "field",
    "find_rests",
    "gyroscope",
    "load",
    "magnetometer",
    "rates_from_attitude",
    "save",
    "to_true_north",
]
