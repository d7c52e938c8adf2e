"""Rotation of the magnetometer axes onto the gyro's, from a recording that turns the sensor (private).

The ellipsoid fit leaves the calibrated field c_k in axes that may be turned by a fixed rotation R against the
gyro's (the mounting of the magnetometer chip, the rotation part of the soft iron).  The gyro tells how the
body turned: with Q_k the attitude of sample k relative to the start of its window (integrated from the
bias-free gyro), a constant field in the window's start axes v_w satisfies ``Q_k R c_k = v_w``.  R and the
v_w follow by alternating least squares: v_w is the mean of ``Q_k R c_k`` over window w, then R solves
Wahba's problem for the pairs (c_k, Q_kᵀ v_w) by SVD (Kabsch 1976).  Short windows keep the gyro's drift
(its remaining bias times the window length) small.
"""

from __future__ import annotations

import numpy as np

from ..propagate.integrate import integrate
from ..rotations.matrix import as_matrix


def kabsch(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The rotation R minimising Σ |R a_i - b_i|² (SVD of Σ b_i a_iᵀ, with the reflection removed)."""
    u, _, vt = np.linalg.svd(b.T @ a)
    d = np.sign(np.linalg.det(u @ vt))
    return u @ np.diag([1.0, 1.0, d]) @ vt


def align(c: np.ndarray, gyro: np.ndarray, fs: float, window: float, iterations: int = 50):
    """R (magnetometer axes to gyro axes) and the rms angle of the residual directions (rad).

    ``c`` (N, 3) calibrated field, NaN rows for missing samples; ``gyro`` (N, 3) bias-free mean rates over each
    step, rad/s (sample k of the field at the start of gyro step k).
    """
    n = len(gyro)
    size = max(2, round(window * fs))
    starts = range(0, n - 1, size)
    rel = np.full((n, 3, 3), np.nan)
    for s in starts:
        e = min(s + size, n)
        q = integrate(gyro[s:e], 1.0 / fs, input="average")  # attitudes at the window's boundaries
        rel[s:e] = as_matrix(q[:-1])  # sample k: body at k to body at the window's start
    ok = np.isfinite(c).all(axis=1) & np.isfinite(rel).all(axis=(1, 2))
    window_of = np.arange(n) // size
    c, rel, window_of = c[ok], rel[ok], window_of[ok]
    unit = c / np.linalg.norm(c, axis=1, keepdims=True)
    r = np.eye(3)
    for _ in range(iterations):
        turned = np.einsum("kij,jl,kl->ki", rel, r, unit)  # Q_k R c_k
        sums = np.zeros((window_of.max() + 1, 3))
        np.add.at(sums, window_of, turned)
        v = sums[window_of]
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        target = np.einsum("kji,kj->ki", rel, v)  # Q_kᵀ v_w
        new = kabsch(unit, target)
        step = np.arccos(np.clip((np.trace(new.T @ r) - 1) / 2, -1.0, 1.0))
        r = new
        if step < 1e-9:
            break
    residual = np.einsum("ij,kj->ki", r, unit) - target
    return r, float(np.sqrt(np.mean(np.sum(residual**2, axis=1))))
