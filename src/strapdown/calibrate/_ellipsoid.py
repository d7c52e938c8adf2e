"""Ellipsoid fit shared by the magnetometer and the accelerometer (private).

Readings r of a constant-magnitude vector v seen in every direction lie on an ellipsoid:
``r = A v + b``, so ``|W (r - b)| = F`` with W A orthogonal.  Only W's symmetric positive-definite form can be
found (a rotation after W changes nothing), ``W = (A Aᵀ)^(-1/2)``; it has 6 parameters, b has 3.

1. Algebraic start (the classic linear least-squares fit of a quadric; Li & Griffiths 2004 without their
   ellipsoid constraint): ``xᵀQx + 2pᵀx = 1``, centre ``b = -Q⁻¹p``, ``W² = Q / (1 + bᵀQb)``.
2. Maximum-likelihood refinement (Levenberg-Marquardt) of the geometric residual
   ``d_i = (|W(r_i - b)| - F) / |Wᵀu_i|`` with ``u_i = W(r_i - b)/|W(r_i - b)|``: to first order the distance of
   r_i from the ellipsoid, so for Gaussian noise of σ per axis the least-squares fit is the ML one and its
   covariance ``σ² (JᵀJ)⁻¹`` is the Cramér-Rao bound to first order.
3. Robustness: Huber weights (k = 1.345 robust sigmas, Huber 1964) by iterative reweighting, with the scale
   from the median absolute residual, so outlying samples (a passing magnet, a spike) lose their pull.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Symmetric matrix from 6 parameters (W00, W11, W22, W01, W02, W12), and the basis E_p with W = Σ w_p E_p.
_SYM = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))
_BASIS = np.zeros((6, 3, 3))
for _p, (_i, _j) in enumerate(_SYM):
    _BASIS[_p, _i, _j] = _BASIS[_p, _j, _i] = 1.0

HUBER_K = 1.345  # 95 % efficiency at the normal distribution (Huber 1964)


def sym(w: np.ndarray) -> np.ndarray:
    return np.einsum("p,pij->ij", w, _BASIS)


def unsym(m: np.ndarray) -> np.ndarray:
    return np.array([m[i, j] for i, j in _SYM])


def sqrtm_spd(m: np.ndarray) -> np.ndarray:
    values, vectors = np.linalg.eigh(m)
    return (vectors * np.sqrt(values)) @ vectors.T


@dataclass
class EllipsoidFit:
    offset: np.ndarray  # b
    matrix: np.ndarray  # W, symmetric
    radius: float  # F
    covariance: np.ndarray  # of (b, w6) with F held
    sigma: float  # noise per axis, reading units
    residual: np.ndarray  # geometric residuals d_i, reading units
    weights: np.ndarray  # Huber weights
    iterations: int
    information_condition: float


def algebraic(r: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Centre and W (unit radius) of the least-squares quadric through r, or None if it is no ellipsoid."""
    mu = r.mean(axis=0)
    scale = np.sqrt(np.mean(np.sum((r - mu) ** 2, axis=1)))
    if not scale > 0:
        return None
    x = (r - mu) / scale  # conditioning: the quadric fit is done on centred, unit-size data
    design = np.column_stack(
        [x[:, 0] ** 2, x[:, 1] ** 2, x[:, 2] ** 2, 2 * x[:, 0] * x[:, 1], 2 * x[:, 0] * x[:, 2], 2 * x[:, 1] * x[:, 2]]
        + [2 * x[:, k] for k in range(3)]
    )
    v, *_ = np.linalg.lstsq(design, np.ones(len(x)), rcond=None)
    q = sym(v[:6])
    try:
        centre = -np.linalg.solve(q, v[6:])
    except np.linalg.LinAlgError:
        return None
    k = 1.0 + centre @ q @ centre
    m = q / k
    if not (np.isfinite(m).all() and np.linalg.eigvalsh(m).min() > 0):
        return None
    return mu + scale * centre, sqrtm_spd(m) / scale


def _residuals(r, b, w_mat, radius):
    d = r - b
    c = d @ w_mat.T
    norm = np.linalg.norm(c, axis=1)
    u = c / np.maximum(norm, 1e-300)[:, None]  # a reading exactly at the centre has no direction: no pull
    grad = u @ w_mat  # rows u_iᵀ W = (Wᵀu_i)ᵀ, W symmetric
    g = 1.0 / np.linalg.norm(grad, axis=1)  # geometric factor: radial residual -> distance in reading units
    e = norm - radius
    # Jacobian of the radial residual: ∂e/∂b = -uᵀW, ∂e/∂w_p = uᵀ E_p d
    jac = np.empty((len(r), 9))
    jac[:, :3] = -grad
    jac[:, 3:] = np.einsum("ni,pij,nj->np", u, _BASIS, d)
    return e * g, jac * g[:, None]


def _huber(res):
    sigma = 1.4826 * np.median(np.abs(res))
    if not sigma > 0:
        return np.ones_like(res), sigma
    a = np.abs(res) / sigma
    return np.where(a <= HUBER_K, 1.0, HUBER_K / np.maximum(a, 1e-300)), sigma


def refine(
    r: np.ndarray,
    b0: np.ndarray,
    w0: np.ndarray,
    radius: float,
    *,
    sample_weights: np.ndarray | None = None,
    robust: bool = True,
    noise: float | None = None,
    max_iterations: int = 100,
) -> EllipsoidFit:
    """Levenberg-Marquardt with Huber reweighting from (b0, W0); ``radius`` F is held fixed.

    ``sample_weights`` s_i say a residual has variance σ²/s_i (a mean of s_i samples); ``noise`` gives σ
    instead of estimating it from the residuals.
    """
    n = len(r)
    s = np.ones(n) if sample_weights is None else np.asarray(sample_weights, dtype=np.float64)
    theta = np.concatenate([b0, unsym(w0)])
    lam = 1e-3
    huber = np.ones(n)

    def cost_of(th, hw):
        res, jac = _residuals(r, th[:3], sym(th[3:]), radius)
        return float(np.sum(s * hw * res**2)), res, jac

    cost, res, jac = cost_of(theta, huber)
    it = 0
    for it in range(1, max_iterations + 1):  # noqa: B007 - the count is reported
        if robust:
            huber, _ = _huber(res * np.sqrt(s))
            cost = float(np.sum(s * huber * res**2))
        wts = s * huber
        jw = jac * np.sqrt(wts)[:, None]
        rw = res * np.sqrt(wts)
        h = jw.T @ jw
        grad = jw.T @ rw
        improved = False
        for _ in range(30):
            try:
                step = np.linalg.solve(h + lam * np.diag(np.diag(h) + 1e-300), -grad)
            except np.linalg.LinAlgError:  # singular even with damping: damp harder
                lam *= 10
                continue
            trial = theta + step
            if np.linalg.eigvalsh(sym(trial[3:])).min() > 0:
                c_new, res_new, jac_new = cost_of(trial, huber)
                if c_new <= cost:
                    theta, cost, res, jac = trial, c_new, res_new, jac_new
                    lam = max(lam / 10, 1e-12)
                    improved = True
                    break
            lam *= 10
        if not improved or np.all(np.abs(step) <= 1e-10 * (np.abs(theta) + 1e-12)):
            break
    # Covariance of an M-estimator (Huber, Robust Statistics, 1981, ch. 7): σ_eff² (JᵀJ)⁻¹ with
    # σ_eff² = scale² · Σψ(z)²/(n - p) / (mean ψ'(z))², z the residuals in robust scales; for the plain fit
    # (ψ(z) = z) this is the usual residual variance.  Sample weights enter J and the residuals as √s_i.
    rs = res * np.sqrt(s)
    js = jac * np.sqrt(s)[:, None]
    if robust:
        huber, scale = _huber(rs)
        z = rs / scale if scale > 0 else rs
        inside = np.abs(z) <= HUBER_K
        psi = np.clip(z, -HUBER_K, HUBER_K)
        sigma_eff = scale * np.sqrt(np.sum(psi**2) / max(n - 9, 1)) / max(float(np.mean(inside)), 1e-12)
    else:
        huber = np.ones(n)
        sigma_eff = float(np.sqrt(np.sum(rs**2) / max(n - 9, 1)))
    sigma = float(sigma_eff) if noise is None else float(noise)
    info = js.T @ js
    scale_info = np.sqrt(np.diag(info))
    cond = float(np.linalg.cond(info / np.outer(scale_info, scale_info)))
    cov = sigma**2 * np.linalg.pinv(info)
    return EllipsoidFit(
        offset=theta[:3],
        matrix=sym(theta[3:]),
        radius=radius,
        covariance=cov,
        sigma=sigma,
        residual=res,
        weights=huber,
        iterations=it,
        information_condition=cond,
    )


def direction_spread(c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues (ascending, x3) and eigenvectors of the scatter of unit directions about their mean.

    Directions spread evenly over the sphere give 1, 1, 1; a direction never tilted gives 0.
    """
    u = c / np.linalg.norm(c, axis=1, keepdims=True)
    values, vectors = np.linalg.eigh(np.cov(u.T, bias=True))
    return 3 * values, vectors


def sphere_coverage(c: np.ndarray, cells: int = 200, radius_deg: float = 20.0) -> float:
    """Fraction of ``cells`` evenly spread directions (a Fibonacci lattice) within ``radius_deg`` of a sample."""
    u = c / np.linalg.norm(c, axis=1, keepdims=True)
    k = np.arange(cells) + 0.5
    z = 1 - 2 * k / cells
    phi = np.pi * (1 + 5**0.5) * k
    rho = np.sqrt(1 - z**2)
    lattice = np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])
    step = max(1, len(u) // 20000)  # a thinned set is enough to tell which cells are hit
    near = np.cos(np.radians(radius_deg))
    hit = np.zeros(cells, dtype=bool)
    for start in range(0, len(u[::step]), 4096):
        hit |= (u[::step][start : start + 4096] @ lattice.T >= near).any(axis=0)
    return float(hit.mean())


def axis_name(v: np.ndarray) -> str:
    """A direction in sensor axes for messages: '[0.00, 0.02, 1.00] (≈ z)'."""
    v = v / np.linalg.norm(v)
    if v[np.argmax(np.abs(v))] < 0:
        v = -v
    text = "[" + ", ".join(f"{x:.2f}" for x in v) + "]"
    k = int(np.argmax(np.abs(v)))
    if abs(v[k]) > 0.9:
        text += f" (≈ {'xyz'[k]})"
    return text
