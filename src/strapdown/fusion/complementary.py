"""A quaternion complementary filter: gyro integration corrected towards the accelerometer and magnetometer.

Not the Euler-angle blend of some libraries (which breaks at pitch ±90° and mixes axes): each step rotates the
gyro-propagated attitude in the reference frame, by a fraction ``1 - exp(-dt/τ_acc)`` of the tilt that makes the
measured gravity vertical (about a horizontal axis, so the heading is untouched) and, in 9D, by a fraction
``1 - exp(-dt/τ_mag)`` of the heading that points the horizontal field north (about the vertical, so the tilt is
untouched).  Computed in ENU.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._base import GRAVITY, UNCOMPILED_S_PER_SAMPLE, Estimator, batch_function, nonnegative
from .estimate import Estimate

__all__ = ["Complementary", "ComplementaryParams", "complementary"]


@dataclass(frozen=True)
class ComplementaryParams:
    """Parameters of :class:`Complementary`.

    Attributes
    ----------
    tau_acc : float
        Time constant of the tilt correction, s.  Default 2.0.
    tau_mag : float
        Time constant of the heading correction, s.  Default 5.0.
    acc_gate : float
        Leave the accelerometer out when its magnitude differs from g by more than this, m/s².  Default inf.
    """

    tau_acc: float = 2.0
    tau_mag: float = 5.0
    acc_gate: float = np.inf

    def __post_init__(self):
        nonnegative(self, ("tau_acc", "tau_mag"), "time constant in seconds")
        if not self.acc_gate > 0:
            raise ValueError(f"acc_gate must be positive (m/s²), got {self.acc_gate!r}")


class Complementary(Estimator):
    """Streaming quaternion complementary filter.

    Parameters
    ----------
    params : ComplementaryParams, optional
        Time constants and gate.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_euler, from_euler
    >>> from strapdown.fusion import Complementary
    >>> f = Complementary(q0=from_euler([0.0, 0.0, 20.0], "ZYX", degrees=True))   # starts 20° off in roll
    >>> est = f.update(np.zeros((2000, 3)), np.tile([0.0, 0.0, 9.81], (2000, 1)), dt=0.01)
    >>> float(np.degrees(as_euler(est.q[-1])[2])) < 1e-3       # pulled level in 20 s (10 time constants)
    True
    """

    params_class = ComplementaryParams
    reports_flags = True

    def _run(self, gyro, acc, mag, dts, extra_in):
        from .._support.uncompiled import call
        from ._complementary_numba import run

        n = gyro.shape[0]
        out = np.empty((n, 4))
        flags = np.empty(n, dtype=np.uint8)
        m = mag if mag is not None else np.zeros((1, 3))
        p = self.params
        q = self._state["q"]
        args = (gyro, acc, m, mag is not None, dts, p.tau_acc, p.tau_mag, GRAVITY, p.acc_gate, q, out, flags)
        call(run, *args, python_seconds=UNCOMPILED_S_PER_SAMPLE * n)
        return Estimate(q=out, frame=self.natural_frame, flags=flags)


complementary = batch_function(Complementary)
