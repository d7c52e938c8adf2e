"""Numba kernels for :mod:`strapdown.propagate.spline` (private): the rotation-vector calculus of the C² spline.

Notation (body frame, as the spline runs q(t) = q_k ⊗ exp(r(t)/2) on segment k, r a cubic in t):

* the rate from the rotation-vector derivative, ``ω = J(r) ṙ`` with the right Jacobian of SO(3)
  ``J(r) = I - k1 [r×] + k3 [r×]²``, ``k1 = (1 - cos θ)/θ²``, ``k3 = (θ - sin θ)/θ³``, θ = |r|;
* its inverse, ``ṙ = J⁻¹(r) ω = ω + ½ r × ω + k [r×]² ω`` with ``k = (1 - (θ/2) cot(θ/2))/θ²``;
* the acceleration ``ω̇ = J(r) r̈ + n(r, ṙ)``, where the term quadratic in ṙ, the derivative of J along ṙ, is
  ``n = (r·ṙ)(m1 (r × ṙ) + m2 r × (r × ṙ)) + k3 ṙ × (r × ṙ)`` with ``m1 = (2(1 - cos θ) - θ sin θ)/θ⁴`` and
  ``m2 = (3 sin θ - θ cos θ - 2θ)/θ⁵`` (scipy's ``_angular_acceleration_nonlinear_term``).

The coefficients lose digits to cancellation for small θ, so below a threshold they come from their Taylor
series (coefficients derived exactly with rational arithmetic; scipy's small-angle m2 has 12604 where the
series has 1260, a difference of θ²·7e-4 that is harmless below its threshold θ = 1e-4).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ..rotations._quaternion_numba import qmul

_SERIES = 0.25  # θ below which k1, k3, m1 and m2 come from six series terms (error < 1e-19)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _k1(t, t2):
    if t < _SERIES:
        return 0.5 - t2 * (1 / 24 - t2 * (1 / 720 - t2 * (1 / 40320 - t2 * (1 / 3628800 - t2 / 479001600))))
    h = math.sin(0.5 * t) / (0.5 * t)  # 1 - cos θ = 2 sin²(θ/2), no cancellation
    return 0.5 * h * h


@nb.njit(cache=True, inline="always", error_model="numpy")
def _k3(t, t2):
    if t < _SERIES:
        return 1 / 6 - t2 * (1 / 120 - t2 * (1 / 5040 - t2 * (1 / 362880 - t2 * (1 / 39916800 - t2 / 6227020800))))
    return (t - math.sin(t)) / (t * t2)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _k(t, t2):
    if t < 0.1:  # θ/2 cot(θ/2) = 1 - θ²/12 - θ⁴/720 - θ⁶/30240 - θ⁸/1209600 - θ¹⁰/47900160 - ...
        return 1 / 12 + t2 * (1 / 720 + t2 * (1 / 30240 + t2 * (1 / 1209600 + t2 / 47900160)))
    return (1.0 - 0.5 * t / math.tan(0.5 * t)) / t2


@nb.njit(cache=True, inline="always", error_model="numpy")
def _m1(t, t2):
    if t < _SERIES:
        return 1 / 12 - t2 * (1 / 180 - t2 * (1 / 6720 - t2 * (1 / 453600 - t2 * (1 / 47900160 - t2 / 7264857600))))
    return (2.0 * (1.0 - math.cos(t)) - t * math.sin(t)) / (t2 * t2)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _m2(t, t2):
    if t < _SERIES:
        tail = 1 / 4989600 - t2 * (1 / 622702080 - t2 / 108972864000)
        return -1 / 60 + t2 * (1 / 1260 - t2 * (1 / 60480 - t2 * tail))
    return (3.0 * math.sin(t) - t * math.cos(t) - 2.0 * t) / (t2 * t2 * t)


@nb.njit(cache=True, inline="always", error_model="numpy")
def _cross(ax, ay, az, bx, by, bz):
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@nb.njit(cache=True, inline="always", error_model="numpy")
def rate_from_rotvec_dot(rx, ry, rz, vx, vy, vz):
    """ω = J(r) ṙ."""
    t2 = rx * rx + ry * ry + rz * rz
    t = math.sqrt(t2)
    k1 = _k1(t, t2)
    k3 = _k3(t, t2)
    cx, cy, cz = _cross(rx, ry, rz, vx, vy, vz)
    ccx, ccy, ccz = _cross(rx, ry, rz, cx, cy, cz)
    return vx - k1 * cx + k3 * ccx, vy - k1 * cy + k3 * ccy, vz - k1 * cz + k3 * ccz


@nb.njit(cache=True, inline="always", error_model="numpy")
def rotvec_dot_from_rate(rx, ry, rz, wx, wy, wz):
    """ṙ = J⁻¹(r) ω."""
    t2 = rx * rx + ry * ry + rz * rz
    t = math.sqrt(t2)
    k = _k(t, t2)
    cx, cy, cz = _cross(rx, ry, rz, wx, wy, wz)
    ccx, ccy, ccz = _cross(rx, ry, rz, cx, cy, cz)
    return wx + 0.5 * cx + k * ccx, wy + 0.5 * cy + k * ccy, wz + 0.5 * cz + k * ccz


@nb.njit(cache=True, inline="always", error_model="numpy")
def nonlinear(rx, ry, rz, vx, vy, vz):
    """n(r, ṙ), the part of ω̇ quadratic in ṙ."""
    t2 = rx * rx + ry * ry + rz * rz
    t = math.sqrt(t2)
    dp = rx * vx + ry * vy + rz * vz
    cx, cy, cz = _cross(rx, ry, rz, vx, vy, vz)
    ccx, ccy, ccz = _cross(rx, ry, rz, cx, cy, cz)
    dx, dy, dz = _cross(vx, vy, vz, cx, cy, cz)
    m1 = _m1(t, t2)
    m2 = _m2(t, t2)
    k3 = _k3(t, t2)
    return (
        dp * (m1 * cx + m2 * ccx) + k3 * dx,
        dp * (m1 * cy + m2 * ccy) + k3 * dy,
        dp * (m1 * cz + m2 * ccz) + k3 * dz,
    )


@nb.njit(cache=True, inline="always", error_model="numpy")
def _matrix(rx, ry, rz, a, b, inverse):
    """The 3×3 matrix a·J(r) (inverse=False) or a·J⁻¹(r) (inverse=True), ``b`` its output."""
    t2 = rx * rx + ry * ry + rz * rz
    t = math.sqrt(t2)
    if inverse:
        c1 = 0.5
        c2 = _k(t, t2)
    else:
        c1 = -_k1(t, t2)
        c2 = _k3(t, t2)
    r = (rx, ry, rz)
    # [r×] and [r×]² = r rᵀ - θ² I
    s = ((0.0, -rz, ry), (rz, 0.0, -rx), (-ry, rx, 0.0))
    for i in range(3):
        for j in range(3):
            b[i, j] = a * ((1.0 if i == j else 0.0) + c1 * s[i][j] + c2 * (r[i] * r[j] - (t2 if i == j else 0.0)))


@nb.njit(cache=True, error_model="numpy")
def _inv3(m, out):
    """Write m⁻¹ into out for a 3×3 matrix m, by the adjugate."""
    c00 = m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1]
    c01 = m[1, 2] * m[2, 0] - m[1, 0] * m[2, 2]
    c02 = m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]
    det = m[0, 0] * c00 + m[0, 1] * c01 + m[0, 2] * c02
    out[0, 0] = c00 / det
    out[1, 0] = c01 / det
    out[2, 0] = c02 / det
    out[0, 1] = (m[0, 2] * m[2, 1] - m[0, 1] * m[2, 2]) / det
    out[1, 1] = (m[0, 0] * m[2, 2] - m[0, 2] * m[2, 0]) / det
    out[2, 1] = (m[0, 1] * m[2, 0] - m[0, 0] * m[2, 1]) / det
    out[0, 2] = (m[0, 1] * m[1, 2] - m[0, 2] * m[1, 1]) / det
    out[1, 2] = (m[0, 2] * m[1, 0] - m[0, 0] * m[1, 2]) / det
    out[2, 2] = (m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]) / det


@nb.njit(cache=True, inline="always", error_model="numpy")
def _mv(m, j, v, k):
    """m[j] @ v[k] for stacks of 3×3 matrices and 3-vectors."""
    return (
        m[j, 0, 0] * v[k, 0] + m[j, 0, 1] * v[k, 1] + m[j, 0, 2] * v[k, 2],
        m[j, 1, 0] * v[k, 0] + m[j, 1, 1] * v[k, 1] + m[j, 1, 2] * v[k, 2],
        m[j, 2, 0] * v[k, 0] + m[j, 2, 1] * v[k, 1] + m[j, 2, 2] * v[k, 2],
    )


@nb.njit(cache=True, error_model="numpy")
def knot_rates(r, dt, w, max_iter, tol):
    """Solve for the body rates w[1:-1] at the inner knots (w[0] and w[-1] are given); return the iterations.

    The C² conditions at inner knot i (r̈ of segment i-1 at its end equals that of segment i at its start, each
    written through ω̇ = J r̈ + n) are, for the cubic segments of Hermite form (scipy's RotationSpline, after
    "Smooth attitude interpolation", the note scipy's docstring cites):

        2 J(r_{i-1})/h_{i-1} ω_{i-1} + 4 (1/h_{i-1} + 1/h_i) ω_i + 2 J⁻¹(r_i)/h_i ω_{i+1}
            = 6 (r_{i-1}/h_{i-1}² + r_i/h_i²) - n(r_{i-1}, J⁻¹(r_{i-1}) ω_i)

    a block-tridiagonal system, nonlinear only through n.  It is solved by fixed-point iteration on n (as
    scipy does), each step by the block Thomas algorithm on a factorisation made once (the system is block
    diagonally dominant: ‖J‖ ≤ 1 and ‖J⁻¹‖ ≤ π/2 against a diagonal of 4 (1/h_{i-1} + 1/h_i)).  The iteration
    stops when no rate changes by more than ``tol (1 + |ω|)``, or after ``max_iter`` steps.
    """
    m = r.shape[0]  # segments; unknowns: knots 1 .. m-1
    size = m - 1
    lower = np.empty((size, 3, 3))
    upper = np.empty((size, 3, 3))
    sinv = np.empty((size, 3, 3))
    cprime = np.empty((size, 3, 3))
    b0 = np.empty((size, 3))
    s = np.empty((3, 3))
    tmp = np.empty((3, 3))
    for j in range(size):
        i = j + 1
        _matrix(r[i - 1, 0], r[i - 1, 1], r[i - 1, 2], 2.0 / dt[i - 1], lower[j], False)
        _matrix(r[i, 0], r[i, 1], r[i, 2], 2.0 / dt[i], upper[j], True)
        for c in range(3):
            b0[j, c] = 6.0 * (r[i - 1, c] / (dt[i - 1] * dt[i - 1]) + r[i, c] / (dt[i] * dt[i]))
        # the known end rates move to the right-hand side
        if j == 0:
            for c in range(3):
                b0[j, c] -= lower[j, c, 0] * w[0, 0] + lower[j, c, 1] * w[0, 1] + lower[j, c, 2] * w[0, 2]
        if j == size - 1:
            for c in range(3):
                b0[j, c] -= upper[j, c, 0] * w[m, 0] + upper[j, c, 1] * w[m, 1] + upper[j, c, 2] * w[m, 2]
    # factorise: S_j = D_j - L_j C'_{j-1},  C'_j = S_j⁻¹ U_j
    for j in range(size):
        d = 4.0 * (1.0 / dt[j] + 1.0 / dt[j + 1])
        for a in range(3):
            for b in range(3):
                v = d if a == b else 0.0
                if j > 0:
                    for c in range(3):
                        v -= lower[j, a, c] * cprime[j - 1, c, b]
                s[a, b] = v
        _inv3(s, tmp)
        sinv[j] = tmp
        for a in range(3):
            for b in range(3):
                v = 0.0
                for c in range(3):
                    v += tmp[a, c] * upper[j, c, b]
                cprime[j, a, b] = v
    rhs = np.empty((size, 3))
    x = np.empty((size, 3))
    iterations = 0
    for _ in range(max_iter):
        iterations += 1
        for j in range(size):
            i = j + 1
            vx, vy, vz = rotvec_dot_from_rate(r[j, 0], r[j, 1], r[j, 2], w[i, 0], w[i, 1], w[i, 2])
            nx, ny, nz = nonlinear(r[j, 0], r[j, 1], r[j, 2], vx, vy, vz)
            e0 = b0[j, 0] - nx
            e1 = b0[j, 1] - ny
            e2 = b0[j, 2] - nz
            if j > 0:
                f0, f1, f2 = _mv(lower, j, rhs, j - 1)
                e0 -= f0
                e1 -= f1
                e2 -= f2
            for c in range(3):
                rhs[j, c] = sinv[j, c, 0] * e0 + sinv[j, c, 1] * e1 + sinv[j, c, 2] * e2
        for j in range(size - 1, -1, -1):
            f0, f1, f2 = _mv(cprime, j, x, j + 1) if j < size - 1 else (0.0, 0.0, 0.0)
            x[j, 0] = rhs[j, 0] - f0
            x[j, 1] = rhs[j, 1] - f1
            x[j, 2] = rhs[j, 2] - f2
        done = True
        for j in range(size):
            for c in range(3):
                if abs(x[j, c] - w[j + 1, c]) > tol * (1.0 + abs(x[j, c])):
                    done = False
                w[j + 1, c] = x[j, c]
        if done:
            break
    return iterations


@nb.njit(cache=True, inline="always", error_model="numpy")
def _poly(coef, k, c, x):
    """r, ṙ and r̈ of component c of segment k at offset x: r = ((c0 x + c1) x + c2) x."""
    c0 = coef[k, 0, c]
    c1 = coef[k, 1, c]
    c2 = coef[k, 2, c]
    return ((c0 * x + c1) * x + c2) * x, (3.0 * c0 * x + 2.0 * c1) * x + c2, 6.0 * c0 * x + 2.0 * c1


@nb.njit(cache=True, error_model="numpy")
def evaluate(coef, q, index, s, order, out):
    """Attitude (order 0, out (N, 4)), body rate (1) or body acceleration (2, out (N, 3)) at offsets s.

    Segment index[n], at s[n] from its start: q = q_k ⊗ exp(r/2), ω = J(r) ṙ, ω̇ = J(r) r̈ + n(r, ṙ).
    """
    for n in range(s.shape[0]):
        k = index[n]
        x = s[n]
        rx, vx, ax = _poly(coef, k, 0, x)
        ry, vy, ay = _poly(coef, k, 1, x)
        rz, vz, az = _poly(coef, k, 2, x)
        if order == 0:
            t = math.sqrt(rx * rx + ry * ry + rz * rz)
            h = 0.5 * t
            # sin(θ/2)/θ, by its series where θ is tiny (the division would lose the digits)
            sh = 0.5 * (1.0 - h * h / 6.0 * (1.0 - h * h / 20.0)) if h < 1e-4 else math.sin(h) / t
            w, x1, y1, z1 = qmul(q[k, 0], q[k, 1], q[k, 2], q[k, 3], math.cos(h), sh * rx, sh * ry, sh * rz)
            out[n, 0] = w
            out[n, 1] = x1
            out[n, 2] = y1
            out[n, 3] = z1
        elif order == 1:
            wx, wy, wz = rate_from_rotvec_dot(rx, ry, rz, vx, vy, vz)
            out[n, 0] = wx
            out[n, 1] = wy
            out[n, 2] = wz
        else:
            bx, by, bz = rate_from_rotvec_dot(rx, ry, rz, ax, ay, az)
            nx, ny, nz = nonlinear(rx, ry, rz, vx, vy, vz)
            out[n, 0] = bx + nx
            out[n, 1] = by + ny
            out[n, 2] = bz + nz


@nb.njit(cache=True, error_model="numpy")
def rotvec_dot_rows(r, w, out):
    """out[n] = J⁻¹(r[n]) w[n]."""
    for n in range(out.shape[0]):
        vx, vy, vz = rotvec_dot_from_rate(r[n, 0], r[n, 1], r[n, 2], w[n, 0], w[n, 1], w[n, 2])
        out[n, 0] = vx
        out[n, 1] = vy
        out[n, 2] = vz
