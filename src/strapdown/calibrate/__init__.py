"""Sensor calibration and true north: fits from recordings, Allan analysis, magnetic declination.

* :func:`magnetometer`: hard and soft iron from a recording that turns the sensor (robust ellipsoid fit);
* :func:`accelerometer`: offsets, scale factors and cross-axis coupling from static poses;
* :func:`gyroscope`: bias from rests, scale and cross-axis coupling from a reference rate or attitude;
* :func:`allan`: angle random walk, bias instability and rate random walk read off the Allan curve;
* :func:`find_rests`: the still intervals of a recording;
* :func:`noise_model`: the noise of a gyro and accelerometer where the recording is still, and the estimator
  parameters it sets (:class:`NoiseModel`, also from a calibration file);
* :func:`declination` and :func:`field`: the Earth's field from position and date (World Magnetic Model,
  the ``geomag`` extra), and :func:`to_true_north` to turn a magnetic heading into a true one.

Each fit returns a :class:`Calibration` (``calibrated = matrix @ (reading - offset)``) with its uncertainty and
quality figures, saved and loaded as JSON (:func:`save`, :func:`load`).  A fit refuses input that cannot
determine it (:class:`InsufficientMotionError`, a ``ValueError``) and says which motion is missing.
"""

from .._support.lazy import exports

# imported when first used: the command line's estimate needs only by_sensor and to_true_north of this package
__getattr__, __dir__, __all__ = exports(
    __name__,
    {
        "_accelerometer": ("GRAVITY", "accelerometer"),
        "_allan": ("AllanAnalysis", "allan", "allan_deviation"),
        "_calibration": ("SENSORS", "Calibration", "by_sensor", "load", "save"),
        "_declination": ("GeomagneticField", "declination", "field", "to_true_north"),
        "_gyroscope": ("gyroscope", "rates_from_attitude"),
        "_magnetometer": ("InsufficientMotionError", "magnetometer"),
        "_noise": ("NoiseModel", "noise_model"),
        "_rests": ("find_rests",),
    },
)
