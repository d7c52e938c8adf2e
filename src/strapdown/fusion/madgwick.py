"""Madgwick's gradient-descent orientation filter (Madgwick, Harrison & Vaidyanathan 2011), 6D and 9D.

The filter integrates ``q̇ = ½ q ⊗ ω - β ∇f/|∇f|`` with a first-order step, where f is the residual between the
gravity (and, in 9D, magnetic) direction predicted by q and the one measured.  It computes in Madgwick's earth
frame, NWU, and reports in ``frame`` (ENU by default).

``variant="reference"`` keeps a slip of the original C code, reproduced by the BROAD benchmark's published
results: the variables named ``_2bx`` and ``_2bz`` there hold b_x and b_z, so the predicted magnetic field is
half as long as the measured unit vector and the magnetometer also pulls on the inclination.  The default,
``"corrected"``, uses 2 b_x and 2 b_z as the derivation asks.  Use ``"reference"`` only to reproduce published
numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._base import UNCOMPILED_S_PER_SAMPLE, Estimator, batch_function, nonnegative
from .estimate import Estimate

__all__ = ["Madgwick", "MadgwickParams", "madgwick"]


@dataclass(frozen=True)
class MadgwickParams:
    """Parameters of :class:`Madgwick`.

    Attributes
    ----------
    beta : float
        Gain of the gradient step, rad/s: the rate at which the accelerometer (and magnetometer) pull the
        estimate.  Default 0.1.
    variant : {"corrected", "reference"}
        ``"reference"`` reproduces the original C code and the BROAD reference results (module notes).
    """

    beta: float = 0.1
    variant: str = "corrected"

    def __post_init__(self):
        nonnegative(self, ("beta",), "gain in rad/s")
        if self.variant not in ("corrected", "reference"):
            raise ValueError(f"variant must be 'corrected' or 'reference', got {self.variant!r}")


class Madgwick(Estimator):
    """Streaming Madgwick filter.

    Parameters
    ----------
    params : MadgwickParams, optional
        Gain and variant.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import Madgwick
    >>> f = Madgwick()
    >>> est = f.update(np.zeros((100, 3)), np.tile([0.0, 0.0, 9.81], (100, 1)), dt=0.01)
    >>> est.q[-1].round(6)
    array([1., 0., 0., 0.])
    """

    natural_frame = "NWU"
    params_class = MadgwickParams

    def _run(self, gyro, acc, mag, dts, extra_in):
        from .._support.uncompiled import call
        from ._madgwick_numba import run

        n = gyro.shape[0]
        out = np.empty((n, 4))
        m = mag if mag is not None else np.zeros((1, 3))
        p = self.params
        args = (gyro, acc, m, mag is not None, dts, p.beta, p.variant == "reference", self._state["q"], out)
        call(run, *args, python_seconds=UNCOMPILED_S_PER_SAMPLE * n)
        return Estimate(q=out, frame=self.natural_frame)


madgwick = batch_function(Madgwick)
