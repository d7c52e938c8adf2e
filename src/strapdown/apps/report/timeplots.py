"""The report's figures against time: one time axis for all, a cursor on each, and the lines decimated for display.

:class:`TimePlots` makes every figure with the same x range (zooming one zooms all), a dashed cursor that the
time slider moves and that a click on any figure sets, and tables thinned by :func:`.decimate.minmax_indices`
(float32: a page of a one-hour log stays small).  Bands mark where a flag is set (rest, acc or mag rejected,
inverted, bias at limit) and the gaps, on the figures and in a lane of their own.
"""

from __future__ import annotations

import numpy as np

from .decimate import break_lines, minmax_indices

__all__ = ["FLAG_COLOURS", "TimePlots", "intervals"]

#: Bands: flag name -> (label, colour).
FLAG_COLOURS = {
    "rest": ("rest", "#2ca02c"),
    "acc_rejected": ("acc rejected", "#ff7f0e"),
    "mag_rejected": ("mag rejected", "#9467bd"),
    "inverted": ("inverted", "#d62728"),
    "bias_at_limit": ("bias at limit", "#8c564b"),
    "gap": ("gap", "#7f7f7f"),
}

PALETTE = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b")
AXIS_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")


def intervals(t: np.ndarray, mask: np.ndarray, join: float) -> tuple[np.ndarray, np.ndarray]:
    """(starts, ends) in seconds of the runs of ``mask``, runs closer than ``join`` seconds merged.

    A run covers its samples' times; a single sample is a run of zero length, which the page widens to
    ``join`` so that it shows.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.apps.report.timeplots import intervals
    >>> a, b = intervals(np.arange(10.0), np.array([0, 1, 1, 0, 0, 0, 1, 0, 1, 1], bool), 2.5)
    >>> a.tolist(), b.tolist()
    ([1.0, 6.0], [2.0, 9.0])
    """
    m = np.asarray(mask, dtype=bool)
    if not m.any():
        return np.zeros(0), np.zeros(0)
    d = np.diff(m.astype(np.int8), prepend=0, append=0)
    first, last = np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1
    a, b = t[first], t[last]
    if a.size > 1:
        keep = np.r_[True, a[1:] - b[:-1] > join]  # a run starting within `join` of the last one joins it
        a, b = a[keep], np.maximum.reduceat(b, np.flatnonzero(keep))
    return a, b


class TimePlots:
    """Figures on one time axis, with their cursors.

    Parameters
    ----------
    t : numpy.ndarray, shape (n,)
        Seconds from the first sample.
    segment : numpy.ndarray of int, shape (n,)
        Segment of each row (lines are broken between segments).
    points : int
        Buckets per line (:func:`.decimate.minmax_indices`).
    """

    def __init__(self, t: np.ndarray, segment: np.ndarray, points: int):
        from bokeh.models import Range1d

        self.t = t
        self.segment = segment
        self.points = points
        end = float(t[-1]) if t[-1] > t[0] else float(t[0]) + 1.0
        self.x_range = Range1d(float(t[0]), end, bounds=(float(t[0]), end))
        self.join = (end - float(t[0])) / (4 * points)
        self.spans: list = []
        self.figures: list = []
        self.slider = None  # set by the page before figures are made: a click moves it

    def figure(self, title: str, y_label: str, height: int = 190, **kw):
        """A new figure on the common time axis, with its cursor (``kw`` for :func:`bokeh.plotting.figure`)."""
        from bokeh.models import CustomJS, Span
        from bokeh.plotting import figure

        f = figure(
            height=height,
            sizing_mode="stretch_width",
            min_width=500,
            x_range=self.x_range,
            title=title,
            tools="xpan,xwheel_zoom,xbox_zoom,reset,save",
            active_scroll="xwheel_zoom",
            name=f"time:{title}",
            **kw,
        )
        f.yaxis.axis_label = y_label
        f.xaxis.axis_label = "t (s)"
        f.min_border_left = 70
        f.toolbar.logo = None
        span = Span(
            location=float(self.t[0]), dimension="height", line_color="#222222", line_dash="dashed", level="overlay"
        )
        span.tags = ["cursor"]
        f.add_layout(span)
        self.spans.append(span)
        self.figures.append(f)
        if self.slider is not None:
            code = "slider.value = Math.min(Math.max(cb_obj.x, slider.start), slider.end);"
            f.js_on_event("tap", CustomJS(args={"slider": self.slider}, code=code))
        return f

    def source(self, columns: dict, rows=None, wrap: tuple = ()):
        """A ColumnDataSource of ``t`` and ``columns`` (each shape (n,)) thinned for display, float32.

        ``rows`` restricts the table to some rows (a sensor at a lower rate: those with a sample); the columns
        named in ``wrap`` are angles in degrees whose jumps over ±180° break the line instead of crossing it.
        """
        from bokeh.models import ColumnDataSource

        rows = np.arange(self.t.size) if rows is None else np.asarray(rows)
        t = self.t[rows]
        values = np.column_stack([np.asarray(v, dtype=np.float64)[rows] for v in columns.values()])
        keep = minmax_indices(t, values, self.points) if t.size else np.zeros(0, dtype=np.intp)
        seg = self.segment[rows][keep]
        change = np.diff(seg, prepend=seg[:1]) != 0
        for name in wrap:  # a wrap of an angle starts a new piece of line too
            v = values[keep, list(columns).index(name)]
            change |= np.abs(np.diff(v, prepend=v[:1])) > 180.0
        picked = break_lines(keep, np.cumsum(change))
        valid = picked >= 0
        data = {"t": np.where(valid, t[np.maximum(picked, 0)], np.nan).astype(np.float32)}
        for j, name in enumerate(columns):
            data[name] = np.where(valid, values[np.maximum(picked, 0), j], np.nan).astype(np.float32)
        return ColumnDataSource(data)

    def lines(self, f, source, names, labels=None, colours=PALETTE, **style):
        """One line per column of ``source``; returns the renderers (for the y range and legends).

        The legend goes above the figure, in a row, so that every figure's time axis starts at the same place and
        no legend hides a line; a click on an entry hides its line.
        """
        out = []
        for i, name in enumerate(names):
            label = None if labels is None else labels[i]
            kw = {"legend_label": label} if label else {}
            out.append(f.line("t", name, source=source, line_color=colours[i % len(colours)], **style, **kw))
        if labels is not None and f.legend and f.legend[0] not in f.above:
            legend = f.legend[0]
            legend.update(orientation="horizontal", click_policy="hide", label_text_font_size="10px", margin=2)
            legend.update(padding=2, spacing=8, glyph_width=16, glyph_height=10, label_height=10)
            f.add_layout(legend, "above")
        return out

    def bands(self, f, flags: dict, names=None, alpha: float = 0.13):
        """Shaded spans where each named flag is set (full height of ``f``), under its lines."""
        from bokeh.models import ColumnDataSource

        for name in names or flags:
            if name not in flags:
                continue
            a, b = flags[name]
            if not a.size:
                continue
            b = np.maximum(b, a + self.join)
            src = ColumnDataSource({"left": a.astype(np.float32), "right": b.astype(np.float32)})
            colour = FLAG_COLOURS[name][1]
            r = f.quad(left="left", right="right", bottom=-1e9, top=1e9, source=src, level="underlay")
            r.glyph.update(fill_color=colour, fill_alpha=alpha, line_alpha=0.0)
            r.tags = [f"band:{name}"]

    def fit_y(self, f, renderers) -> None:
        """Let the y range follow ``renderers`` only (not the bands, which span everything)."""
        from bokeh.models import DataRange1d

        f.y_range = DataRange1d(renderers=list(renderers), range_padding=0.08)

    def lanes(self, flags: dict):
        """A figure with one lane per flag (and the gaps), its intervals drawn as bars."""
        from bokeh.models import ColumnDataSource, FactorRange

        names = [n for n in FLAG_COLOURS if n in flags]
        labels = [FLAG_COLOURS[n][0] for n in names] or ["none set"]
        f = self.figure("flags", "", height=max(120, 28 * len(labels) + 60), y_range=FactorRange(*reversed(labels)))
        for name in names:
            a, b = flags[name]
            if not a.size:
                continue
            b = np.maximum(b, a + self.join)
            lane = FLAG_COLOURS[name][0]
            src = ColumnDataSource({"y": [lane] * a.size, "left": a.astype(np.float32), "right": b.astype(np.float32)})
            f.hbar(y="y", left="left", right="right", height=0.7, source=src, color=FLAG_COLOURS[name][1])
        if not names:  # said in the lane, so that an empty figure never looks like one that failed to draw
            middle = (self.x_range.start + self.x_range.end) / 2
            f.text(
                x=[middle],
                y=["none set"],
                text=["no flag set and no gap over the recording"],
                text_align="center",
                text_baseline="middle",
            )
        return f
