"""The steps that read the rate between samples: the cubic rate model, RK4, coning and Gajda's baselines (private).

Functions of an :class:`~strapdown.propagate.integrate.AttitudeIntegrator` (``integ``), split from it so that
its module holds the streaming logic and this one the methods' arithmetic around their kernels.
"""

from __future__ import annotations

import warnings

import numpy as np

from .methods import BASELINES, NORMALIZE, SINGULAR, SingularityError, coning_table


def rate_model(integ, g, h, ends, final):
    """Per-step rates (start, middle, end), increments and durations of the steps that can be completed."""
    st = integ._state
    n_bodies, n, _ = g.shape
    if not integ._cubic:
        # averages and increments: the rate is constant over the step; increments use unit durations
        hs = np.ones(n) if integ.input == "increment" else np.broadcast_to(h, (n,)).copy()
        omega = g * integ.scale
        inc = omega * hs[None, :, None]
        return omega, omega, omega, inc, hs
    from ._ratemodel_numba import cubic_steps

    # buffer: samples from the first one a future step may still need, with their instants (= step starts)
    starts = np.concatenate([[st.t_end if st.steps_in else 0.0], ends[:-1]]) if n else np.zeros(0)
    buf_s = np.concatenate([st.extra["buf_s"], g * integ.scale], axis=1)
    buf_t = np.concatenate([st.extra["buf_t"], starts])
    first = st.extra["buf_first"]
    total = st.steps_in + n  # samples received, including this chunk
    end_time = ends[-1] if n else st.t_end  # end of the last received step
    k_next = st.steps_out
    span = 2 if integ.method == "rk4" else 1
    if not final:
        # a step may run once its four nodes (k-1 .. k+2, or 0 .. 3 at the start) and its end sample arrived
        k_last = min(total - 1 - span, total - 3) if total >= 4 else k_next - 1
        ks = np.arange(k_next, k_last + 1, span, dtype=np.int64)
        spans = np.full(ks.shape, span, dtype=np.int64)
        j0s = np.maximum(ks - 1, 0)
        npts = np.full(ks.shape, 4, dtype=np.int64)
    else:
        p = min(4, total)
        ks = np.arange(k_next, total, span, dtype=np.int64)
        spans = np.minimum(span, total - ks)
        j0s = np.clip(ks - 1, 0, total - p)
        npts = np.full(ks.shape, p, dtype=np.int64)
    k = int(ks[-1] + spans[-1]) if ks.size else k_next
    m = ks.size
    w0 = np.empty((n_bodies, m, 3))
    wm = np.empty((n_bodies, m, 3))
    w1 = np.empty((n_bodies, m, 3))
    wq = np.empty((n_bodies, m, 3))
    inc = np.empty((n_bodies, m, 3))
    hs = np.empty(m)
    tm = np.empty(m)
    if m:
        if j0s.min() < first:  # the buffer must hold every node; a miss would read the wrong samples
            raise AssertionError(f"rate-model buffer starts at {first}, a window at {j0s.min()}")
        t_rel = np.concatenate([buf_t, [end_time]])
        cubic_steps(
            np.ascontiguousarray(buf_s),
            t_rel,
            first,
            ks,
            spans,
            j0s,
            npts,
            w0,
            wm,
            w1,
            wq,
            inc,
            hs,
            tm,
        )
    # keep what later steps may need: their windows start at k - 1, or at N - 4 >= total - 4 at the end
    keep_from = max(min(k - 1, total - 4), 0)
    drop = keep_from - first
    st.extra["buf_s"] = buf_s[:, drop:].copy()
    st.extra["buf_t"] = buf_t[drop:].copy()
    st.extra["buf_first"] = keep_from
    integ._spans = spans
    integ._tm = tm
    integ._wq = wq
    # the rate at the sample inside a double step is that sample (for spans of 1 it is not used)
    inner = np.minimum(ks + 1 - first, buf_s.shape[1] - 1)
    integ._wi = np.ascontiguousarray(buf_s[:, inner])
    return w0, wm, w1, inc, hs


def run_rk4(integ, w0, wm, w1, hs) -> np.ndarray:
    from ._integrate_numba import rk4

    st = integ._state
    m = w0.shape[1]
    spans = integ._spans if integ._cubic else np.ones(m, dtype=np.int64)
    tm = integ._tm if integ._cubic else np.zeros(m)
    wq = integ._wq if integ._cubic else w0
    wi = integ._wi if integ._cubic else w0
    out = np.empty((w0.shape[0], int(spans.sum()), 4))
    st.counter = rk4(
        w0,
        wm,
        w1,
        wq,
        wi,
        hs,
        spans,
        tm,
        NORMALIZE[integ.normalize],
        integ.normalize_every,
        st.counter,
        st.q,
        out,
    )
    return out


def run_coning(integ, inc) -> np.ndarray:
    from ._integrate_numba import coning

    st = integ._state
    coef, c_prev = coning_table(integ.method)
    out = np.empty((*inc.shape[:2], 4))
    ex = st.extra
    ex["pos"], st.counter = coning(
        np.ascontiguousarray(inc),
        coef,
        c_prev,
        NORMALIZE[integ.normalize],
        integ.normalize_every,
        st.counter,
        ex["pos"],
        st.q,
        ex["alpha"],
        ex["beta"],
        ex["prev"],
        ex["group"],
        out,
    )
    return out


def run_baseline(integ, w0, wm, w1, hs) -> np.ndarray:
    from ._baselines_numba import SCHEME_EULER, SCHEME_RK4, baseline

    st = integ._state
    ex = st.extra
    n_bodies, m = w0.shape[:2]
    out = np.empty((n_bodies, m, 4))
    dist = np.empty((n_bodies, m))
    scheme = SCHEME_EULER if integ.scheme == "euler" else SCHEME_RK4
    with np.errstate(all="ignore"):
        baseline(
            BASELINES[integ.method],
            scheme,
            integ.orthonormalize,
            w0,
            wm,
            w1,
            hs,
            ex["base"],
            ex["last_q"],
            out,
            dist,
        )
    first_step = st.steps_out
    flagged = ~(dist >= integ.singular_tol)
    failed = ex["failed"]
    if flagged.any() or failed.any():
        bodies, steps = np.nonzero(flagged)
        integ.singular_steps.extend((int(b), int(s) + first_step) for b, s in zip(bodies, steps, strict=True))
        if flagged.any() and integ.on_singular == "raise":
            b, s = int(bodies[0]), int(steps[0])
            raise SingularityError(
                f"{integ.method}: step {first_step + s} (body {b}) is {max(dist[b, s], 0.0):.3g} rad from the "
                f"method's singular set ({SINGULAR[integ.method]}), closer than singular_tol="
                f"{integ.singular_tol:.3g} rad; its results would be unreliable.  Use a quaternion method, or "
                "on_singular='nan' / 'warn'"
            )
        if integ.on_singular == "nan":
            for b in range(n_bodies):
                hit = np.flatnonzero(flagged[b])
                if failed[b]:
                    out[b] = np.nan
                elif hit.size:
                    out[b, hit[0] :] = np.nan
                    failed[b] = True
        elif flagged.any():
            warnings.warn(
                f"{integ.method}: {int(flagged.sum())} step(s) within {integ.singular_tol:.3g} rad of the singular "
                f"set ({SINGULAR[integ.method]}), first at step {first_step + int(steps[0])}; results there are "
                "unreliable",
                RuntimeWarning,
                stacklevel=4,
            )
    return out


def baseline_state(integ, q: np.ndarray) -> np.ndarray:
    from ..rotations.euler import as_euler
    from ..rotations.matrix import as_matrix
    from ..rotations.rotvec import as_axis_angle

    state = np.zeros((q.shape[0], 9))
    m = integ.method
    if m == "euler-angles":
        state[:, :3] = as_euler(q, "ZYX")
    elif m == "dcm":
        state[:, :9] = as_matrix(q).reshape(-1, 9)
    elif m == "euler-parameters":
        axis, angle = as_axis_angle(q)
        state[:, :3] = axis
        state[:, 3] = angle
    else:
        w = q[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            state[:, :3] = np.where(w[:, None] != 0, 2 * q[:, 1:] / w[:, None], np.inf)
    return state
