"""Gajda's classic alternatives to quaternions (§1), integrated as baselines (private).

Each keeps its own state and is integrated by classical RK4 (or first-order Euler) over the same rate model as
the quaternion methods, so that a comparison shows the representation, not the integrator:

* euler-angles (1.6): yaw ψ, pitch θ, roll φ (ZYX); singular at θ = ±90° (sec θ, tan θ);
* dcm (1.5), the Poisson equation; with C the body-to-reference matrix (Gajda's B = Cᵀ), Ċ = C [ω×]; optional
  re-orthonormalisation C ← C (3I - CᵀC)/2 each step (one Newton step towards the polar factor); the attitude
  reported is the nearest rotation to C (its orthogonal polar factor), however far C has drifted;
* euler-parameters (1.3): axis e and angle χ, ė = ½ e×ω + ½[ω - (ω·e)e] cot(χ/2), χ̇ = ω·e (the seed prints
  ω×e for the last, a typo: χ̇ is a scalar; math.md §2.2); singular at χ = 0 mod 2π, the identity included;
* rotation-vector (1.4): Gajda's θ = 2 e tan(χ/2), θ̇ = ω + ½ θ×ω + ¼ (ω·θ) θ (the seed prints ½ for the last
  factor; ¼ is right, math.md §2.2); singular at χ = π, where θ is infinite.

Each step reports its distance (rad) from the method's singular set, the smallest over the RK4 stages; the
caller flags it.  Outputs are unit quaternions whose sign follows the previous output, for continuity.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)
from ..rotations._matrix_numba import shepperd

EULER_ANGLES = 0
DCM = 1
EULER_PARAMETERS = 2
ROTATION_VECTOR = 3

SCHEME_RK4 = 0
SCHEME_EULER = 1

STATE_SIZE = 9


@nb.njit(cache=True, error_model="numpy")
def _wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


@nb.njit(cache=True, error_model="numpy")
def _deriv(method, s, ox, oy, oz, d):
    """ds/dt into d; returns the distance (rad) of s from the singular set."""
    if method == EULER_ANGLES:
        th = s[1]
        ph = s[2]
        sp = math.sin(ph)
        cp = math.cos(ph)
        ct = math.cos(th)
        a = sp * oy + cp * oz
        d[0] = a / ct
        d[1] = cp * oy - sp * oz
        d[2] = ox + math.tan(th) * a
        return 0.5 * math.pi - abs(th)
    if method == DCM:
        # Ċ = C [ω×], rows of C times the columns of [ω×] = [[0,-oz,oy],[oz,0,-ox],[-oy,ox,0]]
        for r in range(3):
            c0 = s[3 * r]
            c1 = s[3 * r + 1]
            c2 = s[3 * r + 2]
            d[3 * r] = c1 * oz - c2 * oy
            d[3 * r + 1] = c2 * ox - c0 * oz
            d[3 * r + 2] = c0 * oy - c1 * ox
        return np.inf
    if method == EULER_PARAMETERS:
        ex, ey, ez, chi = s[0], s[1], s[2], s[3]
        dot = ox * ex + oy * ey + oz * ez
        cot = math.cos(0.5 * chi) / math.sin(0.5 * chi)
        d[0] = 0.5 * (ey * oz - ez * oy) + 0.5 * (ox - dot * ex) * cot
        d[1] = 0.5 * (ez * ox - ex * oz) + 0.5 * (oy - dot * ey) * cot
        d[2] = 0.5 * (ex * oy - ey * ox) + 0.5 * (oz - dot * ez) * cot
        d[3] = dot
        return abs(_wrap(chi))
    # rotation vector θ = 2 e tan(χ/2)
    tx, ty, tz = s[0], s[1], s[2]
    dot = ox * tx + oy * ty + oz * tz
    d[0] = ox + 0.5 * (ty * oz - tz * oy) + 0.25 * dot * tx
    d[1] = oy + 0.5 * (tz * ox - tx * oz) + 0.25 * dot * ty
    d[2] = oz + 0.5 * (tx * oy - ty * ox) + 0.25 * dot * tz
    return math.pi - 2.0 * math.atan(0.5 * math.sqrt(tx * tx + ty * ty + tz * tz))


@nb.njit(cache=True, error_model="numpy")
def _polar(s):
    """Orthogonal polar factor of the 3×3 matrix s (row-major): the nearest rotation in the Frobenius norm.

    Scaled Newton iteration X ← ½(γX + X⁻ᵀ/γ), γ = |det X|^(-1/3) (Higham), quadratically convergent for any
    non-singular matrix; an orthonormal input returns after one pass.  NaN when det ≤ 0 (no rotation is near).
    """
    x = np.empty(9)
    for i in range(9):
        x[i] = s[i]
    cof = np.empty(9)
    for _ in range(30):
        cof[0] = x[4] * x[8] - x[5] * x[7]
        cof[1] = x[5] * x[6] - x[3] * x[8]
        cof[2] = x[3] * x[7] - x[4] * x[6]
        cof[3] = x[2] * x[7] - x[1] * x[8]
        cof[4] = x[0] * x[8] - x[2] * x[6]
        cof[5] = x[1] * x[6] - x[0] * x[7]
        cof[6] = x[1] * x[5] - x[2] * x[4]
        cof[7] = x[2] * x[3] - x[0] * x[5]
        cof[8] = x[0] * x[4] - x[1] * x[3]
        det = x[0] * cof[0] + x[1] * cof[1] + x[2] * cof[2]
        if not det > 0.0:
            for i in range(9):
                x[i] = np.nan
            return x
        g = det ** (-1.0 / 3.0)
        change = 0.0
        for i in range(9):
            new = 0.5 * (g * x[i] + cof[i] / (det * g))  # X⁻ᵀ = cofactor / det
            change = max(change, abs(new - x[i]))
            x[i] = new
        if change < 1e-15:
            break
    return x


@nb.njit(cache=True, error_model="numpy")
def _to_quaternion(method, s):
    if method == EULER_ANGLES:  # Gajda (2.16)
        cps = math.cos(0.5 * s[0])
        sps = math.sin(0.5 * s[0])
        cth = math.cos(0.5 * s[1])
        sth = math.sin(0.5 * s[1])
        cph = math.cos(0.5 * s[2])
        sph = math.sin(0.5 * s[2])
        return (
            cps * cth * cph + sps * sth * sph,
            cps * cth * sph - sps * sth * cph,
            cps * sth * cph + sps * cth * sph,
            sps * cth * cph - cps * sth * sph,
        )
    if method == DCM:
        # a drifted matrix is not a rotation: report the nearest one (nabbla's 0.91° for the first-order DCM)
        r = _polar(s)
        return shepperd(r[0], r[1], r[2], r[3], r[4], r[5], r[6], r[7], r[8])
    if method == EULER_PARAMETERS:
        c = math.cos(0.5 * s[3])
        sn = math.sin(0.5 * s[3])
        w, x, y, z = c, s[0] * sn, s[1] * sn, s[2] * sn
    else:
        w, x, y, z = 1.0, 0.5 * s[0], 0.5 * s[1], 0.5 * s[2]
    inv = 1.0 / math.sqrt(w * w + x * x + y * y + z * z)
    return w * inv, x * inv, y * inv, z * inv


@nb.njit(cache=True, error_model="numpy")
def _orthonormalize(s):
    """C ← C (3I - CᵀC)/2, one Newton step of the polar decomposition (the matrix twin of nabbla's series)."""
    m = _product3(s, True, s)
    for i in range(9):
        m[i] = (3.0 if i % 4 == 0 else 0.0) - m[i]  # the diagonal of 3I at 0, 4, 8
    out = _product3(s, False, m)
    for i in range(9):
        s[i] = 0.5 * out[i]


@nb.njit(cache=True, inline="always", error_model="numpy")
def _product3(a, transposed, b):
    """The 3x3 product a b (aᵀ b when ``transposed``) of row-major 9-vectors, each entry summed in order."""
    out = np.empty(9)
    for i in range(3):
        for j in range(3):
            acc = 0.0
            for r in range(3):
                acc += (a[3 * r + i] if transposed else a[3 * i + r]) * b[3 * r + j]
            out[3 * i + j] = acc
    return out


@nb.njit(cache=True, error_model="numpy")
def baseline(method, scheme, orthonormalize, w0, wm, w1, h, state, last_q, out, dist):
    """Advance each body's state over the steps; write unit quaternions to out and distances to dist."""
    n_bodies = w0.shape[0]
    n = w0.shape[1]
    m = 9 if method == DCM else (4 if method == EULER_PARAMETERS else 3)
    s = np.empty(m)
    tmp = np.empty(m)
    k1 = np.empty(m)
    k2 = np.empty(m)
    k3 = np.empty(m)
    k4 = np.empty(m)
    for b in range(n_bodies):
        for i in range(m):
            s[i] = state[b, i]
        for k in range(n):
            hk = h[k]
            if scheme == SCHEME_EULER:
                dmin = _deriv(method, s, w0[b, k, 0], w0[b, k, 1], w0[b, k, 2], k1)
                for i in range(m):
                    s[i] += hk * k1[i]
            else:
                dmin = _deriv(method, s, w0[b, k, 0], w0[b, k, 1], w0[b, k, 2], k1)
                for i in range(m):
                    tmp[i] = s[i] + 0.5 * hk * k1[i]
                dmin = min(dmin, _deriv(method, tmp, wm[b, k, 0], wm[b, k, 1], wm[b, k, 2], k2))
                for i in range(m):
                    tmp[i] = s[i] + 0.5 * hk * k2[i]
                dmin = min(dmin, _deriv(method, tmp, wm[b, k, 0], wm[b, k, 1], wm[b, k, 2], k3))
                for i in range(m):
                    tmp[i] = s[i] + hk * k3[i]
                dmin = min(dmin, _deriv(method, tmp, w1[b, k, 0], w1[b, k, 1], w1[b, k, 2], k4))
                for i in range(m):
                    s[i] += hk / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i])
            if method == DCM and orthonormalize:
                _orthonormalize(s)
            # the distance after the step counts too (a step can jump over the singular set)
            dmin = min(dmin, _deriv(method, s, w1[b, k, 0], w1[b, k, 1], w1[b, k, 2], tmp))
            dist[b, k] = dmin
            w, x, y, z = _to_quaternion(method, s)
            if w * last_q[b, 0] + x * last_q[b, 1] + y * last_q[b, 2] + z * last_q[b, 3] < 0.0:
                w, x, y, z = -w, -x, -y, -z
            last_q[b, 0], last_q[b, 1], last_q[b, 2], last_q[b, 3] = w, x, y, z
            out[b, k, 0], out[b, k, 1], out[b, k, 2], out[b, k, 3] = w, x, y, z
        for i in range(m):
            state[b, i] = s[i]
