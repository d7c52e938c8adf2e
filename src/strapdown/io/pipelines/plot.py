"""``strapdown plot``: PNG figures of an attitude file's angles, errors and bias (matplotlib, the ``plot`` extra).

:func:`plot_file` reads the tables that ``strapdown integrate`` and ``strapdown estimate`` write (``t``,
``qw..qz``, ``bias_*``) and a truth (``qw_true..qz_true`` of ``strapdown simulate``, or any ``qw..qz``), streaming
and thinning long files to at most ``max_points`` rows so that a figure of a day-long log stays small.  The
figures obey :mod:`strapdown.evaluate.figures`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

# strapdown.io.plots of release 0.1 (this module's old path) also held these
from ...evaluate.figures import (  # noqa: F401
    angles_figure,
    angles_for_display,
    comparison_figures,
    line_styles,
    plot_comparison,
    pyplot,
    save_figures,
    time_series_figure,
)
from ...rotations.values import Angles
from ..readers import open_source, read_metadata

__all__ = ["plot_file"]


_TRUTH_NAMES = (("qw_true", "qx_true", "qy_true", "qz_true"), ("qw", "qx", "qy", "qz"))


def _thinned(path, names, max_points: int, format=None) -> dict:
    """Every k-th row of the named fields, k chosen so that at most ``max_points`` rows are kept."""
    with open_source(path, format) as src:
        rows = src.count_rows()
        step = max(1, -(-rows // max_points)) if rows else 1
        keep = {n: [] for n in names}
        for row, cols in src.chunks(names, 1 << 20):
            first = (-row) % step  # the global rows 0, step, 2 step, ... that fall in this chunk
            for n in names:
                keep[n].append(cols[n][first::step])
    return {n: np.concatenate(v) if v else np.zeros(0) for n, v in keep.items()}


def _quat_names(fields, candidates) -> tuple | None:
    for names in candidates:
        if all(n in fields for n in names):
            return names
    return None


def plot_file(
    path,
    truth=None,
    out=None,
    *,
    angles: Angles | None = None,
    max_points: int = 200_000,
    format: str | None = None,
    names: tuple | None = None,
) -> list[Path]:
    """Write PNG figures of an attitude file: angles over time; errors (with a truth); bias (when present).

    Every input is read and checked and every figure drawn before anything is written, and the figures are
    written as one set (:func:`save_figures`): a run that fails leaves no PNG behind.

    Parameters
    ----------
    path : path-like
        An output of ``integrate`` or ``estimate`` (columns ``t``, ``qw``, ``qx``, ``qy``, ``qz``, optionally
        ``bias_x_*``...).
    truth : path-like, optional
        A file with the true attitude row by row (``qw_true``.. or ``qw``..), e.g. the input of a simulation.
        It is drawn under the estimate in the angles figure, and the errors figure shows the difference.
    out : path-like, optional
        Folder for the figures (default: beside ``path``); files ``<stem>_angles.png``, ``<stem>_errors.png``,
        ``<stem>_bias.png``.
    angles : Angles, optional
        Euler sequence, unit and range of the angle figure (default: ZYX in degrees, Gajda's yaw range).
    max_points : int
        Rows drawn at most (long files are thinned evenly).
    format : str, optional
        Format of ``path`` and ``truth`` when the suffix does not tell it.
    names : (str, str), optional
        The names the titles give ``path`` and ``truth`` (by default their file names): the inputs' own, when
        these are scratch copies put on one time line (``plot --truth LOG``).

    Returns
    -------
    list of pathlib.Path
        The figures written.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import write_table
    >>> from strapdown.io.pipelines.plot import plot_file
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> t = np.linspace(0, 1, 50)
    >>> q = {"t": t, "qw": np.cos(t / 2), "qx": np.sin(t / 2), "qy": 0 * t, "qz": 0 * t}
    >>> [p.name for p in plot_file(write_table(folder / "att.csv", q))]
    ['att_angles.png']
    """
    path = Path(path)
    out = path.parent if out is None else Path(out)
    figures = _file_figures(path, truth, angles or Angles(), max_points, format, names)
    return save_figures({out / f"{path.stem}_{name}.png": fig for name, fig in figures.items()})


def _file_figures(path: Path, truth, angles: Angles, max_points: int, format, names: tuple | None = None) -> dict:
    """The figures of :func:`plot_file` by name ("angles", "errors", "bias"), nothing written."""
    names = names or (path.name, None if truth is None else Path(truth).name)
    plt = pyplot()
    with open_source(path, format) as src:
        fields = dict(src.fields)
        rows_in_file = src.count_rows()
    qnames = _quat_names(fields, [("qw", "qx", "qy", "qz")])
    if qnames is None:
        raise ValueError(f"{path} has no quaternion columns qw, qx, qy, qz; it has: {', '.join(fields)}")
    q_true = note = None
    if truth is not None:  # checked before anything is drawn
        with open_source(truth, format) as src:
            tnames = _quat_names(src.fields, _TRUTH_NAMES)
            truth_rows = src.count_rows()
            truth_fields = list(src.fields)
        if tnames is None:
            raise ValueError(f"{truth} has no true attitude (qw_true.. or qw..); it has: {', '.join(truth_fields)}")
        if truth_rows != rows_in_file:
            raise ValueError(
                f"{truth} has {truth_rows} rows but {path} has {rows_in_file}; the truth must match row by row"
            )
        ref = _thinned(truth, list(tnames), max_points, format)
        q_true, note = _truth_in_frame_of(path, truth, np.column_stack([ref[n] for n in tnames]), format)

    bias_names = [n for n in fields if n.startswith("bias_")]
    tname = "t" if "t" in fields else None
    data = _thinned(path, [*([tname] if tname else []), *qnames, *bias_names], max_points, format)
    q = np.column_stack([data[n] for n in qnames])
    t = data[tname] if tname else np.arange(len(q), dtype=float)
    xlabel = "time [s]" if tname else "row"
    unit = "deg" if angles.degrees else "rad"
    figures = {}
    try:
        fig, axes = angles_figure(plt, t, q_true, {path.stem: q}, angles, 10.0, xlabel)
        against = f" against the truth {names[1]}{note}" if truth is not None else ""
        axes[0].set_title(f"{names[0]}: Euler angles ({angles.seq}){against}")
        figures["angles"] = fig

        if q_true is not None:
            from ...evaluate.metrics import attitude_errors

            errors = attitude_errors(q, q_true)
            scale = 180 / np.pi if angles.degrees else 1.0
            # total first and widest, so that heading and inclination (each at most the total) stay visible on it
            widths = {"total": 2.4, "heading": 1.2, "inclination": 1.2}
            lines = [
                (name, errors[name] * scale, {**style, "lw": lw})
                for (name, lw), style in zip(widths.items(), line_styles(3), strict=True)
            ]
            title = f"{names[0]}: attitude error against {names[1]}{note}"
            figures["errors"] = time_series_figure(plt, t, lines, f"error [{unit}]", xlabel, title)

        if bias_names:
            styles = line_styles(len(bias_names))
            lines = [(n, data[n], style) for n, style in zip(bias_names, styles, strict=True)]
            figures["bias"] = time_series_figure(plt, t, lines, "gyro bias", xlabel, f"{names[0]}: estimated gyro bias")
    except BaseException:
        for fig in figures.values():
            plt.close(fig)
        raise
    return figures


def _truth_in_frame_of(path, truth, q_true: np.ndarray, format=None) -> tuple[np.ndarray, str]:
    """The true attitudes re-expressed in the frame of ``path``'s attitudes, when both files name theirs.

    An estimate in NED against a simulated truth in ENU would otherwise show a half turn as its error.
    Returns the attitudes and a note for the figure ("" when nothing was changed).
    """
    ours, theirs = _frame_of(path, format, "frame"), _frame_of(truth, format, "reference", "frame")
    if not (ours and theirs and ours != theirs):
        return q_true, ""
    from ...rotations.frames import change_frame

    return change_frame(q_true, ref_from=theirs, ref_to=ours), f" (truth taken from {theirs} to {ours})"


def _frame_of(path, format, *keys: str) -> str | None:
    """The reference frame a file's metadata names under the first of ``keys`` present, upper case."""
    meta = read_metadata(path, format)
    for key in keys:
        if meta.get(key):
            return meta[key].upper()
    return None
