"""A C² rotation spline with angular rate and acceleration: :class:`RotationSpline` (exported by interpolate).

On segment k, between the samples at t_k and t_{k+1} (h_k = t_{k+1} - t_k), the attitude is
``q(t) = q_k ⊗ exp(r(t)/2)`` with r a cubic in ``s = t - t_k``, r(0) = 0 and r(h_k) = ``r_k``, the rotation vector
of ``q_k* ⊗ q_{k+1}`` (the shorter way, |r_k| ≤ π).  The two remaining coefficients of each cubic come from the
body rates at the knots, which are chosen so that the angular rate and the angular acceleration are continuous:
the rotation-vector spline of scipy's ``RotationSpline`` (whose reference is the note "Smooth attitude
interpolation", https://github.com/scipy/scipy/files/2932755/attitude_interpolation.pdf), with its end
conditions: the rate at the first and at the last sample is that segment's mean rate ``r/h``.

Direction of time.  Each cubic is anchored at its segment's first sample, so the spline through the same samples
played backwards is not exactly the same curve (scipy's neither): the two differ by a term of third order in the
rotation between samples (about 1e-7 rad for steps of 0.01 rad, 1e-4 rad for 0.1 rad; tests/propagate/test_spline.py).

Frames.  r is a body-frame increment (the attitude is updated on the right, strapdown's convention), so the
rates that fall out of it are body rates, ``ω = J(r) ṙ``, the gyro's.  scipy's rates are the same body-frame
rates (its ``Rotation`` composes ``R_k * exp(r)``), in scipy's scalar-last quaternion layout on the way in; here
quaternions are scalar first, ``[w, x, y, z]``.  ``rate_frame="reference"`` rotates rate and acceleration into
the reference frame: ``ω_ref = R ω_body`` and, because ``d(R ω_b)/dt = R (ω̇_b + ω_b × ω_b)``, ``ω̇_ref = R ω̇_b``.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v

__all__ = ["RotationSpline"]

_FRAMES = ("body", "reference")


class RotationSpline:
    """Interpolate attitudes with continuous angular rate and angular acceleration (C²), like scipy's.

    Parameters
    ----------
    t : array_like, shape (n,)
        Strictly increasing sample times, n ≥ 2 (any unit; rates come out per that unit).
    q : array_like, shape (n, ..., 4)
        Non-zero attitude quaternions at those times, scalar first, body to reference (normalised, and made
        continuous in sign, first); several series sampled at the same times interpolate at once, as in
        :mod:`strapdown.propagate.interpolate`.
    extrapolate : bool
        False (default): calling the spline outside ``[t[0], t[-1]]`` raises a ValueError.  True: continue
        the first and last cubic beyond the ends, as scipy's ``RotationSpline`` does (a cubic runs away fast:
        use it only a fraction of a sample interval beyond).
    max_iter, tol : int, float
        The knot rates solve a block-tridiagonal system that is nonlinear in the rates; it is iterated until no
        rate moves by more than ``tol (1 + |ω|)`` (default 1e-14, near rounding; scipy's default is 1e-9 with at
        most 10 steps), at most ``max_iter`` times.  :attr:`iterations` reports what it took: a few for smooth
        motion sampled densely, up to about a hundred for increments of a radian or more between samples.  A
        RuntimeWarning says when ``max_iter`` was not enough.
    check : bool
        Reject NaN, infinities, zero quaternions and non-increasing times (default).

    Attributes
    ----------
    t : numpy.ndarray, shape (n,)
        The knots (float64).
    q : numpy.ndarray, shape (n, ..., 4)
        The unit, sign-continuous attitudes at the knots (float64).
    rates : numpy.ndarray, shape (n, ..., 3)
        Body rates at the knots (float64, per unit of t).
    iterations : int
        Fixed-point iterations the knot rates took.

    Notes
    -----
    See the module notes of ``strapdown.propagate.spline`` for the construction and the frames, and
    ``_spline_numba.knot_rates`` for the equations.  Results keep float32 as float32; computations are in
    float64.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_rotvec
    >>> from strapdown.propagate.interpolate import RotationSpline
    >>> t = np.array([0.0, 1.0, 2.0, 3.0])
    >>> spline = RotationSpline(t, from_rotvec(np.outer(t, [0.0, 0.0, 0.5])))   # 0.5 rad/s about z
    >>> spline([0.5, 2.5], 1).round(12)                       # body rate
    array([[0. , 0. , 0.5],
           [0. , 0. , 0.5]])
    >>> spline(1.5).round(8)                                  # 0.75 rad about z
    array([0.93050762, 0.        , 0.        , 0.36627253])
    """

    def __init__(
        self, t, q, *, extrapolate: bool = False, max_iter: int = 1000, tol: float = 1e-14, check: bool = True
    ):
        from ._series import attitude_series

        tv = _v.finite(t, "t", check=check, dtype=np.float64)
        qv = _v.quaternions(q, "q", check=check)
        tv, q1, _, dtype = attitude_series(tv, qv, tv[:1], check)
        from ..rotations.quaternion import conjugate, multiply
        from ..rotations.rotvec import as_rotvec

        n = tv.shape[0]
        self._series_shape = q1.shape[1:-1]
        # one row of knots per series: (S, n, 4)
        rows = np.ascontiguousarray(np.moveaxis(q1.reshape(n, -1, 4), 1, 0))
        h = np.diff(tv)
        r = np.ascontiguousarray(
            as_rotvec(multiply(conjugate(rows[:, :-1], check=False), rows[:, 1:], check=False), check=False)
        )
        w = np.empty((rows.shape[0], n, 3))
        w[:, :-1] = r / h[:, None]  # the first guess, and the end conditions: the end segments' mean rates
        w[:, -1] = w[:, -2]
        self.iterations = 0
        if n > 2:
            from ._spline_numba import knot_rates

            for k in range(rows.shape[0]):
                self.iterations = max(self.iterations, int(knot_rates(r[k], h, w[k], int(max_iter), float(tol))))
            if self.iterations >= max_iter:
                import warnings

                warnings.warn(
                    f"RotationSpline: the knot rates did not settle to tol={tol:g} in max_iter={max_iter} "
                    "iterations; the spline is still C¹ but its acceleration may jump at the knots",
                    RuntimeWarning,
                    stacklevel=2,
                )
        # Hermite cubic of each segment from r_k, the start rate ω_k (= ṙ(0), as J(0) = I) and ṙ(h) = J⁻¹(r_k) ω_{k+1}
        from ._spline_numba import rotvec_dot_rows

        rdot_end = np.empty_like(r)
        rotvec_dot_rows(r.reshape(-1, 3), np.ascontiguousarray(w[:, 1:]).reshape(-1, 3), rdot_end.reshape(-1, 3))
        hh = h[:, None]
        coef = np.empty((*r.shape[:2], 3, 3))
        coef[..., 0, :] = (-2 * r + hh * w[:, :-1] + hh * rdot_end) / hh**3
        coef[..., 1, :] = (3 * r - 2 * hh * w[:, :-1] - hh * rdot_end) / hh**2
        coef[..., 2, :] = w[:, :-1]
        self.t = tv
        self.q = q1
        self.rates = np.moveaxis(w, 0, 1).reshape((n, *self._series_shape, 3))
        self.extrapolate = bool(extrapolate)
        self._rows = rows
        self._coef = coef
        self._dtype = dtype

    def __len__(self) -> int:
        return self.t.shape[0]

    def __repr__(self) -> str:
        return f"RotationSpline({len(self)} knots, t = {self.t[0]:g} .. {self.t[-1]:g})"

    def __call__(self, t, order: int = 0, *, rate_frame: str = "body", check: bool = True) -> np.ndarray:
        """Attitude, angular rate or angular acceleration at times ``t``.

        Parameters
        ----------
        t : array_like, any shape
            Times, inside ``[t[0], t[-1]]`` unless the spline was made with ``extrapolate=True``.
        order : {0, 1, 2}
            0: unit attitude quaternions (..., 4); 1: angular rate (..., 3), rad per time unit; 2: angular
            acceleration (..., 3), rad per time unit squared.
        rate_frame : {"body", "reference"}
            Frame of the rate and acceleration: body axes (the gyro's, and scipy's), or the reference frame.
        check : bool
            Reject NaN, infinities and times outside the knots (default).

        Returns
        -------
        numpy.ndarray, shape ``t.shape + q.shape[1:-1] + (4,)`` or ``(3,)``
            In the dtype of the spline's input quaternions.
        """
        if order not in (0, 1, 2) or isinstance(order, bool):
            raise ValueError(f"order must be 0 (attitude), 1 (angular rate) or 2 (angular acceleration); got {order!r}")
        _v.choice(rate_frame, "rate_frame", _FRAMES)
        tn = _v.finite(t, "t", check=check, dtype=np.float64)
        if check and not self.extrapolate:
            outside = (tn < self.t[0]) | (tn > self.t[-1])
            if outside.any():
                raise ValueError(
                    f"t{_v.first_index(outside)} = {float(tn[outside].flat[0])!r} is outside the knots "
                    f"[{self.t[0]!r}, {self.t[-1]!r}]; the spline does not extrapolate unless made with "
                    "extrapolate=True"
                )
        flat = np.ascontiguousarray(tn.reshape(-1))
        index = np.clip(np.searchsorted(self.t, flat, side="right") - 1, 0, self.t.shape[0] - 2)
        s = flat - self.t[index]
        series = self._rows.shape[0]
        out = np.empty((flat.shape[0], series, 4 if order == 0 else 3))
        from ._spline_numba import evaluate

        for k in range(series):
            evaluate(self._coef[k], self._rows[k], index, s, order, out[:, k])
        if order and rate_frame == "reference":
            from ..rotations.quaternion import rotate

            attitude = np.empty((flat.shape[0], series, 4))
            for k in range(series):
                evaluate(self._coef[k], self._rows[k], index, s, 0, attitude[:, k])
            out = rotate(attitude, out, check=False)
        return out.reshape((*tn.shape, *self._series_shape, out.shape[-1])).astype(self._dtype, copy=False)
