"""Many files in parallel: a file command over each, on the local cores or on a cluster.

:func:`run_batch` runs file jobs (:class:`Job`: integrate, estimate or convert one file) on the local cores
(a process pool) or on a Dask cluster (``scheduler="tcp://host:port"``, from the ``dask`` extra; the workers
must see the same file system).  Every output is written atomically, and a job that fails is reported in its
:class:`JobResult` without stopping the others.  One long file integrated in parts across the workers is
:func:`strapdown.io.pipelines.split.integrate_split` (``strapdown batch --split``), also importable from here.
"""

from __future__ import annotations

import glob
import os
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from .._support.pool import Runner
from ..io.pipelines import Report, convert_file, default_output, estimate_file, integrate_file
from ..io.pipelines.split import SPLIT_METHODS, check_split, integrate_split

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
    >>> from strapdown.apps.batch import Job, run_job
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
    >>> from strapdown.apps.batch import Job, run_batch
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
    with Runner(scheduler, workers) as runner:
        for i, result in runner.map(run_job, jobs):
            if isinstance(result, BaseException):
                job = jobs[i]
                result = JobResult(job.input, job.output, error=_describe(result))
            results[i] = result
            if progress is not None:
                progress(result)
    return results


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
    >>> from strapdown.apps.batch import expand
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
    >>> from strapdown.apps.batch import batch_outputs
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
