"""The estimators by name, for the file commands, the command line and the benchmarks.

Each entry of :data:`ESTIMATORS` is an :class:`EstimatorEntry`: the streaming class, its parameter dataclass
and whether it takes a magnetometer.  :func:`make_params` turns None, a parameter object or a mapping of
overrides into validated parameters of a named estimator.
"""

from __future__ import annotations

from typing import NamedTuple

from ._base import params_of
from .attitude_estimator import AttitudeEstimator, AttitudeParams
from .complementary import Complementary, ComplementaryParams
from .madgwick import Madgwick, MadgwickParams
from .mahony import Mahony, MahonyParams
from .tilt import TiltEstimator, TiltParams

__all__ = ["ESTIMATORS", "EstimatorEntry", "make_params"]


class EstimatorEntry(NamedTuple):
    """One estimator of the registry (a tuple: ``cls, params, takes_mag = ESTIMATORS[name]``)."""

    cls: type
    params: type
    takes_mag: bool


#: Estimators by name.
ESTIMATORS: dict[str, EstimatorEntry] = {
    "attitude": EstimatorEntry(AttitudeEstimator, AttitudeParams, True),
    "tilt": EstimatorEntry(TiltEstimator, TiltParams, False),
    "complementary": EstimatorEntry(Complementary, ComplementaryParams, True),
    "mahony": EstimatorEntry(Mahony, MahonyParams, True),
    "madgwick": EstimatorEntry(Madgwick, MadgwickParams, True),
}


def make_params(estimator: str, params=None):
    """The parameter object of a named estimator from None, an instance, or a mapping of overrides.

    Parameters
    ----------
    estimator : str
        A key of :data:`ESTIMATORS`.
    params : parameter object, mapping, or None
        Defaults when None; a mapping overrides fields of the defaults by name.

    Returns
    -------
    dataclass
        An instance of the estimator's parameter class (``ESTIMATORS[estimator].params``), its ranges checked.

    Examples
    --------
    >>> from strapdown.fusion.registry import make_params
    >>> make_params("mahony", {"kp": 2.0}).kp
    2.0
    """
    if estimator not in ESTIMATORS:
        raise ValueError(f"unknown estimator {estimator!r}; choose from {', '.join(ESTIMATORS)}")
    return params_of(ESTIMATORS[estimator].params, params, estimator)
