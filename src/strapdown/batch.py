"""Many files in parallel, and one long integration split across workers.

:func:`run_batch` runs file jobs (:class:`Job`: integrate, estimate or convert one file) on the local cores
(a process pool) or on a Dask cluster (``scheduler="tcp://host:port"``, from the ``dask`` extra; the workers
must see the same file system).  Every output is written atomically, and a job that fails is reported in its
:class:`JobResult` without stopping the others.

:func:`integrate_split` integrates one file in P parts at once.  Attitude propagation with body rates is a
product ``q_N = q_0 ⊗ dq_0 ⊗ dq_1 ⊗ ... ⊗ dq_{N-1}``, and products are associative: each part is integrated
from the identity (in parallel), the parts' end quaternions are chained by a prefix product (P small
products), and each part is then rotated by its prefix, ``q_k = P_r ⊗ L_k`` (in parallel).  The result
equals the sequential integration to rounding (``tests/test_batch.py``).  It needs methods whose step k uses
sample k alone (``exact``, ``first-order``, ``second-order``, ``cayley``); rk4 and the coning methods read
neighbouring samples across the cut, so increments, whose default method is ``coning2``, need one named
(:func:`check_split`).  The time checks of :func:`~strapdown.io.integrate_file` (increasing, ``max_gap``) also
hold across the cuts, and the first fault in the file is the one reported.
"""

from __future__ import annotations

import functools
import glob
import itertools
import os
import shutil
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ._files import scratch_dir
from .integrate import AttitudeIntegrator, SingularityError, integrate
from .io.conventions import time_metadata
from .io.imu import ImuColumns, ImuFile, _TimeCheck
from .io.pipeline import (
    CHUNK_ROWS,
    Report,
    _metadata,
    _output_path,
    _rows,
    convert_file,
    default_output,
    estimate_file,
    integrate_axes,
    integrate_file,
    integrate_stream,
)
from .io.readers import format_of, open_source
from .io.tables import OutputSpec, attitude_columns
from .io.writers import csv_comments, table_writer
from .quaternion import multiply

__all__ = [
    "COMMANDS",
    "SPLIT_METHODS",
    "Job",
    "JobResult",
    "batch_outputs",
    "check_split",
    "expand",
    "integrate_split",
    "run_batch",
    "run_job",
]

#: The file commands a batch can run, by name.
COMMANDS: dict[str, Callable[..., Report]] = {
    "integrate": integrate_file,
    "estimate": estimate_file,
    "convert": convert_file,
}

#: The methods whose step k uses sample k alone: the only ones :func:`integrate_split` can cut.
SPLIT_METHODS = ("exact", "first-order", "second-order", "cayley")


@dataclass(frozen=True)
class Job:
    """One file to process.

    Attributes
    ----------
    command : str
        A key of :data:`COMMANDS`.
    input, output : str
        The files.
    options : dict
        Keyword arguments of the command's function (picklable: plain values and frozen dataclasses).
    """

    command: str
    input: str
    output: str
    options: dict = field(default_factory=dict)


@dataclass
class JobResult:
    """The outcome of a :class:`Job`: rows written, or the error that stopped it.

    Attributes
    ----------
    input, output : str
        The files.
    rows : int
        Rows written (0 on error).
    seconds : float
        Wall time of the job.
    error : str or None
        What went wrong, as a user reads it.
    """

    input: str
    output: str
    rows: int = 0
    seconds: float = 0.0
    error: str | None = None

    @property
    def ok(self) -> bool:
        """Whether the output was written."""
        return self.error is None


def run_job(job: Job) -> JobResult:
    """Run one job; any error is caught and returned in the result (a batch goes on).

    Parameters
    ----------
    job : Job
        The file and the command.

    Returns
    -------
    JobResult
        Rows written, or the error.

    Examples
    --------
    >>> from strapdown.batch import Job, run_job
    >>> run_job(Job("integrate", "no/such/file.csv", "out.csv")).error
    'no such file: no/such/file.csv'
    """
    t0 = time.perf_counter()
    try:
        report = COMMANDS[job.command](job.input, job.output, **job.options)
    except Exception as exc:  # a batch reports each file's failure and goes on with the others
        return JobResult(job.input, job.output, 0, time.perf_counter() - t0, _describe(exc))
    return JobResult(job.input, str(report.output), report.rows, time.perf_counter() - t0)


def _describe(exc: BaseException) -> str:
    """An error as a user reads it: our messages say what and where; anything else also says its type."""
    if isinstance(exc, (ValueError, OSError)):
        return str(exc)
    return f"{type(exc).__name__}: {exc}"


# ----------------------------------------------------------------------------------------------------------
class _Runner:
    """Runs a function over items on a local process pool, inline, or on a Dask cluster."""

    def __init__(self, scheduler: str | None = None, workers: int | None = None):
        self.scheduler = scheduler
        self.workers = workers
        self._client = None
        self._pool = None

    def __enter__(self):
        from ._files import guard_signals

        guard_signals()  # SIGTERM/SIGHUP: stop the workers, which remove their temporaries (_files.py)
        if self.scheduler:
            from .io._deps import need

            distributed = need("distributed", "running on a Dask cluster")
            try:
                self._client = distributed.Client(self.scheduler, timeout="20s")
            except OSError as exc:
                raise ValueError(f"cannot reach the Dask scheduler at {self.scheduler}: {exc}") from None
        return self

    def __exit__(self, *exc):
        if self._client is not None:
            self._client.close()
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)

    def map(self, fn, items: Sequence) -> Iterator[tuple[int, object]]:
        """Yield (index, result) as results come in; a result is an exception when the call raised."""
        items = list(items)
        workers = min(self.workers or os.cpu_count() or 1, len(items))
        if self._client is not None or workers > 1:
            fn = functools.partial(_one_thread, fn)  # the parallelism is across files (strapdown._threads)
        if self._client is not None:
            from distributed import as_completed

            futures = self._client.map(fn, items, pure=False)
            index = {f.key: i for i, f in enumerate(futures)}
            for fut in as_completed(futures):
                try:
                    yield index[fut.key], fut.result()
                except Exception as exc:  # a lost worker: the item failed, the others go on
                    yield index[fut.key], exc
            return
        if workers <= 1:
            for i, item in enumerate(items):
                try:
                    yield i, fn(item)
                except Exception as exc:
                    yield i, exc
            return
        if self._pool is None or self._pool._max_workers < workers:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            if self._pool is not None:
                self._pool.shutdown()
            # spawn: a forked child would inherit the parent's Arrow and numba thread pools mid-use
            self._pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
        from concurrent.futures import as_completed

        futures = {self._pool.submit(fn, item): i for i, item in enumerate(items)}
        for fut in as_completed(futures):
            try:
                yield futures[fut], fut.result()
            except Exception as exc:
                yield futures[fut], exc


def _one_thread(fn, item):
    """fn(item) with one numba thread unless ``threads=`` or ``STRAPDOWN_THREADS`` says otherwise."""
    from ._threads import worker_default

    with worker_default(1):
        return fn(item)


def run_batch(
    jobs: Iterable[Job],
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[JobResult], None] | None = None,
) -> list[JobResult]:
    """Run jobs in parallel: on the local cores, or on the Dask cluster at ``scheduler``.

    Parameters
    ----------
    jobs : iterable of Job
        The files and commands.
    scheduler : str, optional
        Address of a Dask scheduler (``"tcp://host:port"``); local processes when None.
    workers : int, optional
        Local processes (default: one per core; 1 runs in this process).
    progress : callable, optional
        Called with each result as it comes in.

    Returns
    -------
    list of JobResult
        In the order of ``jobs``.

    Raises
    ------
    ValueError
        Before any job runs, when jobs share an output or one job's output is another's input.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.batch import Job, run_batch
    >>> from strapdown.io import write_table
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> g = {"gx": np.zeros(10), "gy": np.zeros(10), "gz": np.ones(10)}
    >>> good = write_table(folder / "good.csv", {"t": np.arange(10) * 0.1, **g})
    >>> bad = write_table(folder / "bad.csv", {"t": np.arange(10) * -0.1, **g})
    >>> results = run_batch([Job("integrate", str(p), str(p.with_suffix(".out.csv"))) for p in (good, bad)],
    ...                     workers=1)
    >>> [(pathlib.Path(r.input).name, r.rows, r.ok) for r in results]
    [('good.csv', 10, True), ('bad.csv', 0, False)]
    """
    jobs = list(jobs)
    _check_outputs([j.input for j in jobs], [j.output for j in jobs])
    results: list[JobResult | None] = [None] * len(jobs)
    with _Runner(scheduler, workers) as runner:
        for i, result in runner.map(run_job, jobs):
            if isinstance(result, BaseException):
                job = jobs[i]
                result = JobResult(job.input, job.output, error=_describe(result))
            results[i] = result
            if progress is not None:
                progress(result)
    return results


# ----------------------------------------------------------------------------------------------------------
_OUTPUT_TAGS = tuple(f".{c}" for c in COMMANDS)


def expand(pattern: str) -> tuple[list[Path], Path]:
    """The files matching a glob pattern (``**`` spans folders), sorted, and the folder the pattern starts in.

    Outputs of earlier runs (``*.integrate.csv``, ``*.estimate.parquet``, ...) are left out.

    Parameters
    ----------
    pattern : str
        E.g. ``"logs/**/*.parquet"``.

    Returns
    -------
    files : list of pathlib.Path
        Matching files.
    root : pathlib.Path
        The pattern's leading folders without wildcards (outputs under ``--out`` keep the layout below it).

    Examples
    --------
    >>> from strapdown.batch import expand
    >>> expand("no/such/folder/**/*.csv")
    ([], PosixPath('no/such/folder'))
    """
    files = [Path(p) for p in glob.glob(pattern, recursive=True)]
    files = sorted(p for p in files if p.is_file() and Path(p.stem).suffix not in _OUTPUT_TAGS)
    parts = Path(pattern).parts
    fixed = [p for p in parts[: next((i for i, p in enumerate(parts) if glob.has_magic(p)), len(parts))]]
    root = Path(*fixed) if fixed else Path(".")
    if root == Path(pattern):
        root = root.parent
    return files, root


def batch_outputs(files: Sequence[Path], command: str, root: Path, out: Path | None, format=None) -> list[Path]:
    """Where a batch writes: beside each input, or under ``out`` with the layout below ``root`` kept.

    Parameters
    ----------
    files : sequence of pathlib.Path
        The inputs.
    command : str
        Names the outputs (``<stem>.<command>.<ext>``).
    root : pathlib.Path
        The folder the inputs were found under.
    out : pathlib.Path, optional
        The output folder.
    format : str, optional
        Output format (by default CSV, Parquet for Parquet input).

    Returns
    -------
    list of pathlib.Path
        One output per input.

    Raises
    ------
    ValueError
        When inputs would share an output (``x.csv`` and ``x.h5`` both make ``x.integrate.csv``): the later
        would silently replace the earlier.  The message lists them.

    Examples
    --------
    >>> from pathlib import Path
    >>> from strapdown.batch import batch_outputs
    >>> [str(p) for p in batch_outputs([Path("logs/a/x.parquet")], "estimate", Path("logs"), Path("res"))]
    ['res/a/x.estimate.parquet']
    """
    outputs = []
    for f in files:
        beside = default_output(f, command, format)
        if out is None:
            outputs.append(beside)
            continue
        try:
            rel = f.parent.relative_to(root)
        except ValueError:
            rel = Path()
        outputs.append(Path(out) / rel / beside.name)
    _check_outputs(files, outputs)
    return outputs


def _check_outputs(inputs: Sequence, outputs: Sequence) -> None:
    """Refuse outputs that several inputs share, or that are inputs: whichever job ends last would win silently."""
    owners: dict[str, list] = {}
    for i, o in zip(inputs, outputs, strict=True):
        owners.setdefault(_file_key(o), []).append((i, o))
    clashes = [(shared[0][1], [i for i, _ in shared]) for shared in owners.values() if len(shared) > 1]
    if clashes:
        listing = "; ".join(f"{', '.join(map(str, ins[:-1]))} and {ins[-1]} -> {o}" for o, ins in clashes)
        raise ValueError(
            f"several inputs would be written to one output, each replacing the last: {listing}.  Rename or move "
            "the inputs, or run them separately"
        )
    read = {_file_key(i) for i in inputs}
    for i, o in zip(inputs, outputs, strict=True):
        if _file_key(o) in read:
            raise ValueError(f"the output of {i}, {o}, is also an input; choose another output folder (--out)")


def _file_key(path) -> str:
    return os.path.normcase(os.path.realpath(path))


# ----------------------------------------------------------------------------------------------------------
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
        raise ValueError(f"{part.path}: the integration failed on {_rows(imu, box.get('chunk'))}: {exc}") from None


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
    *,
    parts: int = 2,
    scheduler: str | None = None,
    workers: int | None = None,
    columns: ImuColumns | None = None,
    out: OutputSpec | None = None,
    method: str | None = None,
    input: str = "rate",
    rate_frame: str = "body",
    q0=None,
    chunk_rows: int = CHUNK_ROWS,
    progress: Callable[[str], None] | None = None,
    frame: str | None = None,
    body: str | None = None,
    out_body: str | None = None,
    on_gap: str = "error",
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
        Where the parts run (as for :func:`run_batch`).
    columns, out, method, input, rate_frame, q0, chunk_rows, frame, body, out_body
        As for :func:`~strapdown.io.integrate_file`; ``method`` one of ``SPLIT_METHODS``, or None when the
        default for ``input`` is one (:func:`check_split`).
    on_gap : {"error"}
        Gaps stop a split integration (a ValueError), as ``integrate_file``'s default does.
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
    >>> from strapdown.batch import integrate_split
    >>> from strapdown.io import read_table, write_table
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
    method = check_split(parts, method, input)
    if on_gap != "error":
        raise ValueError(f"a split integration stops at gaps (on_gap='error'), got on_gap={on_gap!r}")
    columns = columns or ImuColumns()
    out = out or OutputSpec()
    output = _output_path(path, output, "integrate", out.format)
    with ImuFile(path, columns, require=("gyro",), increments=input == "increment") as imu:
        n = imu.count_rows()
        read = imu.describe()
        if n == 0:
            raise ValueError(f"{path}: no rows")
        axes, meta = integrate_axes(imu, frame, body, out_body, rate_frame, out)
        meta = {**_metadata("integrate", method=method or "default", input=input, rate_frame=rate_frame), **meta}
        turn = None if axes.matrix is None else tuple(axes.matrix.ravel().tolist())
        bounds = sorted(set(np.linspace(0, n, parts + 1).round().astype(int).tolist()))
        base = _Part(str(path), 0, 0, columns, method, input, rate_frame, chunk_rows, turn=turn)
        ranges = [replace(base, start=a, stop=b) for a, b in itertools.pairwise(bounds)]
        with _Runner(scheduler, workers) as runner:
            ends = _gather(runner.map(_part_end, ranges), len(ranges))
            # the file stays open for the checks across the cuts: a CSV file names rows by line
            _check_in_order(imu, chunk_rows, ranges, ends)
            if progress:
                progress(f"pass 1: {len(ranges)} parts integrated from the identity")
            prefixes = _prefixes(ends, q0, method, input, rate_frame)
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
                rows = sum(_gather(runner.map(_part_write, second), len(second)))
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
    >>> from strapdown.batch import check_split
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


def _gather(results: Iterator[tuple[int, object]], n: int) -> list:
    out: list = [None] * n
    for i, r in results:
        if isinstance(r, BaseException):
            raise r
        out[i] = r
    return out


def _check_in_order(imu: ImuFile, chunk_rows: int, ranges: Sequence[_Part], ends: list[dict]) -> None:
    """Raise the first fault in the file, as one sequential pass would: a part's own, or a step across a cut.

    The steps across the cuts go through the check that :func:`~strapdown.io.integrate_file` runs, with the
    sample period it would have estimated (from the file's first chunk), so the limits and messages are its.
    A part's own rows are judged with the period of the part's first chunk: the same on regularly sampled
    files, not to the last digit on jittery ones.
    """
    check = _TimeCheck(imu)
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
        from ._files import atomic_path

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
