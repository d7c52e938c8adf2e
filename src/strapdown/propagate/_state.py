"""What an AttitudeIntegrator carries between updates, and the check of a state restored into one (private)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._support import validate as _v


@dataclass
class IntegratorState:
    """Everything an :class:`AttitudeIntegrator` carries between updates (read and set with ``state``).

    Attributes
    ----------
    q : numpy.ndarray, shape (B, 4)
        The attitude after the last emitted step (internal frame: conjugated for reference-frame rates).
    steps_in, steps_out : int
        Samples received and attitudes emitted so far.
    t_end : float
        End of the last received step, relative to ``t0`` (s); NaN for increments without times.
    counter : int
        Steps since the last renormalisation.
    extra : dict
        Method-specific arrays (coning group sums, baseline states, the sample buffer of the cubic model).
    """

    q: np.ndarray
    steps_in: int = 0
    steps_out: int = 0
    t_end: float = 0.0
    counter: int = 0
    extra: dict = field(default_factory=dict)

    def copy(self) -> IntegratorState:
        """A deep copy (arrays included)."""
        extra = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self.extra.items()}
        return IntegratorState(self.q.copy(), self.steps_in, self.steps_out, self.t_end, self.counter, extra)


def count(value, name: str) -> int:
    """A non-negative integer counter of a restored state, or ValueError naming it."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | np.integer) or value < 0:
        raise ValueError(f"{name} must be a non-negative integer, got {value!r}")
    return int(value)


def checked_state(integ, value: IntegratorState) -> IntegratorState:
    """A validated copy of ``value``: ValueError naming the entry unless it fits this integrator.

    The kernels index the state's arrays and counters without bounds checks (a coning position of -5 writes
    outside the group buffer), so everything is compared with a fresh state of the same layout first.
    """
    q = _v.quaternions(value.q, "state.q", dtype=np.float64)
    if q.ndim != 2:
        raise ValueError(f"state.q must have shape (B, 4), got {q.shape}")
    ex = value.extra if isinstance(value.extra, dict) else {}
    single, dtype = ex.get("single"), ex.get("dtype")
    if not isinstance(single, bool | np.bool_) or (single and q.shape[0] != 1):
        raise ValueError(f"state.extra['single'] must be a bool (True only for one body), got {single!r}")
    if not (isinstance(dtype, np.dtype | type) and np.dtype(dtype) in (np.float32, np.float64)):
        raise ValueError(f"state.extra['dtype'] must be float32 or float64, got {dtype!r}")
    n_bodies = q.shape[0]
    fresh = integ._fresh_state(n_bodies, bool(single), dtype, q0=q)
    want, have = set(fresh.extra) | {"dt_anchor"}, set(ex) | {"dt_anchor"}
    if want != have:
        raise ValueError(
            f"state.extra has entries {sorted(have)}, but a {integ.method!r} integrator with input={integ.input!r} "
            f"needs {sorted(want)}; take the state from an integrator of the same method"
        )
    counts = {}
    for name in ("steps_in", "steps_out", "counter"):
        counts[name] = count(getattr(value, name), f"state.{name}")
    steps_in, steps_out = counts["steps_in"], counts["steps_out"]
    if steps_out > steps_in or (not integ._cubic and steps_out != steps_in):
        raise ValueError(f"state.steps_out ({steps_out}) does not fit state.steps_in ({steps_in})")
    t_end = value.t_end
    if not isinstance(t_end, float | int | np.floating | np.integer) or not (
        np.isfinite(t_end) or (np.isnan(t_end) and integ.input == "increment")
    ):
        raise ValueError(f"state.t_end must be a finite time in seconds, got {t_end!r}")
    out = IntegratorState(q.copy(), steps_in, steps_out, float(t_end), counts["counter"], {})
    if integ._cubic:
        # a step's interpolation window starts at most one sample before it, or at N - 4 at the end
        latest = max(min(steps_out - 1, steps_in - 4), 0)
        first = count(ex["buf_first"], "state.extra['buf_first']")
        if first > latest:
            raise ValueError(f"state.extra['buf_first'] must be at most {latest} here, got {first}")
    for key, ref in fresh.extra.items():
        name = f"state.extra[{key!r}]"
        v = ex[key]
        if isinstance(ref, np.ndarray):
            arr = np.asarray(v) if isinstance(v, np.ndarray | list | tuple) else None
            if arr is None or arr.dtype.kind != ref.dtype.kind:
                raise ValueError(f"{name} must be a {ref.dtype} array, got {type(v).__name__}")
            shape = list(ref.shape)
            if key in ("buf_s", "buf_t"):  # the sample buffer: its length is steps_in - buf_first
                shape[1 if key == "buf_s" else 0] = steps_in - ex["buf_first"]
            if list(arr.shape) != shape:
                raise ValueError(f"{name} must have shape {tuple(shape)}, got {arr.shape}")
            # the baselines' own states may hold infinities by design (a rotation vector at 180 degrees);
            # their distance to the singular set reports them
            if key not in ("base", "last_q") and arr.dtype.kind == "f":
                _v.check_finite(arr, name)
            out.extra[key] = arr.astype(ref.dtype, copy=True)
        elif key in ("pos", "buf_first"):
            out.extra[key] = count(v, name)
        else:
            out.extra[key] = v
    if "pos" in out.extra and out.extra["pos"] != steps_out % fresh.extra["group"].shape[1]:
        size = fresh.extra["group"].shape[1]
        raise ValueError(
            f"state.extra['pos'] must be state.steps_out mod {size} = {steps_out % size}, got {out.extra['pos']}"
        )
    anchor = ex.get("dt_anchor")
    if anchor is not None:
        ok = isinstance(anchor, tuple) and len(anchor) == 3
        if ok:
            try:
                ok = count(anchor[0], "") <= steps_in and np.isfinite(anchor[1]) and anchor[2] > 0
                ok = ok and np.isfinite(anchor[2])
            except (TypeError, ValueError):
                ok = False
        if not ok:
            raise ValueError(f"state.extra['dt_anchor'] must be None or (step, time, dt), got {anchor!r}")
        out.extra["dt_anchor"] = (int(anchor[0]), float(anchor[1]), float(anchor[2]))
    return out
