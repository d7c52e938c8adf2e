"""Every attitude representation as rows of real numbers, with their column names.

Each representation of :data:`REPRESENTATIONS` is a fixed number of real values, converted by the library's
``from_*`` / ``as_*`` functions: ``quat`` (qw, qx, qy, qz), ``euler`` (any of the 24 sequences; yaw, pitch and
roll for ``"ZYX"``), ``matrix`` (c11 ... c33, row by row), ``rotvec``, ``axis_angle`` (axis and angle), ``gibbs``
(Gajda's or Rodrigues'), ``cayley_klein`` (real and imaginary parts of u11, u12, u21, u22) and ``compressed``
(Liu et al.'s unique angles).  Angles are in degrees or radians, and the names say which (``yaw_deg``).  Files
(:mod:`strapdown.io.tables`) and figures (:mod:`strapdown.evaluate.figures`) take these names and values.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .cayley_klein import as_cayley_klein, from_cayley_klein
from .compressed import as_compressed, from_compressed
from .euler import _parse_seq, as_euler, from_euler
from .matrix import as_matrix, from_matrix
from .rotvec import as_axis_angle, as_gibbs, as_rotvec, from_axis_angle, from_gibbs, from_rotvec

__all__ = ["REPRESENTATIONS", "Angles", "column_names", "from_values", "to_values"]


#: Representation name -> number of real values.
REPRESENTATIONS = {
    "quat": 4,
    "euler": 3,
    "matrix": 9,
    "rotvec": 3,
    "axis_angle": 4,
    "gibbs": 3,
    "cayley_klein": 8,
    "compressed": 3,
}


_ANGULAR = ("euler", "rotvec", "axis_angle", "compressed")


@dataclass(frozen=True)
class Angles:
    """How angles and angle-like values are written.

    Attributes
    ----------
    seq : str
        Euler sequence (scipy's names: upper case intrinsic).
    degrees : bool
        Degrees rather than radians.
    yaw_range : {"signed", "positive"} or None
        Range of the outer Euler angle; None: ``"positive"`` (Gajda's [0, 360°)) for ``"ZYX"``, else signed.
    gibbs : {"gajda", "rodrigues"}
        Gibbs vector convention.
    """

    seq: str = "ZYX"
    degrees: bool = True
    yaw_range: str | None = None
    gibbs: str = "gajda"

    def __post_init__(self):
        _parse_seq(self.seq)
        if self.yaw_range not in (None, "signed", "positive"):
            raise ValueError(f"yaw_range must be 'signed' or 'positive', got {self.yaw_range!r}")
        if self.gibbs not in ("gajda", "rodrigues"):
            raise ValueError(f"gibbs must be 'gajda' or 'rodrigues', got {self.gibbs!r}")

    @property
    def range(self) -> str:
        """The outer-angle range in force."""
        return self.yaw_range or ("positive" if self.seq == "ZYX" else "signed")


def _rep(name: str) -> str:
    if name not in REPRESENTATIONS:
        raise ValueError(f"unknown representation {name!r}; choose from {', '.join(REPRESENTATIONS)}")
    return name


def column_names(rep: str, angles: Angles = Angles()) -> list[str]:
    """Column names of a representation.

    Parameters
    ----------
    rep : str
        A key of :data:`REPRESENTATIONS`.
    angles : Angles
        Sequence and unit of the angles.

    Returns
    -------
    list of str
        One name per value.

    Examples
    --------
    >>> from strapdown.io.tables import Angles, column_names
    >>> column_names("euler"), column_names("euler", Angles("ZXZ", degrees=False))
    (['yaw_deg', 'pitch_deg', 'roll_deg'], ['ZXZ_1_rad', 'ZXZ_2_rad', 'ZXZ_3_rad'])
    """
    unit = "_deg" if angles.degrees else "_rad"
    rep = _rep(rep)
    if rep == "quat":
        return ["qw", "qx", "qy", "qz"]
    if rep == "euler":
        if angles.seq == "ZYX":
            return [f"{a}{unit}" for a in ("yaw", "pitch", "roll")]
        return [f"{angles.seq}_{i}{unit}" for i in (1, 2, 3)]
    if rep == "matrix":
        return [f"c{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)]
    if rep == "rotvec":
        return [f"rotvec_{a}{unit}" for a in "xyz"]
    if rep == "axis_angle":
        return ["axis_x", "axis_y", "axis_z", f"angle{unit}"]
    if rep == "gibbs":
        return [f"gibbs_{a}" for a in "xyz"]
    if rep == "cayley_klein":
        return [f"u{ij}_{part}" for ij in ("11", "12", "21", "22") for part in ("re", "im")]
    return [f"{a}{unit}" for a in ("heading", "pitch", "roll")]  # compressed: Liu et al.'s (ψ, θ, γ)


def to_values(rep: str, q: np.ndarray, angles: Angles = Angles(), *, check: bool = True) -> np.ndarray:
    """A representation of attitudes as an (N, width) real array.

    Parameters
    ----------
    rep : str
        A key of :data:`REPRESENTATIONS`.
    q : array_like, shape (N, 4)
        Quaternions.
    angles : Angles
        Sequence, unit and ranges.
    check : bool
        Validate ``q`` (finite, non-zero; default).  False for quaternions the library made itself, such as an
        integrator's unit quaternions: the validation's per-row reduction costs about half the conversion.

    Returns
    -------
    numpy.ndarray, shape (N, REPRESENTATIONS[rep])
        The values in the order of :func:`column_names`.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.rotations.values import to_values
    >>> to_values("euler", np.array([[0.0, 0.0, 0.0, 1.0]])).round(9)      # 180 deg about z
    array([[180.,   0.,   0.]])
    """
    q = np.asarray(q, dtype=np.float64)
    rep, deg = _rep(rep), angles.degrees
    if rep == "quat":
        return q
    if rep == "euler":
        return as_euler(q, angles.seq, deg, yaw_range=angles.range, check=check)
    if rep == "matrix":
        return as_matrix(q, check=check).reshape(-1, 9)
    if rep == "rotvec":
        return as_rotvec(q, deg, check=check)
    if rep == "axis_angle":
        axis, angle = as_axis_angle(q, deg, check=check)
        return np.column_stack([axis, angle])
    if rep == "gibbs":
        with np.errstate(divide="ignore"):
            return as_gibbs(q, angles.gibbs, check=check)
    if rep == "cayley_klein":
        u = as_cayley_klein(q, check=check).reshape(-1, 4)
        return np.stack([u.real, u.imag], axis=-1).reshape(-1, 8)
    return as_compressed(q, deg, check=check)


def from_values(rep: str, values, angles: Angles = Angles()) -> np.ndarray:
    """Quaternions from an (N, width) array of a representation (the inverse of :func:`to_values`).

    Parameters
    ----------
    rep : str
        A key of :data:`REPRESENTATIONS`.
    values : array_like, shape (N, REPRESENTATIONS[rep])
        The values, in the order of :func:`column_names`.
    angles : Angles
        Sequence and unit.

    Returns
    -------
    numpy.ndarray, shape (N, 4)
        Unit quaternions (a quaternion is normalised).

    Examples
    --------
    >>> from strapdown.rotations.values import from_values
    >>> from_values("euler", [[90.0, 0.0, 0.0]]).round(6)
    array([[0.707107, 0.      , 0.      , 0.707107]])
    """
    rep, deg = _rep(rep), angles.degrees
    v = np.asarray(values, dtype=np.float64)
    if v.ndim != 2 or v.shape[1] != REPRESENTATIONS[rep]:
        raise ValueError(f"{rep} needs {REPRESENTATIONS[rep]} values per row, got shape {v.shape}")
    if rep == "quat":
        norm = np.linalg.norm(v, axis=1, keepdims=True)
        if not (norm > 0).all():
            raise ValueError(f"quaternion {int(np.argmin(norm[:, 0] > 0))} is zero")
        return v / norm
    if rep == "euler":
        return from_euler(v, angles.seq, deg)
    if rep == "matrix":
        return from_matrix(v.reshape(-1, 3, 3))
    if rep == "rotvec":
        return from_rotvec(v, deg)
    if rep == "axis_angle":
        return from_axis_angle(v[:, :3], v[:, 3], deg)
    if rep == "gibbs":
        return from_gibbs(v, angles.gibbs)
    if rep == "cayley_klein":
        u = (v[:, 0::2] + 1j * v[:, 1::2]).reshape(-1, 2, 2)
        return from_cayley_klein(u)
    return from_compressed(v, deg)
