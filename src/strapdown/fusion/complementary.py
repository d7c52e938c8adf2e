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

from .._support.renamed import renamed
from ._base import Estimator
from ._inputs import GRAVITY
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
        for name in ("tau_acc", "tau_mag"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be a non-negative time constant in seconds, got {v!r}")
        if not self.acc_gate > 0:
            raise ValueError(f"acc_gate must be positive (m/s²), got {self.acc_gate!r}")


class Complementary(Estimator):
    """Streaming quaternion complementary filter.

    Parameters
    ----------
    params : ComplementaryParams, optional
        Time constants and gate.
    q0 : array_like, shape (4,), optional
        Initial attitude (sensor to ``frame``); by default from the first sample.
    frame : str
        Reference frame of ``q0`` and of the outputs.

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

    reports_flags = True

    def __init__(self, params: ComplementaryParams | None = None, *, q0=None, frame: str = "ENU"):
        super().__init__(params or ComplementaryParams(), q0=q0, frame=frame)

    def _new_state(self, q, gyro, acc, mag, dts, extra_in):
        return {"q": q.copy()}

    def _run(self, gyro, acc, mag, dts, extra_in):
        from ._complementary_numba import run

        n = gyro.shape[0]
        out = np.empty((n, 4))
        flags = np.empty(n, dtype=np.uint8)
        m = mag if mag is not None else np.zeros((1, 3))
        p = self.params
        run(gyro, acc, m, mag is not None, dts, p.tau_acc, p.tau_mag, GRAVITY, p.acc_gate, self._state["q"], out, flags)
        return Estimate(q=out, frame=self.natural_frame, flags=flags)


@renamed(gyr="gyro")
def complementary(
    gyro, acc, mag=None, *, dt=None, t=None, params: ComplementaryParams | None = None, q0=None, frame: str = "ENU"
) -> Estimate:
    """Run the quaternion complementary filter over whole arrays (the batch form of :class:`Complementary`).

    Parameters
    ----------
    gyro, acc : array_like, shape (N, 3)
        Angular rate (rad/s) and specific force (m/s²).
    mag : array_like, shape (N, 3), optional
        Magnetic field; 9D when given.
    dt : float or array_like, optional
        Seconds per sample.
    t : array_like, shape (N,), optional
        Sample times.
    params : ComplementaryParams, optional
        Time constants.
    q0 : array_like, shape (4,), optional
        Initial attitude.
    frame : str
        Reference frame.

    Returns
    -------
    Estimate
        Attitudes, one per sample, and the accelerometer rejection flags.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import complementary
    >>> complementary(np.zeros((5, 3)), np.tile([0.0, 0.0, 9.81], (5, 1)), dt=0.01).q.shape
    (5, 4)
    """
    return Complementary(params, q0=q0, frame=frame).update(gyro, acc, mag, dt=dt, t=t)
