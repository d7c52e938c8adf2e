"""Figures of attitudes over time (matplotlib, the ``plot`` extra), written as PNG files all or nothing.

The panels of ``strapdown plot`` (:func:`strapdown.io.pipelines.plot.plot_file`) and ``strapdown demo``
(:func:`angles_figure`, :func:`time_series_figure`, :func:`shade`), and the figures of a method comparison
(:func:`comparison_figures`, :func:`plot_comparison` for a :class:`strapdown.evaluate.compare.Comparison`).

What every figure obeys:

* every line has its own colour and dash (:func:`line_styles`), so 17 methods can be told apart;
* a truth is drawn first, wide and grey, so the estimates lie on top of it and it shows where they leave it;
* the outer angles (yaw and roll of ``"ZYX"``) are unwrapped, so a turn through 360° is a straight line and
  not a saw tooth, and they are not drawn near gimbal lock (where only their sum or difference is defined):
  those stretches are shaded and the figure says so (:func:`angles_for_display`);
* a set of figures is written all or nothing (:func:`save_figures`): when one fails, none is left behind.

The functions that draw take ``plt``, the ``matplotlib.pyplot`` module (:func:`pyplot` imports it, headless),
and the times ``t`` of shape (n,) that the x axis shows.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from .._support.deps import need
from .._support.files import _umask
from ..rotations.values import Angles, column_names, to_values

__all__ = [
    "angles_figure",
    "angles_for_display",
    "comparison_figures",
    "line_styles",
    "plot_comparison",
    "pyplot",
    "save_figures",
    "shade",
    "time_series_figure",
]


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
    >>> from strapdown.evaluate.figures import line_styles
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
    >>> from strapdown.evaluate.figures import angles_for_display
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
    >>> from strapdown.evaluate.figures import save_figures
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


def pyplot():
    """matplotlib.pyplot on the Agg backend (files, no window); an ImportError naming the ``plot`` extra.

    Returns
    -------
    module
        ``matplotlib.pyplot``.

    Examples
    --------
    >>> from strapdown.evaluate.figures import pyplot
    >>> pyplot().get_backend().lower()
    'agg'
    """
    need("matplotlib", "plotting")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def shade(ax, t, mask, **kw) -> bool:
    """Shade the stretches of ``t`` where ``mask`` holds (one legend entry for them all).

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    t : array_like, shape (n,)
        The times of the samples.
    mask : array_like of bool, shape (n,)
        The samples to shade.
    **kw
        Passed to ``ax.axvspan`` (``color``, ``label``, ``zorder``).

    Returns
    -------
    bool
        Whether anything was shaded.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.evaluate.figures import pyplot, shade
    >>> fig, ax = pyplot().subplots()
    >>> shade(ax, np.arange(5.0), [0, 1, 1, 0, 1], color="0.9"), len(ax.patches)
    (True, 2)
    """
    edges = np.flatnonzero(np.diff(np.r_[0, np.asarray(mask, dtype=np.int8), 0]))
    for k, (a, b) in enumerate(zip(edges[::2], edges[1::2], strict=True)):
        if k == 1:
            kw.pop("label", None)  # one legend entry for all the stretches
        ax.axvspan(t[a], t[min(b, len(t) - 1)], lw=0, **kw)
    return edges.size > 0


def angles_figure(plt, t, truth, series, angles: Angles, margin_deg: float, xlabel: str):
    """Three panels of Euler angles: the truth (if any) under every series, blanked stretches shaded.

    Parameters
    ----------
    plt, t
        Pyplot and the times (module notes).
    truth : array_like, shape (n, 4), optional
        The true attitudes, drawn first and wide; None for none.
    series : dict of str to array_like, shape (n, 4)
        The attitudes to draw, by label.
    angles : strapdown.rotations.values.Angles
        Sequence, unit and range.
    margin_deg : float
        Outer angles are not drawn within this of gimbal lock (:func:`angles_for_display`).
    xlabel : str
        The time axis's label.

    Returns
    -------
    fig : matplotlib.figure.Figure
    axes : array of matplotlib.axes.Axes, shape (3,)

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.evaluate.figures import angles_figure, pyplot
    >>> from strapdown.rotations.values import Angles
    >>> t = np.linspace(0, 1, 20)
    >>> q = np.column_stack([np.cos(t / 2), 0 * t, 0 * t, np.sin(t / 2)])
    >>> fig, axes = angles_figure(pyplot(), t, q, {"estimate": q}, Angles(), 10.0, "time [s]")
    >>> [ax.get_ylabel() for ax in axes]
    ['yaw [deg]', 'pitch [deg]', 'roll [deg]']
    """
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
        if shade(ax, t, blanked, color="#fff2b3", zorder=0):
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


def time_series_figure(plt, t, lines, ylabel: str, xlabel: str, title: str):
    """One panel of lines over time, with grid and legend.

    Parameters
    ----------
    plt, t
        As for :func:`angles_figure`.
    lines : sequence of (str, array_like, dict)
        Label, values (n,) or (n, k), and the line's style (:func:`line_styles`).
    ylabel, xlabel, title : str
        The labels.

    Returns
    -------
    matplotlib.figure.Figure
        The figure.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.evaluate.figures import line_styles, pyplot, time_series_figure
    >>> t = np.arange(10.0)
    >>> fig = time_series_figure(pyplot(), t, [("x", t, line_styles(1)[0])], "x [m]", "t [s]", "a line")
    >>> fig.axes[0].get_title()
    'a line'
    """
    fig, ax = plt.subplots(figsize=(10, 4), constrained_layout=True)
    for label, values, style in lines:
        ax.plot(t, values, label=label, **style)
    ax.set_ylabel(ylabel)
    ax.set_xlabel(xlabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    return fig


def plot_comparison(comparison, directory, prefix: str = "compare") -> list[Path]:
    """Write the two figures of a method comparison (:func:`comparison_figures`) as PNG files.

    Parameters
    ----------
    comparison : strapdown.evaluate.compare.Comparison
        The result of :func:`strapdown.evaluate.compare.compare`.
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
    >>> from strapdown.evaluate.compare import compare
    >>> from strapdown.evaluate.figures import plot_comparison
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
    comparison : strapdown.evaluate.compare.Comparison
        The result of :func:`strapdown.evaluate.compare.compare`.

    Returns
    -------
    dict
        ``{"angles": Figure, "errors": Figure}`` (matplotlib figures, open: show, save or close them).

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from strapdown.evaluate.compare import compare
    >>> from strapdown.evaluate.figures import comparison_figures
    >>> from strapdown.simulate import ConstantRotation, sample
    >>> cmp = compare(sample(ConstantRotation([0.0, 0.0, 1.0], duration=1.0), 50.0), methods=["exact", "rk4"])
    >>> figs = comparison_figures(cmp)
    >>> [ax.get_title() for ax in figs["errors"].axes]
    ['quaternion steps']
    >>> plt.close("all")
    """
    plt = pyplot()
    t = comparison.data.t
    title = comparison.title.strip() or "attitude"
    figures = {}
    try:
        shown = {r.method: r for r in comparison.results if r.method in ("exact", "euler-angles")}
        fig, axes = angles_figure(
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
