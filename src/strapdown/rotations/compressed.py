"""Unique ("compressed") attitude forms after Liu Gongxu et al. (J. Xidian Univ. 46(4), 2019).

A rotation has two quaternions, ±q, and, at gimbal lock, infinitely many Euler triples.  Liu et al. restrict
both spaces so that each attitude has exactly one representative and the two spaces map one-to-one:

* **compressed quaternion space** (their (18); math.md §3.3 variant A):
  :func:`strapdown.rotations.quaternion.canonical`,
  w > 0, ties broken by x, then y, then z;
* **compressed angle space** (their (1)): the paper's convention, ENU reference frame, body axes
  right-forward-up, ``C_b^n = R_z(ψ) R_x(θ) R_y(γ)`` (intrinsic ``"ZXY"``, their (6)), with
  pitch θ ∈ [-90°, 90°] about X, roll γ ∈ (-180°, 180°] about Y, heading ψ ∈ (-180°, 180°] about Z and, at
  θ = ±90° where only ψ ± γ is defined, the rule γ = 0.

Heading ψ is a right-handed rotation about Up: ψ > 0 turns the nose from North towards **West** (the PSINS
convention).  A navigation azimuth (clockwise from North) is ``-ψ``.  The paper does not say which one it meant.

The triples are ordered as the sequence: ``(ψ, θ, γ)`` = (heading, pitch, roll).
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from .euler import as_euler, from_euler
from .quaternion import canonical

__all__ = ["LIU_SEQUENCE", "as_compressed", "from_compressed"]

LIU_SEQUENCE = "ZXY"


def from_compressed(angles, degrees: bool = False, *, check: bool = True) -> np.ndarray:
    """Canonical quaternions from Liu et al.'s (heading, pitch, roll), their (15) followed by the sign rule.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        (ψ heading about Up, θ pitch about Right, γ roll about Forward), ENU reference, RFU body axes.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions in the compressed (canonical) space.

    Examples
    --------
    >>> from strapdown import from_compressed
    >>> from_compressed([0.0, 0.0, 270.0], degrees=True).round(6)    # roll 270 = roll -90: w > 0 chosen
    array([ 0.707107,  0.      , -0.707107,  0.      ])
    """
    return canonical(from_euler(angles, LIU_SEQUENCE, degrees, check=check), check=False)


def as_compressed(q, degrees: bool = False, *, check: bool = True) -> np.ndarray:
    """The unique compressed angle triple (ψ, θ, γ) of each attitude, their (16) with the lock rule.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions, ENU reference and RFU body axes; ``q`` and ``-q`` give bit-identical results.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        heading ψ ∈ (-π, π], pitch θ ∈ [-π/2, π/2], roll γ ∈ (-π, π]; γ = 0 where θ = ±π/2 exactly.

    Examples
    --------
    >>> from strapdown import as_compressed, from_compressed
    >>> as_compressed(from_compressed([10.0, 90.0, 30.0], degrees=True), degrees=True).round(9)
    array([40., 90.,  0.])
    """
    # validated as a rotation (scaled exactly when far from unit norm), then the sign rule: as_euler's own check
    # is skipped, so it must happen here (q * 1e199 gave pitch 0, the identity at 5e-324 gave -90°)
    return as_euler(canonical(_v.rotations(q, "q", check=check), check=False), LIU_SEQUENCE, degrees, check=False)
