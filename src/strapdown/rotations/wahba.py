"""Attitude from simultaneous vector observations: Wahba's problem, TRIAD, accelerometer plus magnetometer.

The solvers of math.md §4.2 (nabbla parts 13-14): TRIAD, Davenport's q-method, QUEST and OLAE, each vectorised over
epochs, and the static attitude of a body at rest from an accelerometer and a magnetometer sample.

Conventions
-----------
* Epoch n has m observations: unit directions ``b_i`` measured in the body frame and the same directions ``r_i``
  known in the reference frame (a star catalogue, the sun, the local vertical, the Earth's field).  ``body`` and
  ``reference`` have shape (..., m, 3); the leading axes are epochs and broadcast, so a fixed reference catalogue
  of shape (m, 3) serves every epoch without a copy.
* Every solver returns unit attitude quaternions q (..., 4) that map body to reference, the package convention:
  ``reference ≈ rotate(q, body)``.  This is scipy's ``Rotation.align_vectors(reference, body)``.
* Wahba's problem (1965): find q minimising ``L(q) = ½ Σ a_i |r̂_i - R(q) b̂_i|²``.  Each vector is divided by its
  length first (``normalize=True``, the default: the weights alone say how much an observation counts, so an
  accelerometer in m/s² and a magnetometer in µT can be mixed).  With ``normalize=False`` a pair's weight is
  ``a_i |b_i| |r_i|``, which makes the problem exactly scipy's ``Σ a_i |r_i - R b_i|²`` on the raw vectors.
* Weights ``a_i ≥ 0``, of shape (..., m) or (m,), not all zero in an epoch.  Only their ratios change the attitude.
  For :func:`davenport` and :func:`quest` they also set the covariance, see below.

Covariance (``return_covariance=True``)
---------------------------------------
Shuster's QUEST measurement model (Shuster and Oh 1981; Shuster 2006): the measured body direction is the true one
turned by a small random rotation perpendicular to it, of standard deviation σ_i (rad) about each of the two
perpendicular axes.  With weights ``a_i = 1/σ_i²`` (rad⁻²; with ``normalize=False`` the weight that counts is
``a_i |b_i| |r_i|``) the attitude error has the covariance::

    P = (Σ_i a_i (I - b̂_i b̂_iᵀ))⁻¹        [rad²], a (..., 3, 3) array

to first order in σ.  The error is expressed in the **body frame**: ``δθ = as_rotvec(q_est* ⊗ q_true)``, so
``q_true = q_est ⊗ exp(δθ/2)``.  With relative weights ``a_i = c/σ_i²`` multiply P by c; with equal weights
(the default 1) and a common σ, ``P_rad² = σ² · P``.  P is the same for both solvers, since both solve Wahba's
problem exactly.  Where all directions of an epoch are parallel the angle about them is not observable and P is
``+inf``.

Degenerate problems
-------------------
With fewer than two non-parallel directions in an epoch (m = 1, or all vectors parallel) the attitude is not
unique.  :func:`davenport` then returns one of the optimal attitudes (an eigenvector of the repeated top
eigenvalue), and :func:`quest` and :func:`olae` fall back to the same eigenvector solution; none of them returns
NaN.  :func:`triad` and :func:`static_attitude` need two non-parallel vectors and raise otherwise.

References: Wahba, SIAM Review 7(3), 1965; Black, AIAA J. 2(7), 1964 (TRIAD); Davenport 1968, and Keat, NASA
X-733-77-243 (the q-method); Shuster and Oh, JGCD 4(1), 1981 (QUEST); Mortari, Markley and Singla, JGCD 30(5),
2007, doi:10.2514/1.29568 (OLAE); Markley and Crassidis, *Fundamentals of Spacecraft Attitude Determination and
Control*, Springer 2014, ch. 5.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["align_vectors", "davenport", "olae", "quest", "static_attitude", "triad"]

_TINY = np.finfo(np.float64).tiny


def _directions(arr: np.ndarray, name: str) -> None:
    """Raise for a vector whose length is zero or cannot be squared in float64 (the kernels compute in float64)."""
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        n2 = np.einsum("...i,...i->...", arr, arr, dtype=np.float64)
    ok = (n2 >= _TINY) & (n2 < np.inf)
    if ok.all():
        return
    bad = ~ok
    if not np.any(arr[bad][0] != 0):
        raise ValueError(f"{name}{_v.first_index(bad)} is a zero vector; an observation needs a direction")
    size = "small" if n2[bad][0] < _TINY else "large"
    raise ValueError(f"{name}{_v.first_index(bad)} has a length too {size} to use in float64; scale it towards 1")


def _epoch_rows(arr: np.ndarray, lead: tuple, tail: tuple) -> np.ndarray:
    """Float64 C-contiguous rows (N or 1, *tail) of an array broadcast to (*lead, *tail)."""
    arr = arr.astype(np.float64, copy=False)
    own = arr.shape[: arr.ndim - len(tail)]
    if own != lead and int(np.prod(own)) != 1:
        arr = np.broadcast_to(arr, (*lead, *tail))
    return np.ascontiguousarray(arr.reshape((-1, *tail)))


def _observations(body, reference, weights, check: bool):
    """Validated kernel inputs: body and reference rows, weight rows, the epochs' shape and the output dtype."""
    arrays = []
    for value, name in ((body, "body"), (reference, "reference")):
        arr = _v.vectors(value, name, check=check)
        if arr.ndim < 2 or arr.shape[-2] == 0:
            raise ValueError(
                f"{name} must have shape (..., m, 3) with m ≥ 1 vector observations per epoch, got shape {arr.shape}"
            )
        if check:
            _directions(arr, name)
        arrays.append(arr)
    body, reference = arrays
    m = body.shape[-2]
    if reference.shape[-2] != m:
        raise ValueError(
            f"body has {m} observations per epoch (shape {body.shape}) but reference has {reference.shape[-2]} "
            f"(shape {reference.shape}); pair every body vector with its reference vector"
        )
    if weights is None:
        a = np.ones((1, m))
        lead_w: tuple = ()
    else:
        a = _v.finite(weights, "weights", check=check, dtype=np.float64)
        if a.ndim == 0 or a.shape[-1] != m:
            raise ValueError(f"weights must have shape (..., {m}) (one weight per observation), got shape {a.shape}")
        if check:
            negative = a < 0
            if negative.any():
                raise ValueError(f"weights{_v.first_index(negative)} is negative; weights must be ≥ 0")
            empty = ~(a.sum(axis=-1) > 0)
            if empty.any():
                raise ValueError(f"weights{_v.first_index(empty)} are all zero; every epoch needs a positive weight")
        lead_w = a.shape[:-1]
    try:
        lead = np.broadcast_shapes(body.shape[:-2], reference.shape[:-2], lead_w)
    except ValueError:
        raise ValueError(
            f"the epochs of body {body.shape[:-2]}, reference {reference.shape[:-2]} and weights {lead_w} "
            "do not broadcast"
        ) from None
    dtype = _v.result_dtype(body, reference)
    rows = (_epoch_rows(body, lead, (m, 3)), _epoch_rows(reference, lead, (m, 3)), _epoch_rows(a, lead, (m,)))
    return rows, lead, dtype


def _solve(method: int, body, reference, weights, normalize: bool, return_covariance: bool, check: bool):
    (b, r, a), lead, dtype = _observations(body, reference, weights, check)
    n = int(np.prod(lead))
    out = np.empty((n, 4))
    cov = np.empty((n if return_covariance else 1, 3, 3))
    # Each epoch's weights scaled by a power of two so that the largest is in [0.5, 1): exact, so the attitude
    # (which depends on their ratios only) is unchanged, while the information matrix Σ a (I - b̂ b̂ᵀ) and its
    # inverse no longer over- or underflow (weights 1e200 or 1e-200 gave an infinite covariance)
    a_max = a.max(axis=-1)
    _, e = np.frexp(a_max)
    a = np.ldexp(a, -e[:, None])
    from ._wahba_numba import wahba_rows

    wahba_rows(method, b, r, a, bool(normalize), out, cov, bool(return_covariance))
    q = out.reshape((*lead, 4)).astype(dtype, copy=False)
    if not return_covariance:
        return q
    with np.errstate(over="ignore"):
        p = np.ldexp(cov, -np.broadcast_to(e, (cov.shape[0],))[:, None, None])
    overflow = np.isfinite(cov).all(axis=(-2, -1)) & ~np.isfinite(p).all(axis=(-2, -1))
    if check and overflow.any():
        k = int(np.flatnonzero(overflow)[0])
        at = _v.first_index(overflow.reshape(lead))
        raise ValueError(
            f"covariance{at} overflows float64: the weights{at} "
            f"(largest {float(a_max[min(k, a_max.shape[0] - 1)]):.3g}) are too small to invert; scale them up"
        )
    return q, p.reshape((*lead, 3, 3)).astype(dtype, copy=False)


def davenport(
    body, reference, weights=None, *, normalize: bool = True, return_covariance: bool = False, check: bool = True
):
    """Davenport's q-method: the optimal attitude of Wahba's problem as the top eigenvector of the 4×4 K matrix.

    Parameters
    ----------
    body : array_like, shape (..., m, 3)
        Observed directions in the body frame (any non-zero length).
    reference : array_like, shape (..., m, 3)
        The same directions in the reference frame.
    weights : array_like, shape (..., m) or (m,), optional
        Non-negative weights ``a_i``, not all zero in an epoch (default: all 1).  Inverse variances 1/σ_i²
        (rad⁻²) make the covariance absolute.
    normalize : bool
        Divide every vector by its length (default).  False: a pair's weight is ``a_i |b_i| |r_i|``, scipy's
        ``align_vectors`` objective on the raw vectors.
    return_covariance : bool
        Also return Shuster's attitude-error covariance (module docstring: body frame, rad² for weights 1/σ²).
    check : bool
        Reject NaN, infinities, zero vectors, negative weights and all-zero weights (default).

    Returns
    -------
    q : numpy.ndarray, shape (..., 4)
        Unit attitude quaternions (body to reference), canonical sign (w ≥ 0, see
        :func:`strapdown.rotations.quaternion.canonical`).
    covariance : numpy.ndarray, shape (..., 3, 3)
        Only with ``return_covariance=True``.

    Notes
    -----
    ``B = Σ a_i b̂_i r̂_iᵀ``, ``σ = tr B``, ``S = B + Bᵀ``, ``z = [B23 - B32, B31 - B13, B12 - B21]`` and
    ``K = [[σ, zᵀ], [z, S - σI]]`` (math.md §4.2, scalar first); Wahba's gain ``Σ a - L(q) = qᵀ K q`` is largest
    for the eigenvector of the largest eigenvalue.  It is found by cyclic Jacobi sweeps run on 64 epochs side by
    side (backward stable, orthonormal eigenvectors even for a repeated eigenvalue, never NaN).  Computed in
    float64 whatever the input dtype.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.rotations.wahba import davenport
    >>> body = np.array([[[1.0, 0, 0], [0, 1, 0], [0, 0, 1]]]).repeat(2, axis=0)   # two epochs, 3 vectors
    >>> reference = np.array([[[1.0, 1, 0], [-1, 1, 0], [0, 0, 1]], [[0.0, 1, 0], [-1, 0, 0], [0, 0, 1]]])
    >>> davenport(body, reference, weights=[1.0, 1.0, 2.0])             # 45 and 90 deg about z
    array([[0.92387953, 0.        , 0.        , 0.38268343],
           [0.70710678, 0.        , 0.        , 0.70710678]])
    """
    return _solve(0, body, reference, weights, normalize, return_covariance, check)


def quest(
    body, reference, weights=None, *, normalize: bool = True, return_covariance: bool = False, check: bool = True
):
    """QUEST (Shuster and Oh 1981): Davenport's optimal attitude from the characteristic equation of K.

    Parameters
    ----------
    body, reference, weights, normalize, return_covariance, check
        As for :func:`davenport`.

    Returns
    -------
    q, covariance
        As for :func:`davenport`: the same rotations, canonical sign (w ≥ 0), and the same covariance.

    Notes
    -----
    λ_max is the largest root of ``det(λI - K) = λ⁴ - (a + b)λ² - cλ + (ab + cσ - d)`` with ``a = σ² - κ``,
    ``b = σ² + zᵀz``, ``c = Δ + zᵀSz``, ``d = zᵀS²z``, κ = tr adj S and Δ = det S; Newton's method from
    ``λ0 = Σ a_i`` falls onto it monotonically.  Then ``α = λ² - σ² + κ``, ``β = λ - σ``, ``γ = (λ + σ)α - Δ``,
    ``x = (αI + βS + S²) z`` and ``q = (γ, x) / |(γ, x)|``.  That formula loses all accuracy as the rotation angle
    nears 180° (γ → 0), so, as Shuster does, the problem is solved with the reference frame turned by 180° about
    the axis k for which γ is largest (γ of frame k is the k-th diagonal cofactor of λI - K, proportional to
    q_k²) and the rotation is undone.  The root of the quartic carries a rounding error of order ε/g (g the gap
    between the two largest eigenvalues), which the adjugate formula would amplify to ε/g²; so λ is refined once
    by the Rayleigh quotient ``qᵀKq`` of that first solution and the formula applied again, which makes QUEST as
    accurate as :func:`davenport`.  Where the directions are all parallel (λ_max repeated, a degenerate problem)
    the Davenport eigenvector is returned.  Computed in float64 whatever the input dtype.

    Examples
    --------
    >>> from strapdown.rotations.wahba import quest
    >>> body = [[1.0, 0, 0], [0, 1, 0]]
    >>> reference = [[0.0, 1, 0], [-1, 0, 0]]        # the body turned by 90 deg about z
    >>> q, cov = quest(body, reference, weights=[1e6, 1e6], return_covariance=True)   # sigma = 1 mrad each
    >>> q
    array([0.70710678, 0.        , 0.        , 0.70710678])
    >>> cov * 1e6                                    # in mrad²: z is seen by both vectors
    array([[1. , 0. , 0. ],
           [0. , 1. , 0. ],
           [0. , 0. , 0.5]])
    """
    return _solve(1, body, reference, weights, normalize, return_covariance, check)


def olae(body, reference, weights=None, *, normalize: bool = True, check: bool = True):
    """Optimal linear attitude estimator (OLAE; Mortari, Markley and Singla 2007): a 3×3 linear system.

    Parameters
    ----------
    body, reference, weights, check
        As for :func:`davenport`.
    normalize : bool
        As for :func:`davenport`; the vectors themselves are always used as unit vectors (OLAE's Cayley relation
        holds only for vectors of equal length), so False changes only the weights.

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit attitude quaternions (body to reference), canonical sign (w ≥ 0).

    Notes
    -----
    With ``s_i = b̂_i + r̂_i`` and ``d_i = b̂_i - r̂_i`` the Cayley (Gibbs-vector) relation is ``d_i = [s_i×] g``, so
    ``(Σ a_i [s_i×]ᵀ[s_i×]) g = Σ a_i [s_i×]ᵀ d_i`` and ``q = (1, g)/√(1 + |g|²)`` (math.md §4.2), solved as
    ``q ∝ (det M, adj(M) y)``.  It is exact without noise.  With noise its criterion is not Wahba's: it weighs an
    observation by ``|s_i|²``, i.e. by ``cos²`` of half the angle between ``b̂_i`` and ``r̂_i``, so it departs from
    the optimum by a fraction of the noise σ: on 10⁴ random problems with 2 to 6 vectors, random weights and
    σ = 1 mrad the median is 0.1 σ and 99% are below 0.8 σ; it grows as the geometry degrades, as about σ/g
    with g the relative gap between the two largest eigenvalues of Davenport's K (up to 10 σ in nearly
    degenerate two-vector problems).  Its rms error to the truth stays within 3% of the optimum's.

    The Gibbs vector is infinite at 180°, and ``|s_i|`` vanishes there.  So the problem is solved in the frame
    where the rotation is smallest: the reference turned by 180° about x, y or z, or not turned, whichever has
    the largest diagonal cofactor of ``λ0 I - K`` (proportional to q_k², with ``λ0 = Σ a_i ≈ λ_max``); then the
    rotation is undone (Shuster's sequential rotations).  With noise the result depends slightly on that frame.
    Degenerate problems get the Davenport eigenvector.  Computed in float64 whatever the input dtype.

    Examples
    --------
    >>> from strapdown.rotations.wahba import olae
    >>> body = [[1.0, 0, 0], [0, 1, 0]]
    >>> reference = [[0.0, 1, 0], [-1, 0, 0]]        # the body turned by 90 deg about z
    >>> olae(body, reference)
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    return _solve(2, body, reference, weights, normalize, False, check)


def _triad(b1, b2, r1, r2, names, check: bool):
    """TRIAD on validated float arrays; raises for parallel pairs naming `names`."""
    lead = np.broadcast_shapes(b1.shape[:-1], b2.shape[:-1], r1.shape[:-1], r2.shape[:-1])
    n = int(np.prod(lead))
    out = np.empty((n, 4))
    sines = np.empty((n, 2))
    from ._wahba_numba import triad_rows

    triad_rows(*(_epoch_rows(x, lead, (3,)) for x in (b1, b2, r1, r2)), out, sines)
    if check:
        dtype = _v.result_dtype(b1, b2, r1, r2)
        limit = 64 * np.finfo(dtype).eps
        for col, (first, second) in enumerate((names[:2], names[2:])):
            parallel = ~(sines[:, col] > limit)
            if parallel.any():
                idx = _v.first_index(parallel.reshape(lead))
                raise ValueError(
                    f"{second}{idx} is parallel to {first}{idx}: two parallel directions do not fix an attitude"
                )
    return out.reshape((*lead, 4))


def triad(b1, b2, r1, r2, *, check: bool = True):
    """TRIAD (Black 1964): the attitude from two vector pairs, exact for the first pair.

    Parameters
    ----------
    b1, b2 : array_like, shape (..., 3)
        Two non-parallel directions measured in the body frame (any non-zero length).  ``b1`` is the trusted
        one: the result maps it exactly onto ``r1``.
    r1, r2 : array_like, shape (..., 3)
        The same two directions in the reference frame.
    check : bool
        Reject NaN, infinities, zero vectors and parallel pairs (default).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit attitude quaternions (body to reference), canonical sign (w ≥ 0).

    Raises
    ------
    ValueError
        For invalid input or a parallel pair, naming the argument and the first bad index.

    Notes
    -----
    The triads ``t1 = v̂1``, ``t2 = (v1 × v2)/|v1 × v2|``, ``t3 = t1 × t2`` of both pairs give the body-to-reference
    matrix ``C = [t1r t2r t3r][t1b t2b t3b]ᵀ``, then its quaternion by Shepperd's method.  ``C b̂1 = r̂1`` exactly;
    the second vector only fixes the rotation about the first, so a noisy ``b2`` never tilts ``b1`` (which is why
    :func:`static_attitude` takes the tilt from the accelerometer alone).  Without noise TRIAD is exact; with
    noise it is not optimal in Wahba's sense.  Computed in float64 whatever the input dtype.

    Examples
    --------
    >>> from strapdown.rotations.wahba import triad
    >>> triad([1.0, 0, 0], [0, 1, 0], [0, 1, 0], [-1, 0, 0])       # 90 deg about z
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """
    vecs = []
    for value, name in ((b1, "b1"), (b2, "b2"), (r1, "r1"), (r2, "r2")):
        arr = _v.vectors(value, name, check=check)
        if check:
            _directions(arr, name)
        vecs.append(arr)
    try:
        np.broadcast_shapes(*(x.shape[:-1] for x in vecs))
    except ValueError:
        raise ValueError(
            "the leading shapes of b1 {}, b2 {}, r1 {} and r2 {} do not broadcast".format(*(x.shape for x in vecs))
        ) from None
    out = _triad(*vecs, ("b1", "b2", "r1", "r2"), check)
    return out.astype(_v.result_dtype(*vecs), copy=False)


def static_attitude(acc, mag, frame: str = "NED", *, declination=0.0, degrees: bool = False, check: bool = True):
    """Attitude of a body at rest from one accelerometer and one magnetometer sample (TRIAD, tilt from gravity).

    Parameters
    ----------
    acc : array_like, shape (..., 3)
        Accelerometer reading in the body frame: the specific force, which at rest points **up**, opposite to
        gravity (a level body with z down reads ``[0, 0, -9.81]``; with z up, ``[0, 0, +9.81]``).  Any unit.
    mag : array_like, shape (..., 3)
        Magnetometer reading in the same body axes (any unit); it must not be parallel to ``acc``.  Leading
        axes broadcast with those of ``acc``.
    frame : str
        Reference frame of the result: ``"NED"`` (default), ``"ENU"`` or any other frame of
        :func:`strapdown.frame_matrix` (``"NWU"``, ...).
    declination : array_like, shape (...), optional
        Magnetic declination, the angle from true north to magnetic north, positive towards east.  The default 0
        gives the attitude relative to **magnetic** north.  Broadcasts against the epochs.
    degrees : bool
        ``declination`` in degrees.
    check : bool
        Reject NaN, infinities, zero vectors and a field parallel to gravity (default).

    Returns
    -------
    numpy.ndarray, shape (..., 4)
        Unit attitude quaternions (body to ``frame``), canonical sign (w ≥ 0).

    Raises
    ------
    ValueError
        For invalid input, naming the argument and the first bad index; for ``mag`` parallel to ``acc`` (at a
        magnetic pole, or a disturbed field), where the heading is undefined.

    Notes
    -----
    :func:`triad` with ``b1 = acc ↦ r1 = up`` and ``b2 = mag ↦ r2`` = the horizontal direction of magnetic north
    (``[cos D, sin D, 0]`` in NED).  The accelerometer alone sets roll and pitch; the field only sets heading,
    through its projection on the horizontal plane, so neither its inclination (dip) nor its magnitude matters,
    and a magnetic disturbance cannot tilt the result.  The body must be at rest (or unaccelerated): any
    acceleration tilts the estimated vertical.

    Examples
    --------
    >>> from strapdown.rotations.wahba import static_attitude
    >>> acc = [0.0, 0.0, -9.81]                  # level, body z down
    >>> mag = [20.0, 0.0, 45.0]                  # field to the north and down: facing magnetic north
    >>> static_attitude(acc, mag)                # NED: the identity
    array([1., 0., 0., 0.])
    >>> static_attitude(acc, mag, "ENU")         # the same pose in East-North-Up
    array([0.        , 0.70710678, 0.70710678, 0.        ])
    """
    from .frames import frame_matrix

    acc = _v.vectors(acc, "acc", check=check)
    mag = _v.vectors(mag, "mag", check=check)
    dec = _v.finite(declination, "declination", check=check, dtype=np.float64)
    if check:
        _directions(acc, "acc")
        _directions(mag, "mag")
    try:
        lead = np.broadcast_shapes(acc.shape[:-1], mag.shape[:-1], dec.shape)
    except ValueError:
        raise ValueError(
            f"the leading shapes of acc {acc.shape}, mag {mag.shape} and declination {dec.shape} do not broadcast"
        ) from None
    try:
        to_frame = frame_matrix("NED", frame)
    except ValueError:
        raise ValueError(f"frame must name a reference frame such as 'NED' or 'ENU'; got {frame!r}") from None
    if degrees:
        dec = np.deg2rad(dec)
    up = to_frame @ np.array([0.0, 0.0, -1.0])
    north = np.stack([np.cos(dec), np.sin(dec), np.zeros_like(dec)], axis=-1) @ to_frame.T
    out = _triad(acc, mag, up, north, ("acc", "mag", "up", "north"), check)
    return out.reshape((*lead, 4)).astype(_v.result_dtype(acc, mag), copy=False)


# |Σ w (sin, cos)| below this fraction of Σ w |c⊥| |a⊥|-scale terms: the secondaries fix no angle about the primary
_PARALLEL = 64 * np.finfo(np.float64).eps


def align_vectors(a, b, weights=None, *, return_sensitivity: bool = False, check: bool = True):
    """The attitude that best turns the vectors ``b`` onto ``a``: scipy's ``Rotation.align_vectors(a, b, weights)``.

    Parameters
    ----------
    a : array_like, shape (..., m, 3) or (3,)
        Vectors in the reference frame (scipy's frame A).
    b : array_like, shape (..., m, 3) or (3,)
        The same vectors in the body frame (frame B); the same shape as ``a``.
    weights : array_like, shape (m,), optional
        Non-negative weights (default all 1); at most one may be ``inf``, making its pair a constraint met
        exactly.  Vector lengths weigh too (scipy's loss ``½ Σ w |a - C b|²``).
    return_sensitivity : bool
        Also return scipy's sensitivity matrix (Notes); not with an infinite weight or a single pair, where the
        rotation is fixed exactly rather than estimated.
    check : bool
        Reject NaN, zero vectors, negative weights and more than one infinite weight (default).

    Returns
    -------
    q : numpy.ndarray, shape (..., 4)
        Unit quaternions, body to reference: ``a ≈ rotate(q, b)``.
    rssd : numpy.ndarray, shape (...)
        ``√(Σ w |a - C b|²)`` over the pairs of finite weight (scipy's "root sum squared distance").
    sensitivity : numpy.ndarray, shape (..., 3, 3)
        Only with ``return_sensitivity=True``.

    Notes
    -----
    Three cases, as scipy (its docstring and test_rotation.py's ``test_align_vectors_*`` cases):

    * one vector pair: the minimal rotation turning b onto a (:func:`strapdown.rotations.decompose.shortest_arc`);
    * one infinite weight (the primary pair): the minimal rotation of the primary b onto the primary a, then the
      rotation about a that best aligns the other (secondary) pairs, ``φ = atan2(Σ w (c × a)·â_p, Σ w (c·a -
      (c·â_p)(a·â_p)))`` with c the secondary b after the first rotation ("align-constrain"; the limit of Wahba's
      solution as that weight grows).  If the secondary vectors carry no direction about the primary axis (all
      parallel to it) the result is the primary rotation alone;
    * otherwise Wahba's problem on the raw vectors (their lengths weigh, as in scipy's Kabsch solution), by
      :func:`davenport` with ``normalize=False``.

    The sensitivity matrix is Markley's covariance of the SVD solution (Markley, J. Astronaut. Sci. 36(3), 1988,
    eq. 21, as scipy gives it): with ``B = Σ w a bᵀ = U S Vᵀ`` and the singular values s1, s2, s3 (the last with
    the sign of ``det U det V``), ``mean(w) · U diag(1/(s2 + s3), 1/(s3 + s1), 1/(s1 + s2)) Uᵀ``.  It is the
    covariance, up to the factor of the measurement variance, of the attitude error as a small rotation vector
    in the **reference** frame (scipy's frame A): ``q_true = exp(δθ/2) ⊗ q``.  Where the directions are all
    parallel (a rotation about them is not observed) it is ``+inf``.

    Examples
    --------
    >>> from strapdown.rotations.wahba import align_vectors
    >>> q, rssd = align_vectors([1.0, 0, 0], [0.0, 1, 0])      # one pair: the minimal rotation, -90° about z
    >>> q.round(12), float(rssd)
    (array([ 0.70710678,  0.        ,  0.        , -0.70710678]), 0.0)
    >>> q, _ = align_vectors([[1.0, 0, 0], [0, 1, 0]], [[0.0, 1, 0], [0, 1, 0]], weights=[np.inf, 1])
    >>> q.round(12)                                            # the secondary is parallel: primary only
    array([ 0.70710678,  0.        ,  0.        , -0.70710678])
    """
    from .decompose import shortest_arc
    from .quaternion import multiply, rotate
    from .rotvec import from_axis_angle

    av = _v.vectors(a, "a", check=check)
    bv = _v.vectors(b, "b", check=check)
    if av.shape != bv.shape:
        raise ValueError(f"a and b must have the same shape, got {av.shape} and {bv.shape}")
    dtype = _v.result_dtype(av, bv)
    a2 = np.atleast_2d(av).astype(np.float64)
    b2 = np.atleast_2d(bv).astype(np.float64)
    m = a2.shape[-2]
    if weights is None:
        w = np.ones(m)
    else:
        w = _v.as_float_array(weights, "weights", dtype=np.float64)
        if w.shape != (m,):
            raise ValueError(f"weights must have shape ({m},), one per vector pair; got shape {w.shape}")
        if check and (np.isnan(w).any() or (w < 0).any()):
            raise ValueError(f"weights{_v.first_index(~(w >= 0))} is negative or NaN; weights must be ≥ 0")
    infinite = np.isposinf(w)
    if infinite.sum() > 1:
        raise ValueError(f"only one weight may be infinite; weights {np.flatnonzero(infinite).tolist()} are")
    if return_sensitivity and (m == 1 or infinite.any()):
        raise ValueError(
            "return_sensitivity: with "
            + ("a single vector pair" if m == 1 else "an infinite weight")
            + " the rotation is fixed exactly, not estimated, so it has no sensitivity matrix"
        )
    if m == 1 or infinite.any():
        p = 0 if m == 1 else int(np.flatnonzero(infinite)[0])
        a_p, b_p = a2[..., p, :], b2[..., p, :]
        for vec, name in ((a_p, "a"), (b_p, "b")):
            if check and not (np.linalg.norm(vec, axis=-1) > 0).all():
                raise ValueError(f"the primary vector {name}[..., {p}, :] is zero; it has no direction to align")
        q = shortest_arc(b_p, a_p, check=False)
        if m > 1:
            others = np.arange(m) != p
            a_s, w_s = a2[..., others, :], w[others]
            c_s = rotate(q[..., None, :], b2[..., others, :], check=False)
            axis = a_p / np.linalg.norm(a_p, axis=-1, keepdims=True)
            along_c = np.einsum("...ni,...i->...n", c_s, axis)
            along_a = np.einsum("...ni,...i->...n", a_s, axis)
            sin = np.einsum("n,...n->...", w_s, np.einsum("...ni,...i->...n", np.cross(c_s, a_s), axis))
            cos = np.einsum("n,...n->...", w_s, np.einsum("...ni,...ni->...n", c_s, a_s) - along_c * along_a)
            scale = np.einsum("n,...n->...", w_s, np.linalg.norm(c_s, axis=-1) * np.linalg.norm(a_s, axis=-1))
            phi = np.where(np.hypot(sin, cos) > _PARALLEL * scale, np.arctan2(sin, cos), 0.0)
            q = multiply(from_axis_angle(axis, phi, check=False), q, check=False)
    else:
        q = davenport(b2, a2, w, normalize=False, check=check)
    finite = np.where(infinite, 0.0, w)  # the primary pair is met exactly: it adds nothing (not inf · 0)
    residual = a2 - rotate(q[..., None, :], b2, check=False)
    rssd = np.sqrt(np.einsum("n,...n->...", finite, np.einsum("...ni,...ni->...n", residual, residual)))
    shape = av.shape[:-2] if av.ndim >= 2 else ()
    out = q.reshape((*shape, 4)).astype(dtype, copy=False), rssd.reshape(shape).astype(dtype, copy=False)
    if not return_sensitivity:
        return out
    return (*out, _sensitivity(a2, b2, w).reshape((*shape, 3, 3)).astype(dtype, copy=False))


def _sensitivity(a: np.ndarray, b: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Markley's (1988) covariance of the SVD attitude, scipy's sensitivity matrix (align_vectors' Notes)."""
    u, s, vt = np.linalg.svd(np.einsum("n,...ni,...nk->...ik", w, a, b))
    s[..., 2] *= np.sign(np.linalg.det(u) * np.linalg.det(vt))
    pair = np.stack([s[..., 1] + s[..., 2], s[..., 2] + s[..., 0], s[..., 0] + s[..., 1]], axis=-1)
    observed = (pair > 0).all(axis=-1)
    inv = np.where(observed[..., None], 1 / np.where(observed[..., None], pair, 1.0), 0.0)
    out = np.mean(w) * np.einsum("...ik,...k,...jk->...ij", u, inv, u)
    return np.where(observed[..., None, None], out, np.inf)
