"""One attitude at one instant: the algebra, every representation, frames and operations (floor 1).

Inside the floor the modules import downwards in this order:

* :mod:`.quaternion`: the Hamilton algebra (product, conjugate, exp/log, powers, rotation of vectors, slerp);
* the representations, each a ``from_*`` / ``as_*`` pair: :mod:`.matrix`, :mod:`.euler` (all 12 sequences),
  :mod:`.davenport`, :mod:`.mrp`, :mod:`.rotvec` (rotation vector, axis-angle, Gibbs), :mod:`.cayley_klein`,
  :mod:`.compressed` (Liu et al.), :mod:`.tilt` (Rowe's yaw-free tilt quaternion) and :mod:`.interop` (scipy);
* operations on attitudes: :mod:`.frames` (named reference frames and body axes), :mod:`.average` (means and
  distances), :mod:`.decompose` (swing-twist, shortest arc), :mod:`.wahba` (attitude from vector observations),
  :mod:`.groups` (the symmetry groups of solids and reduction by them);
* :mod:`.attitude`: the frame-tagged :class:`~strapdown.Attitude` object over all of them.

The top-level package re-exports the conversions; this floor imports only :mod:`strapdown._support`.

Conventions
-----------
Stated here once; each function's docstring says only what differs.

* Quaternions as in :mod:`.quaternion` (shape (..., 4), scalar first, body to reference); vectors have shape
  (..., 3).  Leading axes broadcast between the arguments of a call; float32 stays float32.
* ``check`` (keyword, default True) rejects, with a ``ValueError`` that names the argument and the first bad
  index, what the function cannot use: NaN, infinities, zero quaternions where a rotation is meant, zero
  vectors where a direction is meant, and whatever else its docstring names.  ``check=False`` skips these
  checks (not the shape tests) for hot code whose input is validated already.
* ``degrees=True`` takes or returns angles in degrees instead of radians.
"""

from .._support.lazy import exports

# submodules and names imported when first used
__getattr__, __dir__, _names = exports(__name__, {})
__all__ = sorted(
    [
        *_names,
        *[
            "attitude",
            "average",
            "cayley_klein",
            "compressed",
            "davenport",
            "decompose",
            "euler",
            "frames",
            "groups",
            "interop",
            "matrix",
            "mrp",
            "quaternion",
            "rotvec",
            "wahba",
        ],
    ]
)
