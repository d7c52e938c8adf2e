"""What one does with attitudes that know their frames: inverse, composition, powers, means, changes of frame.

The operations of :class:`~strapdown.Attitude` (private: the class gathers them; its module notes say how
frames compose and which sign a result takes).  Every result is a new attitude of the same class, with the
frames the algebra gives it, and unit quaternions: where rounding would let the norm grow (products, powers,
means, changes of frame) the result is brought back to unit norm (``_unit_again``), so that ``r = r * p * r``
repeated, or ``x = x * x``, stays unit to rounding (|q| - 1 ≤ 4e-16) instead of drifting geometrically.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._support import validate as _v

_DEFAULT_ATOL = 1e-8  # rad: approx_equal's default, scipy's


def _unit_again(q: np.ndarray) -> np.ndarray:
    """Quaternions off unit norm by rounding only, brought back by one Newton step for 1/|q|, ``(3 - |q|²)/2``.

    The numpy twin of ``_quaternion_numba.unit_again`` (which says why this beats ``q / |q|``).
    """
    return q * ((3 - np.einsum("...i,...i->...", q, q)) / 2)[..., None]


def _compose(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """``p ⊗ q`` of two stored (valid, unit) quaternion arrays, broadcast, brought back to unit norm."""
    from ._quaternion_numba import multiply_unit_rows

    # the stored arrays are C-contiguous: flat views cost nothing; the common cases skip the general broadcast
    if p.shape == q.shape or q.ndim == 1:
        shape = p.shape
    elif p.ndim == 1:
        shape = q.shape
    else:
        shape = (*_v.broadcast(("a", p.shape[:-1]), ("b", q.shape[:-1])), 4)
    dtype = np.result_type(p, q)
    out = np.empty(shape, dtype=dtype)
    multiply_unit_rows(_flat(p, shape, dtype), _flat(q, shape, dtype), out.reshape(-1))
    return out


def _flat(a: np.ndarray, shape: tuple, dtype) -> np.ndarray:
    """The (4n,) components of ``a`` broadcast to ``shape``, or its 4 when it is one quaternion."""
    if a.dtype != dtype:
        a = a.astype(dtype)
    if a.shape != shape and a.size != 4:
        a = np.broadcast_to(a, shape)
    return np.ascontiguousarray(a).reshape(-1)


def _exponent(t) -> float:
    """The exponent of ``a ** t`` as one float: a number, or an array of one element (shape () or (1,))."""
    arr = np.asarray(t)
    if arr.dtype.kind not in "iuf" or arr.ndim > 1 or arr.size != 1:
        raise ValueError(
            f"a ** t takes one real exponent (a number, or an array of shape () or (1,)); got {t!r}. For one "
            "exponent per attitude use strapdown.from_rotvec(t[..., None] * a.as_rotvec())"
        )
    value = float(arr.reshape(()))
    if not np.isfinite(value):
        raise ValueError(f"a ** t needs a finite exponent, got {value}")
    return value


class AttitudeAlgebra:
    """The operations of :class:`~strapdown.Attitude` on its stored unit quaternions ``_q`` and frame names."""

    __slots__ = ()

    def inv(self) -> AttitudeAlgebra:
        """The inverse attitudes, reference to body: the frame names swap.

        Returns
        -------
        Attitude
            The conjugate quaternions, ``reference`` and ``body`` exchanged.
        """
        from .quaternion import conjugate

        return type(self)._wrap(conjugate(self._q, check=False), self._body, self._reference)

    def apply(self, vectors, inverse: bool = False) -> np.ndarray:
        """Body vectors into the reference frame (or back with ``inverse=True``): ``v_ref = q ⊗ v_body ⊗ q*``.

        Parameters
        ----------
        vectors : array_like, shape (..., 3)
            Vectors in ``body`` axes (``reference`` axes with ``inverse=True``), any units; leading axes
            broadcast against the attitudes' shape.
        inverse : bool
            Apply the inverse rotation, reference to body.

        Returns
        -------
        numpy.ndarray, shape (..., 3)
            The vectors in the other frame, same units.
        """
        from .quaternion import conjugate, rotate

        q = conjugate(self._q, check=False) if inverse else self._q
        # the attitudes were checked when the object was made: only the vectors need it
        return rotate(q, _v.vectors(vectors, "vectors"), check=False)

    def __mul__(self, other):
        if not isinstance(other, AttitudeAlgebra):
            return NotImplemented
        if self._body is not None and other._reference is not None and self._body != other._reference:
            raise ValueError(self._mismatch(other))
        return type(self)._wrap(_compose(self._q, other._q), self._reference, other._body)

    def _mismatch(self, other: AttitudeAlgebra) -> str:
        text = (
            f"cannot compose: a * b applies b first, which maps {other._body!r} to {other._reference!r}, but a "
            f"takes vectors from {self._body!r} (a maps {self._body!r} to {self._reference!r}); a's body axes must "
            "be b's reference frame."
        )
        from .frames import _axes

        try:
            kinds = (_axes(self._body, "body")[0], _axes(other._reference, "reference")[0])
        except ValueError:
            kinds = None
        if kinds and kinds[0] == kinds[1]:
            return text + (
                f" Re-express one of them: b.to_frame(reference={self._body!r}) or "
                f"a.to_frame(body={other._reference!r})."
            )
        if all(_known(name) for name in (self._reference, self._body, other._reference, other._body)):
            return text + (
                f" If both are attitudes of bodies, put b in a's frames first, "
                f"b.to_frame({self._reference!r}, {self._body!r}); the rotation from b's body to a's is a.inv() * b."
            )
        return text + " Check which frames each attitude maps (a.reference, a.body), or compose with a.inv()."

    def __pow__(self, t, modulus=None) -> AttitudeAlgebra:
        """Rotations by ``t`` times the angle (in [0, π], the shorter way) about the same axes, as scipy's.

        ``from_rotvec(t · as_rotvec(q))``, so q and -q give the same result, except for three exponents that are
        algebra rather than a scaled angle (scipy's rule): ``a ** 1`` is ``a``, ``a ** -1`` is ``a.inv()`` and
        ``a ** 0`` the identity, whatever the type of the number (``-1``, ``-1.0``, ``np.array([-1.0])``).

        ``t`` is one real number (or an array holding one); ``pow(a, t, m)`` raises ``NotImplementedError``.
        Only a rotation between axes of the same name (``reference == body``, e.g. the relative rotation
        ``a.inv() * b``) or with unnamed frames has powers other than ±1: half of a body-to-NED attitude maps
        between no named frames (for attitudes in between, use ``quaternion.slerp`` or
        :class:`strapdown.propagate.interpolate.RotationSpline`).
        """
        if modulus is not None:
            raise NotImplementedError("pow(a, t, modulus): a modulus has no meaning for rotations")
        t = _exponent(t)
        if t == 1:
            return self
        if t == -1:
            return self.inv()
        if self._reference is not None and self._body is not None and self._reference != self._body:
            raise ValueError(
                f"a ** t needs a rotation between axes of the same name; this one maps {self._body!r} to "
                f"{self._reference!r} (use a.inv() for the inverse, slerp or RotationSpline for attitudes in between)"
            )
        from .rotvec import as_rotvec, from_rotvec

        if t == 0:
            from .quaternion import identity

            return self._like(identity(self.shape, self.dtype))
        scaled = as_rotvec(self._q, check=False) * self.dtype.type(t)
        return self._like(_unit_again(from_rotvec(scaled, check=False)))

    def magnitude(self) -> np.ndarray:
        """Rotation angles of the attitudes, ``2 atan2(|v|, |w|)``.

        Returns
        -------
        numpy.ndarray, shape ``self.shape``
            Radians, in [0, π].
        """
        from .quaternion import _norm3

        return 2 * np.arctan2(_norm3(self._q[..., 1:]), np.abs(self._q[..., 0]))

    def approx_equal(self, other: AttitudeAlgebra, atol: float | None = None, degrees: bool = False) -> np.ndarray:
        """Whether the rotation angle between ``self`` and ``other`` is at most ``atol``.

        Parameters
        ----------
        other : Attitude
            Attitudes with the same frames (a ValueError otherwise); shapes broadcast.
        atol : float, optional
            Largest angle, radians (degrees with ``degrees=True``); default 1e-8 rad.
        degrees : bool
            ``atol`` in degrees.  Without ``atol`` it has nothing to apply to: a UserWarning says so and the
            default 1e-8 rad is used (as scipy does).

        Returns
        -------
        numpy.ndarray of bool
            One per attitude (q and -q count as equal).
        """
        from .quaternion import angle_between

        if not isinstance(other, AttitudeAlgebra):
            raise TypeError(f"other must be an Attitude, got {type(other).__name__}")
        self._same_frames(other, "approx_equal")
        _v.broadcast(("self", self.shape), ("other", other.shape))
        if atol is None:
            if degrees:
                warnings.warn(
                    f"approx_equal(degrees=True) without atol: the default atol is {_DEFAULT_ATOL:g} rad, so degrees "
                    "has no effect; give atol in degrees",
                    UserWarning,
                    stacklevel=2,
                )
            tol = _DEFAULT_ATOL
        else:
            tol = np.deg2rad(atol) if degrees else atol
        return angle_between(self._q, other._q, check=False) <= tol

    def _same_frames(self, other: AttitudeAlgebra, what: str) -> None:
        for mine, theirs, name in ((self._reference, other._reference, "reference"), (self._body, other._body, "body")):
            if mine is not None and theirs is not None and mine != theirs:
                raise ValueError(
                    f"{what}: the {name} frames differ ({mine!r} and {theirs!r}); re-express one with .to_frame"
                )

    def mean(self, weights=None, axis=None) -> AttitudeAlgebra:
        """Weighted chordal L2 mean (Markley et al. 2007; :func:`strapdown.rotations.average.mean`), frames kept.

        Parameters
        ----------
        weights : array_like, optional
            Non-negative weights, broadcast against the attitudes; equal by default.
        axis : int or tuple of int, optional
            Axes of ``self.shape`` to average over (``-1`` is the last of them); all by default.

        Returns
        -------
        Attitude
            The mean attitude(s), unit quaternions with w ≥ 0.
        """
        from .average import mean

        if axis is not None:
            # numbered in the Attitude's shape; average.mean numbers them in q's, whose last axis holds w, x, y, z
            axes = (axis,) if isinstance(axis, int | np.integer) else axis
            if not isinstance(axes, tuple) or not all(
                isinstance(ax, int | np.integer) and not isinstance(ax, bool) for ax in axes
            ):
                raise ValueError(f"axis must be None, an int or a tuple of ints; got {axis!r}")
            nd = len(self.shape)
            for ax in axes:
                if not -nd <= ax < nd:
                    raise ValueError(f"axis {ax} is out of range for an Attitude of shape {self.shape}")
            axis = tuple(sorted({int(ax) % nd for ax in axes}))  # a set of axes, as scipy's (numpy refuses repeats)
        return self._like(_unit_again(mean(self._q, weights=weights, axis=axis)))

    def reduce(self, left=None, right=None, return_indices: bool = False):
        """The attitudes of smallest angle ``l * a * r`` over ``l`` in ``left`` and ``r`` in ``right`` (scipy's).

        When ``left`` and ``right`` are the symmetry groups of two objects (:meth:`create_group`) whose relative
        attitude is ``a``, the reduced attitude is the smallest rotation that turns one onto the other.

        Parameters
        ----------
        left, right : Attitude, optional
            One or a 1-D stack of attitudes each; None (default) stands for the identity.  Frames as for
            ``left * a * right``.
        return_indices : bool
            Also return the indices of the chosen ``l`` and ``r`` (None for a side not given).

        Returns
        -------
        reduced : Attitude
            The shape of ``self``: ``left[i] * self * right[j]`` with ``|w|`` largest (the angle least).
        left_index, right_index : numpy.ndarray of int, shape ``self.shape``
            Only with ``return_indices=True``.
        """
        from .groups import reduce

        for value, name in ((left, "left"), (right, "right")):
            if value is not None and not isinstance(value, AttitudeAlgebra):
                raise TypeError(f"{name} must be an Attitude or None, got {type(value).__name__}")
        _, i, j = reduce(self._q, None if left is None else left._q, None if right is None else right._q, check=False)
        out = self
        if left is not None:
            out = left[i] if not left.single else left
            out = out * self
        if right is not None:
            out = out * (right[j] if not right.single else right)
        return (out, i, j) if return_indices else out

    def to_frame(self, reference: str | None = None, body: str | None = None) -> AttitudeAlgebra:
        """The same physical attitudes expressed in other axes (:func:`strapdown.change_frame`).

        Parameters
        ----------
        reference, body : str, optional
            New reference frame and/or body axes, named by axis letters (``"ENU"``, ``"FLU"``, ...); None
            keeps that side.  The current names must be letter names too.

        Returns
        -------
        Attitude
            The same rotations of the physical body, with the new names (``self`` when nothing changes).

        Examples
        --------
        >>> from strapdown import Attitude
        >>> a = Attitude.identity(reference="NED", body="FRD")
        >>> b = a.to_frame("ENU", "FLU")          # nose north: 90° about ENU's up
        >>> b.reference, b.body, b.as_quat(canonical=True).round(6)
        ('ENU', 'FLU', array([0.707107, 0.      , 0.      , 0.707107]))
        """
        from .frames import change_frame

        options = {}
        for new, old, side in ((reference, self._reference, "ref"), (body, self._body, "body")):
            if new is None or new == old:
                continue
            if old is None:
                what = "reference frame" if side == "ref" else "body axes"
                raise ValueError(f"this attitude's {what} has no name, so it cannot be re-expressed in {new!r}")
            options[f"{side}_from"] = old
            options[f"{side}_to"] = new
        if not options:
            return self
        q = _unit_again(change_frame(self._q, check=False, **options))
        return type(self)._wrap(
            q, self._reference if reference is None else reference, self._body if body is None else body
        )


def _known(name) -> bool:
    """Whether a frame name is made of axis letters that :mod:`strapdown.rotations.frames` can convert."""
    from .frames import _axes

    try:
        _axes(name, "frame")
    except ValueError:
        return False
    return True
