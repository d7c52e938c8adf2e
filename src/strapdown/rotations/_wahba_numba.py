"""Numba kernels for :mod:`strapdown.rotations.wahba` (private).

The kernels take validated, C-contiguous float64 arrays: ``body`` and ``ref`` of shape (N or 1, m, 3) and
``weights`` of shape (N or 1, m); an operand with a single row is broadcast inside the loop, so a fixed star
catalogue is never copied N times.  Every vector is divided by its length; its pair then carries the weight
``a`` (``unit=True``) or ``a |b| |r|`` (``unit=False``, scipy's objective).  The kernels compute in float64 and
write unit quaternions, scalar first, that map body to reference (math.md §4.2).

Notation: ``B = Σ a b rᵀ`` (body times reference transposed), K the 4×4 Davenport matrix ``[[σ, zᵀ], [z, S - σI]]``
whose top eigenvector is our q (math.md §4.2).  B and K are divided by ``λ0 = Σ a``, an upper bound of the top
eigenvalue, so that they are of order one whatever the weights.  "Frame k" (k = 1, 2, 3) is the problem with the
reference vectors turned by 180° about axis k, ``r' = D_k r``; its solution is ``e_k ⊗ q`` (Shuster's method of
sequential rotations, which keeps QUEST and OLAE away from their singularity at 180°).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ._matrix_numba import shepperd

DAVENPORT = 0
QUEST = 1
OLAE = 2

LANES = 64  # epochs whose K matrices one Jacobi call diagonalises side by side (SIMD across epochs)
_CHUNK = 32 * LANES  # epochs per parallel task
_JACOBI_SWEEPS = 20
_NEWTON_STEPS = 100


@nb.njit(cache=True, inline="always", error_model="numpy")
def _frame_sign(k, j):
    """Diagonal entry j of D_k, the 180° rotation about axis k (k = 0: the identity)."""
    if k == 0 or j == k - 1:
        return 1.0
    return -1.0


@nb.njit(cache=True, inline="always", error_model="numpy")
def _undo_frame(k, w, x, y, z):
    """Solution in the original reference frame from that of frame k: q = e_k ⊗ q' (up to sign)."""
    if k == 1:
        return -x, w, -z, y
    if k == 2:
        return -y, z, w, -x
    if k == 3:
        return -z, -y, x, w
    return w, x, y, z


@nb.njit(cache=True, inline="always", error_model="numpy")
def _over(x, y, z, d):
    """(x, y, z) / d, each component divided."""
    return x / d, y / d, z / d


@nb.njit(cache=True, inline="always", error_model="numpy")
def _pair(body, ref, weights, ib, ir, iw, i, unit):
    """Unit vectors b̂, r̂ of observation i and the weight its pair carries."""
    a = weights[iw, i]
    bx = body[ib, i, 0]
    by = body[ib, i, 1]
    bz = body[ib, i, 2]
    rx = ref[ir, i, 0]
    ry = ref[ir, i, 1]
    rz = ref[ir, i, 2]
    lb = math.sqrt(bx * bx + by * by + bz * bz)
    lr = math.sqrt(rx * rx + ry * ry + rz * rz)
    if not unit:
        a *= lb * lr
    return a, bx / lb, by / lb, bz / lb, rx / lr, ry / lr, rz / lr


@nb.njit(cache=True, error_model="numpy")
def profile(body, ref, weights, ib, ir, iw, unit, bmat):
    """Fill bmat = B / λ0 for one epoch, B = Σ a b̂ r̂ᵀ and λ0 = Σ a."""
    for j in range(3):
        for k in range(3):
            bmat[j, k] = 0.0
    lam0 = 0.0
    for i in range(body.shape[1]):
        a, bx, by, bz, rx, ry, rz = _pair(body, ref, weights, ib, ir, iw, i, unit)
        lam0 += a
        bmat[0, 0] += a * bx * rx
        bmat[0, 1] += a * bx * ry
        bmat[0, 2] += a * bx * rz
        bmat[1, 0] += a * by * rx
        bmat[1, 1] += a * by * ry
        bmat[1, 2] += a * by * rz
        bmat[2, 0] += a * bz * rx
        bmat[2, 1] += a * bz * ry
        bmat[2, 2] += a * bz * rz
    if lam0 > 0.0:
        for j in range(3):
            for k in range(3):
                bmat[j, k] /= lam0


@nb.njit(cache=True, error_model="numpy")
def k_lane(bmat, kmat, lane):
    """Davenport's K (math.md §4.2, scalar first) from B, into kmat[:, :, lane]."""
    sigma = bmat[0, 0] + bmat[1, 1] + bmat[2, 2]
    z0 = bmat[1, 2] - bmat[2, 1]
    z1 = bmat[2, 0] - bmat[0, 2]
    z2 = bmat[0, 1] - bmat[1, 0]
    kmat[0, 0, lane] = sigma
    kmat[0, 1, lane] = z0
    kmat[0, 2, lane] = z1
    kmat[0, 3, lane] = z2
    kmat[1, 0, lane] = z0
    kmat[2, 0, lane] = z1
    kmat[3, 0, lane] = z2
    for j in range(3):
        for k in range(3):
            kmat[j + 1, k + 1, lane] = bmat[j, k] + bmat[k, j]
        kmat[j + 1, j + 1, lane] -= sigma


@nb.njit(cache=True, inline="always", error_model="numpy")
def _turn(xp, xq, s, tau):
    """The pair (x_p, x_q) turned by the Jacobi rotation of sine s, in Rutishauser's form with tau = s / (1 + c)."""
    return xp - s * (xq + tau * xp), xq + s * (xp - tau * xq)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _rotate_lanes(a, v, p, q, n_lanes, ss, taus):
    """One Jacobi rotation annihilating a[p, q] in every lane (Golub and Van Loan, Alg. 8.4.1).

    t = tan of the rotation angle, the smaller root of t² + 2θt - 1 = 0 with θ = (a_qq - a_pp) / (2 a_pq),
    written as 2 a_pq sgn(d) / (|d| + √(d² + 4 a_pq²)) with d = a_qq - a_pp so that no lane divides by zero
    (a_pq = 0 gives t = 0, the identity).  The lane loops have no branches and vectorise.
    """
    for lane in range(n_lanes):
        apq = a[p, q, lane]
        d = a[q, q, lane] - a[p, p, lane]
        den = abs(d) + math.sqrt(d * d + 4.0 * apq * apq) + 1e-300
        t = 2.0 * apq * math.copysign(1.0, d) / den
        c = 1.0 / math.sqrt(t * t + 1.0)
        s = t * c
        ss[lane] = s
        taus[lane] = s / (1.0 + c)
        a[p, p, lane] -= t * apq
        a[q, q, lane] += t * apq
        a[p, q, lane] = 0.0
        a[q, p, lane] = 0.0
    for r in range(4):
        if r != p and r != q:
            for lane in range(n_lanes):
                s = ss[lane]
                tau = taus[lane]
                a[r, p, lane], a[r, q, lane] = _turn(a[r, p, lane], a[r, q, lane], s, tau)
                a[p, r, lane] = a[r, p, lane]
                a[q, r, lane] = a[r, q, lane]
    for r in range(4):
        for lane in range(n_lanes):
            s = ss[lane]
            tau = taus[lane]
            v[r, p, lane], v[r, q, lane] = _turn(v[r, p, lane], v[r, q, lane], s, tau)


@nb.njit(cache=True, error_model="numpy")
def jacobi_lanes(a, v, n_lanes, ss, taus):
    """Eigen-decomposition of the symmetric 4×4 matrices a[:, :, lane] by cyclic Jacobi sweeps.

    On return the diagonal of a holds the eigenvalues and the columns of v[:, :, lane] the orthonormal
    eigenvectors.  Jacobi's method is backward stable and gives orthonormal eigenvectors even for repeated
    eigenvalues, so nothing here can be NaN.  Sweeps stop once every lane's off-diagonal part is below 1e-18 of
    its diagonal (the method converges quadratically: four or five sweeps).
    """
    for j in range(4):
        for k in range(4):
            for lane in range(n_lanes):
                v[j, k, lane] = 1.0 if j == k else 0.0
    for _ in range(_JACOBI_SWEEPS):
        worst = 0.0
        for lane in range(n_lanes):
            off = a[0, 1, lane] * a[0, 1, lane] + a[0, 2, lane] * a[0, 2, lane] + a[0, 3, lane] * a[0, 3, lane]
            off += a[1, 2, lane] * a[1, 2, lane] + a[1, 3, lane] * a[1, 3, lane] + a[2, 3, lane] * a[2, 3, lane]
            dia = a[0, 0, lane] * a[0, 0, lane] + a[1, 1, lane] * a[1, 1, lane]
            dia += a[2, 2, lane] * a[2, 2, lane] + a[3, 3, lane] * a[3, 3, lane]
            worst = max(worst, off - 1e-36 * dia)
        if worst <= 0.0:
            break
        _rotate_lanes(a, v, 0, 1, n_lanes, ss, taus)
        _rotate_lanes(a, v, 0, 2, n_lanes, ss, taus)
        _rotate_lanes(a, v, 0, 3, n_lanes, ss, taus)
        _rotate_lanes(a, v, 1, 2, n_lanes, ss, taus)
        _rotate_lanes(a, v, 1, 3, n_lanes, ss, taus)
        _rotate_lanes(a, v, 2, 3, n_lanes, ss, taus)


@nb.njit(cache=True, inline="always", error_model="numpy")
def top_vector(a, v, lane):
    """Eigenvector of the largest eigenvalue after :func:`jacobi_lanes`."""
    top = 0
    for p in range(1, 4):
        if a[p, p, lane] > a[top, top, lane]:
            top = p
    return v[0, top, lane], v[1, top, lane], v[2, top, lane], v[3, top, lane]


@nb.njit(cache=True, error_model="numpy")
def _invariants(bmat, k):
    """σ, S (6 entries), z, κ = tr adj S and Δ = det S of frame k (B' = B D_k)."""
    d0 = _frame_sign(k, 0)
    d1 = _frame_sign(k, 1)
    d2 = _frame_sign(k, 2)
    b00 = bmat[0, 0] * d0
    b01 = bmat[0, 1] * d1
    b02 = bmat[0, 2] * d2
    b10 = bmat[1, 0] * d0
    b11 = bmat[1, 1] * d1
    b12 = bmat[1, 2] * d2
    b20 = bmat[2, 0] * d0
    b21 = bmat[2, 1] * d1
    b22 = bmat[2, 2] * d2
    sigma = b00 + b11 + b22
    s00 = 2.0 * b00
    s11 = 2.0 * b11
    s22 = 2.0 * b22
    s01 = b01 + b10
    s02 = b02 + b20
    s12 = b12 + b21
    z0 = b12 - b21
    z1 = b20 - b02
    z2 = b01 - b10
    kappa = (s11 * s22 - s12 * s12) + (s00 * s22 - s02 * s02) + (s00 * s11 - s01 * s01)
    delta = s00 * (s11 * s22 - s12 * s12) - s01 * (s01 * s22 - s12 * s02) + s02 * (s01 * s12 - s11 * s02)
    return sigma, s00, s01, s02, s11, s12, s22, z0, z1, z2, kappa, delta


@nb.njit(cache=True, error_model="numpy")
def quest_lambda(bmat):
    """λ_max of K by Newton's method on its characteristic polynomial (Shuster and Oh 1981), from λ0 = 1.

    det(λI - K) = λ⁴ - (a + b)λ² - cλ + (ab + cσ - d) with a = σ² - κ, b = σ² + zᵀz, c = Δ + zᵀSz, d = zᵀS²z.
    Above its largest root the quartic is increasing and convex, and λ0 = Σ a = 1 (B is scaled) is at or above
    it, so the iteration falls monotonically onto λ_max; it stops when a step is below 1e-16 or changes sign.
    """
    sigma, s00, s01, s02, s11, s12, s22, z0, z1, z2, kappa, delta = _invariants(bmat, 0)
    sz0 = s00 * z0 + s01 * z1 + s02 * z2
    sz1 = s01 * z0 + s11 * z1 + s12 * z2
    sz2 = s02 * z0 + s12 * z1 + s22 * z2
    a = sigma * sigma - kappa
    b = sigma * sigma + (z0 * z0 + z1 * z1 + z2 * z2)
    c = delta + (z0 * sz0 + z1 * sz1 + z2 * sz2)
    d = sz0 * sz0 + sz1 * sz1 + sz2 * sz2
    e = a * b + c * sigma - d
    lam = 1.0
    for _ in range(_NEWTON_STEPS):
        lam2 = lam * lam
        f = (lam2 - (a + b)) * lam2 - c * lam + e
        fp = (4.0 * lam2 - 2.0 * (a + b)) * lam - c
        if not (fp > 0.0):
            break
        step = f / fp
        if not (step > 1e-16):
            if step > 0.0:
                lam -= step
            break
        lam -= step
    return lam


@nb.njit(cache=True, error_model="numpy")
def rayleigh(bmat, w, x, y, z):
    """Rayleigh quotient qᵀ K q of a unit q (frame 0): σ(w² - |v|²) + 2w zᵀv + vᵀ S v."""
    sigma, s00, s01, s02, s11, s12, s22, z0, z1, z2, _, _ = _invariants(bmat, 0)
    vsv = s00 * x * x + s11 * y * y + s22 * z * z + 2.0 * (s01 * x * y + s02 * x * z + s12 * y * z)
    return sigma * (w * w - (x * x + y * y + z * z)) + 2.0 * w * (z0 * x + z1 * y + z2 * z) + vsv


@nb.njit(cache=True, error_model="numpy")
def _quest_gamma(bmat, k, lam):
    """γ = det((λ + σ)I - S) of frame k: the k-th diagonal cofactor of (λI - K), proportional to q_k²."""
    inv = _invariants(bmat, k)
    sigma = inv[0]
    alpha = lam * lam - sigma * sigma + inv[10]
    return (lam + sigma) * alpha - inv[11]


@nb.njit(cache=True, error_model="numpy")
def quest_vector(bmat, k, lam):
    """Shuster's (γ, x) of frame k, x = (αI + βS + S²) z, undone to our frame (not normalised)."""
    sigma, s00, s01, s02, s11, s12, s22, z0, z1, z2, kappa, delta = _invariants(bmat, k)
    alpha = lam * lam - sigma * sigma + kappa
    beta = lam - sigma
    gamma = (lam + sigma) * alpha - delta
    sz0 = s00 * z0 + s01 * z1 + s02 * z2
    sz1 = s01 * z0 + s11 * z1 + s12 * z2
    sz2 = s02 * z0 + s12 * z1 + s22 * z2
    ssz0 = s00 * sz0 + s01 * sz1 + s02 * sz2
    ssz1 = s01 * sz0 + s11 * sz1 + s12 * sz2
    ssz2 = s02 * sz0 + s12 * sz1 + s22 * sz2
    x0 = alpha * z0 + beta * sz0 + ssz0
    x1 = alpha * z1 + beta * sz1 + ssz1
    x2 = alpha * z2 + beta * sz2 + ssz2
    return _undo_frame(k, gamma, x0, x1, x2)


@nb.njit(cache=True, error_model="numpy")
def olae_frame(body, ref, weights, ib, ir, iw, unit, k):
    """Mortari-Markley OLAE of frame k in homogeneous form (det M, adj(M) y), undone to our frame.

    M = Σ a [s×]ᵀ[s×] = Σ a (|s|² I - s sᵀ) and y = Σ a [s×]ᵀ d = 2 Σ a b × r' with s = b + r', d = b - r'
    (math.md §4.2); the Gibbs vector is g = M⁻¹ y and q ∝ (1, g) ∝ (det M, adj(M) y), which stays finite where
    M is singular.  M and y are divided by Σ a first.
    """
    d0 = _frame_sign(k, 0)
    d1 = _frame_sign(k, 1)
    d2 = _frame_sign(k, 2)
    m00 = m01 = m02 = m11 = m12 = m22 = y0 = y1 = y2 = lam0 = 0.0
    for i in range(body.shape[1]):
        a, bx, by, bz, rx, ry, rz = _pair(body, ref, weights, ib, ir, iw, i, unit)
        rx *= d0
        ry *= d1
        rz *= d2
        lam0 += a
        sx = bx + rx
        sy = by + ry
        sz = bz + rz
        ss = sx * sx + sy * sy + sz * sz
        m00 += a * (ss - sx * sx)
        m11 += a * (ss - sy * sy)
        m22 += a * (ss - sz * sz)
        m01 -= a * sx * sy
        m02 -= a * sx * sz
        m12 -= a * sy * sz
        y0 += 2.0 * a * (by * rz - bz * ry)
        y1 += 2.0 * a * (bz * rx - bx * rz)
        y2 += 2.0 * a * (bx * ry - by * rx)
    if lam0 > 0.0:
        m00, m01, m02 = _over(m00, m01, m02, lam0)
        m11, m12, m22 = _over(m11, m12, m22, lam0)
        y0, y1, y2 = _over(y0, y1, y2, lam0)
    c00, c01, c02, c11, c12, c22, det = _adjugate3(m00, m01, m02, m11, m12, m22)
    g0 = c00 * y0 + c01 * y1 + c02 * y2
    g1 = c01 * y0 + c11 * y1 + c12 * y2
    g2 = c02 * y0 + c12 * y1 + c22 * y2
    return _undo_frame(k, det, g0, g1, g2)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _unit4(w, x, y, z):
    """(w, x, y, z) / norm and the norm; a zero or non-finite vector is returned as is with norm 0."""
    big = max(max(abs(w), abs(x)), max(abs(y), abs(z)))
    if not (big > 0.0) or not (big < math.inf):
        return w, x, y, z, 0.0
    w /= big
    x /= big
    y /= big
    z /= big
    n = math.sqrt(w * w + x * x + y * y + z * z)
    return w / n, x / n, y / n, z / n, n


@nb.njit(cache=True, inline="always", error_model="numpy")
def _canonical(w, x, y, z):
    """The sign rule of :func:`strapdown.rotations.quaternion.canonical`: w > 0, ties broken by x, y, z; no -0.0."""
    if w < 0.0 or (w == 0.0 and (x < 0.0 or (x == 0.0 and (y < 0.0 or (y == 0.0 and z < 0.0))))):
        return -w + 0.0, -x + 0.0, -y + 0.0, -z + 0.0
    return w + 0.0, x + 0.0, y + 0.0, z + 0.0


@nb.njit(cache=True, error_model="numpy")
def information(body, ref, weights, ib, ir, iw, unit):
    """Entries n00, n01, n02, n11, n12, n22 of N = Σ a (I - b̂ b̂ᵀ), the Fisher information of the attitude."""
    n00 = n01 = n02 = n11 = n12 = n22 = 0.0
    for i in range(body.shape[1]):
        a, bx, by, bz, _, _, _ = _pair(body, ref, weights, ib, ir, iw, i, unit)
        n00 += a * (by * by + bz * bz)
        n11 += a * (bx * bx + bz * bz)
        n22 += a * (bx * bx + by * by)
        n01 -= a * bx * by
        n02 -= a * bx * bz
        n12 -= a * by * bz
    return n00, n01, n02, n11, n12, n22


@nb.njit(cache=True, inline="always", error_model="numpy")
def _adjugate3(n00, n01, n02, n11, n12, n22):
    """Cofactors c00, c01, c02, c11, c12, c22 and determinant of a symmetric 3×3 matrix."""
    c00 = n11 * n22 - n12 * n12
    c01 = n02 * n12 - n01 * n22
    c02 = n01 * n12 - n02 * n11
    c11 = n00 * n22 - n02 * n02
    c12 = n01 * n02 - n00 * n12
    c22 = n00 * n11 - n01 * n01
    return c00, c01, c02, c11, c12, c22, n00 * c00 + n01 * c01 + n02 * c02


@nb.njit(cache=True, inline="always", error_model="numpy")
def _singular(det, n00, n11, n22):
    """All directions parallel to rounding: N is singular and the angle about them unobservable.

    det / (tr N / 3)³ is about sin² of the angle between the two most separated directions; below 1e-12
    (directions within 1e-6 rad of each other) the attitude is not determined to better than its rounding.
    """
    scale = (n00 + n11 + n22) / 3.0
    return not (det > 1e-12 * scale * scale * scale)


@nb.njit(cache=True, error_model="numpy")
def well_posed(body, ref, weights, ib, ir, iw, unit):
    """Whether the epoch has two non-parallel directions of positive weight."""
    n00, n01, n02, n11, n12, n22 = information(body, ref, weights, ib, ir, iw, unit)
    det = _adjugate3(n00, n01, n02, n11, n12, n22)[6]
    return not _singular(det, n00, n11, n22)


@nb.njit(cache=True, error_model="numpy")
def covariance(body, ref, weights, ib, ir, iw, unit, out):
    """Shuster's QUEST covariance N⁻¹ = (Σ a (I - b̂ b̂ᵀ))⁻¹ in the body frame, into out; +inf where N is singular."""
    n00, n01, n02, n11, n12, n22 = information(body, ref, weights, ib, ir, iw, unit)
    c00, c01, c02, c11, c12, c22, det = _adjugate3(n00, n01, n02, n11, n12, n22)
    if _singular(det, n00, n11, n22):
        for j in range(3):
            for k in range(3):
                out[j, k] = math.inf
        return
    out[0, 0] = c00 / det
    out[0, 1] = c01 / det
    out[0, 2] = c02 / det
    out[1, 0] = c01 / det
    out[1, 1] = c11 / det
    out[1, 2] = c12 / det
    out[2, 0] = c02 / det
    out[2, 1] = c12 / det
    out[2, 2] = c22 / det


@nb.njit(cache=True, error_model="numpy")
def _fallback(bmat, kmat, vmat, ss, taus):
    """Davenport's eigenvector of one epoch (lane 0), for the degenerate problems where QUEST or OLAE fail."""
    k_lane(bmat, kmat, 0)
    jacobi_lanes(kmat, vmat, 1, ss, taus)
    return top_vector(kmat, vmat, 0)


@nb.njit(cache=True, error_model="numpy")
def _best_frame(bmat, lam):
    """Frame k with the largest γ_k, the k-th diagonal cofactor of (λI - K) ∝ q_k² (Shuster's rotation choice)."""
    top = 0
    best = _quest_gamma(bmat, 0, lam)
    for k in range(1, 4):
        g = _quest_gamma(bmat, k, lam)
        if g > best:
            best = g
            top = k
    return top


@nb.njit(cache=True, error_model="numpy")
def _quest_one(body, ref, weights, ib, ir, iw, unit, bmat, kmat, vmat, ss, taus):
    """QUEST for one epoch: Newton's λ_max, the frame with the largest γ, the Gibbs-vector formula."""
    profile(body, ref, weights, ib, ir, iw, unit, bmat)
    if not well_posed(body, ref, weights, ib, ir, iw, unit):
        return _fallback(bmat, kmat, vmat, ss, taus)  # λ_max repeated: the attitude is not determined
    lam = quest_lambda(bmat)
    top = _best_frame(bmat, lam)
    w, x, y, z = quest_vector(bmat, top, lam)
    w, x, y, z, n = _unit4(w, x, y, z)
    if not n > 0.0:
        return _fallback(bmat, kmat, vmat, ss, taus)
    # The root of the quartic carries a rounding error of order ε/gap, which (γ, x) amplifies to ε/gap²; the
    # Rayleigh quotient of this first solution is accurate to ε, and a second pass brings q to Davenport's ε/gap.
    w2, x2, y2, z2 = quest_vector(bmat, top, rayleigh(bmat, w, x, y, z))
    w2, x2, y2, z2, n = _unit4(w2, x2, y2, z2)
    if n > 0.0:
        return w2, x2, y2, z2
    return w, x, y, z


@nb.njit(cache=True, error_model="numpy")
def _olae_one(body, ref, weights, ib, ir, iw, unit, bmat, kmat, vmat, ss, taus):
    """OLAE for one epoch, in the frame where the rotation is smallest (γ_k of (I - K), λ0 = 1 for λ_max)."""
    profile(body, ref, weights, ib, ir, iw, unit, bmat)
    if well_posed(body, ref, weights, ib, ir, iw, unit):
        w, x, y, z = olae_frame(body, ref, weights, ib, ir, iw, unit, _best_frame(bmat, 1.0))
        w, x, y, z, n = _unit4(w, x, y, z)
        if n > 0.0:
            return w, x, y, z
    return _fallback(bmat, kmat, vmat, ss, taus)  # fewer than two independent directions


@nb.njit(cache=True, parallel=True, error_model="numpy")
def wahba_rows(method, body, ref, weights, unit, out, cov, want_cov):
    """out[n] = attitude of epoch n by `method`; cov[n] = its covariance when want_cov."""
    n_rows = out.shape[0]
    ib_step = 1 if body.shape[0] > 1 else 0
    ir_step = 1 if ref.shape[0] > 1 else 0
    iw_step = 1 if weights.shape[0] > 1 else 0
    n_chunks = (n_rows + _CHUNK - 1) // _CHUNK
    for chunk in nb.prange(n_chunks):
        bmat = np.empty((3, 3))
        kmat = np.empty((4, 4, LANES))
        vmat = np.empty((4, 4, LANES))
        ss = np.empty(LANES)
        taus = np.empty(LANES)
        lo = chunk * _CHUNK
        hi = min(n_rows, lo + _CHUNK)
        if method == DAVENPORT:
            for start in range(lo, hi, LANES):
                n_lanes = min(LANES, hi - start)
                for lane in range(n_lanes):
                    n = start + lane
                    profile(body, ref, weights, n * ib_step, n * ir_step, n * iw_step, unit, bmat)
                    k_lane(bmat, kmat, lane)
                jacobi_lanes(kmat, vmat, n_lanes, ss, taus)
                for lane in range(n_lanes):
                    w, x, y, z = top_vector(kmat, vmat, lane)
                    n = start + lane
                    out[n, 0], out[n, 1], out[n, 2], out[n, 3] = _canonical(w, x, y, z)
        else:
            for n in range(lo, hi):
                ib = n * ib_step
                ir = n * ir_step
                iw = n * iw_step
                if method == QUEST:
                    w, x, y, z = _quest_one(body, ref, weights, ib, ir, iw, unit, bmat, kmat, vmat, ss, taus)
                else:
                    w, x, y, z = _olae_one(body, ref, weights, ib, ir, iw, unit, bmat, kmat, vmat, ss, taus)
                out[n, 0], out[n, 1], out[n, 2], out[n, 3] = _canonical(w, x, y, z)
        if want_cov:
            for n in range(lo, hi):
                covariance(body, ref, weights, n * ib_step, n * ir_step, n * iw_step, unit, cov[n])


@nb.njit(cache=True, inline="always", error_model="numpy")
def _triad_basis(ax, ay, az, bx, by, bz):
    """Orthonormal triad t1 = â, t2 = â × b̂ / |â × b̂|, t3 = t1 × t2, and |â × b̂| (the sine of their angle)."""
    ax, ay, az = _over(ax, ay, az, math.sqrt(ax * ax + ay * ay + az * az))
    bx, by, bz = _over(bx, by, bz, math.sqrt(bx * bx + by * by + bz * bz))
    cx = ay * bz - az * by
    cy = az * bx - ax * bz
    cz = ax * by - ay * bx
    sine = math.sqrt(cx * cx + cy * cy + cz * cz)
    cx, cy, cz = _over(cx, cy, cz, sine)
    return ax, ay, az, cx, cy, cz, ay * cz - az * cy, az * cx - ax * cz, ax * cy - ay * cx, sine


@nb.njit(cache=True, parallel=True, error_model="numpy")
def triad_rows(b1, b2, r1, r2, out, sines):
    """TRIAD: C = [t1r t2r t3r][t1b t2b t3b]ᵀ and its quaternion; sines[n] = (sin∠(b1, b2), sin∠(r1, r2))."""
    n_rows = out.shape[0]
    s_b1 = 1 if b1.shape[0] > 1 else 0
    s_b2 = 1 if b2.shape[0] > 1 else 0
    s_r1 = 1 if r1.shape[0] > 1 else 0
    s_r2 = 1 if r2.shape[0] > 1 else 0
    for n in nb.prange(n_rows):
        i = n * s_b1
        j = n * s_b2
        u0, u1, u2, v0, v1, v2, w0, w1, w2, sb = _triad_basis(
            b1[i, 0], b1[i, 1], b1[i, 2], b2[j, 0], b2[j, 1], b2[j, 2]
        )
        i = n * s_r1
        j = n * s_r2
        p0, p1, p2, q0, q1, q2, t0, t1, t2, sr = _triad_basis(
            r1[i, 0], r1[i, 1], r1[i, 2], r2[j, 0], r2[j, 1], r2[j, 2]
        )
        sines[n, 0] = sb
        sines[n, 1] = sr
        out[n, 0], out[n, 1], out[n, 2], out[n, 3] = shepperd(
            p0 * u0 + q0 * v0 + t0 * w0,
            p0 * u1 + q0 * v1 + t0 * w1,
            p0 * u2 + q0 * v2 + t0 * w2,
            p1 * u0 + q1 * v0 + t1 * w0,
            p1 * u1 + q1 * v1 + t1 * w1,
            p1 * u2 + q1 * v2 + t1 * w2,
            p2 * u0 + q2 * v0 + t2 * w0,
            p2 * u1 + q2 * v1 + t2 * w1,
            p2 * u2 + q2 * v2 + t2 * w2,
        )
