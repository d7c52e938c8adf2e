"""strapdown: quaternion attitude determination.

Conventions, stated once and obeyed everywhere:

* quaternions are float arrays of shape (..., 4), scalar first ``[w, x, y, z]``, Hamilton product;
* an attitude quaternion maps body-frame vectors to the reference frame, ``v_ref = q ⊗ v_body ⊗ q*``, and
  ``as_matrix(q)`` is the matching body-to-reference matrix;
* body rates update an attitude on the right, ``q_{k+1} = q_k ⊗ dq_k``;
* angles are radians unless ``degrees=True``; every function broadcasts over leading axes and keeps float32.

The conversions between attitude representations, the ``Attitude`` object and gyro integration are top-level
names.  The package has one folder per floor, each importing only from the floors below it
(``docs/architecture.md``; ``tests/test_layers.py`` checks it):

* :mod:`strapdown.rotations`: the quaternion algebra, every representation, frames, means, decompositions,
  attitude from vector observations (Wahba) and the :class:`Attitude` object;
* :mod:`strapdown.propagate`: attitude over time from body rates (integration, coning), interpolation, splines;
* :mod:`strapdown.simulate`: trajectories and sensor error models, IMU readings with exact truth;
* :mod:`strapdown.fusion` (gyro/accelerometer/magnetometer estimators and their registry) and
  :mod:`strapdown.calibrate` (sensor calibration, Allan analysis, true north);
* :mod:`strapdown.evaluate`: error metrics, the BROAD benchmark, comparisons of methods and their figures;
* :mod:`strapdown.io`: files in and out, and the file commands as functions (:mod:`strapdown.io.pipelines`);
* :mod:`strapdown.apps` (batch runs, the demo, the warm-up) and :mod:`strapdown.cli` (the ``strapdown`` command).

The module paths of release 0.1 (``strapdown.quaternion``, ``strapdown.metrics``, ...) still import, as the same
modules at their new homes.  Importing the package compiles nothing: the numba kernels are compiled (and cached on
disk) the first time a function needs them.
"""

import sys as _sys

from ._support.moved import install as _install_moved
from ._support.version import VERSION as __version__
from .propagate import interpolate
from .propagate.integrate import METHODS, AttitudeIntegrator, SingularityError, integrate
from .rotations import average, decompose, quaternion, wahba
from .rotations.attitude import Attitude
from .rotations.cayley_klein import as_cayley_klein, from_cayley_klein
from .rotations.compressed import as_compressed, from_compressed
from .rotations.davenport import as_davenport, from_davenport
from .rotations.euler import as_euler, from_euler
from .rotations.frames import change_frame, frame_matrix, frame_quaternion
from .rotations.interop import as_scipy, from_scipy, to_scipy
from .rotations.matrix import as_matrix, from_matrix
from .rotations.mrp import as_mrp, from_mrp
from .rotations.quaternion import angle_between, canonical, multiply
from .rotations.rotvec import as_axis_angle, as_gibbs, as_rotvec, from_axis_angle, from_gibbs, from_rotvec

# strapdown.integrate names the function here and, as a module path of release 0.1, the module: registered up front.
_install_moved({"strapdown.integrate": _sys.modules["strapdown.propagate.integrate"]})


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
    "as_scipy",
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
