"""One module per input format; each declares its format (:mod:`strapdown.io.registry` holds them).

Tables: :mod:`.csv`, :mod:`.parquet`, :mod:`.hdf5`, :mod:`.mat`.  Logs and exports: :mod:`.ulog` (PX4),
:mod:`.dataflash` (ArduPilot), :mod:`.rosbag` (ROS 1 and 2, standalone MCAP), :mod:`.euroc` (ASL/EuRoC/TUM-VI
folders), :mod:`.sensorlogger` and :mod:`.phyphox` (phone exports, folder or zip); :mod:`.multi` merges several
files of one recording.  The logs are read a block or a message at a time and spooled (:mod:`._spool`), never
whole.  Nothing heavy is imported until a file is opened.
"""

from . import csv, dataflash, euroc, hdf5, mat, parquet, phyphox, rosbag, sensorlogger, ulog

#: The formats of these modules, tables first (their suffixes are the common case); the registry adds "files" (several
#: files of one recording, :mod:`.multi`) after the tables.
BUILT_IN = (
    csv.FORMAT,
    euroc.FORMAT,
    hdf5.FORMAT,
    mat.FORMAT,
    parquet.FORMAT,
    phyphox.FORMAT,
    rosbag.FORMAT,
    sensorlogger.FORMAT,
    ulog.FORMAT,
    dataflash.FORMAT,
)
