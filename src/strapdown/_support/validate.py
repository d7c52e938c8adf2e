"""Input checks shared by every public function (private).

Validation happens once, in numpy, before any kernel runs; the kernels assume clean input.  Every error names
the argument, says what is wrong and, for arrays of many rotations, the index of the first offending row.
"""

from __future__ import annotations

import numpy as np


class SampleError(ValueError):
    """A ValueError about one sample of a chunk.

    ``sample`` is its index in the chunk; callers that read files turn it into a file line.
    """

    def __init__(self, message: str, sample: int):
        super().__init__(message)
        self.sample = sample


def float_dtype(x: np.ndarray) -> np.dtype:
    """The floating dtype a result takes: float32 stays float32, float64 stays float64, the rest widen."""
    if x.dtype == np.float32 or x.dtype == np.float64:
        return x.dtype
    if x.dtype == np.float16:
        return np.dtype(np.float32)
    return np.dtype(np.float64)


def first_index(mask: np.ndarray) -> str:
    """Human-readable index of the first True element of `mask` (over leading axes)."""
    flat = int(np.flatnonzero(mask)[0])
    if mask.ndim == 0:
        return ""
    idx = np.unravel_index(flat, mask.shape)
    return "[" + ", ".join(str(int(i)) for i in idx) + "]"


def as_float_array(x, name: str, *, dtype=None) -> np.ndarray:
    """Convert `x` to a real floating array, rejecting complex, string and object input by name."""
    try:
        arr = np.asarray(x)
    except Exception as exc:  # ragged lists and the like
        raise ValueError(f"{name} could not be converted to a numeric array: {exc}") from None
    if arr.dtype.kind == "c":
        raise ValueError(f"{name} must be real, got a complex array")
    if arr.dtype.kind not in "fiub":
        try:
            arr = arr.astype(np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be numeric, got dtype {arr.dtype}") from None
    target = np.dtype(dtype) if dtype is not None else float_dtype(arr)
    return arr.astype(target, copy=False)


def check_last_axis(arr: np.ndarray, name: str, size: int, what: str) -> None:
    """Raise unless `arr` has shape (..., size)."""
    if arr.ndim == 0 or arr.shape[-1] != size:
        raise ValueError(f"{name} must have shape (..., {size}) ({what}), got shape {arr.shape}")


def all_finite(arr: np.ndarray) -> bool:
    """Whether every element is finite, in the usual case by one sum.

    A NaN or an infinity makes the sum non-finite; only a finite sum that overflows goes on to the exact
    elementwise test.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        total = np.add.reduce(arr.reshape(-1)) if arr.size else 0.0
    return bool(np.isfinite(total)) or bool(np.isfinite(arr).all())


def check_finite(arr: np.ndarray, name: str) -> None:
    """Raise if `arr` holds a NaN or an infinity, naming the first offending element."""
    if not all_finite(arr):
        bad = ~np.isfinite(arr)
        first = arr[bad][0]
        kind = "NaN" if np.isnan(first) else "infinite"
        raise ValueError(f"{name}{first_index(bad)} is {kind}; {name} must hold finite numbers")


def quaternions(q, name: str = "q", *, check: bool = True, nonzero: bool = True, dtype=None) -> np.ndarray:
    """Validate an array of quaternions of shape (..., 4), scalar first.

    Parameters
    ----------
    q : array_like
        Quaternions.
    name : str
        Argument name used in error messages.
    check : bool
        When False only the dtype and shape are fixed up (the fast path for hot code).
    nonzero : bool
        Require a usable norm: ``|q|²`` must be a positive normal number of the dtype (all functions that
        stand for a rotation or divide by the norm).  A zero quaternion, and one so small or so large that its
        squared norm underflows or overflows, is rejected rather than turned into NaN or zeros downstream.
    dtype : dtype, optional
        Force this floating dtype.

    Returns
    -------
    numpy.ndarray
        Floating array of shape (..., 4).
    """
    arr = as_float_array(q, name, dtype=dtype)
    check_last_axis(arr, name, 4, "quaternions [w, x, y, z]")
    if not check:
        return arr
    tiny = np.finfo(arr.dtype).tiny
    # One pass in the common case: the squared norm is finite and not below the smallest normal number.
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        n2 = np.einsum("...i,...i->...", arr, arr)
    if np.isfinite(n2).all() and (not nonzero or (n2 >= tiny).all()):
        return arr
    check_finite(arr, name)
    if nonzero:
        zero = ~np.any(arr != 0, axis=-1)
        if zero.any():
            raise ValueError(
                f"{name}{first_index(zero)} is a zero quaternion; a rotation quaternion must have a non-zero norm"
            )
        bad = ~(n2 >= tiny) | ~np.isfinite(n2)
        if bad.any():
            size = "small" if np.isfinite(n2[bad][0]) else "large"
            raise ValueError(
                f"{name}{first_index(bad)} has a norm too {size} to use in {arr.dtype} arithmetic "
                f"(|{name}|² {'underflows' if size == 'small' else 'overflows'}); scale it towards 1 first"
            )
    return arr


def rotations(q, name: str = "q", *, check: bool = True, dtype=None) -> np.ndarray:
    """Validate quaternions that stand for rotations only (their norm does not matter): any finite, non-zero q.

    A row whose largest component is so large or small that products of two or three components would
    overflow or underflow (beyond 2^±(maxexp/4): 1e±77 in float64, 4e9 and 2e-10 in float32) is scaled by a
    power of two, which is exact and leaves the rotation unchanged; other rows are returned bit for bit.  So
    ``q * 1e200`` and ``q * 5e-324`` give the results of ``q``.
    """
    arr = as_float_array(q, name, dtype=dtype)
    check_last_axis(arr, name, 4, "quaternions [w, x, y, z]")
    if not check:
        return arr
    limit = np.finfo(arr.dtype).maxexp // 4
    # The usual case in one fast pass: each row's sum of squares s lies between big² and 4 big² (big its largest
    # |component|), so 4·2^(-2 limit) <= s <= 2^(2 limit) proves every row safe; NaN fails the comparisons, and
    # an overflow or underflow of s only sends the array to the exact test below.  (A maximum over the axis of
    # length 4 costs eight times as much as the einsum and was most of a conversion's time.)
    if arr.size:
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            s = np.einsum("...i,...i->...", arr, arr)
            if s.min() >= np.ldexp(4.0, -2 * limit) and s.max() <= np.ldexp(1.0, 2 * limit):
                return arr
    big = np.max(np.abs(arr), axis=-1)
    safe = (big >= np.ldexp(1.0, -limit)) & (big <= np.ldexp(1.0, limit))  # False for NaN too
    if safe.all():
        return arr
    check_finite(arr, name)
    nonzero_rows(arr, name, "a rotation quaternion must have a non-zero norm")
    _, exponent = np.frexp(big)
    exponent = np.where(safe, 0, exponent).astype(np.int32)
    return np.ldexp(arr, -exponent[..., None]).astype(arr.dtype, copy=False)


def nonzero_rows(arr: np.ndarray, name: str, why: str = "it has no sign to choose") -> None:
    """Raise if a row of (..., 4) is all zeros (for rules that need no norm, such as the sign choice)."""
    zero = ~np.any(arr != 0, axis=-1)
    if zero.any():
        raise ValueError(f"{name}{first_index(zero)} is a zero quaternion; {why}")


def vectors(v, name: str, *, check: bool = True, dtype=None) -> np.ndarray:
    """Validate an array of 3-vectors of shape (..., 3)."""
    arr = as_float_array(v, name, dtype=dtype)
    check_last_axis(arr, name, 3, "3-vectors")
    if check:
        check_finite(arr, name)
    return arr


def finite(x, name: str, *, check: bool = True, dtype=None) -> np.ndarray:
    """Validate an array of any shape holding finite real numbers."""
    arr = as_float_array(x, name, dtype=dtype)
    if check:
        check_finite(arr, name)
    return arr


def choice(value: str, name: str, options: tuple[str, ...]) -> str:
    """Raise unless `value` is one of `options`."""
    if value not in options:
        raise ValueError(f"{name} must be one of {', '.join(repr(o) for o in options)}; got {value!r}")
    return value


def result_dtype(*arrays: np.ndarray) -> np.dtype:
    """Common floating dtype of several validated arrays (float32 only if all are float32)."""
    return np.result_type(*arrays, np.float32)


def weak(x) -> bool:
    """True for a Python int or float: as in NumPy 2, such a scalar takes the dtype of the arrays beside it."""
    return isinstance(x, int | float) and not isinstance(x, bool)


def broadcast(*named: tuple[str, tuple]) -> tuple:
    """Broadcast of the leading shapes of named arguments; ValueError naming the two that do not fit."""
    try:
        return np.broadcast_shapes(*(shape for _, shape in named))
    except ValueError:
        for i, (a, sa) in enumerate(named):
            for b, sb in named[i + 1 :]:
                try:
                    np.broadcast_shapes(sa, sb)
                except ValueError:
                    raise ValueError(
                        f"{a} and {b} do not broadcast: leading shapes {sa} and {sb} (one of them must be 1 or "
                        "absent on every axis where they differ)"
                    ) from None
        raise ValueError(f"the shapes of {', '.join(n for n, _ in named)} do not broadcast together") from None


def promote(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """Cast validated arrays to their common floating dtype (float32 only if all are float32)."""
    dtype = result_dtype(*arrays)
    return tuple(a.astype(dtype, copy=False) for a in arrays)
