"""Error metrics of attitudes (and, from :mod:`strapdown.calibrate`, the Allan deviation of sensor signals).

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

from .._support import validate as _v
from ..calibrate import allan_deviation

__all__ = [
    "allan_deviation",
    "attitude_errors",
    "error_quaternion",
    "remove_heading_offset",
    "rmse",
    "rmse_errors",
]


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
    >>> from strapdown.evaluate.metrics import error_quaternion
    >>> error_quaternion([np.cos(0.05), 0, 0, np.sin(0.05)], [1.0, 0, 0, 0]).round(6)   # 0.1 rad of heading
    array([0.99875 , 0.      , 0.      , 0.049979])
    """
    from ..rotations.quaternion import multiply

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
    >>> from strapdown.evaluate.metrics import attitude_errors
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
    >>> from strapdown.evaluate.metrics import rmse
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
    >>> from strapdown.evaluate.metrics import remove_heading_offset
    >>> est = from_euler([[30.0, 0, 0]], "ZYX", degrees=True)
    >>> remove_heading_offset(est, [[1.0, 0, 0, 0]]).round(12)
    array([[1., 0., 0., 0.]])
    """
    from ..rotations.quaternion import multiply

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
    >>> from strapdown.evaluate.metrics import rmse_errors
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
