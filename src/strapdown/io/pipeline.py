"""File in, file out: integrate gyro logs, run an estimator, convert representations, simulate IMU files.

Each function streams its input through the library's streaming objects (:class:`strapdown.AttitudeIntegrator`
and the estimators of :data:`strapdown.evaluate.ESTIMATORS`, whose ``update`` on chunks equals one call on
everything), so memory stays constant whatever the file's size, and writes through
:func:`strapdown.io.table_writer`: the output appears, whole, only when everything succeeded.

Timing of ``integrate_file``: row k holds the sample of step k, which runs from row k's time to row k+1's (the
library's convention, :mod:`strapdown.integrate`); output row k is the attitude at row k's time, so the output
lines up with the input and the last sample, whose step ends after the file, is not used.  ``estimate_file``
follows the estimators (a sample acts over the interval that ends at it) and also writes one row per input row.
"""

from __future__ import annotations

import inspect
import itertools
import re
import time
from collections.abc import Callable, Iterator
from contextlib import ExitStack
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ..integrate import AttitudeIntegrator, SingularityError
from ._ahead import ReadAhead
from .conventions import GapSplitter, output_metadata, resolve_axes, time_metadata
from .imu import ImuColumns, ImuFile
from .readers import check_chunk_rows, format_of, open_source, require_rows
from .tables import (
    _ANGULAR,
    REPRESENTATIONS,
    Angles,
    OutputSpec,
    _attitude_columns,
    column_names,
    flag_bits,
    from_values,
    to_values,
)
from .writers import table_writer

__all__ = [
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

CHUNK_ROWS = 1 << 18  # rows in flight: about 400 bytes of memory each, and no speed to gain beyond

#: Called after each chunk with (rows done, total rows or None).
Progress = Callable[[int, int | None], None]


@dataclass
class Report:
    """What a file command did.

    Attributes
    ----------
    input, output : pathlib.Path or None
        The files.
    rows : int
        Rows written.
    seconds : float
        Wall time.
    read : str
        Which columns were read, in which units.
    notes : list of str
        What a user should know: frames, gaps, warnings (lines starting with ``warning:``).
    outputs : list of pathlib.Path
        Every file written (several with ``on_gap="split"``).
    """

    input: Path | None
    output: Path
    rows: int
    seconds: float
    read: str = ""
    notes: list = field(default_factory=list)
    outputs: list = field(default_factory=list)


def default_output(input, command: str, format: str | None = None) -> Path:
    """The output beside ``input``: ``<stem>.<command>.<csv|parquet>`` (CSV unless the input is Parquet).

    Parameters
    ----------
    input : path-like
        The input file.
    command : str
        ``"integrate"``, ``"estimate"``, ``"convert"``.
    format : {"csv", "parquet", "hdf5", "mat"}, optional
        The output format.

    Returns
    -------
    pathlib.Path
        The output path.

    Examples
    --------
    >>> from strapdown.io.pipeline import default_output
    >>> str(default_output("logs/a.parquet", "estimate")), str(default_output("b.mat", "integrate"))
    ('logs/a.estimate.parquet', 'b.integrate.csv')
    """
    input = Path(input)
    if format is None:
        try:
            format = "parquet" if format_of(input) == "parquet" else "csv"
        except ValueError:
            format = "csv"
    suffix = {"csv": ".csv", "parquet": ".parquet", "hdf5": ".h5", "mat": ".mat"}[format]
    return input.with_name(f"{input.stem}.{command}{suffix}")


def _metadata(command: str, **items) -> dict:
    from .. import __version__

    meta = {"strapdown_version": __version__, "strapdown_command": command}
    meta.update({k: str(v) for k, v in items.items() if v is not None})
    return meta


def _chunks_with_progress(chunks: Iterator, total: int | None, progress: Progress | None):
    done = 0
    for chunk in chunks:
        yield chunk
        done += len(chunk)
        if progress is not None:
            progress(done, total)


# ----------------------------------------------------------------------------------------------------------
def integrate_stream(
    chunks: Iterator, *, method=None, input="rate", rate_frame="body", q0=None, rate=None
) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Attitudes at the row times of a stream of IMU chunks, in pieces of (times, quaternions).

    Step k uses row k's sample from row k's time to row k+1's (the library's convention); the first row gets
    ``q0`` (identity by default) and the last row's sample is not used.  Memory: about one chunk.

    Parameters
    ----------
    chunks : iterator of ImuChunk
        Consecutive rows.
    method, input, rate_frame, q0
        As for :class:`strapdown.AttitudeIntegrator`.
    rate : float, optional
        The rows are ``1/rate`` apart (no time column): one ``dt`` for every step.

    Yields
    ------
    tuple of numpy.ndarray
        (t (n,), q (n, 4)); together one attitude per row, in order.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.imu import ImuChunk
    >>> from strapdown.io.pipeline import integrate_stream
    >>> t = np.arange(5) * 0.5
    >>> gyro = np.tile([0.0, 0.0, np.pi / 2], (5, 1))              # 90 deg/s about z
    >>> pieces = list(integrate_stream([ImuChunk(0, t[:2], gyro[:2]), ImuChunk(2, t[2:], gyro[2:])]))
    >>> np.concatenate([q for _, q in pieces])[-1].round(12)       # 180 deg after 2 s
    array([0., 0., 0., 1.])
    """
    integ = None
    waiting = _RowTimes()  # row times still waiting for their attitude
    held = None  # the last sample so far: its step ends at the next row's time
    for chunk in chunks:
        if not len(chunk):
            continue
        if integ is None:
            integ = AttitudeIntegrator(method, q0=q0, input=input, rate_frame=rate_frame, t0=float(chunk.t[0]))
            start = np.array([1.0, 0.0, 0.0, 0.0]) if q0 is None else np.asarray(q0, dtype=np.float64)
            yield chunk.t[:1], (start / np.linalg.norm(start))[None]
            waiting.push(chunk.t[1:])
            g, ends = chunk.gyro[:-1], chunk.t[1:]
        else:
            waiting.push(chunk.t)
            g, ends = np.concatenate([held, chunk.gyro[:-1]]), chunk.t
        held = chunk.gyro[-1:]
        if input == "increment":
            q = integ.update(g)
        elif rate is not None:
            q = integ.update(g, dt=1.0 / rate)
        else:
            q = integ.update(g, t=ends)
        if len(q):
            yield waiting.take(len(q)), q
    if integ is not None and integ.state is not None:
        q = integ.finish()
        if len(q):
            yield waiting.take(len(q)), q


class _RowTimes:
    """A queue of times, taken from the front as attitudes come out of the integrator."""

    def __init__(self):
        self.parts: list[np.ndarray] = []

    def push(self, t: np.ndarray) -> None:
        # an empty remainder (every attitude so far out) is dropped: take() then returns a view, not a copy
        self.parts = [p for p in self.parts if len(p)] + [t]

    def take(self, m: int) -> np.ndarray:
        everything = np.concatenate(self.parts) if len(self.parts) > 1 else self.parts[0]
        self.parts = [everything[m:]]
        return everything[:m]


def _inputs(path) -> list[Path]:
    """The files of one recording: one path, or the list of several (one per sensor)."""
    return [Path(p) for p in path] if isinstance(path, list | tuple) else [Path(path)]


def _output_path(path, output, command: str, format: str | None) -> Path:
    inputs = [] if path is None else _inputs(path)
    if output is not None:
        out = Path(output)
    elif len(inputs) > 1:  # one file per sensor: the output is named after their folder, beside them
        folder = inputs[0].parent
        out = default_output(folder / f"{folder.resolve().name or 'recording'}.csv", command, format)
    else:
        out = default_output(path, command, format)
    if any(out.resolve() == p.resolve() for p in inputs):
        raise ValueError(f"the output {out} is the input file; choose another output (-o)")
    return out


def integrate_file(
    path,
    output=None,
    *,
    columns: ImuColumns | None = None,
    out: OutputSpec | None = None,
    method: str | None = None,
    input: str = "rate",
    rate_frame: str = "body",
    q0=None,
    chunk_rows: int = CHUNK_ROWS,
    progress: Progress | None = None,
    frame: str | None = None,
    body: str | None = None,
    out_body: str | None = None,
    on_gap: str = "error",
) -> Report:
    """Integrate the gyro readings of a file into attitudes and write them, streaming (constant memory).

    Parameters
    ----------
    path : path-like
        CSV, Parquet, HDF5 or MATLAB file with gyro readings and a time column or rate.
    output : path-like, optional
        CSV, Parquet, HDF5 or .mat file; by default ``<stem>.integrate.csv`` (``.parquet`` for Parquet input)
        beside the input.  Written atomically.
    columns : ImuColumns, optional
        Column mapping and units (detected where left out).
    out : OutputSpec, optional
        Euler angles and format of the output.
    method, input, rate_frame, q0
        As for :func:`strapdown.integrate`.
    chunk_rows : int
        Rows per chunk.
    progress : callable, optional
        Called with (rows done, total rows or None) after each chunk.
    frame : str, optional
        The reference frame that ``q0`` is given in, written into the output; without it the reference is the
        body's own axes at the first sample (turned by ``q0``), written as ``inertial``.
    body, out_body : str, optional
        Axes of the readings and of the output attitudes, as for :func:`estimate_file` (``out_body`` defaults to
        ``body``, or to the axes that go with ``frame`` when it is given).
    on_gap : {"error", "split", "restart"}
        A time step over ``columns.max_gap`` sample periods: a ValueError (default); a file per segment; or one
        file with a ``segment`` column.  Either way each segment starts again from ``q0``: the rotation during
        a gap is unknown.

    Returns
    -------
    Report
        Files, rows and time taken.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import integrate_file, read_table, write_table
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> n = 101
    >>> _ = write_table(folder / "log.csv", {"t": np.arange(n) * 0.01, "gx": np.full(n, 90.0),
    ...                                      "gy": np.zeros(n), "gz": np.zeros(n)})
    >>> report = integrate_file(folder / "log.csv", columns=ImuColumns(gyro_unit="deg/s"))
    >>> report.output.name, report.rows
    ('log.integrate.csv', 101)
    >>> read_table(report.output)["roll_deg"][[0, 50, 100]].round(9)     # 90 deg/s for 0.5 s and 1 s
    array([ 0., 45., 90.])
    """
    t_start = time.perf_counter()
    chunk_rows = check_chunk_rows(chunk_rows)
    out = out or OutputSpec()
    if on_gap not in ON_GAP:
        raise ValueError(f"on_gap must be one of {', '.join(ON_GAP)}, got {on_gap!r}")
    output = _output_path(path, output, "integrate", out.format)
    columns = columns or ImuColumns()
    gap_limit = columns.max_gap
    if on_gap != "error":
        columns = replace(columns, max_gap=0)
    with ImuFile(path, columns, require=("gyro",), increments=input == "increment") as imu:
        axes, frames = integrate_axes(imu, frame, body, out_body, rate_frame, out)
        meta = {**_metadata("integrate", method=method or "default", input=input, rate_frame=rate_frame), **frames}
        run = _Segments(imu, output, out, gap_limit if on_gap != "error" else 0, on_gap, meta)
        # the next chunks are read and checked by a thread of their own while this one is integrated
        with run, ReadAhead(imu.chunks(chunk_rows)) as chunks:
            pieces = run.pieces(_chunks_with_progress(chunks, imu.rows, progress))
            for seg, group in itertools.groupby(pieces, key=lambda piece: piece[0]):
                turned = (_turned(chunk, axes) for _, chunk in group)
                opts = {"method": method, "input": input, "rate_frame": rate_frame, "q0": q0, "rate": imu.rate}
                try:
                    for t, q in integrate_stream(turned, **opts):
                        columns = _attitude_columns(t, q, out, check=False, t0=run.t_first)
                        run.write(seg, columns)
                except (ValueError, SingularityError) as exc:  # the integrator's words name no file
                    raise ValueError(f"{path}: the integration failed on {_rows(imu, run.current)}: {exc}") from None
        report = Report(_inputs(path)[0], run.outputs[0], run.rows, time.perf_counter() - t_start, imu.describe())
        if frame is None:
            report.notes.append(f"attitude of the {axes.body} axes relative to themselves at t = 0 (turned by q0)")
        else:
            report.notes.append(axes.describe())
        report.notes.extend(run.notes)
        report.outputs = run.outputs
        return report


def integrate_axes(imu, frame, body, out_body, rate_frame: str, out: OutputSpec):
    """The axes of an integration, and their metadata: without a frame the reference is the body at t = 0."""
    if frame is None and out_body is None:
        out_body = body or getattr(imu, "body", None)  # no frame to go with: the readings' own axes
    axes = resolve_axes(imu, frame, body, out_body)
    if axes.matrix is not None and rate_frame != "body":
        raise ValueError("--body turns body rates; rates in the reference frame (--rate-frame reference) cannot be")
    meta = {**axes.metadata(), **output_metadata(out)}
    if frame is None:
        meta["frame"] = "inertial (the body axes at t = 0, turned by q0)"
    return axes, meta


def _turned(chunk, axes):
    if axes.matrix is not None:  # a new chunk: the one read stays as read, for messages naming its columns
        chunk = replace(chunk, gyro=axes.rotate(chunk.gyro))
    return chunk


def estimator_inputs(cls) -> tuple[str, ...]:
    """The extra keyword inputs an estimator's ``update`` takes (``known_acc``, ``pitch_roll``, ...).

    Parameters
    ----------
    cls : type
        An estimator class.

    Returns
    -------
    tuple of str
        Keyword-only parameters other than the timing.

    Examples
    --------
    >>> from strapdown.fusion import Mahony, TiltEstimator
    >>> from strapdown.io.pipeline import estimator_inputs
    >>> estimator_inputs(TiltEstimator), estimator_inputs(Mahony)
    (('known_acc', 'pitch_roll'), ())
    """
    sig = inspect.signature(cls.update)
    skip = {"dt", "t", "degrees"}
    return tuple(n for n, p in sig.parameters.items() if p.kind is inspect.Parameter.KEYWORD_ONLY and n not in skip)


def estimate_file(
    path,
    output=None,
    *,
    estimator: str = "attitude",
    params=None,
    frame: str | None = None,
    mag: bool | None = None,
    q0=None,
    columns: ImuColumns | None = None,
    out: OutputSpec | None = None,
    chunk_rows: int = CHUNK_ROWS,
    progress: Progress | None = None,
    body: str | None = None,
    out_body: str | None = None,
    on_gap: str = "error",
    calibration=None,
    declination: float | None = None,
) -> Report:
    """Run an estimator of :data:`strapdown.evaluate.ESTIMATORS` over a file and write its attitudes, streaming.

    Parameters
    ----------
    path : path-like
        CSV, Parquet, HDF5 or MATLAB file with gyro and accelerometer (and magnetometer) readings.
    output : path-like, optional
        Output file; by default ``<stem>.estimate.csv`` (``.parquet`` for Parquet input) beside the input.
    estimator : str
        A key of :data:`strapdown.evaluate.ESTIMATORS` (default: the AttitudeEstimator).
    params : mapping or parameter object, optional
        Parameters (a mapping overrides the defaults by name; validated).
    frame : str, optional
        Reference frame of the output (``"ENU"``, ``"NED"``, ``"NWU"``, ...); by default the input format's
        preset (a PX4 log is NED), else ENU.
    mag : bool, optional
        Use the magnetometer (9D): None uses it when the file has one and the estimator takes one; True
        requires it; False leaves it out.
    q0 : array_like, shape (4,), optional
        Initial attitude in ``frame``; by default from the first sample.
    columns : ImuColumns, optional
        Column mapping and units; ``extra`` gives the estimator's further inputs (``known_acc``, ``pitch_roll``).
    out : OutputSpec, optional
        Euler angles, bias, flags and format of the output.
    chunk_rows : int
        Rows per chunk.
    progress : callable, optional
        Called with (rows done, total rows or None) after each chunk.
    body : str, optional
        Axes of the readings (``"FRD"``, ``"FLU"``, ...); by default the format's preset, else taken to be
        ``out_body``.  Readings are re-expressed in ``out_body`` before the estimator sees them.
    out_body : str, optional
        Body axes of the output attitudes; by default those that go with ``frame``
        (:func:`strapdown.io.conventions.natural_body`: FRD for NED, FLU for ENU and NWU), so that a level
        vehicle has zero roll and pitch.
    on_gap : {"error", "split", "restart"}
        A time step over ``columns.max_gap`` sample periods: a ValueError (default); a new output file per
        segment (``<stem>-2.csv`` ...) with the estimator started afresh; or one file with the estimator
        started afresh after each gap and a ``segment`` column.
    calibration : mapping of str to strapdown.calibrate.Calibration, optional
        Calibrations by sensor (``"gyroscope"``, ``"accelerometer"``, ``"magnetometer"``, as
        :func:`strapdown.calibrate.load` returns them), applied to the readings in their own axes before
        anything else.
    declination : float, optional
        Magnetic declination (radians, east positive): the 9D heading is turned from magnetic to true north.
        The metadata says which (``heading`` = ``true``, ``magnetic`` or ``free`` for 6D).

    Returns
    -------
    Report
        Files, rows and time taken; ``notes`` holds the gaps and a warning when the bias sits at its limit.

    Notes
    -----
    Output columns: ``t`` (s from the first sample), ``qw..qz``, Euler angles, ``bias_*`` (the unit in the
    name), ``flags`` (bit mask of :func:`strapdown.io.tables.flag_bits`) and one boolean column per flag:
    ``rest``, ``acc_rejected``, ``mag_rejected``, ``inverted``, ``bias_at_limit``.  Metadata:
    :mod:`strapdown.io.conventions`.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import estimate_file, read_table, write_table
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> n = 500
    >>> level = {"t": np.arange(n) * 0.01, "gx": np.zeros(n), "gy": np.zeros(n), "gz": np.zeros(n),
    ...          "ax": np.zeros(n), "ay": np.zeros(n), "az": np.full(n, 9.81)}
    >>> report = estimate_file(write_table(folder / "still.parquet", level), estimator="mahony")
    >>> table = read_table(report.output)
    >>> report.output.name, table["pitch_deg"][-1].round(9), table["roll_deg"][-1].round(9)
    ('still.estimate.parquet', np.float64(0.0), np.float64(0.0))
    """
    from ..evaluate import ESTIMATORS, make_params

    t_start = time.perf_counter()
    chunk_rows = check_chunk_rows(chunk_rows)
    p = make_params(estimator, params)  # also rejects an unknown estimator, listing the known ones
    cls, _, takes_mag = ESTIMATORS[estimator]
    columns = columns or ImuColumns()
    out = out or OutputSpec()
    allowed = estimator_inputs(cls)
    for name, _ in columns.extra:
        if name not in allowed:
            listing = ", ".join(allowed) or "none"
            raise ValueError(f"{estimator} takes no input {name!r} (--extra); its extra inputs: {listing}")
    if mag and not takes_mag:
        raise ValueError(f"{estimator} does not take a magnetometer (6D only): leave out --mag / --9d")
    extra_names = [name for name, _ in columns.extra]
    require = ("gyro",) + (() if "pitch_roll" in extra_names else ("acc",)) + (("mag",) if mag else ())
    optional = ("mag",) if (takes_mag and mag is None) else ()
    if on_gap not in ON_GAP:
        raise ValueError(f"on_gap must be one of {', '.join(ON_GAP)}, got {on_gap!r}")
    output = _output_path(path, output, "estimate", out.format)
    limit = getattr(p, "bias_limit", None)
    gap_limit = columns.max_gap
    if on_gap != "error":  # the reader lets gaps through; they are cut here
        columns = replace(columns, max_gap=0)
    with ImuFile(path, columns, require=require, optional=optional) as imu:
        sparse = set(getattr(imu, "sparse", ()) or ())
        if sparse and not cls.missing_samples:
            raise ValueError(
                f"{path}: the {' and '.join(sorted(sparse))} readings come at a lower rate than the gyro (rows "
                f"without a sample); {estimator} needs a sample of every sensor on every row: use -e attitude, "
                "which takes rows without a sample"
            )
        axes = resolve_axes(imu, frame, body, out_body)
        use_mag = "mag" in imu.picks
        from ..calibrate import _apply, to_true_north  # calibration and true north (strapdown.calibrate)

        cal = _apply.by_sensor(calibration)
        _apply.check_axes(cal, axes.sensor, axes.declared)
        meta = _metadata("estimate", estimator=estimator, mode="9D" if use_mag else "6D")
        meta.update(_apply.heading_metadata(use_mag, declination, cal))
        meta.update(axes.metadata())
        meta.update(output_metadata(out, bias=cls.estimates_bias, flags=cls.reports_flags))
        run = _Segments(imu, output, out, gap_limit if on_gap != "error" else 0, on_gap, meta)
        est = None
        warned = False
        with run, ReadAhead(imu.chunks(chunk_rows)) as chunks:
            for seg, chunk in run.pieces(_chunks_with_progress(chunks, imu.rows, progress)):
                if seg != run.segment_of_estimator:
                    # a new segment starts from its own first sample; q0 is the first segment's only
                    est = cls(p, q0=q0 if est is None else None, frame=axes.frame)
                    run.segment_of_estimator = seg
                timing = {"dt": 1.0 / imu.rate} if imu.rate else {"t": chunk.t}
                extra = {k: axes.rotate(v) if k == "known_acc" else v for k, v in chunk.extra.items()}
                gyro, acc, mag = _apply.readings(cal, chunk.gyro, chunk.acc, chunk.mag if use_mag else None)
                mag_in = axes.rotate(mag) if use_mag else None
                try:
                    e = est.update(axes.rotate(gyro), axes.rotate(acc), mag_in, **timing, **extra)
                except ValueError as exc:  # the estimator's own words name its arrays, not the file
                    k = getattr(exc, "sample", None)  # strapdown._validate.SampleError: one sample of the chunk
                    where = _rows(imu, chunk) if k is None else imu.where(chunk.row + k)
                    raise ValueError(f"{path}: {estimator} failed at {where}: {exc}") from None
                lost = np.flatnonzero(~np.isfinite(e.q).all(axis=1))
                if lost.size:
                    i = int(lost[0])
                    raise ValueError(
                        f"{path}: the {estimator} estimator lost the attitude at {_culprit(imu, chunk, i)}: a "
                        "reading that large is not plausible; check that row and the units"
                    )
                at_limit = None
                if limit and e.bias is not None:
                    # Mahony-type filters clip each axis at bias_limit (a bias there says the limit, not the gyro);
                    # the AttitudeEstimator and TiltEstimator treat it as a prior's bound and set the flag bit
                    at_limit = (np.abs(e.bias) >= limit * (1.0 - 1e-9)).any(axis=1)
                    if e.flags is not None:
                        at_limit |= (np.asarray(e.flags) & flag_bits()["bias_at_limit"]) != 0
                    if at_limit.any() and not warned:
                        warned = True
                        i = int(np.argmax(at_limit))
                        run.notes.append(_bias_warning(e.bias[i], limit, run.t(chunk)[i], imu.where(chunk.row + i)))
                q = e.q if declination is None else to_true_north(e.q, declination, frame=axes.frame)
                columns = _attitude_columns(chunk.t, q, out, e.bias, e.flags, at_limit, check=False, t0=run.t_first)
                run.write(seg, columns)
        report = Report(_inputs(path)[0], run.outputs[0], run.rows, time.perf_counter() - t_start, imu.describe())
        report.notes.append(f"{estimator} {'9D' if use_mag else '6D'}, {axes.describe()}")
        report.notes.extend(run.notes)
        report.outputs = run.outputs
        return report


ON_GAP = ("error", "split", "restart")


def _bias_warning(bias, limit: float, t: float, where: str) -> str:
    axis = "xyz"[int(np.argmax(np.abs(bias)))]
    return (
        f"warning: the gyro bias estimate reached bias_limit = {np.degrees(limit):.3g} deg/s (clipped there, or past "
        f"the bound of the estimator's prior) on the {axis} axis at "
        f"t = {t:.6g} s ({where}); the bias_at_limit column says where.  A bias that large is beyond what the "
        "estimator assumes of the sensor: check the gyro's unit (--gyro-unit), or raise -p bias_limit_deg_s=..."
    )


class _Segments:
    """The output side of a file command: relative time, gaps (``on_gap``), one writer per segment file."""

    def __init__(self, imu, output: Path, out: OutputSpec, max_gap: float, on_gap: str, meta: dict):
        self.imu, self.output, self.out, self.on_gap, self.meta = imu, Path(output), out, on_gap, meta
        self.splitter = GapSplitter(max_gap, getattr(imu, "period", None)) if on_gap != "error" else None
        self.t_first: float | None = None
        self.writers: dict[int, object] = {}
        self.outputs: list[Path] = []
        self.notes: list[str] = []
        self.rows = 0
        self.segment_of_estimator = -1
        self.current = None  # the chunk in flight, for messages
        self._stack = ExitStack()

    def __enter__(self):
        self._stack.__enter__()
        return self

    def __exit__(self, *exc):
        if exc[0] is None:
            if not self.writers:  # no rows: the reader said so already, but never leave without a file
                self._writer(0)
            if self.splitter is not None and self.splitter.gaps:
                listing = "; ".join(f"{a:.6g} s -> {b:.6g} s" for a, b in self.splitter.gaps[:5])
                more = f" and {len(self.splitter.gaps) - 5} more" if len(self.splitter.gaps) > 5 else ""
                how = "a file per segment" if self.on_gap == "split" else "started afresh after each gap"
                self.notes.append(f"{len(self.splitter.gaps)} gap(s) ({how}): {listing}{more}")
        return self._stack.__exit__(*exc)

    def t(self, chunk) -> np.ndarray:
        """Seconds from the first sample of the file."""
        self._start(chunk)
        return chunk.t - self.t_first

    def _start(self, chunk) -> None:
        """The time origin, from the first chunk."""
        if self.t_first is None:
            self.t_first = float(chunk.t[0]) if len(chunk) else 0.0
            self.meta.update(time_metadata(self.imu, self.t_first))
            self.meta["time_first_input_s"] = repr(self.t_first)

    def pieces(self, chunks):
        """(segment, chunk) in order, the chunks cut at the gaps."""
        seg = 0
        for chunk in chunks:
            if not len(chunk):
                continue
            self._start(chunk)
            cuts = [] if self.splitter is None else list(self.splitter(self.t(chunk)))
            start = 0
            for i in [*cuts, len(chunk)]:
                if i > start:
                    self.current = _slice(chunk, start, i)
                    yield seg, self.current
                if i < len(chunk):
                    seg += 1
                start = i

    def _writer(self, seg: int):
        key = seg if self.on_gap == "split" else 0
        if key not in self.writers:
            name = f"{self.output.stem}-{key + 1}{self.output.suffix}"
            path = self.output if key == 0 else self.output.with_name(name)
            meta = dict(self.meta)
            if self.on_gap == "split":
                meta["segment"] = str(key)
            self.writers[key] = self._stack.enter_context(table_writer(path, self.out.format, meta))
            self.outputs.append(path)
        return self.writers[key]

    def write(self, seg: int, columns: dict) -> None:
        if self.on_gap == "restart":
            columns["segment"] = np.full(len(columns["t"]), seg, dtype=np.int32)
        w = self._writer(seg)
        # attitude_columns made new arrays for every chunk: no copy needed
        w.write(columns, copy=False)
        self.rows += len(columns["t"])


#: Readings of a common size in SI units, to find the one most out of scale: rad/s (or rad), m/s², µT.
_TYPICAL = {"gyro": 1.0, "acc": 9.81, "mag": 50.0}
_SI = {"gyro": "rad/s", "acc": "m/s²", "mag": "µT"}


def _culprit(imu, chunk, row: int | None = None) -> str:
    """The reading of a chunk (or of one of its rows) most out of scale, by line and column, for messages.

    A non-finite reading comes first, then the largest relative to its quantity's usual size.  The unit check
    looks at a percentile of the first rows, so one absurd value further on gets through it and fails in the
    integrator or the filter, whose words name their own arrays: this names the file's line and column instead.
    """
    best = None
    for kind, typical in _TYPICAL.items():
        v = getattr(chunk, kind, None)
        if v is None or kind not in imu.picks or not len(v):
            continue
        part = v if row is None else v[row : row + 1]
        size = np.abs(part) / typical  # inf stays inf
        # NaN: no sample of a slower sensor on the gyro's rows (imu.sparse), otherwise a reading gone wrong
        size[np.isnan(size)] = 0.0 if kind in (getattr(imu, "sparse", None) or ()) else np.inf
        i, j = np.unravel_index(int(np.argmax(size)), size.shape)
        if best is None or size[i, j] > best[0]:
            best = (size[i, j], kind, i + (row or 0), j)
    if best is None:
        return "no reading"
    _, kind, i, j = best
    fields = imu.picks[kind].fields
    column = fields[j] if len(fields) == 3 else f"{fields[0]}[{j}]"
    unit = "rad" if kind == "gyro" and getattr(imu, "increments", False) else _SI[kind]
    return f"{imu.where(chunk.row + i)}, column {column} = {getattr(chunk, kind)[i, j]:.4g} {unit}"


def _rows(imu, chunk) -> str:
    """The rows of a chunk as a user finds them ("lines 2 to 201" in a CSV file), and its worst reading."""
    if chunk is None:
        return "its first rows"
    first, last = imu.where(chunk.row), imu.where(chunk.row + len(chunk) - 1)
    return (
        f"{first.split()[0]}s {first.split()[-1]} to {last.split()[-1]} (the reading most out of scale there: "
        f"{_culprit(imu, chunk)})"
    )


def _slice(chunk, a: int, b: int):
    from .imu import ImuChunk

    if (a, b) == (0, len(chunk)):
        return chunk
    part = ImuChunk(chunk.row + a, chunk.t[a:b], chunk.gyro[a:b])
    part.acc = None if chunk.acc is None else chunk.acc[a:b]
    part.mag = None if chunk.mag is None else chunk.mag[a:b]
    part.extra = {k: v[a:b] for k, v in chunk.extra.items()}
    return part


_QUAT_NAMES = (
    ("qw", "qx", "qy", "qz"),
    ("q_w", "q_x", "q_y", "q_z"),
    ("quat_w", "quat_x", "quat_y", "quat_z"),
    ("q0", "q1", "q2", "q3"),
    ("w", "x", "y", "z"),
)
_QUAT_ARRAYS = ("q", "quat", "quaternion", "quaternions", "opt_quat", "orientation")


def _angle_unit(fields) -> bool | None:
    """True (degrees) or False (radians) when every field's name ends in ``_deg`` or every one in ``_rad``."""
    ends = {m.group(1).lower() if (m := re.search(r"[_ ](deg|rad)$", f, re.IGNORECASE)) else None for f in fields}
    return {"deg": True, "rad": False}.get(ends.pop()) if len(ends) == 1 else None


def _representation_fields(fields: dict, rep: str, angles: Angles, given: str | None) -> tuple:
    from .columns import describe_fields, pick_vector

    width = REPRESENTATIONS[rep]
    if given:
        return pick_vector(given, fields, "--columns", width=width).fields
    # the names this package writes, in the declared unit first and then in the other one
    candidates = [
        tuple(column_names(rep, angles)),
        tuple(column_names(rep, replace(angles, degrees=not angles.degrees))),
    ]
    if rep == "quat":
        candidates += list(_QUAT_NAMES)
    for names in candidates:
        if all(fields.get(n) == 1 for n in names):
            return names
    for name, w in fields.items():
        if w == width and (rep != "quat" or name.split("/")[-1].lower() in _QUAT_ARRAYS):
            return (name,)
    raise ValueError(
        f"no {rep} columns found (looked for {', '.join(candidates[0])}); name them with --columns.  The file has: "
        f"{describe_fields(fields)}"
    )


def convert_values(values: np.ndarray, source: str, target: str, angles_in: Angles, angles_out: Angles):
    """Convert an (N, width) array between representations; rows with NaN stay NaN (unknown attitudes).

    Parameters
    ----------
    values : numpy.ndarray, shape (N, REPRESENTATIONS[source])
        Input rows.
    source, target : str
        Keys of :data:`strapdown.io.tables.REPRESENTATIONS`.
    angles_in, angles_out : Angles
        Sequences and units of the input and output.

    Returns
    -------
    numpy.ndarray, shape (N, REPRESENTATIONS[target])
        The converted rows.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.pipeline import convert_values
    >>> from strapdown.io.tables import Angles
    >>> convert_values(np.array([[90.0, 0, 0], [np.nan, 0, 0]]), "euler", "quat", Angles(), Angles()).round(6)
    array([[0.707107, 0.      , 0.      , 0.707107],
           [     nan,      nan,      nan,      nan]])
    """
    values = np.asarray(values, dtype=np.float64)
    unknown = np.isnan(values).any(axis=1)
    infinite = np.flatnonzero(~unknown & ~np.isfinite(values).all(axis=1))
    if infinite.size:
        raise RowError(int(infinite[0]), "an infinite value (a NaN row is an unknown attitude; inf is not)")
    ok = ~unknown
    if source == "quat":
        zero = np.flatnonzero(ok & ~(np.abs(values) > 0).any(axis=1))
        if zero.size:
            raise RowError(int(zero[0]), "a zero quaternion, which is no attitude")
    if source in _ANGULAR:
        # beyond about 1e9 turns' worth the angle has no digits left below a turn: no attitude can be read from it
        limit = 360.0 * 1e9 if angles_in.degrees else 2 * np.pi * 1e9
        angular = values[:, -1:] if source == "axis_angle" else values
        big = np.flatnonzero(ok & (np.abs(angular) > limit).any(axis=1))
        if big.size:
            unit = "deg" if angles_in.degrees else "rad"
            raise RowError(int(big[0]), f"an angle beyond ±{limit:.3g} {unit}: no digits are left below a turn")
    out = np.full((values.shape[0], REPRESENTATIONS[target]), np.nan)
    if ok.any():
        rows = values[ok]
        if source == "quat":
            # a quaternion's attitude does not depend on its scale: bring the largest component to 1 first, so
            # that 1e300 or 5e-324 components neither overflow nor underflow the norm (exact: a division)
            rows = rows / np.abs(rows).max(axis=1, keepdims=True)
        try:
            converted = to_values(target, from_values(source, rows, angles_in), angles_out)
        except ValueError:
            row, problem = _first_refused(rows, source, target, angles_in, angles_out)
            raise RowError(int(np.flatnonzero(ok)[row]), problem) from None
        bad = np.flatnonzero(~np.isfinite(converted).all(axis=1))
        if bad.size:  # a Gibbs vector of a half turn, say: no finite number says it
            row = int(np.flatnonzero(ok)[bad[0]])
            raise RowError(row, f"an attitude the {target} representation cannot hold ({converted[bad[0]].tolist()})")
        out[ok] = converted
    return out


def _first_refused(rows, source, target, angles_in, angles_out) -> tuple[int, str]:
    """The first row the conversion refuses, found by halving (only after a failure), and the reason.

    The library names its own arrays and their indices ("c[0] is not a rotation matrix"): the reason is given
    without that name, for the caller to put the file's line in front.
    """
    lo, hi = 0, len(rows)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        try:
            to_values(target, from_values(source, rows[lo:mid], angles_in), angles_out)
        except ValueError:
            hi = mid
        else:
            lo = mid
    try:
        to_values(target, from_values(source, rows[lo:hi], angles_in), angles_out)
    except ValueError as exc:
        reason = re.sub(r"^[A-Za-z_]\w*(\[0\])? (is )?", "", str(exc))
    else:  # pragma: no cover - the rows fail together but no row alone
        reason = "values the conversion refuses"
    return lo, f"values the {source} to {target} conversion refuses ({reason})"


class RowError(ValueError):
    """A bad input row: ``row`` (0-based within the array) and what is wrong with it, for the caller to place."""

    def __init__(self, row: int, problem: str):
        super().__init__(f"row {row} holds {problem}")
        self.row, self.problem = row, problem


def convert_file(
    path,
    output=None,
    *,
    source: str = "quat",
    target: str = "euler",
    columns: str | None = None,
    time_column: str | None = None,
    angles_in: Angles | None = None,
    angles_out: Angles | None = None,
    format: str | None = None,
    out_format: str | None = None,
    chunk_rows: int = CHUNK_ROWS,
    progress: Progress | None = None,
    unit_from_names: bool = True,
) -> Report:
    """Convert the attitudes in a file from one representation to another, streaming.

    Parameters
    ----------
    path : path-like
        CSV, Parquet, HDF5 or MATLAB file.
    output : path-like, optional
        Output file; by default ``<stem>.convert.csv`` (``.parquet`` for Parquet input) beside the input.
    source, target : str
        Keys of :data:`strapdown.io.tables.REPRESENTATIONS`.
    columns : str, optional
        The input columns, comma-separated, or one (N, k) array; by default the names this package writes
        (``qw,qx,qy,qz``, ``yaw_deg,pitch_deg,roll_deg``, ...) or, for quaternions, common alternatives.
    time_column : str, optional
        A column copied to the output first; by default a detected time column, if any.
    angles_in, angles_out : Angles, optional
        Euler sequence, unit and range of input and output (default: ``Angles()``, ZYX in degrees).
    format, out_format : str, optional
        Formats when the suffixes do not tell them.
    chunk_rows : int
        Rows per chunk.
    progress : callable, optional
        Called with (rows done, total rows or None) after each chunk.
    unit_from_names : bool
        Input columns whose names end in ``_deg`` or ``_rad`` hold angles in that unit: True takes it (for
        the input, and for the output too), False requires ``angles_in`` to agree (ValueError otherwise).

    Returns
    -------
    Report
        Files, rows and time taken.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import convert_file, read_table, write_table
    >>> path = write_table(pathlib.Path(tempfile.mkdtemp()) / "q.csv",
    ...                    {"t": np.array([0.0, 1.0]), "qw": np.array([1.0, 0.0]), "qx": np.zeros(2),
    ...                     "qy": np.zeros(2), "qz": np.array([0.0, 1.0])})
    >>> table = read_table(convert_file(path, target="rotvec").output)
    >>> list(table), table["rotvec_z_deg"].round(9)
    (['t', 'rotvec_x_deg', 'rotvec_y_deg', 'rotvec_z_deg'], array([  0., 180.]))
    """
    from .columns import detect_time, pick_vector

    t_start = time.perf_counter()
    chunk_rows = check_chunk_rows(chunk_rows)
    angles_in, angles_out = angles_in or Angles(), angles_out or Angles()
    output = _output_path(path, output, "convert", out_format)
    with open_source(path, format) as src:
        fields = _representation_fields(src.fields, source, angles_in, columns)
        named = _angle_unit(fields[-1:] if source == "axis_angle" else fields) if source in _ANGULAR else None
        if named is not None and named != angles_in.degrees:
            if not unit_from_names:
                unit = "degrees" if named else "radians"
                raise ValueError(
                    f"the columns {', '.join(fields)} are named in {unit}, but the angles were declared in "
                    f"{'degrees' if angles_in.degrees else 'radians'}; leave the unit out or declare {unit}"
                )
            # the names say the unit: reading yaw_deg as radians would be a silent, plausible-looking error
            angles_in, angles_out = replace(angles_in, degrees=named), replace(angles_out, degrees=named)
        names_out = column_names(target, angles_out)
        tcol = pick_vector(time_column, src.fields, "--time", width=1) if time_column else detect_time(src.fields)
        tname = tcol.fields[0] if tcol and tcol.fields[0] not in fields else None
        wanted = ([tname] if tname else []) + list(fields)
        done = 0
        meta = _metadata("convert", source=source, target=target)
        with table_writer(output, out_format, meta) as w:
            for row, cols in src.chunks(wanted, chunk_rows):
                values = cols[fields[0]] if len(fields) == 1 else np.column_stack([cols[f] for f in fields])
                try:
                    converted = convert_values(values, source, target, angles_in, angles_out)
                except RowError as exc:
                    raise ValueError(
                        f"{path}: {src.where(row + exc.row)} ({', '.join(fields)}) holds {exc.problem}"
                    ) from None
                table = {tname: cols[tname]} if tname else {}
                table.update(zip(names_out, converted.T, strict=True))
                w.write(table)
                done += len(values)
                if progress is not None:
                    progress(done, src.rows)
            require_rows(path, done)  # inside the writer's block, so that no output appears
        return Report(Path(path), output, w.rows, time.perf_counter() - t_start, f"{source}: {','.join(fields)}")


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
    from ..simulate import ImuModel, sample
    from ..simulate.scenarios import scenario as make
    from .units import parse_unit, scale

    t_start = time.perf_counter()
    if imu not in _IMUS:
        raise ValueError(f"imu must be one of {', '.join(_IMUS)}, got {imu!r}")
    model = {"ideal": ImuModel.ideal, "consumer": ImuModel.consumer_mems, "tactical": ImuModel.tactical}[imu]()
    data = sample(
        make(scenario), rate, gyro=gyro, imu=model, seed=seed, reference=reference, body=body, duration=duration
    )
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
    meta = _metadata(
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
    from .writers import write_table

    path = write_table(output, cols, format, meta)
    return Report(None, path, n, time.perf_counter() - t_start, f"{scenario}, {gyro} gyro at {rate:g} Hz, {imu} IMU")
