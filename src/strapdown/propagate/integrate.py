"""Attitude from angular rates: every classic propagation method, batch and streaming.

Timing convention
-----------------
N gyro samples make N steps and N + 1 attitudes, ``q[0] = q0``.  Step k runs from ``t[k]`` to ``t[k+1]`` and
uses sample k; ``q[k+1]`` is the attitude at ``t[k+1]``.  The times come from a scalar ``dt`` (``t[k] = k dt``),
a per-step ``dt`` array, or the N + 1 times ``t`` themselves (any spacing, strictly increasing).

What a sample is (``input=``) and how each method reads it:

===============  ===========================================  ==========================================
input            sample k is                                  methods that need ω(t) inside the step
===============  ===========================================  ==========================================
``"rate"``       the instantaneous rate at ``t[k]``, the      rk4, coning*, baselines: the cubic through
                 start of step k (rad/s)                      the four nearest samples (fourth order)
``"average"``    the mean rate over step k (rad/s), the       constant over the step
                 usual output of a filtered MEMS gyro
``"increment"``  the angle increment ∫ω dt over step k (rad)  constant over the step (= Δθ / h)
===============  ===========================================  ==========================================

exact, first-order, second-order and cayley hold sample k constant over step k (Gajda's assumption): that is
exact for increments and averages and globally second order for smooth motion, but only first order when the
samples are start-of-step instants (math.md §7).  The coning methods turn rate samples into increments by
integrating the cubic, and are fourth order on smooth motion from rates and from increments alike.

The methods (``method=``)::

    ``"exact"``            Gajda stages 2-3: ``q ⊗ exp(φ/2)``, φ = ω h; a Taylor series in |φ/2|² replaces sqrt, sin
                           and cos for |φ|/2 < 0.25 (exact to double precision), φ = 0 needs no division.
    ``"first-order"``      nabbla part 9: ``q ⊗ (1 + φ/2)``; angle error (|φ|)³/12 per step after normalising.
    ``"second-order"``     Taylor: ``q ⊗ ((1 - |φ|²/8) + φ/2)``; angle error (|φ|)³/24 per step.
    ``"cayley"``           ``q ⊗ (1 + φ/4)(1 - φ/4)⁻¹``, unit norm by construction; error (|φ|)³/48 per step.
    ``"rk4"``              classical RK4 on ``q̇ = ½ q ⊗ ω(t)``; renormalised; fourth order from rate samples.
    ``"coning2"``          two-sample rotation vector ``φ = Δθ1 + Δθ2 + ⅔ Δθ1×Δθ2`` per pair of samples (default for
                           increments: fourth order on any smooth motion, math.md §6.4).
    ``"coning3"``..``6``   coning-optimised N-sample sets (math.md §6.2), best under pure coning.
    ``"coning3-poly"``,    polynomial-rate sets, exact for quadratic / cubic rates (math.md §6.2).
    ``"coning4-poly"``
    ``"coning1-prev"``     one update per sample, ``φ_k = Δθ_k + (1/12) Δθ_{k-1}×Δθ_k``.
    ``"euler-angles"``,    Gajda's classic alternatives (1.6, 1.5, 1.3, 1.4) as baselines with their own state,
    ``"dcm"``,             integrated by RK4 (``scheme="euler"``: first order) over the same rate model; steps
    ``"euler-parameters"``,near their singular sets are reported (``on_singular=``), never returned silently.
    ``"rotation-vector"``

Reference-frame rates (``rate_frame="reference"``, the patent's eq. 29) update on the left,
``q_{k+1} = dq ⊗ q_k``.  They are integrated as the conjugate problem: ``q*`` obeys the body-rate equation with
the rates negated, so every quaternion method serves both frames with the same code.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._support import threads as _threads
from .._support import validate as _v
from ._model_steps import baseline_state, rate_model, run_baseline, run_coning, run_rk4
from ._state import IntegratorState, checked_state
from .methods import BASELINES, CONING, MAX_STEP_ANGLE, METHODS, NORMALIZE, STEP_KINDS, SingularityError, coning_table

__all__ = ["METHODS", "AttitudeIntegrator", "SingularityError", "integrate"]


@dataclass
class AttitudeIntegrator:
    """Streaming attitude propagation: feed gyro chunks, get attitudes; any chunking gives the same result.

    Parameters
    ----------
    method : str, optional
        One of :data:`METHODS` (see the module notes).  Default ``"exact"`` for rates, ``"coning2"`` for
        increments.
    q0 : array_like, shape (4,) or (B, 4), optional
        Initial attitude(s), body to reference; identity by default.  Normalised.
    input : {"rate", "average", "increment"}
        What a sample is (module notes).
    rate_frame : {"body", "reference"}
        Frame of the measured rates: body (gyros, right multiplication) or reference (left multiplication).
    degrees : bool
        Samples in deg/s (or deg for increments).
    t0 : float
        Time of ``q0`` in seconds; ``update(..., t=...)`` takes absolute step end times.
    normalize : {"exact", "series", "none"}
        Renormalisation of the propagated quaternion: divide by the norm, multiply by ``(3 - |q|²)/2``
        (nabbla), or leave it.  Applied every ``normalize_every`` steps.  Baselines ignore it.
    normalize_every : int
        Steps between renormalisations.
    parallel : bool, optional
        Use the blocked prefix-product scan for exact, cayley, and first/second-order with exact
        normalisation every step (or none).  ``None``: for single-body chunks of 32768 samples or more.  The
        scan equals the sequential loop to rounding (1e-12 rad over 10⁷ steps), not bit for bit, and gives the
        same bits on any number of threads.
    threads : int or "auto", optional
        Threads of the scan.  None: the ``STRAPDOWN_THREADS`` environment variable, else ``"auto"``, the cores
        free right now (one on a busy machine, never more than the size pays for).  See
        docs/guide/performance.md and :mod:`strapdown._support.threads`.
    scheme : {"rk4", "euler"}
        Integrator of the baselines' differential equations.
    orthonormalize : bool
        dcm baseline: re-orthonormalise the matrix every step.
    on_singular : {"raise", "nan", "warn"}
        What a baseline does at a step within ``singular_tol`` of its singular set: raise
        :class:`SingularityError`, return NaN from that step on, or continue with a ``RuntimeWarning``.
        The steps are listed in ``singular_steps`` in every case.
    singular_tol : float
        Distance (rad) from the singular set that counts as singular: pitch from ±90° (euler-angles), χ from
        0 (euler-parameters), χ from 180° (rotation-vector).  Default 0.5°, where sec θ = 115.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import AttitudeIntegrator
    >>> gyro = np.tile([0.0, 0.0, np.pi / 2], (100, 1))      # 90 deg/s about z
    >>> integ = AttitudeIntegrator("exact")
    >>> first = integ.update(gyro[:40], dt=0.01)
    >>> rest = integ.update(gyro[40:], dt=0.01)
    >>> first.shape, rest.shape
    ((40, 4), (60, 4))
    >>> rest[-1].round(12)                                   # 90 deg about z after 1 s
    array([0.70710678, 0.        , 0.        , 0.70710678])
    """

    def __init__(
        self,
        method: str | None = None,
        *,
        q0=None,
        input: str = "rate",
        rate_frame: str = "body",
        degrees: bool = False,
        t0: float = 0.0,
        normalize: str = "exact",
        normalize_every: int = 1,
        parallel: bool | None = None,
        threads: int | str | None = None,
        scheme: str = "rk4",
        orthonormalize: bool = False,
        on_singular: str = "raise",
        singular_tol: float = np.radians(0.5),
    ):
        self.input = _v.choice(input, "input", ("rate", "average", "increment"))
        if method is None:
            method = "coning2" if input == "increment" else "exact"
        self.method = _v.choice(method, "method", METHODS)
        self.rate_frame = _v.choice(rate_frame, "rate_frame", ("body", "reference"))
        if self.rate_frame == "reference" and method in BASELINES:
            raise ValueError(
                f"method {method!r} is one of Gajda's baselines, written for body rates (§1); "
                "use a quaternion method for rate_frame='reference'"
            )
        self.normalize = _v.choice(normalize, "normalize", tuple(NORMALIZE))
        if not (isinstance(normalize_every, int | np.integer) and normalize_every >= 1):
            raise ValueError(f"normalize_every must be a positive integer, got {normalize_every!r}")
        self.normalize_every = int(normalize_every)
        self.parallel = parallel
        _threads.parse(threads, "threads")  # validated now; "auto" and None are decided per call
        self.threads = threads
        self.scheme = _v.choice(scheme, "scheme", ("rk4", "euler"))
        self.orthonormalize = bool(orthonormalize)
        self.on_singular = _v.choice(on_singular, "on_singular", ("raise", "nan", "warn"))
        if not (np.isfinite(singular_tol) and singular_tol >= 0):
            raise ValueError(f"singular_tol must be a finite angle >= 0 in radians, got {singular_tol!r}")
        self.singular_tol = float(singular_tol)
        self.scale = np.pi / 180 if degrees else 1.0
        t0 = float(t0)
        if not np.isfinite(t0):
            raise ValueError(f"t0 must be finite, got {t0!r}")
        self.t0 = t0
        self._q0 = None if q0 is None else _v.quaternions(q0, "q0")
        if self._q0 is not None and self._q0.ndim > 2:
            raise ValueError(f"q0 must have shape (4,) or (B, 4), got {self._q0.shape}")
        self._state: IntegratorState | None = None
        self._dt_anchor: tuple[int, float, float] | None = None  # (step, t_rel, dt) for scalar-dt timing
        self._finished = False
        self.singular_steps: list[tuple[int, int]] = []
        self._cubic = input == "rate" and (method == "rk4" or method in CONING or method in BASELINES)

    # ----------------------------------------------------------------------------------------------------
    # state
    @property
    def state(self) -> IntegratorState | None:
        """A copy of the internal state (None before the first update); assign one to restore it."""
        return None if self._state is None else self._state.copy()

    @state.setter
    def state(self, value: IntegratorState) -> None:
        if not isinstance(value, IntegratorState):
            raise ValueError("state must be an IntegratorState taken from an integrator of the same method")
        self._state = checked_state(self, value)
        self._dt_anchor = self._state.extra.get("dt_anchor")
        self._finished = False

    @property
    def attitude(self) -> np.ndarray | None:
        """The latest emitted attitude(s), body to reference: shape (4,) or (B, 4)."""
        if self._state is None:
            return None if self._q0 is None else self._q0.copy()
        q = self._state.extra["last_out"]
        q = np.array(q, copy=True)
        if self.rate_frame == "reference":
            q[..., 1:] *= -1
        return q[0] if self._state.extra["single"] else q

    # ----------------------------------------------------------------------------------------------------
    def _start(self, n_bodies: int, single: bool, dtype) -> None:
        self._state = self._fresh_state(n_bodies, single, dtype)

    def _fresh_state(self, n_bodies: int, single: bool, dtype, q0=None) -> IntegratorState:
        """The state before the first sample (from ``q0``, or this integrator's own initial attitude)."""
        if q0 is None:
            q0 = np.array([1.0, 0.0, 0.0, 0.0]) if self._q0 is None else self._q0.astype(np.float64)
        q0 = q0 / np.linalg.norm(q0, axis=-1, keepdims=True)
        if q0.ndim == 2 and q0.shape[0] not in (1, n_bodies):
            raise ValueError(f"q0 has {q0.shape[0]} rows but gyro has {n_bodies} bodies")
        q = np.ascontiguousarray(np.broadcast_to(q0, (n_bodies, 4)), dtype=np.float64)
        if self.rate_frame == "reference":
            q = q * np.array([1.0, -1.0, -1.0, -1.0])
        st = IntegratorState(q=q.copy(), t_end=np.nan if self.input == "increment" else 0.0)
        st.extra["single"] = single
        st.extra["dtype"] = np.dtype(dtype)
        st.extra["last_out"] = q.copy()
        st.extra["q_start"] = q.copy()
        m = self.method
        if m in CONING:
            k, _c_prev = coning_table(m)
            st.extra["alpha"] = np.zeros((n_bodies, 3))
            st.extra["beta"] = np.zeros((n_bodies, 3))
            st.extra["prev"] = np.zeros((n_bodies, 3))
            st.extra["group"] = np.zeros((n_bodies, k.shape[0], 3))
            st.extra["pos"] = 0
        elif m in BASELINES:
            st.extra["base"] = baseline_state(self, q)
            st.extra["last_q"] = q.copy()
            st.extra["failed"] = np.zeros(n_bodies, dtype=bool)
        if self._cubic:
            st.extra["buf_s"] = np.zeros((n_bodies, 0, 3))
            st.extra["buf_t"] = np.zeros(0)  # sample instants (relative), one per buffered sample
            st.extra["buf_first"] = 0  # global index of the first buffered sample
        return st

    def _times(self, n: int, dt, t) -> tuple[np.ndarray, np.ndarray | None, float]:
        """Step durations, step end times and the end of the chunk's last step.

        Returns h of shape (n,) or (1,), the step end times relative to t0 when the rate model needs them (else
        None), and the end of the last step (NaN for increments without times).
        """
        st = self._state
        if dt is not None and t is not None:
            raise ValueError("give either dt or t, not both")
        if dt is None and t is None:
            if self.input == "increment":
                return np.ones(1), None, np.nan
            raise ValueError("dt or t is required for rate samples (seconds per step, or step end times)")
        prev_end = st.t_end if np.isfinite(st.t_end) else 0.0
        if dt is not None:
            dt_arr = _v.finite(dt, "dt", dtype=np.float64)
            if dt_arr.ndim == 0:
                d = float(dt_arr)
                if not d > 0:
                    raise ValueError(f"dt must be positive, got {d!r}")
                k0 = st.steps_in
                if self._dt_anchor is None or self._dt_anchor[2] != d:
                    self._dt_anchor = (k0, prev_end, d)
                st.extra["dt_anchor"] = self._dt_anchor
                ka, ta, _ = self._dt_anchor
                # t_k = t_anchor + (k - k_anchor) dt from the global step index: the same for any chunking
                last = ta + (k0 + n - ka) * d if n else st.t_end
                ends = ta + (np.arange(k0 + 1, k0 + n + 1) - ka) * d if self._cubic else None
                return np.array([d]), ends, last
            if dt_arr.shape != (n,):
                raise ValueError(f"dt must be a scalar or have one entry per sample ({n}), got shape {dt_arr.shape}")
            if not (dt_arr > 0).all():
                raise ValueError(f"dt{_v.first_index(~(dt_arr > 0))} is not positive; durations must be > 0")
            self._dt_anchor = st.extra["dt_anchor"] = None  # also in the state: a restored one must not reuse it
            ends = np.cumsum(np.concatenate([[prev_end], dt_arr]))[1:]
            return dt_arr, ends, float(ends[-1]) if n else st.t_end
        t_arr = _v.finite(t, "t", dtype=np.float64)
        if t_arr.shape != (n,):
            raise ValueError(
                f"t must have one end time per sample here ({n}), got shape {t_arr.shape}; integrate() takes "
                "N + 1 times (the start and the end of every step)"
            )
        self._dt_anchor = st.extra["dt_anchor"] = None
        ends = t_arr - self.t0
        full = np.concatenate([[prev_end], ends])
        steps = np.diff(full)
        if not (steps > 0).all():
            i = int(np.flatnonzero(~(steps > 0))[0])
            raise ValueError(
                f"t is not strictly increasing at sample {st.steps_in + i}: {float(full[i] + self.t0)!r} -> "
                f"{float(full[i + 1] + self.t0)!r}"
            )
        return steps, ends, float(ends[-1]) if n else st.t_end

    # ----------------------------------------------------------------------------------------------------
    def update(self, gyro, dt=None, t=None) -> np.ndarray:
        """Propagate through a chunk of samples and return the attitudes completed by it.

        Parameters
        ----------
        gyro : array_like, shape (n, 3) or (B, n, 3)
            Samples of this chunk (see ``input``), for one body or B bodies.
        dt : float or array_like of shape (n,), optional
            Step duration(s) in seconds.
        t : array_like, shape (n,), optional
            Absolute end time of each sample's step (the start of the first is the previous end, or ``t0``).

        Returns
        -------
        numpy.ndarray, shape (m, 4) or (B, m, 4)
            The attitudes at the ends of the steps completed so far, in order.  m = n except for methods
            that read ω(t) from the cubic through neighbouring rate samples, which lag by up to three samples
            (:meth:`finish` returns the rest).
        """
        return self._public(self._process(self._prepare(gyro), dt, t))

    def finish(self) -> np.ndarray:
        """Complete the steps still waiting for later samples (cubic rate model only) and close the integrator.

        Returns
        -------
        numpy.ndarray, shape (m, 4) or (B, m, 4)
            The remaining attitudes (none for methods without a lag).
        """
        if self._state is None:
            raise ValueError("nothing to finish: no samples were given")
        raw = self._finish_raw()
        self._finished = True
        return self._public(raw)

    def _prepare(self, gyro) -> np.ndarray:
        """Validated samples as a C-contiguous (B, n, 3) array in the internal frame; starts the state."""
        if self._finished:
            raise ValueError("this integrator has been finished; create a new one (or set its state)")
        arr = _v.as_float_array(gyro, "gyro")
        if arr.ndim not in (2, 3) or arr.shape[-1] != 3:
            raise ValueError(f"gyro must have shape (n, 3) or (B, n, 3), got shape {arr.shape}")
        single = arr.ndim == 2
        if self.method not in STEP_KINDS:
            _v.check_finite(arr, "gyro")  # the step methods check their last attitude instead (_process)
        g = arr[None] if single else arr
        if self._state is None:
            self._start(g.shape[0], single, arr.dtype)
        st = self._state
        if g.shape[0] != st.q.shape[0] or single != st.extra["single"]:
            raise ValueError(f"gyro has {g.shape[0]} bodies; this integrator was started with {st.q.shape[0]}")
        g = np.ascontiguousarray(g)
        return -g if self.rate_frame == "reference" else g

    def _process(self, g: np.ndarray, dt, t, out: np.ndarray | None = None) -> np.ndarray:
        """Advance over prepared samples; returns the new attitudes (B, m, 4), internal frame, float64.

        With `out` (a (B, ≥ n, 4) float64 buffer) the step-quaternion methods write into it directly.
        """
        st = self._state
        n = g.shape[1]
        h, ends, last = self._times(n, dt, t)
        if self.input == "increment":
            h = np.ones(1)  # an increment is the step's rotation vector whatever the step lasted
        if self.method in STEP_KINDS:
            saved = st.copy()
            raw = self._run_step_kind(g, h, None if out is None else out[:, :n])
            # A NaN or infinite sample poisons every later attitude of the product chain (and of the scan's
            # block offsets), so a finite last attitude proves the input finite without a pass over it; a huge
            # step that the normalisation turned into a zero quaternion (first-order at 1e200 rad/s) shows as a
            # last attitude off the unit sphere.
            if n and not self._plausible(raw[:, -1]):
                self._state = saved
                _v.check_finite(g[0] if st.extra["single"] else g, "gyro")
                self._check_steps(g, h)
                raise ValueError(
                    "gyro: the step rotations overflow (|gyro| dt is too large to represent); check the units "
                    "and the time step"
                )
        else:
            self._check_steps(g, h)
            raw = self._run_model(g, h, ends, final=False)
        st.steps_in += n
        st.t_end = last
        self._count(raw)
        return raw

    def _plausible(self, q_last: np.ndarray) -> bool:
        """Finite, and unit to 1e-6 where the method keeps unit norm (normalised every step, or norm-preserving)."""
        if not np.isfinite(q_last).all():
            return False
        unit = self.method in ("exact", "cayley") or (self.normalize != "none" and self.normalize_every == 1)
        return not unit or bool((np.abs(np.einsum("...i,...i->...", q_last, q_last) - 1) <= 1e-6).all())

    def _check_steps(self, g: np.ndarray, h: np.ndarray) -> None:
        """Raise unless every step rotation |ω| h is at most MAX_STEP_ANGLE, naming the first sample beyond it.

        Past it float64 no longer holds the angle of a step to 1 mrad, and the RK4, coning and baseline
        arithmetic overflows into NaN (1e200 rad/s, or dt = 1e300).  One pass over the samples, which these
        methods' finiteness check makes anyway.
        """
        with np.errstate(over="ignore", invalid="ignore"):
            peak = np.max(np.abs(g), axis=(0, 2)) if g.size else np.zeros(0)
            step = peak * self.scale * (h if h.shape[0] == peak.shape[0] else h[0])
        bad = ~(step <= MAX_STEP_ANGLE)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            st = self._state
            what = (
                "increment"
                if self.input == "increment"
                else f"rate times its step ({float(h[min(k, h.shape[0] - 1)]):.3g} s)"
            )
            raise ValueError(
                f"gyro sample {st.steps_in + k} turns by {float(step[k]):.3g} rad in one step ({what}), beyond "
                f"{MAX_STEP_ANGLE:.3g} rad where float64 cannot hold a step's angle; check the units and the time step"
            )

    def _finish_raw(self) -> np.ndarray:
        st = self._state
        if not self._cubic:
            return np.zeros((st.q.shape[0], 0, 4))
        raw = self._run_model(np.zeros((st.q.shape[0], 0, 3)), np.ones(1), np.zeros(0), final=True)
        self._count(raw)
        return raw

    def _count(self, raw: np.ndarray) -> None:
        st = self._state
        if raw.shape[1]:
            st.extra["last_out"] = raw[:, -1].copy()
        st.steps_out += raw.shape[1]

    def _public(self, raw: np.ndarray) -> np.ndarray:
        """Internal float64 attitudes -> the caller's frame, dtype and shape."""
        st = self._state
        if self.rate_frame == "reference":
            raw = raw * np.array([1.0, -1.0, -1.0, -1.0])
        if st.extra["dtype"] == np.float32:
            raw = raw.astype(np.float32)
        return raw[0] if st.extra["single"] else raw

    def _run_model(self, g, h, ends, final) -> np.ndarray:
        w0, wm, w1, inc, hs = rate_model(self, g, h, ends, final)
        if self.method == "rk4":
            return run_rk4(self, w0, wm, w1, hs)
        if self.method in CONING:
            return run_coning(self, inc)
        return run_baseline(self, w0, wm, w1, hs)

    def _run_step_kind(self, g, h, out=None) -> np.ndarray:
        from .._support import uncompiled
        from . import _integrate_numba as k

        st = self._state
        kind = STEP_KINDS[self.method]
        norm = NORMALIZE[self.normalize]
        n_bodies, n, _ = g.shape
        if out is None:
            out = np.empty((n_bodies, n, 4))
        if n == 0:
            return out
        hstep = 1 if h.shape[0] > 1 else 0
        # the scan reproduces the sequential semantics to rounding when the outputs are unit (norm-preserving
        # step, or exact normalisation every step) or raw (no normalisation)
        unit = kind in (k.KIND_EXACT, k.KIND_CAYLEY) or (norm == k.NORM_EXACT and self.normalize_every == 1)
        scan_ok = n_bodies == 1 and (unit or norm == k.NORM_NONE)
        use_scan = scan_ok and (self.parallel if self.parallel is not None else n >= 32768)
        if self.parallel and not scan_ok:
            raise ValueError(
                "parallel=True needs one body and, for first/second-order, normalize='exact' every step or "
                "normalize='none'"
            )
        if use_scan:
            q = st.q[0].copy()

            def part(threads, lo, hi):  # samples lo..hi, continuing from q; tile-aligned pieces: the same bits
                hs = h[lo:hi] if hstep else h
                args = (g[0, lo:hi], hs, hstep, self.scale, kind, unit and norm != k.NORM_NONE, q, out[0, lo:hi])
                if threads > 1:
                    k.scan(*args, threads)
                else:
                    k.scan_serial(*args)

            _threads.run(n, self.threads, part)
            # the build this call did not run, for the next process whose load picks it (_support/uncompiled)
            args = (g[0], h, hstep, self.scale, kind, unit and norm != k.NORM_NONE, st.q[0].copy(), out[0])
            uncompiled.compile_later(k.scan, *args, 2)
            uncompiled.compile_later(k.scan_serial, *args)
            st.q[0] = q
            st.counter = 0
        else:
            args = (g, h, hstep, self.scale, kind, norm, self.normalize_every, st.counter, st.q, out)
            # 12 µs a sample uncompiled (_support/uncompiled.py): a short first call need not wait for the compiler
            st.counter = uncompiled.call(k.sequential, *args, python_seconds=12e-6 * n_bodies * n)
        return out


def integrate(
    gyro,
    dt=None,
    *,
    t=None,
    q0=None,
    method: str | None = None,
    input: str = "rate",
    rate_frame: str = "body",
    degrees: bool = False,
    **options,
) -> np.ndarray:
    """Attitudes from gyro samples: the batch form of :class:`AttitudeIntegrator` (update, then finish).

    Parameters
    ----------
    gyro : array_like, shape (N, 3) or (B, N, 3)
        Rate samples (rad/s, or deg/s with ``degrees=True``) or increments (``input="increment"``), for one
        body or B bodies at once.
    dt : float or array_like of shape (N,), optional
        Step duration(s) in seconds.
    t : array_like, shape (N + 1,), optional
        Times of the N + 1 attitudes: step k runs from ``t[k]`` to ``t[k+1]``.  Any spacing, strictly
        increasing.  Neither dt nor t is needed for increments.
    q0 : array_like, shape (4,) or (B, 4), optional
        Initial attitude (body to reference), identity by default.
    method : str, optional
        One of :data:`METHODS`; default ``"exact"`` for rates and ``"coning2"`` for increments.
    input : {"rate", "average", "increment"}
        What a sample is (module notes: timing convention).
    rate_frame : {"body", "reference"}
        Frame of the rates.
    degrees : bool
        Samples in degrees.
    **options
        ``normalize``, ``normalize_every``, ``parallel``, ``threads``, ``scheme``, ``orthonormalize``,
        ``on_singular``, ``singular_tol``: see :class:`AttitudeIntegrator`.

    Returns
    -------
    numpy.ndarray, shape (N + 1, 4) or (B, N + 1, 4)
        ``q[0] = q0``, ``q[k + 1]`` the attitude at the end of step k.  float32 for float32 input.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import as_euler, integrate
    >>> gyro = np.tile([90.0, 0.0, 0.0], (400, 1))            # roll at 90 deg/s
    >>> q = integrate(gyro, dt=0.01, degrees=True)
    >>> q.shape
    (401, 4)
    >>> as_euler(q[[50, 100, 300]], degrees=True).round(9)    # after 0.5 s, 1 s and 3 s
    array([[  0.,   0.,  45.],
           [  0.,   0.,  90.],
           [  0.,   0., -90.]])
    """
    arr = _v.as_float_array(gyro, "gyro")
    if arr.ndim not in (2, 3) or arr.shape[-1] != 3:
        raise ValueError(f"gyro must have shape (N, 3) or (B, N, 3), got shape {arr.shape}")
    n = arr.shape[-2]
    t0 = 0.0
    ends = None
    if t is not None:
        t_arr = _v.finite(t, "t", dtype=np.float64)
        if t_arr.shape != (n + 1,):
            raise ValueError(
                f"t must have N + 1 = {n + 1} entries (the start and end of each of the N steps), got shape "
                f"{t_arr.shape}; for one timestamp per sample, prepend the start of the first step or append the "
                "end of the last"
            )
        t0 = float(t_arr[0])
        ends = t_arr[1:]
    integ = AttitudeIntegrator(method, q0=q0, input=input, rate_frame=rate_frame, degrees=degrees, t0=t0, **options)
    g = integ._prepare(arr)
    st = integ._state
    # one result array: q0, then the kernels write the attitudes straight after it
    result = np.empty((g.shape[0], n + 1, 4))
    result[:, 0] = st.q
    body = integ._process(g, dt, ends, out=result[:, 1:])
    m = body.shape[1]
    if m and not np.shares_memory(body, result):
        result[:, 1 : m + 1] = body
    result[:, m + 1 :] = integ._finish_raw()
    integ._finished = True
    return integ._public(result)
