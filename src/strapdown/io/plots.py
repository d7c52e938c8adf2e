"""PNG figures of attitudes: an attitude file's angles, errors and bias, and a method comparison.

:func:`plot_file` reads the tables that ``strapdown integrate`` and ``strapdown estimate`` write (``t``,
``qw..qz``, ``bias_*``) and a truth (``qw_true..qz_true`` of ``strapdown simulate``, or any ``qw..qz``), streaming
and thinning long files to at most ``max_points`` rows so that a figure of a day-long log stays small.
:func:`comparison_figures` and :func:`plot_comparison` draw a :class:`strapdown.compare.Comparison`.  Needs
matplotlib (``plot`` extra).

What every figure obeys:

* every line has its own colour and dash (:func:`line_styles`), so 17 methods can be told apart;
* a truth is drawn first, wide and grey, so the estimates lie on top of it and it shows where they leave it;
* the outer angles (yaw and roll of ``"ZYX"``) are unwrapped, so a turn through 360° is a straight line and
  not a saw tooth, and they are not drawn near gimbal lock (where only their sum or difference is defined):
  those stretches are shaded and the figure says so (:func:`angles_for_display`);
* a set of figures is written all or nothing (:func:`save_figures`): when one fails, none is left behind.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from .._files import _umask
from ._deps import need
from .readers import open_source, read_metadata
from .tables import Angles, column_names, to_values

__all__ = ["angles_for_display", "comparison_figures", "line_styles", "plot_comparison", "plot_file", "save_figures"]

_TRUTH_NAMES = (("qw_true", "qx_true", "qy_true", "qz_true"), ("qw", "qx", "qy", "qz"))

# matplotlib's tab10 (colour-blind aware, the default cycle) and four dash patterns: 40 distinct pairs
_COLOURS = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
)
_DASHES = ("-", "--", "-.", ":")
_TRUTH_STYLE = {"color": "0.6", "lw": 4.0, "alpha": 0.6, "zorder": 1, "solid_capstyle": "butt"}
_DPI = 110
_BASELINES = ("euler-angles", "dcm", "euler-parameters", "rotation-vector")


def line_styles(n: int) -> list[dict]:
    """``n`` distinct line styles (colour and dash pattern), as keyword arguments of ``Axes.plot``.

    The first ten are solid in matplotlib's ten default colours; the next ten dashed in the same colours shifted
    by three, so that the same colour never carries neighbouring lines; then dash-dot and dotted.  Past 40 the
    pattern repeats with wider lines.

    Parameters
    ----------
    n : int
        How many lines.

    Returns
    -------
    list of dict
        ``{"color": ..., "linestyle": ..., "lw": ...}`` for each line.

    Examples
    --------
    >>> from strapdown.io.plots import line_styles
    >>> styles = line_styles(17)
    >>> len({(s["color"], s["linestyle"]) for s in styles})       # every line its own style
    17
    >>> styles[10]
    {'color': '#d62728', 'linestyle': '--', 'lw': 1.0}
    """
    if not (isinstance(n, int | np.integer) and n >= 0):
        raise ValueError(f"n must be a whole number >= 0, got {n!r}")
    out = []
    for i in range(int(n)):
        block, k = divmod(i, len(_COLOURS))
        dash = _DASHES[block % len(_DASHES)]
        out.append({"color": _COLOURS[(k + 3 * block) % len(_COLOURS)], "linestyle": dash, "lw": 1.0 + block // 4})
    return out


def angles_for_display(
    q, angles: Angles | None = None, margin_deg: float = 10.0, align=None
) -> tuple[np.ndarray, np.ndarray]:
    """Euler angles ready to plot: outer angles unwrapped, and left out near gimbal lock.

    Parameters
    ----------
    q : array_like, shape (N, 4)
        Attitudes in time order; rows with NaN give NaN angles.
    angles : Angles, optional
        Sequence, unit and range (default: ZYX in degrees, yaw in Gajda's [0, 360°) at the start).
    margin_deg : float
        The first and third angle are not drawn where the middle one is within this many degrees of gimbal
        lock (±90° for sequences of three axes such as ZYX, 0° or 180° for ZXZ-type ones).
    align : array_like, shape (N, 3), optional
        Angles of another series from this function (a truth): whole turns are added to the first and third
        angles, sample by sample, to lay them next to it, and they are left out where it has none, so that an
        estimate and its truth are drawn on the same branch.

    Returns
    -------
    values : numpy.ndarray, shape (N, 3)
        The angles; the first and third unwrapped along each stretch where they are shown (they start in the
        range ``angles`` asks for and then run on continuously), NaN where not shown.
    blanked : numpy.ndarray of bool, shape (N,)
        Rows near gimbal lock, where the first and third angles were left out.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_euler
    >>> from strapdown.io.plots import angles_for_display
    >>> yaw = np.radians(np.arange(0, 721, 45.0))                  # two full turns about the vertical
    >>> v, blanked = angles_for_display(from_euler(np.c_[yaw, 0 * yaw, 0 * yaw], "ZYX"))
    >>> v[:, 0]                                                      # no jump at 360
    array([  0.,  45.,  90., 135., 180., 225., 270., 315., 360., 405., 450., 495., 540., 585., 630., 675., 720.])
    >>> bool(blanked.any())
    False
    """
    angles = angles or Angles()
    q = np.asarray(q, dtype=np.float64)
    values = np.full((q.shape[0], 3), np.nan)
    ok = np.isfinite(q).all(axis=-1)
    if ok.any():
        values[ok] = to_values("euler", q[ok], angles)
    middle = np.degrees(values[:, 1]) if not angles.degrees else values[:, 1]
    seq = angles.seq.upper()
    if seq[0] == seq[2]:  # proper Euler angles: locked at 0° and 180°
        near = (middle < margin_deg) | (middle > 180.0 - margin_deg)
    else:
        near = np.abs(middle) > 90.0 - margin_deg
    blanked = near & ok
    values[blanked, 0] = np.nan
    values[blanked, 2] = np.nan
    period = 360.0 if angles.degrees else 2 * np.pi
    for col in (0, 2):
        shown = np.isfinite(values[:, col])
        edges = np.flatnonzero(np.diff(np.r_[0, shown.astype(np.int8), 0]))
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            values[a:b, col] = np.unwrap(values[a:b, col], period=period)
    if align is not None:
        align = np.asarray(align, dtype=np.float64)
        if align.shape != values.shape:
            raise ValueError(f"align must have the shape of the angles {values.shape}, got {align.shape}")
        for col in (0, 2):
            values[:, col] += period * np.round((align[:, col] - values[:, col]) / period)  # NaN where either is
    return values, blanked


def save_figures(figures: dict, dpi: int = _DPI) -> list[Path]:
    """Write matplotlib figures as PNG files, all or nothing, and close them.

    Every figure is rendered into a temporary file beside its target first; only when all of them have been
    written are they renamed onto their targets (each rename atomic).  If any fails, the temporary files are
    deleted and no target is touched: a failed run leaves neither partial nor stray figures.

    Parameters
    ----------
    figures : dict
        Target path (path-like) to ``matplotlib.figure.Figure``.
    dpi : int
        Resolution.

    Returns
    -------
    list of pathlib.Path
        The files written, in the order of ``figures``.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> import matplotlib.pyplot as plt
    >>> from strapdown.io.plots import save_figures
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> figs = {folder / "a.png": plt.figure(), folder / "b.png": plt.figure()}
    >>> [p.name for p in save_figures(figs)]
    ['a.png', 'b.png']
    """
    import matplotlib.pyplot as plt

    staged: list[tuple[Path, Path]] = []
    try:
        for target, fig in figures.items():
            target = Path(target)
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
            os.close(fd)
            staged.append((Path(tmp), target))
            fig.savefig(tmp, format="png", dpi=dpi)
            os.chmod(tmp, 0o666 & ~_umask())
        for tmp, target in staged:
            os.replace(tmp, target)
    finally:
        for tmp, _ in staged:
            tmp.unlink(missing_ok=True)
        for fig in figures.values():
            plt.close(fig)
    return [target for _, target in staged]


def _pyplot():
    need("matplotlib", "plotting")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _shade(ax, t, mask, **kw) -> bool:
    """Shade the stretches of ``t`` where ``mask`` holds; True if there was any."""
    edges = np.flatnonzero(np.diff(np.r_[0, np.asarray(mask, dtype=np.int8), 0]))
    for k, (a, b) in enumerate(zip(edges[::2], edges[1::2], strict=True)):
        if k == 1:
            kw.pop("label", None)  # one legend entry for all the stretches
        ax.axvspan(t[a], t[min(b, len(t) - 1)], lw=0, **kw)
    return edges.size > 0


def _angles_axes(plt, t, truth, series, angles: Angles, margin_deg: float, xlabel: str):
    """Three panels of Euler angles: the truth (if any) under every series, blanked stretches shaded."""
    unit = "deg" if angles.degrees else "rad"
    names = [n.replace(f"_{unit}", f" [{unit}]") for n in column_names("euler", angles)]
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 7.5), constrained_layout=True)
    blanked = np.zeros(len(t), dtype=bool)
    ref = None
    if truth is not None:
        ref, b = angles_for_display(truth, angles, margin_deg)
        blanked |= b
    shown = []
    for label, q in series.items():
        v, b = angles_for_display(q, angles, margin_deg, align=ref)
        blanked |= b
        shown.append((label, v))
    styles = line_styles(len(shown))
    for i, ax in enumerate(axes):
        if ref is not None:
            ax.plot(t, ref[:, i], label="truth", **_TRUTH_STYLE)
        for (label, v), style in zip(shown, styles, strict=True):
            ax.plot(t, v[:, i], label=label, zorder=2, **style)
        if _shade(ax, t, blanked, color="#fff2b3", zorder=0):
            if i == 0:
                ax.text(
                    0.005,
                    0.97,
                    f"shaded: within {margin_deg:g}° of gimbal lock, {names[0].split()[0]} and "
                    f"{names[2].split()[0]} are not drawn (only their sum or difference is defined there)",
                    transform=ax.transAxes,
                    va="top",
                    fontsize=8,
                    bbox={"facecolor": "white", "alpha": 0.8, "lw": 0},
                )
        ax.set_ylabel(names[i])
        ax.grid(alpha=0.3)
    if len(shown) > 1 or ref is not None:  # outside the panels, where it hides no line
        fig.legend(*axes[-1].get_legend_handles_labels(), loc="outside lower center", fontsize=8, ncol=len(shown) + 1)
    axes[-1].set_xlabel(xlabel)
    return fig, axes


def _time_series(plt, t, lines, ylabel: str, xlabel: str, title: str):
    """One panel of (label, values, style) lines over time, with grid and legend."""
    fig, ax = plt.subplots(figsize=(10, 4), constrained_layout=True)
    for label, values, style in lines:
        ax.plot(t, values, label=label, **style)
    ax.set_ylabel(ylabel)
    ax.set_xlabel(xlabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    return fig


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

    Returns
    -------
    list of pathlib.Path
        The figures written.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import write_table
    >>> from strapdown.io.plots import plot_file
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> t = np.linspace(0, 1, 50)
    >>> q = {"t": t, "qw": np.cos(t / 2), "qx": np.sin(t / 2), "qy": 0 * t, "qz": 0 * t}
    >>> [p.name for p in plot_file(write_table(folder / "att.csv", q))]
    ['att_angles.png']
    """
    path = Path(path)
    out = path.parent if out is None else Path(out)
    figures = _file_figures(path, truth, angles or Angles(), max_points, format)
    return save_figures({out / f"{path.stem}_{name}.png": fig for name, fig in figures.items()})


def _file_figures(path: Path, truth, angles: Angles, max_points: int, format) -> dict:
    """The figures of :func:`plot_file` by name ("angles", "errors", "bias"), nothing written."""
    plt = _pyplot()
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
        fig, axes = _angles_axes(plt, t, q_true, {path.stem: q}, angles, 10.0, xlabel)
        against = f" against the truth {Path(truth).name}{note}" if truth is not None else ""
        axes[0].set_title(f"{path.name}: Euler angles ({angles.seq}){against}")
        figures["angles"] = fig

        if q_true is not None:
            from ..metrics import attitude_errors

            errors = attitude_errors(q, q_true)
            scale = 180 / np.pi if angles.degrees else 1.0
            # total first and widest, so that heading and inclination (each at most the total) stay visible on it
            widths = {"total": 2.4, "heading": 1.2, "inclination": 1.2}
            lines = [
                (name, errors[name] * scale, {**style, "lw": lw})
                for (name, lw), style in zip(widths.items(), line_styles(3), strict=True)
            ]
            title = f"{path.name}: attitude error against {Path(truth).name}{note}"
            figures["errors"] = _time_series(plt, t, lines, f"error [{unit}]", xlabel, title)

        if bias_names:
            styles = line_styles(len(bias_names))
            lines = [(n, data[n], style) for n, style in zip(bias_names, styles, strict=True)]
            figures["bias"] = _time_series(plt, t, lines, "gyro bias", xlabel, f"{path.name}: estimated gyro bias")
    except BaseException:
        for fig in figures.values():
            plt.close(fig)
        raise
    return figures


def plot_comparison(comparison, directory, prefix: str = "compare") -> list[Path]:
    """Write the two figures of a method comparison (:func:`comparison_figures`) as PNG files.

    Parameters
    ----------
    comparison : strapdown.compare.Comparison
        The result of :func:`strapdown.compare.compare`.
    directory : path-like
        Folder for ``<prefix>_angles.png`` and ``<prefix>_errors.png`` (created if missing).
    prefix : str
        File-name prefix.

    Returns
    -------
    list of pathlib.Path
        The files written (both or, on failure, none).

    Examples
    --------
    >>> import pathlib, tempfile
    >>> from strapdown.compare import compare
    >>> from strapdown.io.plots import plot_comparison
    >>> from strapdown.simulate import ConstantRotation, sample
    >>> cmp = compare(sample(ConstantRotation([0.0, 0.0, 1.0], duration=1.0), 50.0), methods=["exact", "rk4"])
    >>> [p.name for p in plot_comparison(cmp, tempfile.mkdtemp(), "spin")]
    ['spin_angles.png', 'spin_errors.png']
    """
    directory = Path(directory)
    figures = comparison_figures(comparison)
    return save_figures({directory / f"{prefix}_{name}.png": fig for name, fig in figures.items()})


def comparison_figures(comparison) -> dict:
    """The figures of a method comparison: Euler angles over time, and every method's error.

    The angles figure draws the truth and the ``exact`` and ``euler-angles`` methods over it, marks where a
    method stopped at its singularity and shades where yaw and roll are not drawn (near the vertical).  The
    error figure has one panel per family of methods (quaternion steps, multi-sample coning algorithms, Gajda's
    baselines), every method in its own colour and dash.

    Parameters
    ----------
    comparison : strapdown.compare.Comparison
        The result of :func:`strapdown.compare.compare`.

    Returns
    -------
    dict
        ``{"angles": Figure, "errors": Figure}`` (matplotlib figures, open: show, save or close them).

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from strapdown.compare import compare
    >>> from strapdown.io.plots import comparison_figures
    >>> from strapdown.simulate import ConstantRotation, sample
    >>> cmp = compare(sample(ConstantRotation([0.0, 0.0, 1.0], duration=1.0), 50.0), methods=["exact", "rk4"])
    >>> figs = comparison_figures(cmp)
    >>> [ax.get_title() for ax in figs["errors"].axes]
    ['quaternion steps']
    >>> plt.close("all")
    """
    plt = _pyplot()
    t = comparison.data.t
    title = comparison.title.strip() or "attitude"
    figures = {}
    try:
        shown = {r.method: r for r in comparison.results if r.method in ("exact", "euler-angles")}
        fig, axes = _angles_axes(
            plt, t, comparison.data.q_true, {m: r.q for m, r in shown.items()}, Angles(yaw_range="signed"), 10.0,
            "time [s]",
        )  # fmt: skip
        for r in shown.values():
            if r.first_singular_time is not None:
                for ax in axes:
                    ax.axvline(r.first_singular_time, color="r", ls=":", lw=1)
                axes[1].annotate(
                    f"{r.method} stops at its singularity",
                    (r.first_singular_time, 0.05),
                    xycoords=("data", "axes fraction"),
                    color="r",
                    fontsize=8,
                    xytext=(4, 0),
                    textcoords="offset points",
                )
        fig.suptitle(title)
        figures["angles"] = fig

        # small multiples by family, each method also in its own style: 17 lines in one panel cannot be read
        results = list(comparison.results)
        styles = dict(zip([r.method for r in results], line_styles(len(results)), strict=True))
        families = {"quaternion steps": [], "multi-sample (coning)": [], "Gajda's baselines": []}
        for r in results:
            family = "Gajda's baselines" if r.method in _BASELINES else "quaternion steps"
            families["multi-sample (coning)" if r.method.startswith("coning") else family].append(r)
        families = {k: v for k, v in families.items() if v}
        fig, axes = plt.subplots(
            1, len(families), sharey=True, figsize=(5 * len(families), 5.5), constrained_layout=True, squeeze=False
        )
        for ax, (family, members) in zip(axes[0], families.items(), strict=True):
            for r in members:
                ax.semilogy(t, np.degrees(np.maximum(r.error, 1e-16)), label=r.method, **styles[r.method])
                if r.first_singular_time is not None:
                    ax.axvline(r.first_singular_time, color=styles[r.method]["color"], ls=":", lw=1)
            ax.set_title(family, fontsize=10)
            ax.set_xlabel("time [s]")
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=8, loc="best")
        axes[0, 0].set_ylabel("attitude error [deg]")
        fig.suptitle(f"{title}: attitude error of every method (dotted: a baseline stopped at its singularity)")
        figures["errors"] = fig
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
    from ..frames import change_frame

    return change_frame(q_true, ref_from=theirs, ref_to=ours), f" (truth taken from {theirs} to {ours})"


def _frame_of(path, format, *keys: str) -> str | None:
    """The reference frame a file's metadata names under the first of ``keys`` present, upper case."""
    meta = read_metadata(path, format)
    for key in keys:
        if meta.get(key):
            return meta[key].upper()
    return None
