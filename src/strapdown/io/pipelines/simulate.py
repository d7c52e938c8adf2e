"""``strapdown simulate``: an IMU file with its exact truth, from a named motion."""

from __future__ import annotations

import time

import numpy as np

from ._common import (
    Report,
    metadata,
)

__all__ = ["simulate_file"]

_IMUS = ("ideal", "consumer", "tactical")


# column-name suffixes of the units simulate_file writes; the SI units (the readers' defaults) go unmarked
_UNIT_SUFFIX = {"rad/s": "", "deg/s": "_dps", "m/s2": "", "g": "_g", "mg": "_mg", "uT": "", "gauss": "_gauss"}
_UNIT_SUFFIX |= {"nT": "_nT", "mT": "_mT"}


def simulate_file(
    output,
    *,
    scenario: str = "hammerhead-loop",
    rate: float = 100.0,
    gyro: str = "average",
    imu: str = "ideal",
    seed: int = 0,
    reference: str = "ENU",
    body: str = "FLU",
    duration: float | None = None,
    gyro_unit: str = "rad/s",
    acc_unit: str = "m/s2",
    mag_unit: str = "uT",
    truth: bool = True,
    format: str | None = None,
) -> Report:
    """Write a simulated IMU log with its true attitude (:mod:`strapdown.simulate`) to a file.

    Row k holds time ``t[k]`` (the start of sample k's step), the gyro sample (rate, mean rate, or angle
    increment per ``gyro``), the mean specific force over the step (or the instantaneous one for ``gyro="rate"``),
    the magnetometer, and the true attitude at ``t[k]`` (``qw_true``, ...): exactly what :func:`integrate_file`
    computes for that row.

    Parameters
    ----------
    output : path-like
        CSV, Parquet, HDF5 or .mat file.
    scenario : str
        A key of :data:`strapdown.simulate.scenarios.SCENARIOS`.
    rate : float
        Sample rate, Hz.
    gyro : {"rate", "average", "increment", "rotvec"}
        What a gyro sample is (:func:`strapdown.simulate.sample`).
    imu : {"ideal", "consumer", "tactical"}
        Sensor errors (:class:`strapdown.simulate.ImuModel` presets).
    seed : int
        Seed of the sensor errors.
    reference, body : str
        Frames of the truth and the readings.
    duration : float, optional
        Seconds to simulate (the whole scenario by default).
    gyro_unit, acc_unit, mag_unit : str
        Units of the written readings (:data:`strapdown.io.units.UNITS`).
    truth : bool
        Write the true attitude.
    format : str, optional
        When the suffix does not tell it.

    Returns
    -------
    Report
        The file and its rows.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.io import read_table, simulate_file
    >>> report = simulate_file(pathlib.Path(tempfile.mkdtemp()) / "sim.parquet", scenario="coning", duration=1.0)
    >>> report.rows, list(read_table(report.output))[:4]
    (100, ['t', 'gx', 'gy', 'gz'])
    """
    from ...simulate import ImuModel, sample
    from ...simulate.scenarios import scenario as make
    from ..units import parse_unit, scale

    t_start = time.perf_counter()
    if imu not in _IMUS:
        raise ValueError(f"imu must be one of {', '.join(_IMUS)}, got {imu!r}")
    model = {"ideal": ImuModel.ideal, "consumer": ImuModel.consumer_mems, "tactical": ImuModel.tactical}[imu]()
    trajectory = make(scenario, duration)
    data = sample(trajectory, rate, gyro=gyro, imu=model, seed=seed, reference=reference, body=body, duration=duration)
    n = data.gyro.shape[0]
    acc = data.acc
    if gyro in ("increment", "rotvec"):
        acc = acc / np.diff(data.t)[:, None]  # velocity increments -> mean specific force: acc is always m/s²
    cols = {"t": data.t[:n]}
    for prefix, values, kind, unit in (
        ("g", data.gyro, "gyro", gyro_unit),
        ("a", acc, "acc", acc_unit),
        ("m", data.mag, "mag", mag_unit),
    ):
        # a unit other than the readers' default goes into the names (gx_dps, ax_g, mx_nT): the file must say
        # what it holds, or reading it back would take degrees for radians
        suffix = _UNIT_SUFFIX[parse_unit(kind, unit)]
        cols.update({f"{prefix}{a}{suffix}": values[:, i] / scale(kind, unit) for i, a in enumerate("xyz")})
    if truth:
        cols.update({f"{c}_true": data.q_true[:n, i] for i, c in enumerate(("qw", "qx", "qy", "qz"))})
    meta = metadata(
        "simulate",
        scenario=scenario,
        rate_hz=rate,
        gyro_input=data.gyro_input,
        reference=reference,
        frame=reference.upper(),  # the truth's, and the name every reader of frames looks for
        body=body.upper(),
        quaternion="w,x,y,z scalar first, Hamilton, body to frame (qw_true..qz_true)",
        time_unit="s",
        time_origin="0",
        time_origin_unit="s",
        time_origin_kind="file",
        gyro_unit=gyro_unit,
        acc_unit=acc_unit,
        mag_unit=mag_unit,
        imu=imu,
        seed=seed,
    )
    from ..writers import write_table

    path = write_table(output, cols, format, meta)
    return Report(None, path, n, time.perf_counter() - t_start, f"{scenario}, {gyro} gyro at {rate:g} Hz, {imu} IMU")
