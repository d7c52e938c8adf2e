"""The attitude time series that interpolation and splines take, checked once (private)."""

from __future__ import annotations

import numpy as np

from .._support import validate as _v


def attitude_series(t, q, t_new, check: bool):
    """Validated times (float64), unit hemisphere-aligned attitudes (float64), new times, output dtype."""
    tv = _v.finite(t, "t", check=check, dtype=np.float64)
    if tv.ndim != 1 or tv.shape[0] < 2:
        raise ValueError(f"t must have shape (n,) with n ≥ 2 sample times, got shape {tv.shape}")
    step = np.diff(tv)
    if check and not (step > 0).all():
        i = int(np.flatnonzero(~(step > 0))[0]) + 1
        raise ValueError(
            f"t[{i}] = {float(tv[i])!r} is not after t[{i - 1}] = {float(tv[i - 1])!r}; "
            "times must be strictly increasing"
        )
    qv = _v.rotations(q, "q", check=check)
    if qv.ndim < 2 or qv.shape[0] != tv.shape[0]:
        raise ValueError(
            f"q must have shape (n, ..., 4) with n = len(t) = {tv.shape[0]} attitudes, got shape {qv.shape}"
        )
    tn = _v.finite(t_new, "t_new", check=check, dtype=np.float64)
    outside = (tn < tv[0]) | (tn > tv[-1])
    if outside.any():
        bad = float(tn[outside].flat[0])
        raise ValueError(
            f"t_new{_v.first_index(outside)} = {bad!r} is outside the sampled interval [t[0], t[-1]] = "
            f"[{float(tv[0])!r}, {float(tv[-1])!r}]; interpolation does not extrapolate"
        )
    q1 = qv.astype(np.float64, copy=False)
    q1 = q1 / np.sqrt(np.einsum("...i,...i->...", q1, q1))[..., None]
    # hemisphere alignment: flip sample i when it lies opposite to the (already aligned) sample i - 1
    flips = np.cumprod(np.where(np.einsum("...i,...i->...", q1[1:], q1[:-1]) < 0, -1.0, 1.0), axis=0)
    q1 = np.concatenate([q1[:1], q1[1:] * flips[..., None]], axis=0)
    return tv, q1, tn, qv.dtype
