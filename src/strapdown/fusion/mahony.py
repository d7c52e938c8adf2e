"""Mahony's explicit complementary filter with integral gyro-bias estimation (Mahony et al., IEEE TAC 2008).

The error between the measured and predicted directions of gravity (and, in 9D, of the horizontal magnetic
field), ``e = â × v̂ + m̂ × ŵ``, feeds back proportionally into the rate and integrally into a bias estimate:
``b ← b - ki e dt``, ``ω = gyro - b + kp e``.  The attitude step is the exact exponential.  Computed in ENU.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._base import UNCOMPILED_S_PER_SAMPLE, Estimator, batch_function, nonnegative
from .estimate import Estimate

__all__ = ["Mahony", "MahonyParams", "mahony"]


@dataclass(frozen=True)
class MahonyParams:
    """Parameters of :class:`Mahony`.

    Attributes
    ----------
    kp : float
        Proportional gain, 1/s (rad/s of correction per unit of direction error).  Default 1.0.
    ki : float
        Integral gain, 1/s² (bias learning).  Default 0.02; 0 disables bias estimation.  At rest the bias
        error decays with the slow root of ``s² + kp s + ki``, time constant ≈ ``kp/ki`` (50 s by default).
    bias0 : tuple of float
        Initial gyro bias estimate, rad/s.
    """

    kp: float = 1.0
    ki: float = 0.02
    bias0: tuple = (0.0, 0.0, 0.0)

    def __post_init__(self):
        nonnegative(self, ("kp", "ki"), "gain")
        if len(self.bias0) != 3 or not np.isfinite(self.bias0).all():
            raise ValueError(f"bias0 must be three finite rates in rad/s, got {self.bias0!r}")


class Mahony(Estimator):
    """Streaming Mahony filter with integral bias.

    Parameters
    ----------
    params : MahonyParams, optional
        Gains and initial bias.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import Mahony
    >>> bias = np.radians([0.5, -0.3, 0.0])
    >>> n = 30_000                                 # 300 s: six bias time constants kp/ki = 50 s
    >>> est = Mahony().update(np.tile(bias, (n, 1)), np.tile([0.0, 0.0, 9.81], (n, 1)), dt=0.01)
    >>> np.degrees(est.bias[-1]).round(2)          # the horizontal bias is learnt at rest
    array([ 0.5, -0.3,  0. ])
    """

    params_class = MahonyParams
    estimates_bias = True
    _state_layout = (("q", (4,)), ("bias", (3,)))

    def _new_state(self, q, gyro, acc, mag, dts, extra_in):
        return {"q": q.copy(), "bias": np.array(self.params.bias0, dtype=float)}

    def _run(self, gyro, acc, mag, dts, extra_in):
        from .._support.uncompiled import call
        from ._mahony_numba import run

        n = gyro.shape[0]
        out = np.empty((n, 4))
        bias = np.empty((n, 3))
        m = mag if mag is not None else np.zeros((1, 3))
        p = self.params
        args = (gyro, acc, m, mag is not None, dts, p.kp, p.ki, self._state["q"], self._state["bias"], out, bias)
        call(run, *args, python_seconds=UNCOMPILED_S_PER_SAMPLE * n)
        return Estimate(q=out, frame=self.natural_frame, bias=bias)


mahony = batch_function(Mahony)
