"""Hard- and soft-iron calibration of a magnetometer from a recording that turns the sensor.

A magnetometer near iron reads ``m = A h + b``: the hard iron b (µT) adds a field that turns with the sensor,
the soft iron, scale factors and cross-axis coupling form A.  Turned through all directions in a constant
field h, the readings lie on an ellipsoid; the fit (:mod:`strapdown.calibrate._ellipsoid`: algebraic start,
maximum-likelihood Levenberg-Marquardt refinement, Huber reweighting) finds b and the symmetric
positive-definite W with ``|W (m - b)|`` constant.  A rotation of the sensor axes after W cannot be seen in
the field alone (it is the sensor's mounting, found with the accelerometer or the estimator), so W is the
symmetric form ``(A Aᵀ)^(-1/2)`` (times a scale, below).
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from .._support.renamed import renamed
from . import _ellipsoid as _e
from ._calibration import Calibration

__all__ = ["InsufficientMotionError", "magnetometer"]

_MIN_SAMPLES = 30
_MIN_THICKNESS = 0.1  # smallest/largest principal spread of the raw readings: below, they lie in a plane
_MIN_SPREAD = 0.1  # smallest direction-scatter eigenvalue (x3, 1 = even) after the fit
_MAX_SOFT_IRON_CONDITION = 5.0
_EARTH_UT = (15.0, 100.0)  # the main field is 22-67 µT everywhere (WMM); a fit far outside saw no sphere
_WARRANTED = 3.0  # raw field-norm scatter over the calibrated one above which the fit is worth applying


class InsufficientMotionError(ValueError):
    """The recording did not move the sensor enough for the fit; the message says which motion is missing."""


def _rows(x, name: str) -> np.ndarray:
    """Finite (n, 3) float64 rows of x; NaN rows mean no sample and are dropped."""
    arr = _v.as_float_array(x, name, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"{name} must have shape (N, 3) (one 3-vector per sample), got shape {arr.shape}")
    present = ~np.isnan(arr).any(axis=1)
    arr = arr[present]
    _v.check_finite(arr, name)
    return arr


def _check_raw_motion(m: np.ndarray, name: str) -> None:
    """Refuse readings that did not turn, or turned about one axis only (they then lie in a plane)."""
    values, vectors = np.linalg.eigh(np.cov(m.T, bias=True))
    width = np.sqrt(max(values[2], 0.0))
    size = np.median(np.linalg.norm(m - np.median(m, axis=0), axis=1)) + np.mean(np.linalg.norm(m, axis=1))
    if width < 0.02 * size:
        raise InsufficientMotionError(
            f"{name} hardly changes (spread {width:.3g} around readings of {np.mean(np.linalg.norm(m, axis=1)):.3g}):"
            " the sensor was not turned; turn it through all directions (each axis pointing up, down and"
            " around, e.g. a slow figure-eight while rolling it over)"
        )
    thickness = np.sqrt(max(values[0], 0.0)) / width
    if thickness < _MIN_THICKNESS:
        # In a plane: a ring (turning about one axis: every reading as far from the centre) or a filled patch
        # (moving without turning much: distances from 0 to the edge; uniform on a disc their spread is 0.35).
        distance = np.linalg.norm((m - m.mean(axis=0)) @ vectors[:, 1:], axis=1)
        if np.std(distance) > 0.25 * np.mean(distance):
            raise InsufficientMotionError(
                f"{name} covers only a small patch of directions (spread {width:.3g} around readings of "
                f"{np.mean(np.linalg.norm(m, axis=1)):.3g}): the sensor moved but hardly turned; turn it through"
                " all directions (each axis pointing up, down and around)"
            )
        raise InsufficientMotionError(
            f"{name} lies close to a plane (thickness {thickness:.3f} of its width): the sensor turned about one"
            f" axis only, near sensor axis {_e.axis_name(vectors[:, 0])}; also turn it about the other two axes"
            " (tilt it up and down and roll it over) so that the field points in every direction"
        )


def _normalise(fit: _e.EllipsoidFit) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """Scale W to determinant 1 (the sensor's mean gain is kept), with the covariance of (b, w6, F)."""
    w = fit.matrix
    c = np.linalg.det(w) ** (-1.0 / 3.0)
    w6 = _e.unsym(w)
    inv = np.linalg.inv(w)
    dlogdet = np.einsum("ij,pji->p", inv, _e._BASIS)  # ∂ ln det W / ∂w_p = tr(W⁻¹ E_p)
    dc = -c / 3.0 * dlogdet
    jac = np.zeros((10, 9))
    jac[:3, :3] = np.eye(3)
    jac[3:9, 3:] = c * np.eye(6) + np.outer(w6, dc)
    jac[9, 3:] = fit.radius * dc
    cov = jac @ fit.covariance @ jac.T
    return c * w, fit.offset, c * fit.radius, cov


@renamed(gyr="gyro", m="mag")
def magnetometer(
    mag,
    *,
    field_strength: float | None = None,
    frame: str = "sensor",
    robust: bool = True,
    noise: float | None = None,
    gyro=None,
    fs: float | None = None,
    gyro_bias=None,
    window: float = 2.0,
) -> Calibration:
    """Fit hard and soft iron to magnetometer readings taken while the sensor turns in a steady field.

    Parameters
    ----------
    mag : array_like, shape (N, 3)
        Readings, µT, in the sensor axes ``frame``; NaN rows (no sample) are skipped.  The sensor must turn
        through many directions (all axes up and down); a few per cent of outliers are tolerated.
    field_strength : float, optional
        The local field strength (µT), e.g. from :func:`strapdown.calibrate.field`.  Given, the calibrated
        field has this magnitude; otherwise the matrix has determinant 1 (the sensor's mean gain is kept) and
        the magnitude is fitted (``quality["field_strength"]``).
    frame : str
        Name of the sensor axes, stored with the calibration.
    robust : bool
        Down-weight outliers (Huber); False gives the plain maximum-likelihood fit.
    noise : float, optional
        Known noise per axis and sample (µT); by default estimated from the residuals.
    gyro : array_like, shape (N, 3), optional
        Gyro readings of the same samples (rad/s, mean rate over the step that starts at each sample): the
        rotation of the magnetometer axes onto the gyro's, which the field alone cannot show, is fitted too
        (:mod:`strapdown.calibrate._alignment`), and the matrix becomes ``R W``: the calibrated field is in
        the gyro's axes.  Needs ``fs``.
    fs : float, optional
        Sample rate, Hz (with ``gyro``).
    gyro_bias : array_like, shape (3,), or Calibration, optional
        The gyro's bias (rad/s), removed before integrating (e.g. :func:`gyroscope` at rest); a gyro
        calibration's whole correction is applied.
    window : float
        Seconds over which the gyro is integrated at a time (its leftover bias drifts by bias x window).

    Returns
    -------
    Calibration
        ``calibrated = matrix @ (mag - offset)`` with the hard iron as offset and the symmetric soft-iron
        correction as matrix, their one-sigma uncertainties (``offset_sigma``, ``matrix_sigma``; first-order
        Cramér-Rao level for Gaussian noise), and ``quality``:

        * ``field_strength``, ``field_strength_sigma``: magnitude of the calibrated field (µT);
        * ``residual_rms``: rms distance of the readings from the fitted ellipsoid (µT), about the noise;
        * ``noise``: the noise per axis used for the uncertainties (µT);
        * ``coverage``: fraction of the sphere of directions seen (within 20° of a sample; 1 = all);
        * ``direction_spread``: eigenvalues of the scatter of the calibrated directions, times 3
          (1, 1, 1 for directions spread evenly; a value near 0 means a direction never tilted);
        * ``condition``: condition number of the scaled information matrix (large: poorly determined);
        * ``soft_iron_condition``: condition number of the matrix; ``outliers``: fraction of down-weighted
          samples (Huber weight < 0.5); ``samples``, ``iterations``;
        * with ``gyro``: ``gyro_alignment_deg`` (the rotation R found) and ``alignment_residual_deg`` (rms
          angle between the field turned by the gyro and as measured; the matrix sigmas do not include R's);
        * ``norm_scatter``, ``norm_scatter_raw``: standard deviation of the field magnitude after and before
          the calibration (µT, at the fitted scale), and ``warranted``: whether the fit cuts it more than
          threefold.  A field that varies in space, a disturbance or an already calibrated sensor leave a
          scatter the ellipsoid cannot remove; a fit that removes little of it is within that model error and
          may do more harm than good (on BROAD's calibrated sensor it does: ``benchmarks/bench_calibrate.py``).

    Raises
    ------
    InsufficientMotionError
        When the sensor did not turn, turned about one axis only, the field directions stayed in a narrow
        cone (the message names the axis and the motion that is missing), or the readings cover only a small
        patch of directions (the fitted field is not the Earth's).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import magnetometer
    >>> rng = np.random.default_rng(1)
    >>> h = rng.standard_normal((2000, 3))
    >>> h *= 48.0 / np.linalg.norm(h, axis=1, keepdims=True)             # a 48 µT field in all directions
    >>> soft = np.array([[1.1, 0.05, 0.0], [0.05, 0.9, 0.02], [0.0, 0.02, 1.0]])
    >>> m = h @ soft.T + [20.0, -35.0, 8.0] + 0.2 * rng.standard_normal((2000, 3))
    >>> cal = magnetometer(m, field_strength=48.0)
    >>> cal.offset.round(1)
    array([ 20., -35.,   8.])
    >>> bool(np.std(np.linalg.norm(cal.apply(m), axis=1)) < 0.3)     # the norm is constant within the noise
    True
    """
    full = _v.as_float_array(mag, "mag", dtype=np.float64)
    r = _rows(mag, "mag")
    if len(r) < _MIN_SAMPLES:
        raise ValueError(f"mag has {len(r)} readings; the magnetometer fit needs at least {_MIN_SAMPLES}")
    if field_strength is not None:
        field_strength = float(_v.finite(field_strength, "field_strength", dtype=np.float64))
        if not field_strength > 0:
            raise ValueError(f"field_strength is {field_strength}; it must be positive (µT)")
    if noise is not None and not float(noise) > 0:
        raise ValueError(f"noise is {noise}; it must be positive (µT)")
    _check_raw_motion(r, "mag")

    start = _e.algebraic(r)
    if start is None:  # not an ellipsoid: start from a sphere about the mean
        centre = r.mean(axis=0)
        start = centre, np.eye(3) / np.mean(np.linalg.norm(r - centre, axis=1))
    radius = 1.0 if field_strength is None else field_strength
    b0, w0 = start
    fit = _e.refine(r, b0, w0 * radius, radius, robust=robust, noise=noise)

    if field_strength is None:
        matrix, offset, strength, cov = _normalise(fit)
        strength_sigma = float(np.sqrt(cov[9, 9]))
    else:
        matrix, offset, strength, cov = fit.matrix, fit.offset, field_strength, fit.covariance
        strength_sigma = 0.0
    calibrated = (r - offset) @ matrix.T
    spread, axes = _e.direction_spread(calibrated)
    if spread[0] < _MIN_SPREAD:
        raise InsufficientMotionError(
            f"the field was seen only in a narrow cone of directions around sensor axis {_e.axis_name(axes[:, 0])}"
            f" (direction spread {spread[0]:.3f}, 1 = even): turn the sensor also about axes across that one"
            " (tilt it so that this axis points up, down and sideways)"
        )
    if field_strength is None and not _EARTH_UT[0] <= strength <= _EARTH_UT[1]:
        raise InsufficientMotionError(
            f"the fitted field is {strength:.3g} µT, not the Earth's 22-67 µT: the readings cover only a small patch"
            " of directions (the sensor moved but hardly turned); turn it through all directions"
        )
    raw_extent = float(np.sqrt(np.linalg.eigvalsh(np.cov(r.T, bias=True))[-1]))
    if raw_extent < 0.2 * strength * np.linalg.det(matrix) ** (-1 / 3):
        raise InsufficientMotionError(
            f"the readings span {raw_extent:.3g} µT (rms) of a {strength:.3g} µT field: only a small patch of"
            " directions was seen (the sensor moved but hardly turned); turn it through all directions"
        )
    soft_condition = float(np.linalg.cond(matrix))
    if soft_condition > _MAX_SOFT_IRON_CONDITION:
        raise InsufficientMotionError(
            f"the fitted soft iron has condition number {soft_condition:.1f} (> {_MAX_SOFT_IRON_CONDITION}), which no"
            " real sensor has: the readings do not trace an ellipsoid; turn the sensor slowly through all directions"
            " away from iron and magnets"
        )
    sigmas = np.sqrt(np.maximum(np.diag(cov), 0.0))
    matrix_sigma = _e.sym(sigmas[3:9])  # the sigmas of the 6 distinct elements, placed symmetrically
    norms = np.linalg.norm(calibrated, axis=1)
    raw_norms = np.linalg.norm(r, axis=1) * (strength / np.mean(norms))  # raw readings at the fitted field scale
    scatter, raw_scatter = float(np.std(norms)), float(np.std(raw_norms))
    quality = {
        "field_strength": float(strength),
        "field_strength_sigma": strength_sigma,
        "residual_rms": float(np.sqrt(np.mean(fit.residual[fit.weights > 0.5] ** 2))),
        "noise": fit.sigma,
        "coverage": _e.sphere_coverage(calibrated),
        "direction_spread": spread.tolist(),
        "condition": fit.information_condition,
        "soft_iron_condition": soft_condition,
        "outliers": float(np.mean(fit.weights < 0.5)),
        "norm_scatter": scatter,
        "norm_scatter_raw": raw_scatter,
        "warranted": bool(raw_scatter > _WARRANTED * scatter),
        "samples": len(r),
        "iterations": fit.iterations,
    }
    method = "ellipsoid: algebraic start, maximum-likelihood Levenberg-Marquardt" + (", Huber-robust" if robust else "")
    if gyro is not None:
        matrix = _align_to_gyro(full, offset, matrix, gyro, fs, gyro_bias, window, quality)
        method += "; rotation onto the gyro axes"
    return Calibration(
        "mag",
        offset=offset,
        matrix=matrix,
        frame=frame,
        offset_sigma=sigmas[:3],
        matrix_sigma=matrix_sigma,
        quality=quality,
        method=method,
    )


def _align_to_gyro(m, offset, matrix, gyro, fs, gyro_bias, window, quality) -> np.ndarray:
    """``R W`` with R the rotation of the calibrated field onto the gyro's axes; figures into ``quality``."""
    from ._alignment import align

    g = _v.as_float_array(gyro, "gyro", dtype=np.float64)
    if g.shape != m.shape:
        raise ValueError(f"gyro has shape {g.shape}; it must match mag, {m.shape} (one gyro sample per reading)")
    _v.check_finite(g, "gyro")
    if fs is None or not float(fs) > 0:
        raise ValueError(f"fs is {fs}; the gyro alignment needs the sample rate (Hz)")
    if isinstance(gyro_bias, Calibration):
        g = gyro_bias.apply(g)
    elif gyro_bias is not None:
        g = g - _v.finite(gyro_bias, "gyro_bias", dtype=np.float64)
    rot, residual = align((m - offset) @ matrix.T, g, float(fs), float(window))
    quality["gyro_alignment_deg"] = float(np.degrees(np.arccos(np.clip((np.trace(rot) - 1) / 2, -1.0, 1.0))))
    quality["alignment_residual_deg"] = float(np.degrees(residual))
    return rot @ matrix
