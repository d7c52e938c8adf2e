"""The propagation methods by name, their constants, and the error of a baseline at its singular set.

:data:`METHODS` lists every method of :func:`strapdown.integrate` (the notes of :mod:`strapdown.propagate.integrate`
say what each does).  The step methods hold the sample constant over its step (:data:`STEP_KINDS`), the coning
methods combine increments (:func:`coning_table`), and Gajda's baselines integrate their own state
(:data:`BASELINES`, singular where :data:`SINGULAR` says).
"""

from __future__ import annotations

import numpy as np

__all__ = ["METHODS", "SingularityError"]


class SingularityError(RuntimeError):
    """A baseline method (Euler angles, Euler parameters, rotation vector) reached its singular set."""


STEP_KINDS = {"exact": 0, "first-order": 1, "second-order": 2, "cayley": 3}


BASELINES = {"euler-angles": 0, "dcm": 1, "euler-parameters": 2, "rotation-vector": 3}


NORMALIZE = {"none": 0, "exact": 1, "series": 2}


# Coning-optimised sets (math.md §6.2; PSINS glv.cs): φ = ΣΔθ + (Σ_{i<N} k_i Δθ_i) × Δθ_N.
_CONING_OPTIMISED = {
    2: [2 / 3],
    3: [9 / 20, 27 / 20],
    4: [54 / 105, 92 / 105, 214 / 105],
    5: [250 / 504, 525 / 504, 650 / 504, 1375 / 504],
    6: [2315 / 4620, 4558 / 4620, 7296 / 4620, 7834 / 4620, 15797 / 4620],
}


def coning_table(method: str) -> tuple[np.ndarray, float]:
    """(K, c_prev) with φ = ΣΔθ_i + Σ_{i<j} K[i, j] Δθ_i × Δθ_j + c_prev Δθ_prev × Δθ_1."""
    if method == "coning1-prev":
        return np.zeros((1, 1)), 1 / 12
    if method == "coning3-poly":  # (33/80) Δθ1×Δθ3 + (57/80) Δθ2×(Δθ3 - Δθ1)
        k = np.zeros((3, 3))
        k[0, 2] = 33 / 80
        k[1, 2] = 57 / 80
        k[0, 1] = 57 / 80
        return k, 0.0
    if method == "coning4-poly":
        k = np.zeros((4, 4))
        k[0, 1] = k[2, 3] = 736 / 945
        k[0, 2] = k[1, 3] = 334 / 945
        k[0, 3] = 526 / 945
        k[1, 2] = 654 / 945
        return k, 0.0
    n = int(method[len("coning") :])
    k = np.zeros((n, n))
    k[: n - 1, n - 1] = _CONING_OPTIMISED[n]
    return k, 0.0


# The largest rotation of one step, rad: beyond it its angle is not known to 1 mrad in float64 (1e-3 / eps, the
# limit quaternion.power uses), and the arithmetic of several methods overflows soon after.
MAX_STEP_ANGLE = 2e-3 / np.finfo(np.float64).eps


CONING = ["coning1-prev", "coning2", "coning3", "coning4", "coning5", "coning6", "coning3-poly", "coning4-poly"]


METHODS = (*STEP_KINDS, "rk4", *CONING, *BASELINES)


SINGULAR = {
    "euler-angles": "pitch ±90°, Gajda 1.6",
    "euler-parameters": "rotation angle 0 mod 360°, Gajda 1.3",
    "rotation-vector": "rotation angle 180°, Gajda 1.4",
    "dcm": "none",
}
