"""``strapdown integrate``: gyro readings of a file integrated into attitudes, streaming."""

from __future__ import annotations

import itertools
import time
from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np

from ...propagate.integrate import AttitudeIntegrator, SingularityError
from .._ahead import ReadAhead
from ..conventions import output_metadata, resolve_axes
from ..imu import ImuFile
from ..tables import OutputSpec, _attitude_columns
from ._common import (
    FileOptions,
    Report,
    Segments,
    gap_bridge,
    input_paths,
    metadata,
    options_of,
    output_path,
    read_columns,
    rows_text,
    with_progress,
)

__all__ = ["IntegrateOptions", "integrate_file", "integrate_stream"]


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
    >>> from strapdown.io.pipelines import integrate_stream
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


@dataclass(frozen=True)
class IntegrateOptions(FileOptions):
    """The options of :func:`integrate_file` (and ``strapdown integrate``), besides those of every file command.

    Attributes
    ----------
    method, input, rate_frame, q0
        As for :func:`strapdown.integrate`: the method (None: the default), ``"rate"`` or ``"increment"``
        readings, rates in the ``"body"`` or ``"reference"`` frame, and the initial attitude (identity).

    The fields of :class:`FileOptions` apply too.  Without ``frame`` the reference is the body's own axes at the
    first sample (turned by ``q0``), written as ``inertial``; with it, ``q0`` is given in that frame.
    ``out_body`` defaults to ``body``, or to the axes that go with ``frame`` when it is given.  At a gap
    (``on_gap`` other than ``"error"``) each segment starts again from ``q0``: the rotation during a gap is
    unknown.
    """

    method: str | None = None
    input: str = "rate"
    rate_frame: str = "body"
    q0: object = None


def integrate_file(path, output=None, options: IntegrateOptions | None = None, *, progress=None, **changes) -> Report:
    """Integrate the gyro readings of a file into attitudes and write them, streaming (constant memory).

    Parameters
    ----------
    path : path-like or sequence of path-like
        A file with gyro readings and a time column or rate, in any input format.
    output : path-like, optional
        CSV, Parquet, HDF5 or .mat file; by default ``<stem>.integrate.csv`` (``.parquet`` for Parquet input)
        beside the input.  Written atomically.
    options, **changes
        How to integrate, read and write: :class:`IntegrateOptions` (``method="rk4"``).

    Returns
    -------
    Report
        ``rows``: the attitudes written, one per input row; ``notes``: the frames and the gaps.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import ImuColumns, integrate_file, read_table, write_table
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
    o = options_of(IntegrateOptions, options, changes, "integrate_file")
    output = output_path(path, output, "integrate", o.out.format)
    columns = read_columns(o)
    stream = {"method": o.method, "input": o.input, "rate_frame": o.rate_frame, "q0": o.q0}
    with ImuFile(path, columns, require=("gyro",), increments=o.input == "increment") as imu:
        axes, frames = integrate_axes(imu, o.frame, o.body, o.out_body, o.rate_frame, o.out)
        meta = {**metadata("integrate", method=o.method or "default", input=o.input, rate_frame=o.rate_frame), **frames}
        run = Segments(imu, output, o.out, o.columns.max_gap, o.on_gap, meta, gap_bridge(o, imu))
        # the next chunks are read and checked by a thread of their own while this one is integrated
        with run, ReadAhead(imu.chunks(o.chunk_rows)) as chunks:
            pieces = run.pieces(with_progress(chunks, imu.rows, progress))
            for seg, group in itertools.groupby(pieces, key=lambda piece: piece[0]):
                turned = (_turned(chunk, axes) for _, chunk in group)
                try:
                    for t, q in integrate_stream(turned, **stream, rate=imu.rate):
                        run.write(seg, _attitude_columns(t, q, o.out, check=False, t0=run.t_first))
                except (ValueError, SingularityError) as exc:  # the integrator's words name no file
                    raise ValueError(
                        f"{path}: the integration failed on {rows_text(imu, run.current)}: {exc}"
                    ) from None
        report = Report(input_paths(path)[0], run.outputs[0], run.rows, time.perf_counter() - t_start, imu.describe())
        if o.frame is None:
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
