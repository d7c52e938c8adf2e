"""scipy's ``Rotation`` and ``Slerp`` spelled over :class:`strapdown.Attitude`: conventions only, no maths.

scipy's own tests (``scipy/spatial/transform/tests/test_rotation*.py``, read from the installed scipy by
:func:`load`) run against these two classes.  Each method hands its arguments to the Attitude method of the same
meaning and wraps what comes back; what it changes is only how scipy spells things:

* quaternions are scalar last in scipy, scalar first in strapdown (``from_quat``, ``as_quat``, ``Rotation(q)``,
  the array view and scipy's private ``_quat``);
* argument names and their defaults: scipy's ``from_matrix(assume_valid=False)`` orthonormalises, which is
  strapdown's ``orthonormalize=True``; ``random(random_state=...)`` is scipy's old name of ``rng``;
* frames are left unnamed (scipy has none), so no composition is refused;
* error messages: ``pytest.raises`` and ``pytest.warns`` inside the tests compare the exception's type, not its
  wording (strapdown's messages name the argument and the numbers instead of scipy's sentences).

An argument scipy has and strapdown cannot take raises a ``TypeError`` here rather than being dropped, so a test
that needs it fails instead of passing for the wrong reason.
"""

from __future__ import annotations

import importlib.util
import operator
import types

import numpy as np
import pytest

from strapdown import Attitude
from strapdown.propagate.interpolate import slerp_series


def _att(value):
    """The Attitude inside a Rotation; anything else unchanged (so strapdown sees, and refuses, the same thing)."""
    return value._a if isinstance(value, Rotation) else value


class Rotation:
    """scipy's Rotation API over one :class:`strapdown.Attitude` (``_a``)."""

    __slots__ = ("_a",)
    __array_ufunc__ = None  # as Attitude: no arithmetic through numpy

    def __init__(self, quat, normalize=True, copy=True, *, scalar_first=False):
        if not normalize:
            raise TypeError("adapter: Attitude always normalises its quaternions (normalize=False has no equivalent)")
        self._a = Attitude.from_quat(quat, scalar_first=scalar_first)

    @classmethod
    def _of(cls, attitude) -> Rotation:
        out = cls.__new__(cls)
        out._a = attitude
        return out

    # constructors
    @classmethod
    def from_quat(cls, quat, *, scalar_first=False):
        return cls._of(Attitude.from_quat(quat, scalar_first=scalar_first))

    @classmethod
    def from_matrix(cls, matrix, *, assume_valid=False):
        return cls._of(Attitude.from_matrix(matrix, orthonormalize=not assume_valid))

    @classmethod
    def from_rotvec(cls, rotvec, degrees=False):
        return cls._of(Attitude.from_rotvec(rotvec, degrees))

    @classmethod
    def from_mrp(cls, mrp):
        return cls._of(Attitude.from_mrp(mrp))

    @classmethod
    def from_euler(cls, seq, angles, degrees=False):
        return cls._of(Attitude.from_euler(seq, angles, degrees))

    @classmethod
    def from_davenport(cls, axes, order, angles, degrees=False):
        return cls._of(Attitude.from_davenport(axes, order, angles, degrees))

    @classmethod
    def identity(cls, num=None, *, shape=None):
        return cls._of(Attitude.identity(num=num, shape=shape))

    @classmethod
    def random(cls, num=None, rng=None, *, shape=None, random_state=None):
        if random_state is not None:
            rng = random_state
        return cls._of(Attitude.random(num, rng, shape=shape))

    @classmethod
    def align_vectors(cls, a, b, weights=None, return_sensitivity=False):
        out = Attitude.align_vectors(a, b, weights, return_sensitivity=return_sensitivity)
        return (cls._of(out[0]), *out[1:])

    @classmethod
    def concatenate(cls, rotations):
        items = _att(rotations) if isinstance(rotations, Rotation) else [_att(r) for r in rotations]
        return cls._of(Attitude.concatenate(items))

    @classmethod
    def create_group(cls, group, axis="Z"):
        return cls._of(Attitude.create_group(group, axis))

    # exporters
    def as_quat(self, canonical=False, *, scalar_first=False):
        return self._a.as_quat(canonical, scalar_first=scalar_first)

    def as_matrix(self):
        return self._a.as_matrix()

    def as_rotvec(self, degrees=False):
        return self._a.as_rotvec(degrees)

    def as_mrp(self):
        return self._a.as_mrp()

    def as_euler(self, seq, degrees=False, *, suppress_warnings=False):
        return self._a.as_euler(seq, degrees, suppress_warnings=suppress_warnings)

    def as_davenport(self, axes, order, degrees=False, *, suppress_warnings=False):
        return self._a.as_davenport(axes, order, degrees, suppress_warnings=suppress_warnings)

    @property
    def _quat(self):
        return self._a.as_quat(scalar_first=False)

    def __array__(self, dtype=None, copy=None):
        return np.roll(np.asarray(self._a, dtype=dtype), -1, axis=-1)

    # operations
    def apply(self, vectors, inverse=False):
        return self._a.apply(vectors, inverse)

    def inv(self):
        return Rotation._of(self._a.inv())

    def magnitude(self):
        return self._a.magnitude()

    def approx_equal(self, other, atol=None, degrees=False):
        return self._a.approx_equal(_att(other), atol, degrees)

    def mean(self, weights=None, axis=None):
        return Rotation._of(self._a.mean(weights, axis))

    def reduce(self, left=None, right=None, return_indices=False):
        out = self._a.reduce(_att(left), _att(right), return_indices=return_indices)
        return (Rotation._of(out[0]), *out[1:]) if return_indices else Rotation._of(out)

    def __mul__(self, other):
        out = self._a.__mul__(_att(other))
        return out if out is NotImplemented else Rotation._of(out)

    def __pow__(self, n, modulus=None):
        return Rotation._of(self._a.__pow__(n, modulus))

    # container
    @property
    def single(self):
        return self._a.single

    @property
    def shape(self):
        return self._a.shape

    def __len__(self):
        return len(self._a)

    def __bool__(self):
        return bool(self._a)

    def __iter__(self):
        return (Rotation._of(a) for a in iter(self._a))

    def __getitem__(self, index):
        return Rotation._of(self._a[index])

    def __setitem__(self, index, value):
        operator.setitem(self._a, index, _att(value))

    def __eq__(self, other):
        return self._a == _att(other)

    __hash__ = None

    def __repr__(self):
        return repr(self._a)


class Slerp:
    """scipy's ``Slerp(times, rotations)`` over :func:`strapdown.propagate.interpolate.slerp_series`."""

    def __init__(self, times, rotations):
        self.times = np.asarray(times)
        self._q = _att(rotations)
        slerp_series(self.times, self._q, self.times)  # scipy checks its input here, strapdown at every call

    def __call__(self, times):
        return Rotation._of(Attitude(slerp_series(self.times, self._q, times)))


def _type_only(check):
    """``pytest.raises`` or ``pytest.warns`` comparing the type only (module notes: messages differ in wording)."""

    def wrapper(expected, *args, match=None, **kwargs):
        return check(expected, *args, **kwargs)

    return wrapper


def load(name: str, namespace: dict, expected: dict[str, str]) -> None:
    """Run scipy's test module ``scipy.spatial.transform.tests.<name>`` against the adapter, in ``namespace``.

    The module is read from the installed scipy and executed afresh (scipy's own copy is not touched); its
    ``Rotation`` and ``Slerp`` are then replaced by the adapter's and its ``test_*`` functions put into
    ``namespace``, the calling test module, with an ``xp`` fixture (numpy: scipy's default array backend) and
    ``expected``: ``{test id or function name: reason}``, the cases that fail by design or not yet, marked as
    strict xfails so that an unexpected pass shows as well as an unexpected failure.
    """
    spec = importlib.util.find_spec(f"scipy.spatial.transform.tests.{name}")
    if spec is None:
        raise ImportError(f"scipy.spatial.transform.tests.{name} is not installed; the scipy suite cannot run")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.Rotation = Rotation
    if hasattr(module, "Slerp"):
        module.Slerp = Slerp
    module.pytest = types.SimpleNamespace(
        **{k: getattr(pytest, k) for k in dir(pytest) if not k.startswith("__")},
    )
    module.pytest.raises = _type_only(pytest.raises)
    module.pytest.warns = _type_only(pytest.warns)
    tests = {k: v for k, v in vars(module).items() if k.startswith("test_") and callable(v)}
    unknown = sorted({key.split("[")[0] for key in expected} - set(tests))
    if unknown:
        raise AssertionError(f"expected failures name tests that scipy's {name} no longer has: {unknown}")
    namespace.update(tests)

    @pytest.fixture
    def xp():
        return np

    @pytest.fixture(autouse=True)
    def _expected_failure(request):
        reason = expected.get(request.node.name) or expected.get(request.node.originalname)
        if reason:
            request.applymarker(pytest.mark.xfail(reason=reason, strict=True))

    namespace["xp"] = xp
    namespace["_expected_failure"] = _expected_failure
