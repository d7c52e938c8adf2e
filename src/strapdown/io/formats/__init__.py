"""One module per input format; importing this package registers them all (:mod:`strapdown.io.registry`).

Tables: :mod:`.csv`, :mod:`.parquet`, :mod:`.hdf5`, :mod:`.mat`.  Logs and exports: :mod:`.ulog` (PX4),
:mod:`.rosbag` (ROS 1 and 2), :mod:`.euroc` (ASL/EuRoC/TUM-VI folders), :mod:`.sensorlogger` and
:mod:`.phyphox` (phone exports, folder or zip); :mod:`.multi` merges several files of one recording.
Nothing heavy is imported until a file is opened.
"""

from . import (  # noqa: F401  (tables first: their suffixes are the common case)  # noqa: F401
    csv,
    euroc,
    hdf5,
    mat,
    multi,
    parquet,
    phyphox,
    rosbag,
    sensorlogger,
    ulog,
)
