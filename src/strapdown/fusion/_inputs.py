"""The checks every fusion filter runs on its inputs before its kernel trusts them (private)."""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from ..rotations.quaternion import rotate

GRAVITY = 9.80665


# Accepted input range (docs/guide/reliability.md): beyond these the kernels' squares and products overflow into
# NaN, and no sensor or clock comes near them.
MAX_SAMPLE = 1e100  # largest |component| of a gyro, accelerometer or magnetometer sample, in any unit


MAX_DT = 1e9  # s (32 years): the longest sample interval


MAX_STEP_ANGLE = 2e-3 / np.finfo(np.float64).eps  # rad: |gyro| dt of one sample, as in strapdown.integrate


def _sensor(v, name: str, missing: bool, check: bool = True) -> tuple[np.ndarray, float]:
    """A (N, 3) sensor array, finite and within MAX_SAMPLE, and a bound of its largest |component|.

    With ``missing``, whole NaN rows are allowed (no sample of that sensor then).  Without ``check``, only the
    dtype and shape (and the bound is None).
    """
    arr = _v.vectors(v, name, check=False, dtype=np.float64)
    if not check:
        return arr, None
    if arr.size:
        # The usual case in one pass: a sum of squares within (MAX_SAMPLE/2)² bounds every component, and a NaN
        # or an infinity fails the comparison.  Its root bounds the largest component (for the step check).
        # einsum, not a dot product: OpenBLAS's threads would spin on the cores the filter needs next; and no
        # per-row maxima over the axis of length 3, which cost as much as the filter itself on long inputs.
        flat = arr.reshape(-1)
        squares = np.einsum("i,i->", flat, flat)
        if squares <= (0.5 * MAX_SAMPLE) ** 2:
            return arr, float(np.sqrt(squares))
    if not missing:
        _v.check_finite(arr, name)
    elif not np.isfinite(arr).all():
        absent = np.isnan(arr).all(axis=-1)
        bad = ~(np.isfinite(arr).all(axis=-1) | absent)
        if bad.any():
            i = _v.first_index(bad)
            raise ValueError(f"{name}{i} is partly NaN or infinite; a row must be finite, or all NaN for no sample")
    _in_range(arr, name)
    return arr, _largest(arr)


def _largest(arr: np.ndarray) -> float:
    """The largest |component| of an array, NaN ignored (0 when empty or all NaN)."""
    if not arr.size:
        return 0.0
    flat = arr.reshape(-1)
    big = max(np.fmax.reduce(flat), -np.fmin.reduce(flat))
    return 0.0 if big != big else float(big)


def _in_range(arr: np.ndarray, name: str) -> None:
    """Raise if a sample has a component beyond MAX_SAMPLE (NaN rows, "no sample", are skipped)."""
    if _largest(arr) <= MAX_SAMPLE:
        return
    with np.errstate(invalid="ignore"):
        big = np.abs(arr).max(axis=-1, initial=0.0) > MAX_SAMPLE
    if big.any():
        k = int(np.flatnonzero(big)[0])
        raise _v.SampleError(
            f"{name}[{k}] = {arr[k].tolist()} is beyond {MAX_SAMPLE:.0e} in magnitude: no sensor reads that; "
            "check the units",
            k,
        )


def _triads(gyro, acc, mag, need_mag: bool, missing: bool = False, check: bool = True):
    """gyro, acc, mag checked and C-contiguous float64 (no copy when they are already), and a bound of |gyro|.

    Without ``check``, the values are not looked at (only dtypes and shapes; the bound is None).
    """
    g, g_max = _sensor(gyro, "gyro", False, check)
    a, _ = _sensor(acc, "acc", missing, check)
    if g.ndim != 2 or a.ndim != 2:
        raise ValueError(f"gyro and acc must have shape (N, 3), got {g.shape} and {a.shape}")
    if a.shape != g.shape:
        raise ValueError(f"acc has {a.shape[0]} samples but gyro has {g.shape[0]}; give one of each per sample")
    m = None
    if mag is not None:
        m, _ = _sensor(mag, "mag", missing, check)
        if m.shape != g.shape:
            raise ValueError(f"mag has {m.shape[0]} samples but gyro has {g.shape[0]}; give one of each per sample")
        m = np.ascontiguousarray(m)
    elif need_mag:
        raise ValueError("this filter was created for magnetometer data (9D): give mag, or create it without")
    return np.ascontiguousarray(g), np.ascontiguousarray(a), m, g_max


def _check_steps(g: np.ndarray, dts: np.ndarray, g_max: float) -> None:
    """Raise unless every interval is at most MAX_DT and every gyro step |gyro| dt at most MAX_STEP_ANGLE.

    ``g_max`` bounds every |gyro| component: that rate over the longest interval within bounds settles it.
    """
    if dts.size:
        longest = dts.max()
        if longest <= MAX_DT and g_max * longest <= MAX_STEP_ANGLE:
            return
    if not (dts <= MAX_DT).all():
        k = int(np.flatnonzero(~(dts <= MAX_DT))[0])
        raise _v.SampleError(
            f"sample {k} lasts {dts[k]:.3g} s, beyond {MAX_DT:.0e} s; check the time unit of dt or t", k
        )
    if len(dts) < len(g):  # compact intervals (Estimator.compact_intervals)
        dts = np.concatenate([dts, np.full(len(g) - len(dts), dts[-1])])
    step = np.abs(g).max(axis=-1, initial=0.0) * dts
    if not (step <= MAX_STEP_ANGLE).all():
        k = int(np.flatnonzero(~(step <= MAX_STEP_ANGLE))[0])
        raise _v.SampleError(
            f"gyro[{k}] turns by {step[k]:.3g} rad in one sample, beyond {MAX_STEP_ANGLE:.3g} rad where float64 "
            "cannot hold a step's angle; check the units and the time step",
            k,
        )


def _back_to_first_sample(gyro: np.ndarray, dts: np.ndarray, k: int, v: np.ndarray) -> np.ndarray:
    """A vector read by the sensor at the end of sample k, in the sensor axes at the end of sample 0.

    The sensor turns by the product of the steps 1..k: v_0 = D ⊗ v_k ⊗ D* (the bias is not known yet).
    """
    if k == 0:
        return v
    from ..propagate.integrate import integrate

    h = dts[1 : k + 1] if len(dts) > k else dts[-1]  # compact intervals: dts[-1] is every later one
    return rotate(integrate(gyro[1 : k + 1], dt=h)[-1], v)


def _first_present(arr: np.ndarray, name: str) -> int:
    if arr.shape[0] and arr[0, 0] == arr[0, 0]:
        return 0
    present = np.flatnonzero(~np.isnan(arr[:, 0]))
    if not len(present):
        raise ValueError(f"{name} has no sample in the first chunk: the attitude cannot be initialised (give q0)")
    return int(present[0])
