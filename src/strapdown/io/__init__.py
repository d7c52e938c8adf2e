"""File I/O: IMU logs in CSV, Parquet, HDF5 and MATLAB files, read and written in chunks of any size.

Reading needs the ``io`` extra (pyarrow, h5py, scipy): ``pip install 'strapdown[io]'``.  Nothing heavy is
imported until a file is opened.

* :func:`open_source` / :func:`read_table`: the fields of a file, streamed or whole (:mod:`.readers`), in any
  registered format (:mod:`.registry`, one module per format in :mod:`.formats`: CSV, Parquet, HDF5, MATLAB,
  PX4 ULog, ROS 1/2 bags, ASL/EuRoC, Sensor Logger and phyphox exports, several files of one recording);
* :func:`read_reference`: a log's own attitude (PX4 ``vehicle_attitude``) or a table's quaternions as truth;
* :class:`ImuFile` / :func:`read_imu`: gyro, accelerometer, magnetometer and time in SI units, with the column
  mapping detected or given (:class:`ImuColumns`) and every chunk checked (:mod:`.imu`, :mod:`.units`,
  :mod:`.columns`);
* :func:`table_writer` / :func:`write_table`: CSV, Parquet, HDF5 or .mat output, atomically (:mod:`.writers`);
* :func:`integrate_file`, :func:`estimate_file`, :func:`convert_file`, :func:`simulate_file`: the file commands
  of the ``strapdown`` CLI as functions (:mod:`.pipeline`); attitude columns in :mod:`.tables`.

Examples
--------
>>> import numpy as np, pathlib, tempfile
>>> from strapdown import angle_between
>>> from strapdown.io import integrate_file, read_table, simulate_file
>>> log = simulate_file(pathlib.Path(tempfile.mkdtemp()) / "loop.parquet", duration=5.0).output
>>> truth = read_table(log)
>>> q_true = np.column_stack([truth[c] for c in ("qw_true", "qx_true", "qy_true", "qz_true")])
>>> result = read_table(integrate_file(log, q0=q_true[0]).output)
>>> q = np.column_stack([result[c] for c in ("qw", "qx", "qy", "qz")])
>>> bool(angle_between(q, q_true).max() < 1e-12)      # an ideal IMU's mean rates integrate exactly
True
"""

from .._support.lazy import exports

# The names below are imported from their modules when first used: ``strapdown.io.units`` or
# ``strapdown.io.readers`` alone (the command line's option parsing) then does not load the pipeline, the
# writers and every format.
_HOME = {
    "imu": ("ImuChunk", "ImuColumns", "ImuFile", "read_imu"),
    "pipelines": (
        "EstimateOptions",
        "IntegrateOptions",
        "Report",
        "convert_file",
        "default_output",
        "estimate_file",
        "integrate_file",
        "simulate_file",
    ),
    "readers": (
        "FORMATS",
        "INPUT_FORMATS",
        "Source",
        "format_of",
        "input_format",
        "open_source",
        "read_metadata",
        "read_table",
    ),
    "reference": ("Reference", "read_reference"),
    "source": ("TimeOrigin",),
    "tables": (
        "REPRESENTATIONS",
        "Angles",
        "OutputSpec",
        "attitude_columns",
        "column_names",
        "from_values",
        "to_values",
    ),
    "units": ("UNITS",),
    "writers": ("TableWriter", "table_writer", "write_table"),
}
__getattr__, __dir__, __all__ = exports(__name__, _HOME)
