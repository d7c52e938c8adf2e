"""An immutable batch of attitudes that knows its frames: :class:`Attitude`.

strapdown's functions work on plain (..., 4) arrays; :class:`Attitude` is a thin layer over them for users who
think in objects (and for scipy users: the ``from_*`` / ``as_*`` names, indexing, ``len``, iteration,
``concatenate``, ``inv``, ``apply``, ``*``, ``mean``, ``magnitude``, ``approx_equal``, ``random`` and pickling of
``scipy.spatial.transform.Rotation``).  What scipy's object does not carry, this one does: the names of the two
frames an attitude connects.

Frames and composition
----------------------
An attitude maps vectors from its **body** axes to its **reference** frame, ``v_ref = a.apply(v_body)``
(strapdown's convention; ``reference="NED", body="FRD"`` is the aviation one).  Frame names are any strings;
names made of three axis letters (``"NED"``, ``"ENU"``, ``"NWU"``; ``"FRD"``, ``"FLU"``, ``"RFU"``: see
:mod:`strapdown.rotations.frames`) can also be converted into each other with :meth:`Attitude.to_frame`.  ``None`` (the
default) means "not named" and is never checked.

``a * b`` is "apply b, then a" (the Hamilton product ``a.q ⊗ b.q``, as scipy's ``a * b``): b takes vectors from
b's body axes into b's reference frame, and a must take vectors *from that frame*.  So a's body axes must be
b's reference frame, and the product maps b's body to a's reference::

    (ref_a ← body_a) * (ref_b ← body_b)  requires  body_a == ref_b,  and gives  (ref_a ← body_b)

Typical chains: a vehicle attitude times a sensor mounting, ``(NED ← FRD) * (FRD ← "imu") = (NED ← "imu")``.
The rotation from one body to another, both in the same reference frame, is ``a.inv() * b`` =
``(FRD ← NED) * (NED ← FRD)``: the result maps b's body axes into a's body axes (both named ``"FRD"``; the names
say which axes, not which vehicle).  Composing attitudes whose frames do not meet raises a ``ValueError`` that
names both and says how to re-express one, e.g. ``b.to_frame("NED", "FRD")`` for a b given in ENU/FLU.

``inv()`` swaps the names.  ``mean``, ``approx_equal`` and ``concatenate`` need the same frames throughout.

Storage: ``a.q`` is the (..., 4) array itself, scalar first, read-only and never copied; the constructors that
take user data (:meth:`from_quat`, the constructor) copy and normalise it, as scipy does.  Every operation that
makes a new attitude returns unit quaternions: products, powers, means and changes of frame are brought back to
unit norm, so that long chains (``r = r * p * r``, ``x = x * x``) do not drift off it.

Sign
----
q and -q are one attitude; which of the two an Attitude holds follows one rule, scipy's:

* what names a quaternion keeps its sign: the user's quaternions (the constructor, :meth:`from_quat`), the
  algebra (``a * b`` is the Hamilton product, :meth:`inv` the conjugate, ``a ** 1`` is a, ``a ** -1`` is
  ``a.inv()``, :meth:`reduce` a product, :meth:`to_frame` a product with the frames' quaternions) and the
  parametrisations that name one quaternion (rotation vectors and powers through the exponential map
  ``exp(θ/2)``, MRPs, Gibbs vectors, Euler and Davenport angles as products of elementary turns);
* what knows only the rotation gives ``w ≥ 0`` (:func:`~strapdown.rotations.quaternion.canonical`):
  matrices, :meth:`align_vectors`, :meth:`mean`, :meth:`random`, :meth:`create_group` and the identity.

``as_quat(canonical=True)`` gives ``w ≥ 0`` for any of them.
"""

from __future__ import annotations

import numpy as np

from .._support import validate as _v
from ._attitude_algebra import AttitudeAlgebra

__all__ = ["Attitude"]


def _name(value, what: str):
    if value is None:
        return None
    if not isinstance(value, str) or not value:
        raise ValueError(f"{what} must be a frame name such as 'NED' or 'FRD', or None; got {value!r}")
    return value


def _generator(rng):
    """A numpy Generator, or a legacy RandomState (scipy's ``random_state``) used as it is."""
    return rng if isinstance(rng, np.random.Generator | np.random.RandomState) else np.random.default_rng(rng)


def _lead_shape(num, shape) -> tuple:
    """The leading shape of ``identity`` and ``random`` from scipy's ``num`` or ``shape`` (an int or a tuple)."""
    if num is not None and shape is not None:
        raise ValueError(f"give num or shape, not both (num={num!r}, shape={shape!r})")
    value = num if shape is None else shape
    if value is None:
        return ()
    items = value if isinstance(value, tuple) else (value,)
    if not all(isinstance(n, int | np.integer) and not isinstance(n, bool) and n >= 0 for n in items):
        what = "num" if shape is None else "shape"
        raise ValueError(f"{what} must be a non-negative int or a tuple of them; got {value!r}")
    return tuple(int(n) for n in items)


class Attitude(AttitudeAlgebra):
    """Attitudes (body to reference) of any leading shape, with the names of both frames.

    Parameters
    ----------
    q : array_like, shape (..., 4)
        Non-zero quaternions, scalar first ``[w, x, y, z]`` (strapdown's layout; for scipy's scalar-last layout
        use ``Attitude.from_quat(q, scalar_first=False)``).  They are copied and normalised.
    reference, body : str, optional
        Names of the reference frame and of the body axes (module notes).
    check : bool
        Reject NaN, infinities and zero quaternions (default).

    Examples
    --------
    >>> from strapdown import Attitude
    >>> a = Attitude.from_euler([90.0, 0.0, 0.0], "ZYX", degrees=True, reference="NED", body="FRD")
    >>> a
    Attitude([0.707107, 0, 0, 0.707107], reference='NED', body='FRD')
    >>> a.apply([1.0, 0.0, 0.0]).round(12)        # the nose points east
    array([0., 1., 0.])
    >>> a.to_frame("ENU", "FLU").as_euler("ZYX", degrees=True).round(9) + 0.0   # east is ENU's zero heading
    array([0., 0., 0.])
    """

    __slots__ = ("_body", "_q", "_reference")

    def __init__(self, q, reference: str | None = None, body: str | None = None, *, check: bool = True):
        from .quaternion import normalize

        arr = normalize(_v.quaternions(q, "q", check=check), check=False)
        self._set(arr, _name(reference, "reference"), _name(body, "body"))

    def _set(self, q: np.ndarray, reference, body) -> None:
        view = q.view()
        view.flags.writeable = False
        object.__setattr__(self, "_q", view)
        object.__setattr__(self, "_reference", reference)
        object.__setattr__(self, "_body", body)

    @classmethod
    def _wrap(cls, q: np.ndarray, reference, body) -> Attitude:
        """An Attitude around a fresh unit-quaternion array, without checks or copies."""
        out = cls.__new__(cls)
        out._set(q, reference, body)
        return out

    def _like(self, q: np.ndarray) -> Attitude:
        return Attitude._wrap(q, self._reference, self._body)

    def __setattr__(self, name, value):
        raise AttributeError("Attitude is immutable; make a new one (e.g. with to_frame or Attitude(q, ...))")

    def __reduce__(self):
        return (Attitude._wrap, (np.array(self._q), self._reference, self._body))

    # ------------------------------------------------------------------------------------------------ data
    @property
    def q(self) -> np.ndarray:
        """The unit quaternions (..., 4), scalar first: the stored array itself (read-only, no copy)."""
        return self._q

    @property
    def reference(self) -> str | None:
        """Name of the reference frame (where :meth:`apply` puts vectors), or None."""
        return self._reference

    @property
    def body(self) -> str | None:
        """Name of the body axes (where :meth:`apply` takes vectors from), or None."""
        return self._body

    @property
    def shape(self) -> tuple:
        """Leading shape: ``()`` for a single attitude."""
        return self._q.shape[:-1]

    @property
    def single(self) -> bool:
        """True for one attitude (shape ``()``), as scipy's ``Rotation.single``."""
        return self._q.ndim == 1

    @property
    def dtype(self) -> np.dtype:
        """float32 or float64."""
        return self._q.dtype

    def __len__(self) -> int:
        if self.single:
            raise TypeError("a single Attitude has no len(); it has shape ()")
        return self._q.shape[0]

    def __bool__(self) -> bool:
        """Always True, also for a single attitude or an empty stack (as scipy's Rotation)."""
        return True

    def __iter__(self):
        if self.single:
            raise TypeError("a single Attitude is not iterable")
        return (self._like(row) for row in self._q)

    def __getitem__(self, index) -> Attitude:
        if self.single:
            raise TypeError("a single Attitude is not subscriptable")
        # index the leading axes only: a zero-stride placeholder of the leading shape raises numpy's IndexError
        # for too many indices instead of letting one fall on the quaternion components
        np.broadcast_to(np.empty((), dtype=bool), self.shape)[index]
        key = index if isinstance(index, tuple) else (index,)
        return self._like(self._q[(*key, slice(None))])

    def __repr__(self) -> str:
        frames = f"reference={self._reference!r}, body={self._body!r}"
        if self.single:
            parts = ", ".join(f"{float(c):.6g}" for c in self._q)
            return f"Attitude([{parts}], {frames})"
        return f"Attitude(shape={self.shape}, {frames}, dtype={self.dtype})"

    # Conversion to an array gives the quaternions (no copy), so every strapdown function takes an Attitude where
    # it takes q; arithmetic through numpy is refused, so ``2.0 * a`` cannot quietly scale quaternion components.
    __array_ufunc__ = None

    def __array__(self, dtype=None, copy=None):
        if copy:
            return np.array(self._q, dtype=dtype)
        return self._q if dtype is None else self._q.astype(dtype, copy=False)

    def __eq__(self, other):
        raise TypeError("use a.approx_equal(b, atol) to compare attitudes: q and -q are the same rotation")

    __hash__ = None

    # ------------------------------------------------------------------------------------------------ constructors
    @classmethod
    def from_quat(cls, q, *, scalar_first: bool = True, reference=None, body=None, check: bool = True) -> Attitude:
        """From quaternions, scalar first by default (``scalar_first=False``: scipy's ``[x, y, z, w]``).

        Parameters
        ----------
        q : array_like, shape (..., 4)
            Non-zero quaternions, body to ``reference``; they are normalised.
        scalar_first : bool
            ``[w, x, y, z]`` (default) or scipy's ``[x, y, z, w]``.
        reference, body : str, optional
            Frame names (axis letters such as ``"NED"`` and ``"FRD"``, or any name).
        check : bool
            Reject NaN, infinities and zero quaternions (default).

        Returns
        -------
        Attitude
            Shape ``q.shape[:-1]``, float32 for float32 input.
        """
        arr = _v.quaternions(q, "q", check=check)
        if not scalar_first:
            arr = np.roll(arr, 1, axis=-1)
        return cls(arr, reference, body, check=False)

    @classmethod
    def from_matrix(
        cls, matrix, *, orthonormalize: bool = False, atol: float = 1e-5, reference=None, body=None, check=True
    ) -> Attitude:
        """From body-to-reference rotation matrices (..., 3, 3); see :func:`strapdown.from_matrix`.

        A matrix further than ``atol`` from a rotation is refused unless ``orthonormalize=True``, which takes
        the nearest rotation instead (scipy's ``from_matrix`` does that always; its ``assume_valid=True`` is
        this default).
        """
        from .matrix import from_matrix

        q = from_matrix(matrix, orthonormalize=orthonormalize, atol=atol, check=check)
        return cls._wrap(q, _name(reference, "reference"), _name(body, "body"))

    @classmethod
    def from_euler(cls, angles, seq="ZYX", degrees: bool = False, *, reference=None, body=None, check: bool = True):
        """From Euler angles (:func:`strapdown.from_euler`); scipy's argument order ``(seq, angles)`` works too."""
        from .euler import from_euler

        if isinstance(angles, str):  # scipy's Rotation.from_euler(seq, angles)
            angles, seq = seq, angles
        q = from_euler(angles, seq, degrees, check=check)
        return cls._wrap(q, _name(reference, "reference"), _name(body, "body"))

    @classmethod
    def from_rotvec(cls, rotvec, degrees: bool = False, *, reference=None, body=None, check: bool = True):
        """From rotation vectors (:func:`strapdown.from_rotvec`)."""
        from .rotvec import from_rotvec

        return cls._wrap(from_rotvec(rotvec, degrees, check=check), _name(reference, "reference"), _name(body, "body"))

    @classmethod
    def from_mrp(cls, mrp, *, reference=None, body=None, check: bool = True) -> Attitude:
        """From modified Rodrigues parameters (:func:`strapdown.from_mrp`)."""
        from .mrp import from_mrp

        return cls._wrap(from_mrp(mrp, check=check), _name(reference, "reference"), _name(body, "body"))

    @classmethod
    def from_davenport(cls, axes, order, angles, degrees: bool = False, *, reference=None, body=None, check=True):
        """From Davenport angles (:func:`strapdown.from_davenport`, scipy's argument order)."""
        from .davenport import from_davenport

        q = from_davenport(axes, order, angles, degrees, check=check)
        return cls._wrap(q, _name(reference, "reference"), _name(body, "body"))

    @classmethod
    def from_gibbs(cls, gibbs, convention: str = "gajda", *, reference=None, body=None, check: bool = True):
        """From Gibbs vectors (:func:`strapdown.from_gibbs`; ``convention="rodrigues"`` for n tan(χ/2))."""
        from .rotvec import from_gibbs

        q = from_gibbs(gibbs, convention, check=check)
        return cls._wrap(q, _name(reference, "reference"), _name(body, "body"))

    @classmethod
    def from_axis_angle(cls, axis, angle, degrees: bool = False, *, reference=None, body=None, check=True):
        """From axes and angles (:func:`strapdown.from_axis_angle`)."""
        from .rotvec import from_axis_angle

        q = from_axis_angle(axis, angle, degrees, check=check)
        return cls._wrap(q, _name(reference, "reference"), _name(body, "body"))

    @classmethod
    def from_scipy(cls, rot, *, reference=None, body=None) -> Attitude:
        """From a ``scipy.spatial.transform.Rotation``."""
        from .interop import from_scipy

        return cls(from_scipy(rot), reference, body, check=False)

    @classmethod
    def identity(cls, shape=None, *, num=None, reference=None, body=None, dtype=np.float64) -> Attitude:
        """Identity attitudes of the given leading shape.

        Parameters
        ----------
        shape : int or tuple of int, optional
            Leading shape; None or ``()`` (default) gives one attitude.
        num : int, optional
            scipy's name: ``num`` attitudes, shape ``(num,)`` (give ``num`` or ``shape``).
        reference, body : str, optional
            Frame names.
        dtype : numpy dtype
            float64 (default) or float32.

        Returns
        -------
        Attitude
            ``[1, 0, 0, 0]`` everywhere.
        """
        from .quaternion import identity

        q = identity(_lead_shape(num, shape), dtype)
        return cls._wrap(q, _name(reference, "reference"), _name(body, "body"))

    @classmethod
    def random(cls, num: int | None = None, rng=None, *, shape=None, reference=None, body=None) -> Attitude:
        """Uniformly distributed attitudes (Haar measure): normalised 4-D Gaussians (Shoemake 1992).

        The same rotations as scipy's ``Rotation.random`` from the same generator (its draws are read scalar
        last, as scipy reads them), in canonical sign (w ≥ 0).

        Parameters
        ----------
        num : int, optional
            How many; None (default) gives one attitude of shape ``()``.
        rng : numpy.random.Generator, numpy.random.RandomState or seed, optional
            The random generator (a seed is passed to ``numpy.random.default_rng``).
        shape : int or tuple of int, optional
            Leading shape instead of ``num``.
        reference, body : str, optional
            Frame names.

        Returns
        -------
        Attitude
            Shape ``()``, ``(num,)`` or ``shape``; float64.
        """
        from .quaternion import canonical

        g = _generator(rng).standard_normal((*_lead_shape(num, shape), 4))
        g = np.roll(g, 1, axis=-1)  # scipy's draws are [x, y, z, w]
        g /= np.linalg.norm(g, axis=-1, keepdims=True)
        return cls._wrap(canonical(g, check=False), _name(reference, "reference"), _name(body, "body"))

    @classmethod
    def align_vectors(cls, a, b, weights=None, return_sensitivity: bool = False, *, reference=None, body=None):
        """The attitude turning body vectors ``b`` onto reference vectors ``a`` and its rssd (scipy's names).

        See :func:`strapdown.rotations.wahba.align_vectors` (one pair: the minimal rotation; an infinite weight:
        that pair exactly, the others about it; otherwise Wahba's problem on the raw vectors).

        Returns
        -------
        attitude : Attitude
            Body (frame of ``b``) to reference (frame of ``a``), w ≥ 0.
        rssd : float or numpy.ndarray
            Root sum squared distance of the pairs of finite weight.
        sensitivity : numpy.ndarray, shape (..., 3, 3)
            Only with ``return_sensitivity=True``: scipy's sensitivity matrix, in the reference frame.
        """
        from .wahba import align_vectors

        out = align_vectors(a, b, weights, return_sensitivity=return_sensitivity)
        return (cls._wrap(out[0], _name(reference, "reference"), _name(body, "body")), *out[1:])

    @classmethod
    def create_group(cls, group: str, axis: str = "Z", *, frame=None) -> Attitude:
        """The rotations of a symmetry group (:func:`strapdown.rotations.groups.create_group`, scipy's names).

        Parameters
        ----------
        group : {"I", "O", "T", "Cn", "Dn"}
            Icosahedral, octahedral, tetrahedral, cyclic or dihedral group of order n.
        axis : {"X", "Y", "Z"}
            Main axis of ``"Cn"`` and ``"Dn"``.
        frame : str, optional
            The axes the group turns into themselves (its reference and body, the same name).

        Returns
        -------
        Attitude
            Shape (m,), w ≥ 0, the identity first.
        """
        from .groups import create_group

        frame = _name(frame, "frame")
        return cls._wrap(create_group(group, axis), frame, frame)

    @classmethod
    def concatenate(cls, attitudes) -> Attitude:
        """One stack from several Attitudes (single ones count as one row) with the same frames.

        Parameters
        ----------
        attitudes : Attitude or sequence of Attitude
            Attitudes of shape ``()`` or ``(n_i, ...)``, all with the same reference and body names.

        Returns
        -------
        Attitude
            Shape ``(sum n_i, ...)``.

        Raises
        ------
        TypeError
            For an item that is not an Attitude.
        ValueError
            When the frames differ (the message names the first one that does and how to re-express it).
        """
        items = [attitudes] if isinstance(attitudes, Attitude) else list(attitudes)
        if not items:
            raise ValueError("concatenate needs a non-empty sequence of Attitude objects")
        for i, a in enumerate(items):
            if not isinstance(a, Attitude):
                raise TypeError(f"concatenate takes Attitude objects only; attitudes[{i}] is a {type(a).__name__}")
        first = items[0]
        for i, a in enumerate(items[1:], 1):
            if (a.reference, a.body) != (first.reference, first.body):
                raise ValueError(
                    f"attitudes[{i}] maps {a.body!r} to {a.reference!r} but attitudes[0] maps {first.body!r} to "
                    f"{first.reference!r}; re-express it with .to_frame({first.reference!r}, {first.body!r})"
                )
        q = np.concatenate([np.atleast_2d(a.q) for a in items], axis=0)
        return cls._wrap(q, first.reference, first.body)

    # ------------------------------------------------------------------------------------------------ conversions
    def as_quat(self, canonical: bool = False, *, scalar_first: bool = True) -> np.ndarray:
        """A copy of the quaternions; ``canonical=True`` picks w ≥ 0 (:func:`~.quaternion.canonical`)."""
        from .quaternion import canonical as canon

        out = canon(self._q, check=False) if canonical else self._q.copy()
        return out if scalar_first else np.roll(out, -1, axis=-1)

    def as_matrix(self) -> np.ndarray:
        """Body-to-reference rotation matrices (..., 3, 3)."""
        from .matrix import as_matrix

        return as_matrix(self._q, check=False)

    def as_euler(
        self, seq: str = "ZYX", degrees: bool = False, yaw_range: str = "signed", *, suppress_warnings: bool = False
    ) -> np.ndarray:
        """Euler angles (:func:`strapdown.as_euler`, exact at gimbal lock).

        As scipy's, a UserWarning says when an attitude lies within 1e-7 rad of gimbal lock, where only the sum
        or difference of the first and third angle is determined (``suppress_warnings=True`` silences it; the
        plain function never warns).
        """
        from .davenport import _BASIS, _warn_gimbal_lock
        from .euler import as_euler

        angles = as_euler(self._q, seq, degrees, yaw_range, check=False)
        if not suppress_warnings:  # seq is valid: as_euler took it; its middle angle is as_davenport's
            middle = np.deg2rad(angles[..., 1]) if degrees else angles[..., 1]
            _warn_gimbal_lock(middle, [_BASIS[c] for c in seq.lower()], "e" if seq.islower() else "i")
        return angles

    def as_rotvec(self, degrees: bool = False) -> np.ndarray:
        """Rotation vectors, angle in [0, π] (:func:`strapdown.as_rotvec`)."""
        from .rotvec import as_rotvec

        return as_rotvec(self._q, degrees, check=False)

    def as_mrp(self) -> np.ndarray:
        """Modified Rodrigues parameters, the short set |p| ≤ 1 (:func:`strapdown.as_mrp`)."""
        from .mrp import as_mrp

        return as_mrp(self._q, check=False)

    def as_davenport(self, axes, order: str, degrees: bool = False, *, suppress_warnings: bool = False) -> np.ndarray:
        """Davenport angles about three axes (:func:`strapdown.as_davenport`; gimbal lock as :meth:`as_euler`)."""
        from .davenport import _warn_gimbal_lock, as_davenport

        angles = as_davenport(self._q, axes, order, degrees, check=False)
        if not suppress_warnings:
            _warn_gimbal_lock(np.deg2rad(angles[..., 1]) if degrees else angles[..., 1], axes, order)
        return angles

    def as_gibbs(self, convention: str = "gajda") -> np.ndarray:
        """Gibbs vectors (:func:`strapdown.as_gibbs`); infinite, and refused, at 180°."""
        from .rotvec import as_gibbs

        return as_gibbs(self._q, convention)

    def as_axis_angle(self, degrees: bool = False):
        """Unit axes and angles in [0, π] (:func:`strapdown.as_axis_angle`)."""
        from .rotvec import as_axis_angle

        return as_axis_angle(self._q, degrees, check=False)

    def as_scipy(self):
        """A ``scipy.spatial.transform.Rotation`` of the same rotations (frames are not kept)."""
        from .interop import as_scipy

        return as_scipy(self._q, check=False)

    def to_scipy(self):
        """:meth:`as_scipy` by its name of release 0.1."""
        return self.as_scipy()
