"""File in, file out: the file commands of ``strapdown`` as functions, one module each.

* :mod:`.integrate`: :func:`integrate_file`, gyro readings integrated into attitudes;
* :mod:`.estimate`: :func:`estimate_file`, an estimator of :data:`strapdown.fusion.ESTIMATORS` over a file;
* :mod:`.convert`: :func:`convert_file`, attitudes from one representation into another;
* :mod:`.simulate`: :func:`simulate_file`, an IMU file with its exact truth;
* :mod:`.plot`: :func:`~strapdown.io.pipelines.plot.plot_file`, PNG figures of an attitude file, and
  :mod:`.truth`, a truth file put on an estimate's frames and rows.

Each function streams its input through the library's streaming objects (:class:`strapdown.AttitudeIntegrator`
and the estimators, whose ``update`` on chunks equals one call on everything), so memory stays constant whatever
the file's size, and writes through :func:`strapdown.io.table_writer`: the output appears, whole, only when
everything succeeded.  The options of a command are one frozen dataclass (:class:`IntegrateOptions`,
:class:`EstimateOptions`), given whole (``options``, the defaults when None) or field by field as keyword
arguments (``**changes``, by field name).  ``progress``, when given, is called with (rows done, total rows or
None) after each chunk.  Every file function returns a :class:`Report`: the files, the rows and the time taken,
and the notes a user should read.

Timing of ``integrate_file``: row k holds the sample of step k, which runs from row k's time to row k+1's (the
library's convention, :mod:`strapdown.propagate.integrate`); output row k is the attitude at row k's time, so the
output lines up with the input and the last sample, whose step ends after the file, is not used.
``estimate_file`` follows the estimators (a sample acts over the interval that ends at it) and also writes one row
per input row.
"""

from ._common import FileOptions, Report, default_output
from .convert import convert_file, convert_values
from .estimate import EstimateOptions, estimate_file, estimator_inputs
from .integrate import IntegrateOptions, integrate_file, integrate_stream
from .simulate import simulate_file

__all__ = [
    "EstimateOptions",
    "FileOptions",
    "IntegrateOptions",
    "Report",
    "convert_file",
    "convert_values",
    "default_output",
    "estimate_file",
    "estimator_inputs",
    "integrate_file",
    "integrate_stream",
    "simulate_file",
]
