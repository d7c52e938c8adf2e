"""The linear triad model ``r = A v + b`` fitted against known true values v (private).

Used by the six-position accelerometer fit (v = ±g along an axis) and the gyro fit against a reference rate.
Each sensor axis is its own weighted least-squares problem ``r_i = A_i · v + b_i`` (the axes' noises are
independent), so the covariance of A is block diagonal.
"""

from __future__ import annotations

import numpy as np


def fit(v: np.ndarray, r: np.ndarray, weights: np.ndarray | None = None, noise: np.ndarray | None = None):
    """A, b, covariance of A's 9 elements (row-major), sigma of b, residuals and the noise per axis used.

    ``weights`` w_k say residual k has variance noise²/w_k; without ``noise`` it is estimated from the residuals.
    """
    w = np.ones(len(v)) if weights is None else np.asarray(weights, dtype=np.float64)
    x = np.column_stack([v, np.ones(len(v))])
    info = x.T @ (x * w[:, None])
    beta = np.linalg.solve(info, x.T @ (r * w[:, None]))  # (4, 3): column i is axis i
    residual = r - x @ beta
    if noise is None:
        noise = np.sqrt(np.sum(w[:, None] * residual**2, axis=0) / max(len(v) - 4, 1))
    inv_info = np.linalg.inv(info)
    cov_a = np.zeros((9, 9))
    for i in range(3):
        cov_a[3 * i : 3 * i + 3, 3 * i : 3 * i + 3] = noise[i] ** 2 * inv_info[:3, :3]
    return beta[:3].T, beta[3], cov_a, noise * np.sqrt(inv_info[3, 3]), residual, noise


def correction(a: np.ndarray, cov_a: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
    """The calibration matrix A⁻¹, its element sigmas, and A as scale factors and coupling with sigmas."""
    inv = np.linalg.inv(a)
    # δ(A⁻¹) = -A⁻¹ δA A⁻¹: ∂(A⁻¹)_pq / ∂A_ij = -(A⁻¹)_pi (A⁻¹)_jq
    jac = -np.einsum("pi,jq->pqij", inv, inv).reshape(9, 9)
    matrix_sigma = np.sqrt(np.diag(jac @ cov_a @ jac.T)).reshape(3, 3)
    a_sigma = np.sqrt(np.diag(cov_a)).reshape(3, 3)
    off = ~np.eye(3, dtype=bool)
    figures = {
        "scale_factor": (np.diag(a) - 1).tolist(),
        "scale_factor_sigma": np.diag(a_sigma).tolist(),
        "misalignment": np.where(off, a, 0.0).tolist(),
        "misalignment_sigma": np.where(off, a_sigma, 0.0).tolist(),
    }
    return inv, matrix_sigma, figures
