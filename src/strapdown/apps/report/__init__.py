"""An interactive report of one recording, in one HTML file that opens offline: ``strapdown report``.

* :mod:`.data`: the recording read, the estimators run, the reference aligned (:func:`assemble`,
  :class:`ReportOptions`), everything at full rate;
* :mod:`.decimate`: long lines thinned for display with their peaks kept (min-max over time buckets);
* :mod:`.summary`: the summary and the error table as text and numbers;
* :mod:`.timeplots`, :mod:`.widgets`, :mod:`.view3d`, :mod:`.calibration` and :mod:`.page`: the page, drawn
  with Bokeh (the ``report`` extra): linked time figures, the 3D view with its slider and play button.

:func:`report_file` does it all and writes the page atomically: a bad or empty input raises a ``ValueError``
naming the file, and no page (nor a part of one) is left behind.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path

from .data import EstimatorRun, Recording, ReportOptions, assemble

__all__ = ["EstimatorRun", "Recording", "ReportOptions", "ReportResult", "assemble", "report_file"]


@dataclass
class ReportResult:
    """What :func:`report_file` wrote.

    Attributes
    ----------
    output : pathlib.Path
        The page.
    bytes : int
        Its size.
    rows : int
        Rows of the recording.
    seconds : float
        Wall time, reading to writing.
    recording : Recording
        The data behind the page (its numbers: ``recording.runs[k].rmse``).
    notes : list of str
        What the reader and the alignment said.
    read : str
        The columns read and their units (as the other file commands report them).
    """

    output: Path
    bytes: int
    rows: int
    seconds: float
    recording: Recording
    notes: list = field(default_factory=list)
    read: str = ""


def default_report_path(path) -> Path:
    """``<stem>.report.html`` beside the input (beside the folder, for an export folder or several files).

    Examples
    --------
    >>> from strapdown.apps.report import default_report_path
    >>> str(default_report_path("logs/flight.ulg"))
    'logs/flight.report.html'
    """
    first = Path(path[0] if isinstance(path, list | tuple) else path)
    if isinstance(path, list | tuple) and len(path) > 1:
        first = first.parent
    return first.with_name(f"{first.stem or 'recording'}.report.html")


def report_file(path, output=None, options: ReportOptions | None = None, *, progress=None, **changes) -> ReportResult:
    """Write the interactive report of a recording: one self-contained HTML file.

    Parameters
    ----------
    path : path-like or sequence of path-like
        One recording: a file in any input format, an export folder, or one file per sensor.
    output : path-like, optional
        The page (default ``<stem>.report.html`` beside the input).
    options, **changes
        :class:`ReportOptions`, whole or field by field (``estimators=("attitude", "mahony")``,
        ``truth="sim.parquet"``).
    progress : callable, optional
        Called with (rows done, rows in all) while reading and estimating.

    Returns
    -------
    ReportResult
        The page's path and size, and the data behind it.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.apps.report import report_file
    >>> from strapdown.io import simulate_file
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> log = simulate_file(folder / "show.parquet", scenario="hammerhead-loop", imu="consumer", rate=100.0).output
    >>> result = report_file(log, truth=log)                                # doctest: +SKIP
    >>> result.output.name, result.recording.main.rmse["total"] < 5         # doctest: +SKIP
    ('show.report.html', True)
    """
    from ..._support.files import atomic_path

    start = time.perf_counter()
    o = options or ReportOptions()
    o = replace(o, **changes) if changes else o
    output = Path(output) if output is not None else default_report_path(path)
    if output.suffix.lower() not in (".html", ".htm"):
        raise ValueError(f"the report is an HTML page: name it .html, got {output}")
    rec = assemble(path, o, progress=progress)
    rec.title = o.title or ", ".join(p.name for p in rec.paths)
    from .page import page_html

    text = page_html(rec, o)
    with atomic_path(output) as tmp:
        tmp.write_text(text, encoding="utf-8")
    seconds = time.perf_counter() - start
    read = dict(rec.summary).get("Read", "")
    return ReportResult(output, output.stat().st_size, int(rec.t.size), seconds, rec, rec.notes, read)
