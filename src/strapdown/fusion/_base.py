"""What every fusion filter shares: the checks of its inputs, timing, frames, initialisation, state (private).

Timing: sample k is applied over the interval that ends at it; ``dt`` gives its length (a scalar, or one per
sample), or ``t`` gives the sample times, and then dt_k = t_k - t_k-1.  A given ``q0`` is the attitude at the
start of the first interval.  Without one, the attitude is initialised from the first sample, i.e. at its end:
that sample's gyro reading is then not integrated (as with ``t``, where the first sample has no interval).
Outputs have one attitude per sample: the estimate after that sample.

Frames: each filter computes in its own reference frame (Madgwick's is NWU, the others ENU: x east, y north,
z up) and reports in ``frame``; the body axes are the sensor's own.  The accelerometer reads specific force,
+g along body up at rest.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import fields, replace
from numbers import Real

import numpy as np

from .._support import validate as _v
from .._support.renamed import renamed
from ..rotations.frames import check_frame, frame_quaternion
from ..rotations.quaternion import multiply, rotate
from .estimate import Estimate
from .initial import initial_attitude

__all__ = ["Estimator"]


GRAVITY = 9.80665
#: The small filters' kernels run uncompiled (Mahony, Madgwick, complementary; measured 15-40 µs, 9D the
#: most): seconds a sample, for a first call's choice (_support/uncompiled.py).
UNCOMPILED_S_PER_SAMPLE = 4e-5


# Accepted input range (docs/guide/reliability.md): beyond these the kernels' squares and products overflow into
# NaN, and no sensor or clock comes near them.
MAX_SAMPLE = 1e100  # largest |component| of a gyro, accelerometer or magnetometer sample, in any unit


MAX_DT = 1e9  # s (32 years): the longest sample interval


MAX_STEP_ANGLE = 2e-3 / np.finfo(np.float64).eps  # rad: |gyro| dt of one sample, as in strapdown.integrate


def _sensor(v, name: str, missing: bool, check: bool = True) -> tuple[np.ndarray, float]:
    """A (N, 3) sensor array, finite and within MAX_SAMPLE, and a bound of its largest |component|.

    With ``missing``, whole NaN rows are allowed (no sample of that sensor then).  Without ``check``, only the
    dtype and shape (and the bound is None).
    """
    arr = _v.vectors(v, name, check=False, dtype=np.float64)
    if not check:
        return arr, None
    if arr.size:
        # The usual case in one pass: a sum of squares within (MAX_SAMPLE/2)² bounds every component, and a NaN
        # or an infinity fails the comparison.  Its root bounds the largest component (for the step check).
        # einsum, not a dot product: OpenBLAS's threads would spin on the cores the filter needs next; and no
        # per-row maxima over the axis of length 3, which cost as much as the filter itself on long inputs.
        flat = arr.reshape(-1)
        squares = np.einsum("i,i->", flat, flat)
        if squares <= (0.5 * MAX_SAMPLE) ** 2:
            return arr, float(np.sqrt(squares))
    if not missing:
        _v.check_finite(arr, name)
    elif not np.isfinite(arr).all():
        absent = np.isnan(arr).all(axis=-1)
        bad = ~(np.isfinite(arr).all(axis=-1) | absent)
        if bad.any():
            i = _v.first_index(bad)
            raise ValueError(f"{name}{i} is partly NaN or infinite; a row must be finite, or all NaN for no sample")
    _in_range(arr, name)
    return arr, _largest(arr)


def _largest(arr: np.ndarray) -> float:
    """The largest |component| of an array, NaN ignored (0 when empty or all NaN)."""
    if not arr.size:
        return 0.0
    flat = arr.reshape(-1)
    big = max(np.fmax.reduce(flat), -np.fmin.reduce(flat))
    return 0.0 if big != big else float(big)


def _in_range(arr: np.ndarray, name: str) -> None:
    """Raise if a sample has a component beyond MAX_SAMPLE (NaN rows, "no sample", are skipped)."""
    if _largest(arr) <= MAX_SAMPLE:
        return
    with np.errstate(invalid="ignore"):
        big = np.abs(arr).max(axis=-1, initial=0.0) > MAX_SAMPLE
    if big.any():
        k = int(np.flatnonzero(big)[0])
        raise _v.SampleError(
            f"{name}[{k}] = {arr[k].tolist()} is beyond {MAX_SAMPLE:.0e} in magnitude: no sensor reads that; "
            "check the units",
            k,
        )


def _triads(gyro, acc, mag, need_mag: bool, missing: bool = False, check: bool = True):
    """gyro, acc, mag checked and C-contiguous float64 (no copy when they are already), and a bound of |gyro|.

    Without ``check``, the values are not looked at (only dtypes and shapes; the bound is None).
    """
    g, g_max = _sensor(gyro, "gyro", False, check)
    a, _ = _sensor(acc, "acc", missing, check)
    if g.ndim != 2 or a.ndim != 2:
        raise ValueError(f"gyro and acc must have shape (N, 3), got {g.shape} and {a.shape}")
    if a.shape != g.shape:
        raise ValueError(f"acc has {a.shape[0]} samples but gyro has {g.shape[0]}; give one of each per sample")
    m = None
    if mag is not None:
        m, _ = _sensor(mag, "mag", missing, check)
        if m.shape != g.shape:
            raise ValueError(f"mag has {m.shape[0]} samples but gyro has {g.shape[0]}; give one of each per sample")
        m = np.ascontiguousarray(m)
    elif need_mag:
        raise ValueError("this filter was created for magnetometer data (9D): give mag, or create it without")
    return np.ascontiguousarray(g), np.ascontiguousarray(a), m, g_max


def _check_steps(g: np.ndarray, dts: np.ndarray, g_max: float) -> None:
    """Raise unless every interval is at most MAX_DT and every gyro step |gyro| dt at most MAX_STEP_ANGLE.

    ``g_max`` bounds every |gyro| component: that rate over the longest interval within bounds settles it.
    """
    if dts.size:
        longest = dts.max()
        if longest <= MAX_DT and g_max * longest <= MAX_STEP_ANGLE:
            return
    if not (dts <= MAX_DT).all():
        k = int(np.flatnonzero(~(dts <= MAX_DT))[0])
        raise _v.SampleError(
            f"sample {k} lasts {dts[k]:.3g} s, beyond {MAX_DT:.0e} s; check the time unit of dt or t", k
        )
    if len(dts) < len(g):  # compact intervals (Estimator.compact_intervals)
        dts = np.concatenate([dts, np.full(len(g) - len(dts), dts[-1])])
    step = np.abs(g).max(axis=-1, initial=0.0) * dts
    if not (step <= MAX_STEP_ANGLE).all():
        k = int(np.flatnonzero(~(step <= MAX_STEP_ANGLE))[0])
        raise _v.SampleError(
            f"gyro[{k}] turns by {step[k]:.3g} rad in one sample, beyond {MAX_STEP_ANGLE:.3g} rad where float64 "
            "cannot hold a step's angle; check the units and the time step",
            k,
        )


def _back_to_first_sample(gyro: np.ndarray, dts: np.ndarray, k: int, v: np.ndarray) -> np.ndarray:
    """A vector read by the sensor at the end of sample k, in the sensor axes at the end of sample 0.

    The sensor turns by the product of the steps 1..k: v_0 = D ⊗ v_k ⊗ D* (the bias is not known yet).
    """
    if k == 0:
        return v
    from ..propagate.integrate import integrate

    h = dts[1 : k + 1] if len(dts) > k else dts[-1]  # compact intervals: dts[-1] is every later one
    return rotate(integrate(gyro[1 : k + 1], dt=h)[-1], v)


def _first_present(arr: np.ndarray, name: str) -> int:
    if arr.shape[0] and arr[0, 0] == arr[0, 0]:
        return 0
    present = np.flatnonzero(~np.isnan(arr[:, 0]))
    if not len(present):
        raise ValueError(f"{name} has no sample in the first chunk: the attitude cannot be initialised (give q0)")
    return int(present[0])


class Estimator:
    """Base of the streaming fusion filters: subclasses set ``natural_frame`` and implement the kernel calls.

    Parameters
    ----------
    params : dataclass, optional
        The filter's parameter object; by default ``params_class()``.
    q0, frame
        As every filter takes them (:mod:`strapdown.fusion`).
    """

    natural_frame = "ENU"
    params_class: type | None = None  # the parameter dataclass: its defaults when no params are given
    estimates_bias = False
    reports_flags = False  # True: the Estimate carries per-sample flags
    # True: NaN rows of acc and mag mean "no sample" (sensors at different rates); such an estimator must take its
    # heading from the first field it gets, as 9D may start before the magnetometer's first sample
    missing_samples = False
    # the layout of ``state``: the shape of every entry (() for a number), and the entries that are attitudes
    _state_layout: tuple[tuple[str, tuple[int, ...]], ...] = (("q", (4,)),)
    _unit_keys: tuple[str, ...] = ("q",)
    _optional_keys: tuple[str, ...] = ()  # entries an older state may lack (the kernel call has a default)
    # True: _run returns (estimate, sums of squares of gyro, acc and mag over the chunk), formed by the kernel as it
    # reads the samples, and the samples are checked only if those are not within bounds (a pass over the input
    # less; a bad chunk's results are thrown away and the state put back, as for a diverging one)
    checks_in_kernel = False
    # True: the kernels take a constant interval as two entries, the first sample's and the rest's (sample k's
    # interval is dts[min(k, len(dts) - 1)]), instead of a per-sample array written and read only to repeat it
    compact_intervals = False
    # True: an update replaces the state's arrays and never writes into them, so what a failed chunk puts back
    # is the old dict's entries, not copies of them
    _replaces_state = False

    def __init__(self, params=None, *, q0=None, frame: str = "ENU"):
        self.params = self.params_class() if params is None else params
        self.frame = check_frame(frame, "frame", "reference")
        self._to_out = frame_quaternion(self.natural_frame, frame)
        self._to_in = self._to_out * np.array([1.0, -1.0, -1.0, -1.0])
        self._q0 = None if q0 is None else _v.quaternions(q0, "q0", dtype=np.float64).reshape(4)
        self._state: dict | None = None
        self._t_last: float | None = None
        self._use_mag: bool | None = None

    # ----------------------------------------------------------------------------------------------------
    @property
    def state(self) -> dict | None:
        """A copy of the internal state (arrays in the filter's own frame); assign one back to restore it."""
        if self._state is None:
            return None
        out = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self._state.items()}
        out["_t_last"] = self._t_last
        out["_use_mag"] = self._use_mag
        out["_kind"] = type(self).__name__
        return out

    @state.setter
    def state(self, value: dict) -> None:
        kind = type(self).__name__
        if not isinstance(value, dict) or value.get("_kind") != kind:
            raise ValueError(f"state must be a dict taken from the .state of a {kind}")
        value = dict(value)
        del value["_kind"]
        t_last = value.pop("_t_last", None)
        use_mag = value.pop("_use_mag", None)
        if t_last is not None and not (isinstance(t_last, Real) and np.isfinite(t_last)):
            raise ValueError(f"state['_t_last'] must be None or a finite time in seconds, got {t_last!r}")
        if not isinstance(use_mag, bool | np.bool_):
            raise ValueError(f"state['_use_mag'] must be True or False, got {use_mag!r}")
        # The kernels index these arrays without bounds checks: a short or mis-shaped array would make them read
        # or write outside it, so every entry is checked against the class's layout before it gets there.
        layout = {k: v for k, v in self._state_layout if k in value or k not in self._optional_keys}
        state = _checked_state(value, layout, self._unit_keys)
        self._t_last = None if t_last is None else float(t_last)
        self._use_mag = bool(use_mag)
        self._state = state

    @property
    def attitude(self) -> np.ndarray | None:
        """The current attitude estimate, sensor to ``frame``."""
        if self._state is None:
            return None
        return multiply(self._to_out, self._state["q"])

    def reset(self) -> None:
        """Forget everything; the next update initialises again."""
        self._state = None
        self._t_last = None
        self._use_mag = None

    # ----------------------------------------------------------------------------------------------------
    def _dts(self, n: int, dt, t) -> np.ndarray:
        if (dt is None) == (t is None):
            raise ValueError("give exactly one of dt (seconds per sample) and t (sample times in seconds)")
        if dt is not None:
            d = _v.finite(dt, "dt", dtype=np.float64)
            if d.ndim == 0:
                if not d > 0:
                    raise ValueError(f"dt must be positive, got {float(d)!r}")
                return np.full(min(n, 2) if self.compact_intervals else n, float(d))
            if d.shape != (n,):
                raise ValueError(f"dt must be a scalar or have one entry per sample ({n}), got shape {d.shape}")
            if not (d > 0).all():
                raise ValueError(f"dt{_v.first_index(~(d > 0))} is not positive")
            return np.ascontiguousarray(d)
        tt = _v.finite(t, "t", dtype=np.float64)
        if tt.shape != (n,):
            raise ValueError(f"t must have one time per sample ({n}), got shape {tt.shape}")
        prev = tt[0] if self._t_last is None else self._t_last
        d = np.diff(np.concatenate([[prev], tt]))
        bad = ~(d > 0)
        if self._t_last is None:
            bad[0] = False
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            before = prev if i == 0 else tt[i - 1]
            raise ValueError(f"t is not strictly increasing at sample {i}: {float(before)!r} -> {float(tt[i])!r}")
        if n:
            self._t_last = float(tt[-1])
        return d

    @renamed(gyr="gyro")
    def update(self, gyro, acc, mag=None, *, dt=None, t=None, **inputs) -> Estimate:
        """Process a chunk of samples; any chunking gives the same result.

        Parameters
        ----------
        gyro, acc, dt, t
            The samples and their timing (:mod:`strapdown.fusion`); ``t`` strictly increasing.
        mag : array_like, shape (N, 3), optional
            9D when given.  A filter started with (or without) magnetometer data must be fed the same way.
        **inputs
            Filter-specific inputs (see the subclass).

        Returns
        -------
        Estimate
            One attitude per sample, and the filter's extra outputs.
        """
        deferred = self.checks_in_kernel
        g, a, m, g_max = _triads(
            gyro, acc, mag, need_mag=bool(self._use_mag), missing=self.missing_samples, check=not deferred
        )
        # what a diverging chunk puts back (the kernels update the state arrays in place)
        kept = None
        if self._state is not None and self._replaces_state:
            kept = dict(self._state)
        elif self._state is not None:
            kept = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in self._state.items()}
        saved = (kept, self._t_last, self._use_mag)
        if self._use_mag is not None and m is not None and not self._use_mag:
            raise ValueError("this filter was started without magnetometer data (6D): do not give mag now")
        n = g.shape[0]
        dts = self._dts(n, dt, t)
        if not deferred:
            _check_steps(g, dts, g_max)
        extra_in = self._prepare_inputs(n, **inputs)
        if self._state is None:
            if n == 0:
                return float32_if(self._empty(), gyro, acc, mag)
            self._use_mag = m is not None
            if deferred:  # the rows the initialisation reads are checked first
                k = _first_present(a, "acc") + 1
                _, _, _, g_start = _triads(g[:k], a[:k], None, False, self.missing_samples)
                if m is not None:
                    _sensor(m[:1], "mag", self.missing_samples)
                _check_steps(g[:k], dts[:k], g_start)
            # the first accelerometer sample present, turned back to the sensor axes of the first row (which the
            # initial attitude is for): the initialisation and the subclasses' first state start from it
            ka = _first_present(a, "acc")
            self._acc0 = (ka, _back_to_first_sample(g, dts, ka, a[ka]))
            if self._q0 is None:
                q_init = self._initial(g, a, m, dts, extra_in)
                # the attitude from the first sample is the one at its end: its gyro reading has nothing left to do
                if dt is not None and np.ndim(dt):  # the caller's intervals, perhaps their own array
                    dts = dts.copy()
                dts[0] = 0.0
            else:
                q_init = multiply(self._to_in, self._q0)
            self._state = self._new_state(q_init / np.linalg.norm(q_init), g, a, m, dts, extra_in)
        out = self._run(g, a, m, dts, extra_in)
        if deferred:
            out, squares = out
            try:
                self._check_after(g, a, m, dts, squares)
            except ValueError:
                self._state, self._t_last, self._use_mag = saved
                raise
        if n and not np.isfinite(out.q[-1]).all():
            # NaN propagates along the filter's chain, so the last attitude shows whether any sample diverged
            k = int(np.flatnonzero(~np.isfinite(out.q).all(axis=-1))[0])
            self._state, self._t_last, self._use_mag = saved
            raise _v.SampleError(
                f"the filter diverged at sample {k} (gyro {g[k].tolist()}, acc {a[k].tolist()}); the state before this "
                "chunk is kept",
                k,
            )
        if out.q.size and self.frame != self.natural_frame:
            out.q = multiply(self._to_out, out.q, check=False)
        out.frame = self.frame
        return float32_if(out, gyro, acc, mag)

    def _check_after(self, g, a, m, dts, squares) -> None:
        """checks_in_kernel: raise as the checks before the kernel would have (the sums tell when to look)."""
        limit = (0.5 * MAX_SAMPLE) ** 2  # within it, every component is within MAX_SAMPLE; NaN fails the test
        if all(v <= limit for v in squares[: 2 if m is None else 3]):
            g_max = float(np.sqrt(squares[0]))
        else:  # a bad sample, or rows without a sample (NaN): the full checks find which
            _, _, _, g_max = _triads(g, a, m, bool(self._use_mag), self.missing_samples)
        _check_steps(g, dts, g_max)

    def _empty(self) -> Estimate:
        # the same fields as a non-empty result, so that callers need no special case for an empty chunk
        bias = np.zeros((0, 3)) if self.estimates_bias else None
        flags = np.zeros(0, dtype=np.uint8) if self.reports_flags else None
        return Estimate(q=np.zeros((0, 4)), frame=self.frame, bias=bias, flags=flags)

    # subclass hooks ------------------------------------------------------------------------------------
    def _prepare_inputs(self, n: int, **inputs) -> dict:
        if inputs:
            raise ValueError(f"unexpected inputs: {', '.join(inputs)}")
        return {}

    def _initial(self, gyro, acc, mag, dts, extra_in) -> np.ndarray:
        """Initial attitude in the natural frame from the first sample: tilt from acc, heading from mag.

        With missing samples allowed, the first accelerometer sample present is used, turned back by the gyro to
        the sensor axes of the first sample (which the attitude is for).  A first sample without a field (only
        possible then) starts from the tilt alone, whatever the chunk holds, so that any chunking starts alike:
        such an estimator takes its heading from the first field it gets.
        """
        a = self._acc0[1]
        m = None if mag is None or np.isnan(mag[0, 0]) else mag[0]
        return initial_attitude(a, m, self.natural_frame)

    def _new_state(self, q, gyro, acc, mag, dts, extra_in) -> dict:
        # the attitude alone: a filter with more state (bias, filters) extends this and its _state_layout
        return {"q": q.copy()}

    def _run(self, gyro, acc, mag, dts, extra_in) -> Estimate:
        raise NotImplementedError


# How far from unit norm a restored attitude may be: float32 storage and text round trips stay far inside it, a
# corrupted or hand-made quaternion does not.  The kernels assume unit attitudes (a norm of 10 grows to 1e205).
_UNIT_TOL = 1e-5


def _checked_state(value: dict, shapes: dict, unit_keys: tuple) -> dict:
    """A validated copy of a state dict, or ValueError naming the entry.

    Exactly the keys of ``shapes``, float64 arrays of those shapes, finite, and unit attitudes under ``unit_keys``
    (renormalised unless within rounding of 1).
    """
    missing = [k for k in shapes if k not in value]
    if missing:
        raise ValueError(f"state has no {', '.join(repr(k) for k in missing)}; take the state from .state")
    unknown = [k for k in value if k not in shapes]
    if unknown:
        raise ValueError(f"state has unknown entries {', '.join(repr(k) for k in unknown)}")
    out = {}
    for key, shape in shapes.items():
        name = f"state[{key!r}]"
        v = value[key]
        if v is None or isinstance(v, str | bytes | dict):
            raise ValueError(f"{name} must be {_shape_text(shape)}, got {type(v).__name__}")
        arr = _v.as_float_array(v, name, dtype=np.float64)
        if arr.shape != shape:
            raise ValueError(f"{name} must be {_shape_text(shape)}, got shape {arr.shape}")
        _v.check_finite(arr, name)
        if key in unit_keys:
            # scaled by a power of two first: no overflow for a corrupted 1e200
            _, e = np.frexp(np.max(np.abs(arr)))
            norm = float(np.ldexp(np.sqrt(np.sum(np.ldexp(arr, -e) ** 2)), e))
            if not abs(norm - 1.0) <= _UNIT_TOL:
                raise ValueError(f"{name} must be a unit quaternion, got norm {norm:.6g}")
            if abs(norm - 1.0) > 1e-12:  # beyond the rounding a kernel leaves: restore bit for bit otherwise
                arr = arr / norm
        out[key] = float(arr) if shape == () else arr.copy()
    return out


def _shape_text(shape: tuple) -> str:
    return "a number" if shape == () else f"an array of shape {shape}"


def nonnegative(params, names: tuple[str, ...], what: str) -> None:
    """Raise unless each named field of a parameter object is finite and ≥ 0 (``what``: "gain", ...)."""
    for name in names:
        v = getattr(params, name)
        if not (np.isfinite(v) and v >= 0):
            raise ValueError(f"{name} must be a non-negative {what}, got {v!r}")


_BATCH_DOC = """Run :class:`{cls}` over whole arrays: the batch form of the streaming filter.

Parameters
----------
gyro, acc, mag, dt, t
    The samples, as for ``update`` (:mod:`strapdown.fusion`).
params : {params}, optional
    The filter's parameters; their defaults when None.
q0, frame
    As for :class:`{cls}`.

Returns
-------
Estimate
    Attitudes, one per sample{outputs}.

Examples
--------
>>> import numpy as np
>>> from strapdown.fusion import {name}
>>> est = {name}(np.zeros((5, 3)), np.tile([0.0, 0.0, 9.81], (5, 1)), dt=0.01)
>>> est.q.shape
(5, 4)
"""


def batch_function(cls: type):
    """The batch function of a filter class that takes ``(params, q0=, frame=)`` and updates on arrays alone.

    ``mahony = batch_function(Mahony)`` runs ``Mahony(params, q0=q0, frame=frame).update(gyro, acc, mag, dt=dt,
    t=t)``, under the lower-case name of the class, documented (and doctested) in the class's module.
    """

    def run(gyro, acc, mag=None, *, dt=None, t=None, params=None, q0=None, frame: str = "ENU") -> Estimate:
        return cls(params, q0=q0, frame=frame).update(gyro, acc, mag, dt=dt, t=t)

    name = cls.__name__.lower()
    outputs = (", with the bias estimates" if cls.estimates_bias else "") + (
        ", and the accelerometer rejection flags" if cls.reports_flags else ""
    )
    run.__name__ = run.__qualname__ = name
    run.__module__ = cls.__module__
    run.__doc__ = _BATCH_DOC.format(cls=cls.__name__, params=cls.params_class.__name__, name=name, outputs=outputs)
    return renamed(gyr="gyro")(run)


def params_of(cls, params, owner: str):
    """A parameter object of ``cls`` from None (the defaults), an instance, or a mapping of overrides by name.

    ``owner`` names the estimator in messages.  The parameter classes check ranges; this checks names and that
    numbers are numbers, since text where a number belongs would otherwise fail deep inside a kernel.
    """
    if params is None:
        return cls()
    if isinstance(params, cls):
        return params
    if not isinstance(params, Mapping):
        raise ValueError(f"params must be a {cls.__name__} or a mapping of its fields, got {type(params).__name__}")
    known = [f.name for f in fields(cls)]
    unknown = [k for k in params if k not in known]
    if unknown:
        raise ValueError(
            f"{owner} has no parameter {', '.join(unknown)}; its parameters: {', '.join(known)} "
            f"(unknown {cls.__name__} field)"
        )
    defaults = cls()
    for name, value in params.items():
        if isinstance(getattr(defaults, name), Real) and not isinstance(value, Real):
            raise ValueError(f"{owner} parameter {name} must be a number, got {value!r}")
    return replace(defaults, **params)


def float32_if(est: Estimate, *inputs) -> Estimate:
    """``est`` with float32 arrays when every given input array is float32 (float32 in, float32 out)."""
    given = [x for x in inputs if x is not None]
    if not given or not all(isinstance(x, np.ndarray) and x.dtype == np.float32 for x in given):
        return est
    est.q = est.q.astype(np.float32)
    if est.bias is not None:
        est.bias = est.bias.astype(np.float32)
    est.extra = {
        k: (v.astype(np.float32) if isinstance(v, np.ndarray) and v.dtype == np.float64 else v)
        for k, v in est.extra.items()
    }
    return est
