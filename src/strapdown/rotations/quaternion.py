"""Quaternion algebra on plain numpy arrays.

Conventions (the same everywhere in strapdown)
----------------------------------------------
* A quaternion is a float array of shape (..., 4), **scalar first** ``[w, x, y, z]``; products are Hamilton
  products (``i j = k``), Gajda (2.14).
* An attitude quaternion ``q`` maps body-frame vectors to the reference frame:
  ``v_ref = q ⊗ v_body ⊗ q*``.  Body rates update it on the right, ``q_{k+1} = q_k ⊗ dq_k``.
* Every function broadcasts over leading axes, keeps float32 as float32 (other input widens to float64) and
  returns a new array.

Input checks
------------
``check`` as everywhere in :mod:`strapdown.rotations`: NaN and infinities raise a ``ValueError`` that names the
argument and the first bad row.  ``multiply``, ``conjugate`` and ``norm`` are plain algebra in the quaternions and
accept a zero quaternion; every other function interprets its argument as a rotation or divides by its norm and
rejects a zero quaternion.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = [
    "angle_between",
    "canonical",
    "conjugate",
    "exp",
    "identity",
    "inverse",
    "log",
    "multiply",
    "norm",
    "normalize",
    "power",
    "rotate",
    "slerp",
]


def identity(shape=(), dtype=np.float64) -> np.ndarray:
    """Identity quaternions ``[1, 0, 0, 0]`` of the given leading shape.

    Parameters
    ----------
    shape : int or tuple of int
        Leading shape; the result has shape ``shape + (4,)``.
    dtype : dtype
        float32 or float64.

    Returns
    -------
    numpy.ndarray
        Identity quaternions.

    Examples
    --------
    >>> from strapdown import quaternion as quat
    >>> quat.identity(2)
    array([[1., 0., 0., 0.],
           [1., 0., 0., 0.]])
    """
    shape = (shape,) if np.isscalar(shape) else tuple(shape)
    if not all(isinstance(n, int | np.integer) and not isinstance(n, bool) and n >= 0 for n in shape):
        raise ValueError(f"shape must be a non-negative integer or a tuple of them, got {shape!r}")
    dtype = np.dtype(dtype)
    if dtype not in (np.float32, np.float64):
        raise ValueError(f"dtype must be float32 or float64, got {dtype}")
    out = np.zeros((*shape, 4), dtype=dtype)
    out[..., 0] = 1
    return out


def _rows(a: np.ndarray, shape: tuple, dtype) -> np.ndarray:
    """(n, 4) C-contiguous rows of `a`; a single quaternion stays one row (the kernel broadcasts it)."""
    a = a.astype(dtype, copy=False)
    if a.shape[:-1] != shape and a.shape[:-1] and int(np.prod(a.shape[:-1])) != 1:
        a = np.broadcast_to(a, (*shape, 4))
    return np.ascontiguousarray(a.reshape(-1, 4))


def multiply(p, q, *, check: bool = True) -> np.ndarray:
    """Hamilton product ``p ⊗ q``.

    Composition of attitudes: if ``p`` maps frame B to A and ``q`` maps C to B, then ``p ⊗ q`` maps C to A.

    Parameters
    ----------
    p, q : array_like, shape (..., 4)
        The factors, in that order (zero allowed).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        The product, in Gajda's (2.14) reordered scalar first.

    Examples
    --------
    >>> from strapdown import quaternion as quat
    >>> quat.multiply([0, 1, 0, 0], [0, 0, 1, 0])   # i j = k
    array([0., 0., 0., 1.])
    """
    p = _v.quaternions(p, "p", check=check, nonzero=False)
    q = _v.quaternions(q, "q", check=check, nonzero=False)
    shape = _v.broadcast(("p", p.shape[:-1]), ("q", q.shape[:-1]))
    dtype = _v.result_dtype(p, q)
    p_rows = _rows(p, shape, dtype)
    q_rows = _rows(q, shape, dtype)
    out = np.empty((int(np.prod(shape)), 4), dtype=dtype)
    from .._support.uncompiled import call
    from ._quaternion_numba import multiply_rows

    with np.errstate(over="ignore", invalid="ignore"):
        call(multiply_rows, p_rows, q_rows, out, python_seconds=3e-6 * out.shape[0])  # 3 µs a row uncompiled
    out = out.reshape((*shape, 4))
    if check and not _v.all_finite(out):
        bad = ~np.isfinite(out).all(axis=-1)
        i = _v.first_index(bad)
        pn, qn = np.broadcast_to(norm(p), shape)[bad][0], np.broadcast_to(norm(q), shape)[bad][0]
        raise ValueError(
            f"p ⊗ q{i} overflows: |p| = {pn:.3g} and |q| = {qn:.3g}, and the product's norm |p| |q| exceeds the "
            f"largest {dtype} ({np.finfo(dtype).max:.3g}); normalise the factors first"
        )
    return out


def conjugate(q, *, check: bool = True) -> np.ndarray:
    """Conjugate ``q* = [w, -x, -y, -z]``.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions, zero included (plain algebra).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        The conjugates; for a unit quaternion, the inverse rotation.

    Examples
    --------
    >>> from strapdown import quaternion as quat
    >>> quat.conjugate([1.0, 2.0, 3.0, 4.0])
    array([ 1., -2., -3., -4.])
    """
    q = _v.quaternions(q, "q", check=check, nonzero=False)
    out = -q
    out[..., 0] = q[..., 0]
    return out


def norm(q, *, check: bool = True) -> np.ndarray:
    """Euclidean norm ``|q|`` over the last axis.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions of any finite size: with ``check`` (the default), components of 1e200 or 1e-200 get their
        norms to rounding, where the sum of squares would overflow or underflow.

    Returns
    -------
    numpy.ndarray, shape (...)
        Norms.

    Examples
    --------
    >>> from strapdown import quaternion as quat
    >>> quat.norm([[1, 1, 1, 1], [0, 0, 3, 4]])
    array([2., 5.])
    """
    q = _v.quaternions(q, "q", check=check, nonzero=False)
    n2 = np.einsum("...i,...i->...", q, q)
    info = np.finfo(q.dtype)
    fine = (n2 >= info.tiny) & (n2 <= info.max)  # |q|² neither under- nor overflowed
    if fine.all() or not check:
        return np.sqrt(n2)
    # |q| = 2^e |q 2^-e| with the largest component scaled into [0.5, 1) by a power of two (exact): no square
    # can overflow or underflow, so 1e200 and 1e-200 get their norms to rounding
    _, e = np.frexp(np.max(np.abs(q), axis=-1))
    with np.errstate(over="ignore"):
        scaled = np.ldexp(q, -e[..., None])
        out = np.where(fine, np.sqrt(n2), np.ldexp(np.sqrt(np.einsum("...i,...i->...", scaled, scaled)), e))
    if not np.isfinite(out).all():
        raise ValueError(f"q{_v.first_index(~np.isfinite(out))} has a norm beyond the largest {q.dtype}")
    return out.astype(q.dtype, copy=False)


def inverse(q, *, check: bool = True) -> np.ndarray:
    """Multiplicative inverse ``q* / |q|²``.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions of any non-zero norm (for a unit one the inverse is the conjugate).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Inverses, so that ``multiply(q, inverse(q))`` is the identity.

    Examples
    --------
    >>> from strapdown import quaternion as quat
    >>> quat.inverse([0.0, 0.0, 2.0, 0.0])
    array([ 0. , -0. , -0.5, -0. ])
    """
    q = _v.quaternions(q, "q", check=check)
    n2 = np.einsum("...i,...i->...", q, q)
    out = -q / n2[..., None]
    out[..., 0] = -out[..., 0]
    return out


def normalize(q, method: str = "exact", *, check: bool = True) -> np.ndarray:
    """Scale quaternions to unit norm.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions: any finite norm for ``"exact"`` (rows far from unit norm are first scaled by a
        power of two, exactly), ``|q|²`` within 0.5 of 1 for ``"series"``.
    method : {"exact", "series"}
        ``"exact"`` divides by ``|q|``.  ``"series"`` multiplies by ``(3 - |q|²)/2``, the first-order series of
        ``1/√(|q|²)`` about 1 (nabbla part 9, eqs. 6-7): no division and no square root, for fixed-point or
        very small processors.  It leaves a norm error of about ``-(3/8) ε²`` where ``ε = |q|² - 1``, so it is
        meant for quaternions already close to unit norm (renormalising an integrator every few steps).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Normalised quaternions (approximately, for ``"series"``).

    Examples
    --------
    >>> from strapdown import quaternion as quat
    >>> quat.normalize([0.0, 3.0, 0.0, 4.0])
    array([0. , 0.6, 0. , 0.8])
    >>> float(quat.norm(quat.normalize([1.01, 0, 0, 0], method="series")))
    0.99985
    """
    _v.choice(method, "method", ("exact", "series"))
    if method == "exact":
        q = _v.rotations(q, "q", check=check)
        return q / np.sqrt(np.einsum("...i,...i->...", q, q))[..., None]
    q = _v.quaternions(q, "q", check=check)
    n2 = np.einsum("...i,...i->...", q, q)[..., None]
    if check and not (np.abs(n2 - 1) <= 0.5).all():
        bad = ~(np.abs(n2[..., 0] - 1) <= 0.5)
        raise ValueError(
            f"q{_v.first_index(bad)} has |q|² = {float(n2[..., 0][bad][0]):.3g}: the series normalisation is for "
            "|q|² within 0.5 of 1 (its error grows as (3/8)(|q|² - 1)²); use method='exact'"
        )
    return q * ((3 - n2) / 2)


def _norm3(v: np.ndarray) -> np.ndarray:
    """Length of 3-vectors without underflow.

    sqrt(x² + y² + z²) keeps only a few bits once the squares are subnormal (components below 1e-154), and the
    length sets a direction, so use nested hypot.
    """
    return np.hypot(np.hypot(v[..., 0], v[..., 1]), v[..., 2])


def _sinc(a: np.ndarray) -> np.ndarray:
    """sin(a)/a with the removable singularity filled; a series below 1e-4 avoids dividing by a tiny number."""
    small = a < 1e-4
    with np.errstate(invalid="ignore", divide="ignore"):
        direct = np.sin(a) / a
    a2 = np.where(small, a, 0) ** 2  # the series only where it is used: a² of 1e78 would overflow (and warn)
    return np.where(small, 1 - a2 / 6 * (1 - a2 / 20), direct)


def exp(q, *, check: bool = True) -> np.ndarray:
    """Quaternion exponential ``e^w (cos|v| + v̂ sin|v|)``.

    For a pure quaternion ``(0, θ n / 2)`` the result is the unit quaternion of a rotation by θ about the unit
    axis n (Gajda 2.7); :func:`strapdown.from_rotvec` wraps exactly that.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Quaternions ``[w, x, y, z]``.
    check : bool
        Reject NaN and infinities (default), and a scalar part w whose e^w is not a normal number (outside
        [-708.3, 709.7] in float64, [-87.3, 88.7] in float32): the result would overflow or lose its bits.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Exponentials, of norm e^w: unit quaternions for pure ``q``.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import quaternion as quat
    >>> quat.exp([0.0, 0.0, 0.0, np.pi / 4])     # 90 deg about z
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    q = _v.quaternions(q, "q", check=check, nonzero=False)
    if check:
        _exp_range(q[..., 0], "q", "w")
    v = q[..., 1:]
    a = _norm3(v)
    scale = np.exp(q[..., 0])
    out = np.empty_like(q)
    out[..., 0] = scale * np.cos(a)
    out[..., 1:] = (scale * _sinc(a))[..., None] * v
    return out


def _exp_range(w: np.ndarray, name: str, what: str) -> None:
    """Raise unless e^w is a normal number of w's dtype (|exp q| = e^w would overflow, or lose its bits)."""
    info = np.finfo(w.dtype)
    lo, hi = np.log(info.tiny), np.log(info.max)
    bad = ~((w >= lo) & (w <= hi))
    if bad.any():
        raise ValueError(
            f"{name}{_v.first_index(bad)} has {what} = {float(w[bad][0]):.6g}, and e^({what}) = |result| "
            f"{'overflows' if w[bad][0] > 0 else 'underflows'} {w.dtype}: {what} must lie in [{lo:.1f}, {hi:.1f}]"
        )


def _half_angle(q: np.ndarray):
    """|v|, the half angle atan2(|v|, w) in [0, π], and the unit axis v̂ (zero where v = 0).

    v is scaled by its largest component before it is normalised: for tiny vector parts both |v|² and |v|
    itself can be subnormal and carry too few bits to give a unit v̂ (exp(log q) would drift by 1e-13).
    """
    v = q[..., 1:]
    big = np.max(np.abs(v), axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        scaled = v / big[..., None]
        length = _norm3(scaled)
        unit = scaled / length[..., None]
    unit = np.where(big[..., None] > 0, unit, 0 * v)
    s = np.where(big > 0, big * length, 0 * big)
    return s, np.arctan2(s, q[..., 0]), unit


def log(q, *, check: bool = True) -> np.ndarray:
    """Quaternion logarithm ``ln|q| + v̂ atan2(|v|, w)``, the inverse of :func:`exp`.

    For a unit quaternion the result is the pure quaternion ``(0, θ n / 2)`` with θ in [0, 2π] (no sign is
    chosen: ``log(-q)`` describes the same rotation the long way round).  For ``q = -|q|`` (vector part exactly
    zero, w < 0) the axis is undefined and the x axis is returned, so that ``exp(log(q)) == q`` still holds.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions: the scalar part of the result is ln|q|.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Logarithms.

    Examples
    --------
    >>> from strapdown import quaternion as quat
    >>> quat.log([0.0, 0.0, 1.0, 0.0])     # 180 deg about y: (0, pi/2 * y)
    array([0.        , 0.        , 1.57079633, 0.        ])
    """
    q = _v.quaternions(q, "q", check=check)
    s, half, unit = _half_angle(q)
    out = np.empty_like(q)
    n2 = np.einsum("...i,...i->...", q, q)
    out[..., 0] = 0.5 * np.log(n2)
    out[..., 1:] = half[..., None] * unit
    undefined = (s == 0) & (q[..., 0] < 0)
    if undefined.any():
        out[undefined, 1] = np.pi
    return out


def power(q, t, *, check: bool = True) -> np.ndarray:
    """Quaternion power ``q^t = exp(t log q)``: for a unit quaternion, the same axis and t times the angle.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions.
    t : array_like, shape (...)
        Real exponents, broadcast against the leading axes of ``q``.
    check : bool
        Reject NaN, infinities and zero quaternions (default), and results out of range: ``|q|^t`` must be
        a normal number, and ``|t| θ/2`` (θ the angle of q) at most ``1e-3/ε`` rad (4.5e12 in float64, 8.4e3
        in float32), beyond which rounding scrambles the angle of the result by more than 1 mrad.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Powers.  As for :func:`log`, ``q = -|q|`` takes the x axis.  float32 stays float32, also with a Python
        float ``t``.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import quaternion as quat
    >>> q90 = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]
    >>> quat.power(q90, 0.5)     # 45 deg about z
    array([0.92387953, 0.        , 0.        , 0.38268343])
    """
    t_in = t
    q = _v.quaternions(q, "q", check=check)
    t = _v.finite(t, "t", check=check)
    if _v.weak(t_in):
        t = t.astype(q.dtype)
    q, t = _v.promote(q, t)
    _v.broadcast(("q", q.shape[:-1]), ("t", t.shape))
    lq = log(q, check=False)
    lq, t = np.broadcast_arrays(lq, t[..., None])
    lt = lq * t
    if check:
        # |q^t| = e^(t ln|q|) must be representable, and the angle t θ/2 known to 1 mrad: beyond |t θ/2| ε ≈ 1e-3
        # rounding has scrambled it (power(q, 1e20) of a unit q gave a zero quaternion)
        _exp_range(lt[..., 0], "q^t", "t ln|q|")
        turn = _norm3(lt[..., 1:])
        limit = 1e-3 / np.finfo(q.dtype).eps
        if not (turn <= limit).all():
            bad = ~(turn <= limit)
            raise ValueError(
                f"q^t{_v.first_index(bad)}: t times the half angle is {float(turn[bad][0]):.3g} rad, beyond "
                f"{limit:.3g} rad, where {q.dtype} rounding leaves the angle of the result unknown"
            )
    return exp(lt, check=False)


def rotate(q, v, *, check: bool = True) -> np.ndarray:
    """Rotate vectors: ``q ⊗ v ⊗ q*`` for unit ``q``, i.e. body-frame vectors into the reference frame.

    Equal to ``as_matrix(q) @ v``.  A non-unit ``q`` applies the rotation of ``q / |q|``.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero attitude quaternions (body to reference), any finite norm (1e200 and 1e-300 are exact: rows
        far from unit norm are scaled by a power of two first).
    v : array_like, shape (..., 3)
        Vectors in the body frame.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        The vectors in the reference frame.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import quaternion as quat
    >>> q90z = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]
    >>> quat.rotate(q90z, [1.0, 0.0, 0.0]).round(12)
    array([0., 1., 0.])
    """
    q = _v.rotations(q, "q", check=check)
    q, v = _v.promote(q, _v.vectors(v, "v", check=check))
    if check:
        _v.broadcast(("q", q.shape[:-1]), ("v", v.shape[:-1]))
    w = q[..., :1]
    u = q[..., 1:]
    s = 2 / np.einsum("...i,...i->...", q, q)[..., None]
    with np.errstate(over="ignore", invalid="ignore"):
        uv = np.cross(u, v)
        # v + (2/|q|²) (w (u×v) + u×(u×v)): the sandwich product expanded, exact for any non-zero q.
        out = v + s * (w * uv + np.cross(u, uv))
    if check and not np.isfinite(out).all():
        raise ValueError(
            f"v{_v.first_index(~np.isfinite(out).all(axis=-1))} is too long to rotate in {out.dtype} (the "
            f"intermediate products overflow beyond about {np.finfo(out.dtype).max / 4:.3g})"
        )
    return out


def angle_between(p, q, *, check: bool = True) -> np.ndarray:
    """Rotation angle of ``p* ⊗ q`` in [0, π]: the geodesic distance between two attitudes.

    Computed as ``2 atan2(|vec r|, |scalar r|)``, accurate for tiny angles (unlike ``2 acos|p·q|``) and
    sign-invariant in ``p`` and ``q``.

    Parameters
    ----------
    p, q : array_like, shape (..., 4)
        Non-zero quaternions.

    Returns
    -------
    numpy.ndarray, shape (...)
        Angles in radians.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import quaternion as quat
    >>> q90z = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]
    >>> round(float(np.degrees(quat.angle_between([1, 0, 0, 0], q90z))), 9)
    90.0
    """
    p = _v.rotations(p, "p", check=check)
    q = _v.rotations(q, "q", check=check)
    if check:
        _v.broadcast(("p", p.shape[:-1]), ("q", q.shape[:-1]))
    r = multiply(conjugate(p, check=False), q, check=False)
    s = _norm3(r[..., 1:])
    return 2 * np.arctan2(s, np.abs(r[..., 0]))


def slerp(p, q, t, *, check: bool = True) -> np.ndarray:
    """Spherical linear interpolation from ``p`` (t = 0) to ``q`` (t = 1) along the shorter arc.

    ``slerp(p, q, t) = p ⊗ (p* ⊗ q)^t`` after ``q`` is sign-aligned with ``p``; the inputs are normalised.

    Parameters
    ----------
    p, q : array_like, shape (..., 4)
        Non-zero quaternions.
    t : array_like, shape (...)
        Interpolation parameters (values outside [0, 1] extrapolate).  ``|t|`` times the half angle between p
        and q must stay within ``1e-3/ε`` rad (4.5e12 in float64), as in :func:`power`.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit quaternions.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import quaternion as quat
    >>> q90z = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]
    >>> quat.slerp([1, 0, 0, 0], q90z, [0.0, 0.5])
    array([[1.        , 0.        , 0.        , 0.        ],
           [0.92387953, 0.        , 0.        , 0.38268343]])
    """
    p = normalize(_v.rotations(p, "p", check=check), check=False)
    q = normalize(_v.rotations(q, "q", check=check), check=False)
    t_in = t
    t = _v.finite(t, "t", check=check)
    dtype = _v.result_dtype(p, q) if _v.weak(t_in) else _v.result_dtype(p, q, t)
    _v.broadcast(("p", p.shape[:-1]), ("q", q.shape[:-1]), ("t", t.shape))
    r = multiply(conjugate(p, check=False), q, check=False).astype(dtype, copy=False)
    r = np.where(r[..., :1] < 0, -r, r)  # shorter arc
    _, half, unit = _half_angle(r)
    half, t = np.broadcast_arrays(half, t.astype(dtype, copy=False))
    th = t * half
    # as in power: beyond |t θ/2| ε ≈ 1e-3 rounding leaves the angle unknown (t = 1.7e308 made th inf and q NaN)
    limit = 1e-3 / np.finfo(dtype).eps
    if not (np.abs(th) <= limit).all():
        bad = ~(np.abs(th) <= limit)
        raise ValueError(
            f"slerp{_v.first_index(bad)}: t times the half angle between p and q is {float(th[bad][0]):.3g} rad, "
            f"beyond {limit:.3g} rad, where {np.dtype(dtype).name} rounding leaves the angle of the result unknown"
        )
    rt = np.empty((*half.shape, 4), dtype=dtype)
    rt[..., 0] = np.cos(th)
    rt[..., 1:] = np.sin(th)[..., None] * unit
    return multiply(p, rt, check=False)


def canonical(q, *, check: bool = True) -> np.ndarray:
    """Pick one of ``±q`` by a total rule, removing the double cover (Liu et al.'s compressed quaternion space).

    The rule: ``w > 0``; on a tie (``w = 0``) ``x > 0``; then ``y > 0``; then ``z > 0``.  Signed zeros count as
    ties and come out as ``+0.0``, so ``canonical(q)`` and ``canonical(-q)`` are bit-identical.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions; the norm is kept (call :func:`normalize` first if you need unit ones).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        ``q`` or ``-q``, whichever the rule picks.

    Examples
    --------
    >>> from strapdown import quaternion as quat
    >>> quat.canonical([[-0.5, 0.5, -0.5, 0.5], [0.0, -1.0, 0.0, 0.0]])
    array([[ 0.5, -0.5,  0.5, -0.5],
           [ 0. ,  1. ,  0. ,  0. ]])
    """
    q = _v.quaternions(q, "q", check=check, nonzero=False)
    if check:
        _v.nonzero_rows(q, "q")
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    flip = (w < 0) | ((w == 0) & ((x < 0) | ((x == 0) & ((y < 0) | ((y == 0) & (z < 0))))))
    # Adding +0.0 turns every -0.0 into +0.0, which makes the result independent of the input's sign.
    return np.where(flip[..., None], -q, q) + q.dtype.type(0)
