"""Error metrics and signal statistics (attitude errors, sensor noise characterisation).

Conventions: signals are float arrays with time on the first axis, sampled uniformly at ``fs`` Hz; times and
averaging intervals τ are in seconds; results are float64.  Invalid input raises a ``ValueError`` naming the
argument.

Attitude errors follow the BROAD protocol exactly (Laidig et al., Data 6(7):72, 2021, and its example code):
both attitudes map the sensor to the same reference frame (z up for the heading/inclination split), the error
quaternion is ``q_err = normalize(q_est) ⊗ normalize(q_ref)*``, expressed in the reference frame, and

* total error ``2 acos(min(|w|, 1))``, the whole rotation angle;
* heading error ``2 atan(|z / w|)``, the part about the vertical;
* inclination error ``2 acos(min(√(w² + z²), 1))``, the part about horizontal axes.

RMSE values ignore NaN (samples where the optical truth was occluded) and, when a mask is given, count only
the masked samples (BROAD's movement phases).
"""

from __future__ import annotations

import numpy as np

from . import _validate as _v

__all__ = [
    "allan_deviation",
    "attitude_errors",
    "error_quaternion",
    "remove_heading_offset",
    "rmse",
    "rmse_errors",
]


def _cluster_sizes(n: int, fs: float, taus) -> np.ndarray:
    """Cluster sizes m (samples per averaging interval) for `taus`, or the default log-spaced set."""
    if taus is None:
        top = max(1, n // 10)
        return np.unique(np.round(np.logspace(0, np.log10(top), 30)).astype(np.int64))
    tau = _v.finite(taus, "taus", dtype=np.float64)
    if tau.ndim > 1:
        raise ValueError(f"taus must be a scalar or have shape (T,), got shape {tau.shape}")
    tau = np.atleast_1d(tau)
    m = np.round(tau * fs).astype(np.int64)
    bad = (m < 1) | (m > n // 2)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"taus[{i}] is {tau[i]} s; averaging times must lie between 1/fs = {1 / fs} s and "
            f"(N // 2)/fs = {(n // 2) / fs} s for N = {n} samples"
        )
    return m


def allan_deviation(x, fs: float, taus=None, *, overlapping: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Allan deviation of a rate signal (a gyro's deg/s, an accelerometer's m/s², any sampled quantity).

    Parameters
    ----------
    x : array_like, shape (N,) or (N, c)
        N samples at ``fs`` Hz of one signal or of c signals (for example the three axes of a gyro).
    fs : float
        Sample rate (Hz).
    taus : array_like, shape (T,), optional
        Averaging times (s), each rounded to a whole number m of samples with ``1 <= m <= N // 2``.  By default
        about 30 log-spaced cluster sizes from 1 sample to N/10 samples (fewer when N is small, as sizes are
        whole numbers and repeats are dropped).
    overlapping : bool
        Use every start sample (the overlapping estimator, the default and the more efficient one); otherwise
        only the non-overlapping clusters starting at multiples of m.

    Returns
    -------
    taus : numpy.ndarray, shape (T,)
        The averaging times used, ``m / fs``.
    adev : numpy.ndarray, shape (T,) or (T, c)
        Allan deviation, in the units of x.  With θ the running integral of x (θ_0 = 0, θ_k the sum of the first
        k samples over fs) and τ = m/fs::

            adev(τ)² = Σ_k (θ_{k+2m} - 2θ_{k+m} + θ_k)² / (2 τ² K)

        over the K = N + 1 - 2m starts k = 0, 1, ..., N - 2m (overlapping) or the K = N // m - 1 starts
        k = 0, m, 2m, ... (non-overlapping).  Each term is the difference of the means of two adjacent
        clusters of m samples.  Reading the curve: white noise of density D gives D/√τ (slope -1/2, the value
        at τ = 1 s is D), a rate random walk K gives K √(τ/3) (slope +1/2), a constant bias gives nothing.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.metrics import allan_deviation
    >>> x = np.array([1.0, -1.0] * 50)                       # alternating: the two-sample pairs cancel
    >>> taus, adev = allan_deviation(x, fs=10.0, taus=[0.1, 0.2])
    >>> taus, adev
    (array([0.1, 0.2]), array([1.41421356, 0.        ]))
    >>> rng = np.random.default_rng(0)
    >>> taus, adev = allan_deviation(rng.standard_normal((100_000, 3)), fs=100.0)
    >>> taus.shape, adev.shape, float(taus[0]), float(taus[-1])
    ((29,), (29, 3), 0.01, 100.0)
    """
    arr = _v.as_float_array(x, "x", dtype=np.float64)
    if arr.ndim not in (1, 2):
        raise ValueError(f"x must have shape (N,) or (N, c), got shape {arr.shape}")
    _v.check_finite(arr, "x")
    n = arr.shape[0]
    if n < 2:
        raise ValueError(f"x has {n} sample(s); the Allan deviation needs at least 2")
    fs_arr = _v.finite(fs, "fs", dtype=np.float64)
    if fs_arr.ndim != 0 or not fs_arr > 0:
        raise ValueError(f"fs must be a positive scalar (Hz), got {fs_arr}")
    fs = float(fs_arr)
    sizes = _cluster_sizes(n, fs, taus)

    # The Allan variance ignores a constant offset (the second difference of a line is zero); removing the mean
    # first keeps the running sum small, so the differences of its far-apart values lose no digits.
    # The deviation is linear in x, so each signal is scaled by a power of two (exact) to a peak in [0.5, 1):
    # the squares below cannot overflow (x ~ 1e200 gave inf) or underflow.  In sample units (θ without the 1/fs,
    # τ = m) fs cancels from d²/τ², so it cannot under- or overflow them either.
    _, e = np.frexp(np.max(np.abs(arr), axis=0))
    scaled = np.ldexp(arr, -e)
    centred = scaled - scaled.mean(axis=0)
    theta = np.zeros((n + 1, *arr.shape[1:]))
    np.cumsum(centred, axis=0, out=theta[1:])
    adev = np.empty((sizes.shape[0], *arr.shape[1:]))
    for i, m in enumerate(sizes):
        stride = 1 if overlapping else m
        d = theta[2 * m :: stride] - 2 * theta[m : n + 1 - m : stride] + theta[: n + 1 - 2 * m : stride]
        adev[i] = np.sqrt(np.mean(d**2, axis=0) / (2.0 * m * m))
    with np.errstate(over="ignore"):
        adev = np.ldexp(adev, e)
    if not np.isfinite(adev).all():
        raise ValueError(f"the Allan deviation of x exceeds the largest float64: x reaches {np.abs(arr).max():.3g}")
    return sizes / fs, adev


def error_quaternion(q_est, q_ref) -> np.ndarray:
    """Reference-frame error quaternion ``normalize(q_est) ⊗ normalize(q_ref)*``, normalised.

    NaN rows of either input (occluded truth) give NaN rows; no other value is checked here.

    Parameters
    ----------
    q_est, q_ref : array_like, shape (..., 4)
        Estimated and true attitudes (sensor to reference, scalar first).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        The rotation that takes the true attitude to the estimate, in reference axes.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.metrics import error_quaternion
    >>> error_quaternion([np.cos(0.05), 0, 0, np.sin(0.05)], [1.0, 0, 0, 0]).round(6)   # 0.1 rad of heading
    array([0.99875 , 0.      , 0.      , 0.049979])
    """
    from .quaternion import multiply

    est = _unit_or_nan(q_est, "q_est")
    ref = _unit_or_nan(q_ref, "q_ref")
    _v.broadcast(("q_est", est.shape[:-1]), ("q_ref", ref.shape[:-1]))
    with np.errstate(invalid="ignore"):
        ref = ref * np.array([1.0, -1.0, -1.0, -1.0])
        out = multiply(est, ref, check=False)
        return out / np.linalg.norm(out, axis=-1, keepdims=True)


def _unit_or_nan(q, name: str) -> np.ndarray:
    """Quaternions scaled to unit norm, any finite norm (a power of two first, exactly); NaN rows stay NaN.

    A row that is neither NaN (occluded truth) nor a usable rotation, i.e. infinite or zero, is an error.
    """
    arr = _v.quaternions(q, name, check=False, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        big = np.max(np.abs(arr), axis=-1)
    bad = ~(big > 0) & ~np.isnan(big) | np.isinf(big)
    if bad.any():
        what = "infinite" if np.isinf(big[bad][0]) else "a zero quaternion"
        raise ValueError(f"{name}{_v.first_index(bad)} is {what}; use NaN rows for missing attitudes")
    _, e = np.frexp(big)
    arr = np.ldexp(arr, -e[..., None])
    with np.errstate(invalid="ignore"):
        return arr / np.linalg.norm(arr, axis=-1, keepdims=True)


def attitude_errors(q_est, q_ref) -> dict:
    """Total, heading and inclination errors (rad) per sample, exactly as BROAD computes them.

    Parameters
    ----------
    q_est, q_ref : array_like, shape (..., 4)
        Estimated and true attitudes (sensor to a z-up reference frame such as ENU or NWU).

    Returns
    -------
    dict of numpy.ndarray
        ``"total"``, ``"heading"``, ``"inclination"``, each of shape (...); NaN where the truth is NaN.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_euler
    >>> from strapdown.metrics import attitude_errors
    >>> est = from_euler([10.0, 0.0, 5.0], "ZYX", degrees=True)     # 10° heading, 5° roll off the identity
    >>> e = attitude_errors(est, [1.0, 0, 0, 0])
    >>> [round(float(np.degrees(e[k])), 6) for k in ("total", "heading", "inclination")]
    [11.1775, 10.0, 5.0]
    """
    q = error_quaternion(q_est, q_ref)
    w, z = q[..., 0], q[..., 3]
    with np.errstate(invalid="ignore", divide="ignore"):
        return {
            "total": 2 * np.arccos(np.clip(np.abs(w), 0, 1)),
            # atan2(|z|, |w|) = atan(|z / w|) where w != 0, and 0 (not NaN) for a half turn about a horizontal axis
            "heading": 2 * np.arctan2(np.abs(z), np.abs(w)),
            "inclination": 2 * np.arccos(np.clip(np.sqrt(w**2 + z**2), 0, 1)),
        }


def rmse(x, mask=None) -> float:
    """Root mean square ignoring NaN, over the samples selected by ``mask`` (all by default).

    Parameters
    ----------
    x : array_like, shape (N,)
        Values.
    mask : array_like of bool, shape (N,), optional
        Samples that count.

    Returns
    -------
    float
        ``sqrt(nanmean(x[mask]²))``, NaN values (missing) left out; NaN when no value is selected.  An
        infinite value is an error.

    Examples
    --------
    >>> from strapdown.metrics import rmse
    >>> rmse([3.0, 4.0, float("nan")])
    3.5355339059327378
    """
    x = _v.as_float_array(x, "x", dtype=np.float64)
    if mask is not None:
        mask = np.asarray(mask, dtype=bool).reshape(-1)
        if mask.shape != x.shape[:1]:
            raise ValueError(f"mask must have one entry per sample ({x.shape[0]}), got shape {mask.shape}")
        x = x[mask]
    if np.isinf(x).any():
        raise ValueError(f"x{_v.first_index(np.isinf(x))} is infinite; NaN marks a missing value, inf is an error")
    finite = np.isfinite(x)
    if not finite.any():
        return float("nan")
    # scaled by a power of two (exact) so that the squares neither overflow (1e200 gave inf) nor underflow
    vals = x[finite]
    _, e = np.frexp(np.max(np.abs(vals)))
    return float(np.ldexp(np.sqrt(np.mean(np.ldexp(vals, -e) ** 2)), e))


def remove_heading_offset(q_est, q_ref, mask=None) -> np.ndarray:
    """Rotate the estimate about the vertical by the mean heading error (for 6D estimators, whose heading drifts).

    The offset is the circular mean of the signed heading error ``2 atan2(z, w)`` of the error quaternion over
    the masked, finite samples; the estimate is left-multiplied by the rotation that removes it.  Inclination
    errors are unchanged; total and heading errors then measure only the heading's drift around its mean.

    Parameters
    ----------
    q_est, q_ref : array_like, shape (N, 4)
        Estimated and true attitudes.
    mask : array_like of bool, shape (N,), optional
        Samples that define the offset.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        The estimate with the offset removed.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_euler
    >>> from strapdown.metrics import remove_heading_offset
    >>> est = from_euler([[30.0, 0, 0]], "ZYX", degrees=True)
    >>> remove_heading_offset(est, [[1.0, 0, 0, 0]]).round(12)
    array([[1., 0., 0., 0.]])
    """
    from .quaternion import multiply

    est = _v.as_float_array(q_est, "q_est", dtype=np.float64)
    q = error_quaternion(est, q_ref)
    signed = 2 * np.arctan2(q[:, 3], q[:, 0])
    use = np.isfinite(signed) if mask is None else np.isfinite(signed) & np.asarray(mask, dtype=bool)
    if not use.any():
        return est.copy()
    offset = np.arctan2(np.sin(signed[use]).mean(), np.cos(signed[use]).mean())
    turn = np.array([np.cos(-offset / 2), 0.0, 0.0, np.sin(-offset / 2)])
    return multiply(turn, est, check=False)


def rmse_errors(q_est, q_ref, mask=None, *, heading_offset: bool = False, degrees: bool = True) -> dict:
    """Total, heading and inclination RMSE of an estimate over a mask: one BROAD result.

    Parameters
    ----------
    q_est, q_ref : array_like, shape (N, 4)
        Estimated and true attitudes, sensor to a common z-up frame; NaN truth is ignored.
    mask : array_like of bool, shape (N,), optional
        Samples that count (BROAD: the movement phases).
    heading_offset : bool
        Remove the mean heading offset first (6D estimators).
    degrees : bool
        Results in degrees (BROAD's unit) rather than radians.

    Returns
    -------
    dict of float
        ``"total"``, ``"heading"``, ``"inclination"``.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_euler
    >>> from strapdown.metrics import rmse_errors
    >>> est = from_euler(np.column_stack([np.zeros(4), np.zeros(4), [1.0, -1, 1, -1]]), "ZYX", degrees=True)
    >>> {k: round(v, 9) for k, v in rmse_errors(est, np.tile([1.0, 0, 0, 0], (4, 1))).items()}
    {'total': 1.0, 'heading': 0.0, 'inclination': 1.0}
    """
    est = _v.quaternions(q_est, "q_est", check=False, dtype=np.float64)
    ref = _v.as_float_array(q_ref, "q_ref", dtype=np.float64)
    if est.ndim != 2 or est.shape != ref.shape:
        raise ValueError(f"q_est and q_ref must both have shape (N, 4), got {est.shape} and {ref.shape}")
    if heading_offset:
        est = remove_heading_offset(est, ref, mask)
    errors = attitude_errors(est, ref)
    scale = 180 / np.pi if degrees else 1.0
    return {k: rmse(v, mask) * scale for k, v in errors.items()}
