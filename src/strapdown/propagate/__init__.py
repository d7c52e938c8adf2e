"""Attitude over time from body rates, and between samples (floor 2).

* :mod:`.integrate`: :func:`~strapdown.integrate` and :class:`~strapdown.AttitudeIntegrator`, every classic
  propagation method (exact, first to fourth order, Cayley, RK4, coning corrections, the baselines of Gajda);
* :mod:`.interpolate`: slerp and squad over time series, resampling;
* :mod:`.spline`: :class:`~strapdown.propagate.spline.RotationSpline`, C² in attitude, with angular rate and
  acceleration.

Imports :mod:`strapdown.rotations` and :mod:`strapdown._support` only.
"""

from .._support.lazy import exports

# submodules and names imported when first used
__getattr__, __dir__, _names = exports(__name__, {})
__all__ = sorted([*_names, *["integrate", "interpolate", "spline"]])
