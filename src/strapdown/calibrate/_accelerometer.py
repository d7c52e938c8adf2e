"""Accelerometer offsets, scale factors and cross-axis coupling from static poses.

At rest an accelerometer reads ``r = A g_body + b`` with g_body gravity's reaction (magnitude g, up) in
sensor axes; ``A = I + diag(s) + M`` holds the scale errors s and the cross-axis coupling M (the model of
:class:`strapdown.simulate.TriadModel`).  Two fits, chosen from the poses found:

* **six-position** (the tumble test of IEEE Std 1293, reduced to six faces): when every axis was once pointing up and
  once down, each pose's g_body is taken as ±g along that axis and ``r = A g_body + b`` is solved by weighted
  linear least squares for all 12 numbers of A and b.  The cross-axis terms then include the few tenths of a
  degree by which the faces were not level: they are the coupling relative to the faces of the box;
* **ellipsoid** (any poses): with at least 9 different orientations, ``|W (r - b)| = g`` is fitted as for the
  magnetometer (:mod:`strapdown.calibrate._ellipsoid`), W symmetric (a rotation of the axes is not seen by
  gravity alone).

The noise of a pose mean comes from the scatter of the samples within the rests, so the uncertainties are
those of white noise; ``quality["chi2"]`` says whether the pose means agree with the model that well.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .._support import validate as _v
from .._support.renamed import renamed
from . import _ellipsoid as _e
from . import _linear
from ._calibration import Calibration
from ._magnetometer import InsufficientMotionError, _rows
from ._rests import find_rests

__all__ = ["GRAVITY", "accelerometer"]

GRAVITY = 9.80665  # standard gravity, m/s²
_FACE_COS = np.cos(np.radians(25.0))  # a pose is "axis up/down" within 25° of it
_FACES = ("+x", "-x", "+y", "-y", "+z", "-z")


def _poses(acc, fs, gyro, rests, rest_options) -> tuple[list[np.ndarray], list]:
    """The readings of each pose, and where each came from."""
    if isinstance(acc, Sequence) and not isinstance(acc, np.ndarray) and len(acc) and np.ndim(acc[0]) == 2:
        return [_rows(p, f"acc[{i}]") for i, p in enumerate(acc)], [f"acc[{i}]" for i in range(len(acc))]
    r = _v.as_float_array(acc, "acc", dtype=np.float64)
    if r.ndim != 2 or r.shape[1] != 3:
        raise ValueError(f"acc must have shape (N, 3) or be a list of (n, 3) poses, got shape {r.shape}")
    _v.check_finite(r, "acc")
    if rests is None:
        if fs is None:
            raise ValueError("fs (Hz) is needed to find the rests in acc; or give rests=[(start, stop), ...]")
        rests = find_rests(r, gyro, fs=fs, **rest_options)
    rests = np.asarray(rests, dtype=np.int64).reshape(-1, 2)
    bad = (rests[:, 0] < 0) | (rests[:, 1] > len(r)) | (rests[:, 1] - rests[:, 0] < 2)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"rests[{i}] is {rests[i].tolist()}; a rest is [start, stop) within the {len(r)} samples")
    return [r[a:b] for a, b in rests], [[int(a), int(b)] for a, b in rests]


def _face(mean: np.ndarray) -> str | None:
    k = int(np.argmax(np.abs(mean)))
    if abs(mean[k]) < _FACE_COS * np.linalg.norm(mean):
        return None
    return ("+" if mean[k] > 0 else "-") + "xyz"[k]


def _six_position(faces, gravity) -> np.ndarray:
    """The true specific force of each pose: ±g along the axis that is up."""
    g_body = np.zeros((len(faces), 3))
    for k, face in enumerate(faces):
        g_body[k, "xyz".index(face[1])] = gravity if face[0] == "+" else -gravity
    return g_body


@renamed(gyr="gyro")
def accelerometer(
    acc,
    *,
    fs: float | None = None,
    gyro=None,
    rests=None,
    gravity: float = GRAVITY,
    frame: str = "sensor",
    method: str = "auto",
    **rest_options,
) -> Calibration:
    """Fit offsets, scale factors and cross-axis coupling of an accelerometer to several static poses.

    Parameters
    ----------
    acc : array_like, shape (N, 3), or list of array_like, shape (n_k, 3)
        A recording (m/s², sensor axes ``frame``) whose rests are found (:func:`find_rests`) or given in
        ``rests``; or the readings of each pose, one array per pose.
    fs : float, optional
        Sample rate (Hz), to find the rests.
    gyro : array_like, shape (N, 3), optional
        Gyro readings (rad/s) of the recording, to find the rests more surely.
    rests : array_like of int, shape (K, 2), optional
        ``[start, stop)`` of each pose's samples, instead of finding them.
    gravity : float
        Local gravity, m/s² (standard gravity by default; the local value differs by up to 0.3 %, which
        otherwise ends up in the scale factors).
    frame : str
        Name of the sensor axes, stored with the calibration.
    method : {"auto", "six-position", "ellipsoid"}
        The fit (module notes); "auto" takes six-position when every axis was once up and once down.
    **rest_options
        Passed to :func:`find_rests` (``min_duration``, ``acc_threshold`` ...).

    Returns
    -------
    Calibration
        ``calibrated = matrix @ (acc - offset)`` with one-sigma uncertainties, and ``quality``: ``poses``
        (their count), ``faces`` (the face up in each pose, or null), ``rests``, ``noise`` (per-sample
        scatter at rest, m/s², per axis), ``residual_rms`` (of the pose means about the model, m/s²),
        ``chi2`` (per degree of freedom, about 1 when the model fits to the noise), ``gravity``; for the
        six-position fit also ``scale_factor``, ``misalignment`` (A's off-diagonal terms, rad) and their
        sigmas.

    Raises
    ------
    InsufficientMotionError
        With fewer poses than the fit needs, or poses that leave an axis untried; the message lists the
        missing faces.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.calibrate import accelerometer
    >>> a = np.eye(3) + np.diag([0.01, -0.02, 0.005])                  # scale errors of 1, -2 and 0.5 %
    >>> up = 9.80665 * np.vstack([np.eye(3), -np.eye(3)])              # each axis up, then down
    >>> rng = np.random.default_rng(0)
    >>> poses = [g @ a.T + [0.1, -0.2, 0.05] + 0.01 * rng.standard_normal((200, 3)) for g in up]
    >>> cal = accelerometer(poses)
    >>> cal.offset.round(2), np.round(cal.quality["scale_factor"], 3)
    (array([ 0.1 , -0.2 ,  0.05]), array([ 0.01 , -0.02 ,  0.005]))
    """
    _v.choice(method, "method", ("auto", "six-position", "ellipsoid"))
    gravity = float(_v.finite(gravity, "gravity", dtype=np.float64))
    if not gravity > 0:
        raise ValueError(f"gravity is {gravity}; it must be positive (m/s²)")
    poses, where = _poses(acc, fs, gyro, rests, rest_options)
    if not poses:
        raise InsufficientMotionError(
            "no rest found in acc: hold the sensor still in each pose (at least "
            f"{rest_options.get('min_duration', 1.0)} s), each axis pointing up and then down"
        )
    counts = np.array([len(p) for p in poses], dtype=np.float64)
    means = np.array([p.mean(axis=0) for p in poses])
    scatter = np.concatenate([p - p.mean(axis=0) for p in poses])
    noise = np.sqrt(np.sum(scatter**2, axis=0) / max(len(scatter) - len(poses), 1))
    noise = np.maximum(noise, 1e-12)
    faces = [_face(m) for m in means]
    seen = sorted({f for f in faces if f})
    missing = [f for f in _FACES if f not in seen]
    if method == "auto":
        method = "six-position" if not missing else "ellipsoid"
    needed = 9
    if len(poses) == 1 or (method == "six-position" and missing) or (method == "ellipsoid" and len(poses) < needed):
        what = f"{len(poses)} pose" + ("s" if len(poses) != 1 else "")
        face_text = ", ".join(f or "tilted" for f in faces)
        raise InsufficientMotionError(
            f"{what} found ({face_text}); the accelerometer fit needs the sensor still on each of its six faces "
            f"(each axis up, then down; missing: {', '.join(missing) or 'none'}), or at least {needed} different "
            "orientations"
        )

    quality = {"poses": len(poses), "faces": faces, "rests": where, "noise": noise.tolist(), "gravity": gravity}
    if method == "six-position":
        a, offset, cov_a, offset_sigma, residual, _ = _linear.fit(_six_position(faces, gravity), means, counts, noise)
        matrix, matrix_sigma, figures = _linear.correction(a, cov_a)
        quality.update(figures)
        chi2 = float(np.sum(counts[:, None] * residual**2 / noise**2) / max(3 * len(poses) - 12, 1))
        rms = float(np.sqrt(np.mean(residual**2)))
    else:
        spread, axes = _e.direction_spread(means)
        if spread[0] < 0.1:
            raise InsufficientMotionError(
                f"the {len(poses)} poses all have gravity near a cone around sensor axis {_e.axis_name(axes[:, 0])}"
                f" (direction spread {spread[0]:.3f}, 1 = even): also tilt that axis up, down and sideways"
            )
        start = _e.algebraic(means) if len(poses) >= needed else None
        if start is None:
            centre = means.mean(axis=0)
            start = centre, np.eye(3) / np.mean(np.linalg.norm(means - centre, axis=1))
        sigma = float(np.sqrt(np.mean(noise**2)))
        fit = _e.refine(means, start[0], start[1] * gravity, gravity, sample_weights=counts, robust=False, noise=sigma)
        sig = np.sqrt(np.maximum(np.diag(fit.covariance), 0.0))
        matrix_sigma = _e.sym(sig[3:9])  # the sigmas of the 6 distinct elements, placed symmetrically
        matrix, offset, offset_sigma = fit.matrix, fit.offset, sig[:3]
        chi2 = float(np.sum(counts * fit.residual**2) / sigma**2 / max(len(poses) - 9, 1))
        rms = float(np.sqrt(np.mean(fit.residual**2)))
        quality["direction_spread"] = spread.tolist()
    quality.update(residual_rms=rms, chi2=chi2)
    return Calibration(
        "acc",
        offset=offset,
        matrix=matrix,
        frame=frame,
        offset_sigma=offset_sigma,
        matrix_sigma=matrix_sigma,
        quality=quality,
        method=method,
    )
