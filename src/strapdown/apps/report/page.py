"""The report page: a :class:`~.data.Recording` drawn with Bokeh into one HTML file that works offline.

Why Bokeh: it writes a standalone file with its scripts inline (``bokeh.resources.INLINE``: nothing is fetched when
the page opens, no CDN), linked ranges are one shared object, and ``CustomJS`` callbacks wire a slider, a play
button and a drag to any part of the page without a server; the figures draw on a 2D canvas, so the page and its
3D view work in any browser, with or without a GPU, headless ones included.  Plotly would give a WebGL 3D scene,
which headless browsers and many remote desktops cannot draw, and animates by precomputed frames, which for a long
log means a large page.

Tabs: summary (with the error table), attitude (yaw, pitch and roll of every estimator over the reference, the
errors below and the flags' lanes), quaternion, sensors (gyro, ``|acc|`` against g, ``|mag|`` and the magnetic
dip), bias (with ±σ), estimators (side by side) and calibration (when one was applied or fitted, or an Allan
recording given).  Beside them the 3D view, its slider and play button.  The page's numbers are also in a
``<script type="application/json" id="strapdown-results">`` block (:func:`.summary.results`).
"""

from __future__ import annotations

import html
import json

import numpy as np

from .summary import ERROR_COLUMNS, error_rows, results
from .timeplots import AXIS_COLOURS, PALETTE, TimePlots, intervals
from .widgets import make_slider, view_panel

__all__ = ["page_html"]

_G = 9.80665
_ANGLES = ("yaw", "pitch", "roll")


def page_html(rec, options) -> str:
    """The whole page as HTML text.

    Parameters
    ----------
    rec : Recording
        From :func:`.data.assemble`.
    options : ReportOptions
        ``points`` and ``frames``.

    Returns
    -------
    str
        A standalone HTML document.
    """
    from ..._support.deps import need

    need("bokeh", "strapdown report")
    from bokeh.embed import file_html
    from bokeh.layouts import column, row
    from bokeh.models import TabPanel, Tabs
    from bokeh.resources import INLINE

    plots = TimePlots(rec.t, rec.segment, options.points)
    plots.slider = make_slider(rec.t, options.frames)
    flags = _flag_intervals(rec, plots)
    tabs = [TabPanel(child=_summary(rec), title="Summary")]
    tabs.append(TabPanel(child=column(*_attitude(rec, plots, flags), sizing_mode="stretch_width"), title="Attitude"))
    tabs.append(TabPanel(child=_quaternion(rec, plots), title="Quaternion"))
    tabs.append(TabPanel(child=column(*_sensors(rec, plots, flags), sizing_mode="stretch_width"), title="Sensors"))
    bias = _bias(rec, plots, flags)
    if bias is not None:
        tabs.append(TabPanel(child=bias, title="Bias"))
    tabs.append(TabPanel(child=_estimators(rec, plots), title="Estimators"))
    calibration = _calibration(rec)
    if calibration is not None:
        tabs.append(TabPanel(child=calibration, title="Calibration"))
    view = view_panel(rec, rec.main, plots.slider, plots.spans, options.frames)
    page = row(view, Tabs(tabs=tabs, sizing_mode="stretch_width", name="tabs"), sizing_mode="stretch_width")
    title = rec.title or ", ".join(p.name for p in rec.paths)
    text = file_html(page, INLINE, title=f"strapdown report: {title}")
    block = json.dumps(results(rec), allow_nan=False, default=float).replace("</", "<\\/")
    script = f'<script type="application/json" id="strapdown-results">{block}</script>\n'
    end = text.rindex("</body>")  # the last: the inline scripts hold the text "</body>" too
    return text[:end] + script + text[end:]


def _flag_intervals(rec, plots: TimePlots) -> dict:
    out = {name: intervals(rec.t, mask, plots.join) for name, mask in rec.main.flags.items() if np.any(mask)}
    if rec.gaps:
        out["gap"] = (np.array([a for a, _ in rec.gaps]), np.array([b for _, b in rec.gaps]))
    return out


def _degrees(run) -> np.ndarray:
    from ...rotations.euler import as_euler

    return as_euler(run.q, "ZYX", degrees=True)


def _attitude(rec, plots: TimePlots, flags: dict) -> list:
    """Yaw, pitch and roll of every run over the reference, the errors and the flag lanes."""
    from ...rotations.euler import as_euler

    angles = {run.name: _degrees(run) for run in rec.runs}
    ref = None
    if rec.reference is not None:
        inside = np.isfinite(rec.reference).all(axis=1)
        ref = np.full((rec.t.size, 3), np.nan)
        ref[inside] = as_euler(rec.reference[inside], "ZYX", degrees=True)
    out = []
    for j, name in enumerate(_ANGLES):
        f = plots.figure(f"{name} ({'ZYX'[j]})", "deg")
        columns = {}
        if ref is not None:
            columns["reference"] = ref[:, j]
        columns.update({run: a[:, j] for run, a in angles.items()})
        src = plots.source(columns, wrap=tuple(columns) if j != 1 else ())
        lines = []
        if ref is not None:
            lines += plots.lines(f, src, ["reference"], [rec.reference_label], ("#9aa0a8",), line_width=4, alpha=0.6)
        lines += plots.lines(f, src, list(angles), list(angles), line_width=1.3)
        plots.bands(f, flags, ["inverted", "gap"])  # every flag has its lane below
        plots.fit_y(f, lines)
        out.append(f)
    if rec.reference is not None:
        f = plots.figure(f"error against {rec.reference_label}", "deg")
        columns = {}
        for run in rec.runs:
            for kind in ("total", "heading", "inclination"):
                columns[f"{run.name} {kind}"] = np.degrees(run.errors[kind])
        src = plots.source(columns)
        lines = []
        for i, run in enumerate(rec.runs):
            colour = (PALETTE[i % len(PALETTE)],)
            for kind, dash in (("total", "solid"), ("heading", "dashed"), ("inclination", "dotted")):
                name = f"{run.name} {kind}"
                lines += plots.lines(f, src, [name], [name], colour, line_dash=dash)
        plots.fit_y(f, lines)
        out.append(f)
    out.append(plots.lanes(flags))
    return out


def _quaternion(rec, plots: TimePlots):
    f = plots.figure(f"quaternion of {rec.main.name} (w, x, y, z; {rec.axes.body} to {rec.axes.frame})", "", 320)
    q = rec.main.q
    columns = {c: q[:, i] for i, c in enumerate("wxyz")}
    if rec.reference is not None:
        # the reference on the estimate's sign, so that q and -q (one attitude) do not look different
        ref = rec.reference * np.where(np.nansum(rec.reference * q, axis=1) < 0, -1.0, 1.0)[:, None]
        columns.update({f"ref {c}": ref[:, i] for i, c in enumerate("wxyz")})
    src = plots.source(columns)
    colours = ("#333333", *AXIS_COLOURS)
    lines = plots.lines(f, src, list("wxyz"), [f"q{c}" for c in "wxyz"], colours, line_width=1.3)
    if rec.reference is not None:
        lines += plots.lines(f, src, [f"ref {c}" for c in "wxyz"], None, colours, line_width=4, alpha=0.25)
    plots.fit_y(f, lines)
    return f


def _rows_with(x: np.ndarray) -> np.ndarray:
    return np.flatnonzero(np.isfinite(x).all(axis=1))


def _sensors(rec, plots: TimePlots, flags: dict) -> list:
    """Gyro, |acc| against g, |mag| and the magnetic dip: why a stretch was rejected."""
    from ...rotations.frames import frame_matrix
    from ...rotations.quaternion import rotate

    out = []
    f = plots.figure("gyro (body axes)", "deg/s")
    g = np.degrees(rec.gyro)
    src = plots.source({a: g[:, i] for i, a in enumerate("xyz")})
    lines = plots.lines(
        f, src, list("xyz"), [f"gyro {a} {rec.axes.body[i]}" for i, a in enumerate("xyz")], AXIS_COLOURS
    )
    plots.bands(f, flags, ["rest", "gap"])
    plots.fit_y(f, lines)
    out.append(f)
    if rec.acc is not None:
        rows = _rows_with(rec.acc)
        f = plots.figure("|acc| against g", "m/s²")
        src = plots.source({"norm": np.linalg.norm(rec.acc, axis=1)}, rows=rows)
        lines = plots.lines(f, src, ["norm"], ["|acc|"], ("#ff7f0e",))
        f.line(
            [float(rec.t[0]), float(rec.t[-1])], [_G, _G], line_color="#333333", line_dash="dashed", legend_label="g"
        )
        plots.bands(f, flags, ["acc_rejected", "gap"])
        plots.fit_y(f, lines)
        out.append(f)
    if rec.mag is not None:
        rows = _rows_with(rec.mag)
        m = rec.mag
        # the field in the reference frame, turned to east-north-up: dip is its angle below the horizontal
        enu = rotate(rec.main.q[rows], m[rows]) @ frame_matrix(rec.axes.frame, "ENU").T
        dip = np.full(rec.t.size, np.nan)
        dip[rows] = np.degrees(np.arctan2(-enu[:, 2], np.hypot(enu[:, 0], enu[:, 1])))
        f = plots.figure("|mag| (calibrated)" if "mag" in rec.calibrations else "|mag|", "µT")
        src = plots.source({"norm": np.linalg.norm(m, axis=1)}, rows=rows)
        lines = plots.lines(f, src, ["norm"], ["|mag|"], ("#9467bd",))
        plots.bands(f, flags, ["mag_rejected", "gap"])
        plots.fit_y(f, lines)
        out.append(f)
        f = plots.figure(f"magnetic dip (below the horizontal, by {rec.main.name}'s attitude)", "deg")
        src = plots.source({"dip": dip}, rows=rows)
        lines = plots.lines(f, src, ["dip"], ["dip"], ("#9467bd",))
        median = float(np.nanmedian(dip)) if rows.size else 0.0
        f.line(
            [float(rec.t[0]), float(rec.t[-1])],
            [median, median],
            line_color="#333333",
            line_dash="dashed",
            legend_label=f"median {median:.1f}°",
        )
        plots.bands(f, flags, ["mag_rejected", "gap"])
        plots.fit_y(f, lines)
        out.append(f)
    return out


def _bias(rec, plots: TimePlots, flags: dict):
    """Each run's gyro bias (deg/s); the main one with its ±σ band."""
    from bokeh.layouts import column

    runs = [r for r in rec.runs if r.bias is not None]
    if not runs:
        return None
    figures = []
    for i, axis in enumerate("xyz"):
        f = plots.figure(f"gyro bias, {axis} ({rec.axes.body[i]})", "deg/s", 200)
        columns = {}
        for run in runs:
            columns[run.name] = np.degrees(run.bias[:, i])
            if run.bias_sigma is not None:
                columns[f"{run.name} lo"] = columns[run.name] - np.degrees(run.bias_sigma[:, i])
                columns[f"{run.name} hi"] = columns[run.name] + np.degrees(run.bias_sigma[:, i])
        src = plots.source(columns)
        lines = []
        for k, run in enumerate(runs):
            colour = PALETTE[k % len(PALETTE)]
            if run.bias_sigma is not None:
                band = f.varea(
                    "t",
                    f"{run.name} lo",
                    f"{run.name} hi",
                    source=src,
                    fill_color=colour,
                    fill_alpha=0.2,
                    legend_label=f"{run.name} ±σ",
                )
                lines.append(band)
            lines += plots.lines(f, src, [run.name], [run.name], (colour,), line_width=1.5)
        plots.bands(f, flags, ["bias_at_limit", "rest", "gap"])
        plots.fit_y(f, lines)
        figures.append(f)
    return column(*figures, sizing_mode="stretch_width")


def _estimators(rec, plots: TimePlots):
    """The estimators side by side: the error table, and each one's error (or difference to the first)."""
    from bokeh.layouts import column, row

    from ...rotations.quaternion import angle_between

    figures = []
    for i, run in enumerate(rec.runs):
        if run.errors is not None:
            f = plots.figure(f"{run.name} ({run.mode}) error", "deg", 260)
            columns = {k: np.degrees(run.errors[k]) for k in ("total", "heading", "inclination")}
        else:
            f = plots.figure(f"{run.name} ({run.mode}) against {rec.main.name}", "deg", 260)
            columns = {"total": np.degrees(angle_between(run.q, rec.main.q))}
        src = plots.source(columns)
        lines = []
        for kind, dash in zip(columns, ("solid", "dashed", "dotted"), strict=False):
            lines += plots.lines(f, src, [kind], [kind], (PALETTE[i % len(PALETTE)],), line_dash=dash)
        plots.fit_y(f, lines)
        f.min_width = 300
        figures.append(f)
    return column(_error_table(rec), row(*figures, sizing_mode="stretch_width"), sizing_mode="stretch_width")


def _calibration(rec):
    from bokeh.layouts import row

    from .calibration import allan_figure, mag_figure

    parts = []
    cal = rec.calibrations.get("mag")
    if cal is not None and rec.mag_raw is not None:
        parts.append(mag_figure(rec.mag_raw, cal.apply(rec.mag_raw), cal))
    if rec.allan is not None:
        parts.append(allan_figure(rec.allan))
    return row(*parts) if parts else None


_STYLE = (
    "<style>table.sd{border-collapse:collapse;font:13px sans-serif;margin:6px 0}"
    "table.sd td,table.sd th{border:1px solid #d0d4da;padding:3px 8px;text-align:left;vertical-align:top}"
    "table.sd th{background:#f1f3f6}</style>"
)


def _summary(rec):
    from bokeh.models import Div

    cells = "".join(
        f"<tr><th>{html.escape(k)}</th><td data-key='{html.escape(k)}'>{html.escape(v)}</td></tr>"
        for k, v in rec.summary
    )
    text = (
        f"{_STYLE}<h3 style='font:600 16px sans-serif'>{html.escape(rec.title)}</h3><table class='sd'>{cells}</table>"
    )
    from bokeh.layouts import column

    return column(
        Div(text=text, name="summary", sizing_mode="stretch_width"), _error_table(rec), sizing_mode="stretch_width"
    )


def _error_table(rec):
    """Each estimator's RMS errors against the reference and its final bias, as a table."""
    from bokeh.models import Div

    rows = error_rows(rec)
    head = ["estimator", "mode", "north", *ERROR_COLUMNS.values(), "final bias (deg/s)"]
    body = []
    for r in rows:
        cells = [r["estimator"], r["mode"], r["north"]]
        values = [f"{r[k]:.3f}" if k in r else "–" for k in ERROR_COLUMNS]
        bias = r.get("bias_deg_s")
        sigma = r.get("bias_sigma_deg_s")
        if bias is None:
            btext = "–"
        elif sigma is None:
            btext = ", ".join(f"{b:.4f}" for b in bias)
        else:
            btext = ", ".join(f"{b:.4f} ± {s:.4f}" for b, s in zip(bias, sigma, strict=True))
        tds = "".join(f"<td>{html.escape(c)}</td>" for c in cells)
        tds += "".join(f"<td data-rms='{k}'>{v}</td>" for k, v in zip(ERROR_COLUMNS, values, strict=True))
        tds += f"<td data-bias='1'>{html.escape(btext)}</td>"
        body.append(f"<tr data-estimator='{html.escape(r['estimator'])}'>{tds}</tr>")
    note = "" if rec.reference is not None else "<p style='font:12px sans-serif'>no reference: give --truth</p>"
    ths = "".join(f"<th>{html.escape(h)}</th>" for h in head)
    return Div(
        text=f"{_STYLE}<table class='sd errors'><tr>{ths}</tr>{''.join(body)}</table>{note}",
        name="errors",
        sizing_mode="stretch_width",
    )
