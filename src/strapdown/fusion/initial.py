"""The attitude of a body at rest from one accelerometer (and magnetometer) sample: where the filters start."""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from ..rotations.frames import frame_quaternion
from ..rotations.quaternion import multiply

__all__ = ["initial_attitude"]


def initial_attitude(acc, mag=None, frame: str = "ENU") -> np.ndarray:
    """Attitude (sensor to ``frame``) from one accelerometer sample at rest and optionally one magnetometer sample.

    Without a magnetometer the heading is chosen so that the attitude is a pure tilt (no rotation about the
    vertical: the tilt quaternion of the Rowe patent).  With one, north is the horizontal part of the field
    (magnetic north; declination is not applied).

    Parameters
    ----------
    acc : array_like, shape (3,)
        Specific force, any unit (+g along body up at rest).
    mag : array_like, shape (3,), optional
        Magnetic field, any unit.
    frame : str
        Reference frame of the result.

    Returns
    -------
    numpy.ndarray, shape (4,)
        Unit quaternion (float32 when the inputs are).

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.fusion import initial_attitude
    >>> initial_attitude([0.0, 0.0, 9.81]).round(12)          # level: identity
    array([1., 0., 0., 0.])
    >>> initial_attitude([0.0, 0.0, 9.81], [0.0, 20.0, -40.0], "ENU").round(12)   # y axis points north
    array([1., 0., 0., 0.])
    """
    out_dtype = _v.result_dtype(*(_v.as_float_array(x, n) for x, n in ((acc, "acc"), (mag, "mag")) if x is not None))
    return _initial_attitude(acc, mag, frame).astype(out_dtype, copy=False)


def _one_vector(v, name: str) -> np.ndarray:
    """One 3-vector scaled by a power of two to a largest component in [0.5, 1), exactly.

    Only its direction is used, and the norms below then neither overflow (1e200) nor underflow.
    """
    arr = _v.vectors(v, name, dtype=np.float64)
    if arr.shape != (3,):
        raise ValueError(f"{name} must be one sample of shape (3,), got shape {arr.shape}")
    _, e = np.frexp(np.max(np.abs(arr)))
    return np.ldexp(arr, -e)


def _initial_attitude(acc, mag, frame: str) -> np.ndarray:
    from ..rotations.matrix import from_matrix

    a = _one_vector(acc, "acc")
    na = np.linalg.norm(a)
    if not na > 0:
        raise ValueError("acc is zero: no direction of gravity to start from")
    up = a / na
    to_frame = frame_quaternion("ENU", frame)
    if mag is None:
        # shortest arc taking the sensor's up to z (math.md §5.5): a tilt, e3 = 0
        c = np.sqrt(max(0.0, 0.5 * (1 + up[2])))
        if c < 1e-9:  # upside down: a half turn about x
            q = np.array([0.0, 1.0, 0.0, 0.0])
        else:
            q = np.array([c, up[1] / (2 * c), -up[0] / (2 * c), 0.0])
        return multiply(to_frame, q)
    m = _one_vector(mag, "mag")
    east = np.cross(m, up)
    ne = np.linalg.norm(east)
    if not ne > 1e-9 * np.linalg.norm(m):
        raise ValueError("mag is parallel to gravity: no horizontal field to take north from")
    east /= ne
    north = np.cross(up, east)
    q_enu = from_matrix(np.array([east, north, up]))  # rows: E, N, U in sensor axes, so sensor -> ENU
    return multiply(to_frame, q_enu)
