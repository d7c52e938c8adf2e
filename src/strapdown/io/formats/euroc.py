"""ASL/EuRoC/TUM-VI dataset folders: ``mav0/imu0/data.csv`` (or ``imu0/data.csv``) read as a CSV table.

The file is ``#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],
...``: the header is a comment line, times are integer nanoseconds, ``w_RS_S`` and ``a_RS_S`` are the angular
rate and specific force of the sensor S (relative to R, in S).  The CSV reader takes such a file on its own;
this module finds it in a dataset folder.  The sensor axes are the IMU's own (``mav0/imu0/sensor.yaml`` gives
``T_BS``), so no frame preset is given.
"""

from __future__ import annotations

from pathlib import Path

from .base import Format
from .csv import CsvSource

__all__ = ["imu_file", "open_euroc"]


def imu_file(path: Path) -> Path | None:
    r"""The IMU table of a dataset folder (``mav0/imu0/data.csv``, ``imu0/data.csv``), or None.

    Parameters
    ----------
    path : pathlib.Path
        The folder.

    Returns
    -------
    pathlib.Path or None
        The file.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io.formats.euroc import imu_file
    >>> root = pathlib.Path(tempfile.mkdtemp())
    >>> (root / "mav0" / "imu0").mkdir(parents=True)
    >>> _ = (root / "mav0" / "imu0" / "data.csv").write_text("#timestamp [ns],w_RS_S_x [rad s^-1]\n")
    >>> imu_file(root).relative_to(root).as_posix()
    'mav0/imu0/data.csv'
    """
    for rel in ("mav0/imu0/data.csv", "imu0/data.csv", "data.csv"):
        candidate = path / rel
        if candidate.is_file():
            with open(candidate, encoding="utf-8-sig", errors="replace") as f:
                if f.readline(1 << 16).startswith("#timestamp"):
                    return candidate
    return None


def open_euroc(path) -> CsvSource:
    r"""The IMU table of an ASL/EuRoC/TUM-VI folder.

    Parameters
    ----------
    path : path-like
        The dataset folder (containing ``mav0``) or ``mav0`` itself.

    Returns
    -------
    CsvSource
        The ``imu0/data.csv`` table.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io.formats.euroc import open_euroc
    >>> root = pathlib.Path(tempfile.mkdtemp())
    >>> (root / "imu0").mkdir()
    >>> _ = (root / "imu0" / "data.csv").write_text("#timestamp [ns],w_RS_S_x [rad s^-1]\n1403636579758555392,0.1\n")
    >>> list(open_euroc(root).fields)
    ['timestamp [ns]', 'w_RS_S_x [rad s^-1]']
    """
    found = imu_file(Path(path))
    if found is None:
        raise ValueError(f"{path}: no imu0/data.csv with a #timestamp header in this folder")
    src = CsvSource(found)
    src.format = "euroc"
    return src


#: This module's format, for :mod:`strapdown.io.registry`.
FORMAT = Format(
    "euroc",
    open_euroc,
    detect=lambda p: p.is_dir() and imu_file(p) is not None,
    description="ASL/EuRoC/TUM-VI folder",
)
