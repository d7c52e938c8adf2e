"""The rate model between samples, for the methods that need ω(t) inside a step (private).

For instantaneous rate samples (``input="rate"``) ω(t) on step k is the cubic through the four samples nearest to
it (nodes k-1 .. k+2, shifted inwards at the ends), on arbitrary times.  A cubic's error is O(h⁴), which keeps rk4
and the coning algorithms fourth order; linear interpolation would cap them at second order (the midpoint error is
h² ω''/8), so we deviate from "linearly interpolated" in the issue text on purpose.

For each step the kernel returns the rate at the start, middle and end of the step and its integral over the
step (the gyro increment a delta-angle sensor would have measured).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from .._support import kernel_cache  # noqa: F401  (strapdown's own numba cache, before any kernel: its notes)


@nb.njit(cache=True, error_model="numpy")
def _basis_value(taus, npts, j, tau):
    """L_j(τ) of the Lagrange basis on nodes taus[:npts]."""
    v = 1.0
    for m in range(npts):
        if m != j:
            v *= (tau - taus[m]) / (taus[j] - taus[m])
    return v


@nb.njit(cache=True, error_model="numpy")
def _basis_integral(taus, npts, j, h):
    """∫_0^h L_j(τ) dτ, from the coefficients of the product of the linear factors."""
    coef = np.zeros(4)  # coef[p] multiplies τ^p
    coef[0] = 1.0
    deg = 0
    denom = 1.0
    for m in range(npts):
        if m == j:
            continue
        # multiply the polynomial by (τ - τ_m)
        for p in range(deg + 1, 0, -1):
            coef[p] = coef[p - 1] - taus[m] * coef[p]
        coef[0] = -taus[m] * coef[0]
        deg += 1
        denom *= taus[j] - taus[m]
    total = 0.0
    hp = h
    for p in range(deg + 1):
        total += coef[p] * hp / (p + 1)
        hp *= h
    return total / denom


@nb.njit(cache=True, error_model="numpy")
def cubic_steps(s, t_rel, first, ks, spans, j0s, npts, w0, wm, w1, wq, inc, h, tm):
    """Rate model of the steps ks from the buffer of samples s (B, M, 3) taken at times t_rel (M + 1,).

    s[:, i] is the sample at t_rel[i] (buffer index i = global index - first); t_rel[M] is the end of the last
    buffered step.  Step n starts at sample ks[n] and spans spans[n] sample intervals (2 for rk4's double steps,
    whose stages then fall on samples); its nodes are the npts[n] samples from j0s[n].  Returns in h the step
    length, in tm the time of the first sample inside the step (spans of 2), in w0, wm, w1 the rates at its start,
    middle and end, in wq the rate halfway to that inner sample, and in inc the integral of the rate over the step.
    """
    n_bodies = s.shape[0]
    taus = np.empty(4)
    for n in range(ks.shape[0]):
        k = ks[n] - first
        span = spans[n]
        j0 = j0s[n] - first
        p = npts[n]
        t0 = t_rel[k]
        hk = t_rel[k + span] - t0
        h[n] = hk
        tm[n] = t_rel[k + 1] - t0
        for j in range(p):
            taus[j] = t_rel[j0 + j] - t0
        for b in range(n_bodies):
            for c in range(3):
                w0[b, n, c] = s[b, k, c]
                wm[b, n, c] = 0.0
                w1[b, n, c] = 0.0
                wq[b, n, c] = 0.0
                inc[b, n, c] = 0.0
        for j in range(p):
            lm = _basis_value(taus, p, j, 0.5 * hk)
            l1 = _basis_value(taus, p, j, hk)
            lq = _basis_value(taus, p, j, 0.5 * tm[n])
            li = _basis_integral(taus, p, j, hk)
            for b in range(n_bodies):
                for c in range(3):
                    v = s[b, j0 + j, c]
                    wm[b, n, c] += lm * v
                    w1[b, n, c] += l1 * v
                    wq[b, n, c] += lq * v
                    inc[b, n, c] += li * v
        # stage times that fall on a sample take the sample itself, not a sum of weights
        if k + span < j0 + p:
            for b in range(n_bodies):
                for c in range(3):
                    w1[b, n, c] = s[b, k + span, c]
        if span == 2 and hk == 2.0 * tm[n]:
            for b in range(n_bodies):
                for c in range(3):
                    wm[b, n, c] = s[b, k + 1, c]
