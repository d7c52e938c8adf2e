"""strapdown: quaternion attitude determination.

Conventions, stated once and obeyed everywhere:

* quaternions are float arrays of shape (..., 4), scalar first ``[w, x, y, z]``, Hamilton product;
* an attitude quaternion maps body-frame vectors to the reference frame, ``v_ref = q ⊗ v_body ⊗ q*``, and
  ``as_matrix(q)`` is the matching body-to-reference matrix;
* body rates update an attitude on the right, ``q_{k+1} = q_k ⊗ dq_k``;
* angles are radians unless ``degrees=True``; every function broadcasts over leading axes and keeps float32.

The quaternion algebra lives in :mod:`strapdown.quaternion`; the conversions between attitude representations
are top-level names, in symmetric ``from_*`` / ``as_*`` pairs.  Subpackages and modules with one job each:
:mod:`strapdown.wahba` (attitude from vector observations), :mod:`strapdown.average` (means and distances),
:mod:`strapdown.decompose` (swing-twist, shortest arc, control error), :mod:`strapdown.interpolate` (slerp and
squad over time), :mod:`strapdown.fusion` (gyro/accelerometer/magnetometer filters), :mod:`strapdown.simulate`,
:mod:`strapdown.metrics`, :mod:`strapdown.broad` and :mod:`strapdown.evaluate` (the BROAD benchmark).

Importing the package compiles nothing: the numba kernels are compiled (and cached on disk) the first time a
function needs them.
"""

from . import average, decompose, interpolate, quaternion, wahba
from .attitude import Attitude
from .cayley_klein import as_cayley_klein, from_cayley_klein
from .compressed import as_compressed, from_compressed
from .davenport import as_davenport, from_davenport
from .euler import as_euler, from_euler
from .frames import change_frame, frame_matrix, frame_quaternion
from .integrate import METHODS, AttitudeIntegrator, SingularityError, integrate
from .interop import from_scipy, to_scipy
from .matrix import as_matrix, from_matrix
from .mrp import as_mrp, from_mrp
from .quaternion import angle_between, canonical, multiply
from .rotvec import as_axis_angle, as_gibbs, as_rotvec, from_axis_angle, from_gibbs, from_rotvec

__version__ = "0.1.0"

__all__ = [
    "METHODS",
    "Attitude",
    "AttitudeIntegrator",
    "SingularityError",
    "__version__",
    "angle_between",
    "as_axis_angle",
    "as_cayley_klein",
    "as_compressed",
    "as_davenport",
    "as_euler",
    "as_gibbs",
    "as_matrix",
    "as_mrp",
    "as_rotvec",
    "average",
    "canonical",
    "change_frame",
    "decompose",
    "frame_matrix",
    "frame_quaternion",
    "from_axis_angle",
    "from_cayley_klein",
    "from_compressed",
    "from_davenport",
    "from_euler",
    "from_gibbs",
    "from_matrix",
    "from_mrp",
    "from_rotvec",
    "from_scipy",
    "integrate",
    "interpolate",
    "multiply",
    "quaternion",
    "to_scipy",
    "wahba",
]
