"""One long integration split across workers: the same output as :func:`~strapdown.io.integrate_file`.

:func:`integrate_split` integrates one file in P parts at once.  Attitude propagation with body rates is a
product ``q_N = q_0 ⊗ dq_0 ⊗ dq_1 ⊗ ... ⊗ dq_{N-1}``, and products are associative: each part is integrated
from the identity (in parallel), the parts' end quaternions are chained by a prefix product (P small
products), and each part is then rotated by its prefix, ``q_k = P_r ⊗ L_k`` (in parallel).  The result
equals the sequential integration to rounding (``tests/apps/test_batch.py``).  It needs methods whose step k uses
sample k alone (``exact``, ``first-order``, ``second-order``, ``cayley``); rk4 and the coning methods read
neighbouring samples across the cut, so increments, whose default method is ``coning2``, need one named
(:func:`check_split`).  The time checks of :func:`~strapdown.io.integrate_file` (increasing, ``max_gap``) also
hold across the cuts, and the first fault in the file is the one reported.
"""

from __future__ import annotations

import itertools
import shutil
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..._support.files import scratch_dir
from ..._support.pool import Runner, gather
from ...propagate.integrate import AttitudeIntegrator, SingularityError, integrate
from ...rotations.quaternion import multiply
from ..conventions import time_metadata
from ..imu import ImuColumns, ImuFile
from ..plausibility import TimeCheck
from ..readers import format_of, open_source
from ..tables import OutputSpec, attitude_columns
from ..writers import csv_comments, table_writer
from ._common import Report, metadata, options_of, output_path, rows_text
from .integrate import IntegrateOptions, integrate_axes, integrate_stream

__all__ = ["SPLIT_METHODS", "check_split", "integrate_split"]


#: The methods whose step k uses sample k alone: the only ones :func:`integrate_split` can cut.
SPLIT_METHODS = ("exact", "first-order", "second-order", "cayley")


@dataclass(frozen=True)
class _Part:
    """One part of a split integration (a row range), with everything a worker needs."""

    path: str
    start: int
    stop: int
    columns: ImuColumns
    method: str
    input: str
    rate_frame: str
    chunk_rows: int
    prefix: tuple | None = None  # the attitude at row `start` (second pass)
    out: OutputSpec | None = None
    part_file: str | None = None
    turn: tuple | None = None  # readings' axes -> the output's body axes (3 x 3, row by row), or None
    t0: float = 0.0  # the file's first time: output t counts from it (second pass)


def _part_stream(part: _Part, imu: ImuFile, box: dict):
    def tapped():
        m = None if part.turn is None else np.asarray(part.turn).reshape(3, 3)
        for chunk in imu.chunks(part.chunk_rows, part.start, part.stop):
            box["chunk"] = chunk  # as read, for messages naming the file's columns
            if m is not None:
                chunk = replace(chunk, gyro=chunk.gyro @ m.T)
            box.setdefault("first_t", float(chunk.t[0]))
            box["last_t"] = float(chunk.t[-1])
            box["last_g"] = chunk.gyro[-1].copy()
            yield chunk

    stream = integrate_stream(tapped(), method=part.method, input=part.input, rate_frame=part.rate_frame, rate=imu.rate)
    try:
        yield from stream
    except (ValueError, SingularityError) as exc:  # the integrator's words name no file
        raise ValueError(f"{part.path}: the integration failed on {rows_text(imu, box.get('chunk'))}: {exc}") from None


def _part_end(part: _Part) -> dict:
    """First pass: integrate the part from the identity; its end attitude, the samples at its edges, or its error.

    The error is returned, not raised, with the times read before it: the parent reports the first fault in
    the file, which may be a step across this part's first cut rather than this error.
    """
    box: dict = {}
    try:
        with ImuFile(part.path, part.columns, require=("gyro",), increments=part.input == "increment") as imu:
            end = np.array([1.0, 0.0, 0.0, 0.0])
            for _, q in _part_stream(part, imu, box):
                end = q[-1]
            box["end"] = end
            box["rate"] = imu.rate
    except Exception as exc:
        box["error"] = exc
    return box


def _part_write(part: _Part) -> int:
    """Second pass: integrate the part again, rotate it by its prefix and write it to its part file."""
    prefix = np.asarray(part.prefix)
    reference = part.rate_frame == "reference"
    rows = 0
    with ImuFile(part.path, part.columns, require=("gyro",), increments=part.input == "increment") as imu:
        with table_writer(part.part_file, part.out.format) as w:
            for t, q in _part_stream(part, imu, {}):
                q = multiply(q, prefix) if reference else multiply(prefix, q)
                w.write(attitude_columns(t - part.t0, q, part.out))
            rows = w.rows
    return rows


def integrate_split(
    path,
    output=None,
    options: IntegrateOptions | None = None,
    *,
    parts: int = 2,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[str], None] | None = None,
    **changes,
) -> Report:
    """Integrate one file in ``parts`` row ranges at once (module notes); the same output as :func:`integrate_file`.

    Parameters
    ----------
    path : path-like
        The gyro log.
    output : path-like, optional
        The output (default as for :func:`~strapdown.io.integrate_file`), written atomically.
    parts : int
        Row ranges integrated in parallel.
    scheduler, workers
        Where the parts run (as for :func:`strapdown.apps.batch.run_batch`).
    options : IntegrateOptions, optional
        As for :func:`~strapdown.io.integrate_file`; ``method`` one of ``SPLIT_METHODS``, or None when the
        default for ``input`` is one (:func:`check_split`).  Gaps stop a split integration (``on_gap`` must be
        ``"error"`` or the default, which means the same here): integrate the file whole to bridge them.
    **changes
        Fields of :class:`~strapdown.io.pipelines.IntegrateOptions` to replace, by name.
    progress : callable, optional
        Called with a line of text as each pass ends.

    Returns
    -------
    Report
        Files, rows and time taken.

    Raises
    ------
    ValueError
        As :func:`~strapdown.io.integrate_file` for the same file, with the same message (time running back or
        jumping by more than ``columns.max_gap`` periods is found across the cuts too); and when the method
        cannot be split.  Nothing is written then.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown import integrate
    >>> from strapdown.io.pipelines.split import integrate_split
    >>> from strapdown.io import ImuColumns, read_table, write_table
    >>> rng = np.random.default_rng(0)
    >>> gyro = rng.normal(size=(1000, 3))
    >>> path = write_table(pathlib.Path(tempfile.mkdtemp()) / "g.parquet",
    ...                    {"gx": gyro[:, 0], "gy": gyro[:, 1], "gz": gyro[:, 2]})
    >>> report = integrate_split(path, parts=4, workers=1, columns=ImuColumns(rate=100.0))
    >>> table = read_table(report.output)
    >>> q = np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])
    >>> bool(np.abs(q - integrate(gyro[:-1], dt=0.01)).max() < 1e-13)
    True
    """
    t_start = time.perf_counter()
    o = options_of(IntegrateOptions, options, changes, "integrate_split")
    method = check_split(parts, o.method, o.input)
    if o.on_gap not in ("auto", "error"):
        raise ValueError(f"a split integration stops at gaps (on_gap='error'), got on_gap={o.on_gap!r}")
    columns, out, input, rate_frame, chunk_rows = o.columns, o.out, o.input, o.rate_frame, o.chunk_rows
    output = output_path(path, output, "integrate", out.format)
    with ImuFile(path, columns, require=("gyro",), increments=input == "increment") as imu:
        n = imu.count_rows()
        read = imu.describe()
        if n == 0:
            raise ValueError(f"{path}: no rows")
        axes, meta = integrate_axes(imu, o.frame, o.body, o.out_body, rate_frame, out)
        meta = {**metadata("integrate", method=method or "default", input=input, rate_frame=rate_frame), **meta}
        turn = None if axes.matrix is None else tuple(axes.matrix.ravel().tolist())
        bounds = sorted(set(np.linspace(0, n, parts + 1).round().astype(int).tolist()))
        base = _Part(str(path), 0, 0, columns, method, input, rate_frame, chunk_rows, turn=turn)
        ranges = [replace(base, start=a, stop=b) for a, b in itertools.pairwise(bounds)]
        with Runner(scheduler, workers) as runner:
            ends = gather(runner.map(_part_end, ranges), len(ranges))
            # the file stays open for the checks across the cuts: a CSV file names rows by line
            _check_in_order(imu, chunk_rows, ranges, ends)
            if progress:
                progress(f"pass 1: {len(ranges)} parts integrated from the identity")
            prefixes = _prefixes(ends, o.q0, method, input, rate_frame)
            fmt = format_of(output, out.format)
            t0 = ends[0].get("first_t", 0.0)
            meta.update(time_metadata(imu, t0))
            meta["time_first_input_s"] = repr(t0)
            with scratch_dir(output) as scratch:
                files = [str(scratch / f"part{i:05d}.{fmt}") for i in range(len(ranges))]
                second = [
                    replace(r, prefix=tuple(p), out=replace(out, format=fmt), part_file=f, t0=t0)
                    for r, p, f in zip(ranges, prefixes, files, strict=True)
                ]
                rows = sum(gather(runner.map(_part_write, second), len(second)))
                if progress:
                    progress(f"pass 2: {len(second)} parts rotated by their prefixes and written")
                _concatenate(files, output, fmt, chunk_rows, meta)
    return Report(Path(path), output, rows, time.perf_counter() - t_start, read, [f"split into {len(ranges)} parts"])


def check_split(parts, method: str | None, input: str = "rate") -> str | None:
    """Check that an integration can be split, before anything is read: the method it then runs.

    Parameters
    ----------
    parts : int
        Row ranges, at least 1.
    method : str or None
        The method asked for; None for the default of :class:`~strapdown.AttitudeIntegrator`, which for
        ``input="increment"`` is ``coning2``: it cannot be split, so increments need a method named.
    input : str
        What a sample is, as for :func:`~strapdown.integrate`.

    Returns
    -------
    str or None
        ``method`` unchanged: None runs the same default as an integration of the whole file.

    Raises
    ------
    ValueError
        When ``parts`` is not a positive integer, or the method (given or default) is not in ``SPLIT_METHODS``.

    Examples
    --------
    >>> from strapdown.io.pipelines.split import check_split
    >>> check_split(4, None, "rate") is None, check_split(4, "cayley", "increment")
    (True, 'cayley')
    >>> check_split(4, None, "increment")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    ValueError: input='increment' integrates with method 'coning2' by default, which cannot be split: ...
    """
    if isinstance(parts, bool) or not (isinstance(parts, int) and parts >= 1):
        raise ValueError(f"parts must be a positive integer, got {parts!r}")
    runs = AttitudeIntegrator(method, input=input).method  # checks both names and resolves the default
    if runs in SPLIT_METHODS:
        return method
    if method is None:
        what = f"input={input!r} integrates with method {runs!r} by default, which"
    else:
        what = f"method {runs!r}"
    raise ValueError(
        f"{what} cannot be split: it reads neighbouring samples across a cut.  Name a method that can "
        f"({', '.join(SPLIT_METHODS)}), or integrate the file whole"
    )


def _check_in_order(imu: ImuFile, chunk_rows: int, ranges: Sequence[_Part], ends: list[dict]) -> None:
    """Raise the first fault in the file, as one sequential pass would: a part's own, or a step across a cut.

    The steps across the cuts go through the check that :func:`~strapdown.io.integrate_file` runs, with the
    sample period it would have estimated (from the file's first chunk), so the limits and messages are its.
    A part's own rows are judged with the period of the part's first chunk: the same on regularly sampled
    files, not to the last digit on jittery ones.
    """
    check = TimeCheck(imu)
    if check.period is None and len(ranges) > 1:
        for chunk in imu.chunks(chunk_rows):
            check(chunk.t, chunk.row)
            if check.period is not None:
                break
    for r, (part, box) in enumerate(zip(ranges, ends, strict=True)):
        if r and "first_t" in box:
            check.last = ends[r - 1]["last_t"]
            check(np.array([box["first_t"]]), part.start)
        if "error" in box:
            raise box["error"]


def _prefixes(ends: list[dict], q0, method: str | None, input: str, rate_frame: str) -> list[np.ndarray]:
    """The attitude at the first row of each part: P_{r+1} = P_r ⊗ E_r ⊗ S_r, S_r the step across the cut."""
    p = np.array([1.0, 0.0, 0.0, 0.0]) if q0 is None else np.asarray(q0, dtype=np.float64)
    p = p / np.linalg.norm(p)
    out = [p]
    reference = rate_frame == "reference"
    for before, after in itertools.pairwise(ends):
        g = before["last_g"][None]
        if input == "increment":
            step = integrate(g, method=method, input=input, rate_frame=rate_frame)[-1]
        else:
            # time increases across the cut (_check_in_order)
            h = 1.0 / before["rate"] if before["rate"] else after["first_t"] - before["last_t"]
            step = integrate(g, dt=h, method=method, input=input, rate_frame=rate_frame)[-1]
        p = multiply(step, multiply(before["end"], p)) if reference else multiply(multiply(p, before["end"]), step)
        out.append(p)
    return out


def _concatenate(files: Sequence[str], output: Path, fmt: str, chunk_rows: int, meta: dict) -> None:
    """Join part files into the output, atomically: CSV by bytes (one header), others by chunks of rows.

    ``meta`` is what :func:`~strapdown.io.integrate_file` stores with its table (CSV: comment lines).
    """
    if fmt == "csv":
        from ..._support.files import atomic_path

        with atomic_path(output) as tmp, open(tmp, "wb") as dst:
            dst.write(csv_comments(meta).encode())
            for i, f in enumerate(files):
                with open(f, "rb") as src:
                    header = src.readline()
                    if i == 0:
                        dst.write(header)
                    shutil.copyfileobj(src, dst, 1 << 24)
        return
    with table_writer(output, fmt, meta) as w:
        for f in files:
            with open_source(f, fmt) as src:
                names = list(src.fields)
                for _, cols in src.chunks(names, chunk_rows):
                    if "flags" in cols:
                        cols["flags"] = cols["flags"].astype(np.uint8)
                    if "segment" in cols:
                        cols["segment"] = cols["segment"].astype(np.int32)
                    w.write(cols)
