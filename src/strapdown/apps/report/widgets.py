"""The 3D view's panel: the projected model, the time slider, the play button and the readout, wired together.

One slider drives everything: moving it (by hand, by the play button, or by a click on any time figure) redraws
the model at the attitude of that instant and moves the cursor of every time figure.  A drag on the view turns
the camera.  The callbacks are Bokeh ``CustomJS`` with the projection of ``view3d.js`` in front of their code.
"""

from __future__ import annotations

import numpy as np

from .view3d import CAMERA, scene, script, view_spec

__all__ = ["make_slider", "orbit_figure", "view_panel"]

_LIMIT = 2.3  # half-width of the view, in model units (the reference axes are 1.9 long)


def make_slider(t: np.ndarray, frames: int):
    """The time slider: from the first to the last sample, in ``frames`` steps."""
    from bokeh.models import Slider

    start, end = float(t[0]), float(t[-1])
    end = end if end > start else start + 1.0
    slider = Slider(
        start=start, end=end, value=start, step=(end - start) / frames, title="t (s)", sizing_mode="stretch_width"
    )
    slider.format = "0[.]000"
    slider.tags = ["time-slider"]
    return slider


def _frames(t: np.ndarray, q: np.ndarray, frames: int) -> dict:
    """Attitudes at ``frames`` instants spread evenly over the recording (the last sample at or before each)."""
    from ...rotations.euler import as_euler

    grid = np.linspace(t[0], t[-1], frames)
    k = np.unique(np.clip(np.searchsorted(t, grid, side="right") - 1, 0, t.size - 1))
    ypr = as_euler(q[k], "ZYX", degrees=True)
    cols = {"t": t[k], "qw": q[k, 0], "qx": q[k, 1], "qy": q[k, 2], "qz": q[k, 3]}
    cols.update(yaw=ypr[:, 0], pitch=ypr[:, 1], roll=ypr[:, 2])
    return {name: np.asarray(v, dtype=np.float64) for name, v in cols.items()}


def _readout(frames: dict, k: int) -> str:
    angles = f"yaw {frames['yaw'][k]:.1f}°, pitch {frames['pitch'][k]:.1f}°, roll {frames['roll'][k]:.1f}°"
    return f"t = {frames['t'][k]:.3f} s   {angles}"


# The readout is a label drawn in the view's own canvas, not an HTML block: a block's new text makes Bokeh lay
# the whole page out again, which took most of a slider step's time (benchmarks/bench_report.py).
_READOUT_JS = """
const d = frames.data;
readout.text = `t = ${d.t[k].toFixed(3)} s   yaw ${d.yaw[k].toFixed(1)}°, pitch ${d.pitch[k].toFixed(1)}°, `
  + `roll ${d.roll[k].toFixed(1)}°`;
"""


def orbit_figure(size: int, limit: float, title: str, name: str):
    """A square figure with no axes whose drag turns a camera (its range is fixed: the picture never moves)."""
    from bokeh.models import PanTool, Range1d
    from bokeh.plotting import figure

    bounds = (-limit, limit)
    f = figure(
        width=size,
        height=size,
        x_range=Range1d(*bounds, bounds=bounds),
        y_range=Range1d(*bounds, bounds=bounds),
        tools=[PanTool()],
        toolbar_location=None,
        title=title,
        name=name,
    )
    f.axis.visible = False
    f.grid.visible = False
    return f


def view_panel(rec, run, slider, spans: list, frames: int):
    """The 3D figure, its readout and the play button, and the slider's callback over them and ``spans``.

    Parameters
    ----------
    rec : Recording
        The recording (times, frames).
    run : EstimatorRun
        The estimator whose attitude is drawn.
    slider : bokeh.models.Slider
        From :func:`make_slider`.
    spans : list of bokeh.models.Span
        The cursors of the time figures.
    frames : int
        Attitudes to step through.

    Returns
    -------
    bokeh layout
        The panel (figure, readout, slider, play button).
    """
    from bokeh.layouts import column, row
    from bokeh.models import ColumnDataSource, CustomJS, Label, Toggle

    spec = view_spec(rec.axes.frame, rec.axes.body)
    table = _frames(rec.t, run.q, frames)
    frames_src = ColumnDataSource(table)
    frames_src.tags = ["view-frames"]
    first = scene(spec, [table[c][0] for c in ("qw", "qx", "qy", "qz")])
    model = ColumnDataSource(first["model"])
    axes = ColumnDataSource(first["axes"])
    ring = ColumnDataSource(first["ring"])
    for src, tag in ((model, "view-model"), (axes, "view-axes"), (ring, "view-ring")):
        src.tags = [tag]
    title = f"{run.name}: {rec.axes.body} body in {rec.axes.frame}, angles ZYX (drag to turn)"
    f = orbit_figure(440, _LIMIT, title, "view3d")
    f.outline_line_color = "#cccccc"
    f.line("x", "y", source=ring, line_color="#c8ccd2", line_dash="dotted")
    f.patches("xs", "ys", source=model, fill_color="color", line_color="#2b2f36", line_width=0.6)
    f.segment("x0", "y0", "x1", "y1", source=axes, line_color="color", line_width=2.5)
    f.text("tx", "ty", text="text", source=axes, text_color="color", text_font_size="12px", text_align="center")
    readout = Label(
        x=6, y=6, x_units="screen", y_units="screen", text=_readout(table, 0), name="view-readout", level="overlay"
    )
    readout.update(text_font_size="12px", text_color="#222222", text_font_style="bold")
    f.add_layout(readout)
    sources = {"model": model, "axes": axes, "ring": ring}
    state = f"const cam = (window.__sdCam = window.__sdCam || {{az: {CAMERA['az']!r}, el: {CAMERA['el']!r}}});\n"
    args = {"spec": spec, "frames": frames_src, "readout": readout, **sources}
    draw = "const k = SD.draw(spec, {model, axes, ring}, frames, slider.value, cam);\n" + _READOUT_JS
    slider.js_on_change(
        "value",
        CustomJS(
            args={**args, "slider": slider, "spans": spans},
            code=script() + state + draw + "for (const s of spans) s.location = slider.value;\n",
        ),
    )
    f.js_on_event(
        "pan",
        CustomJS(
            args={**args, "slider": slider},
            code=script() + state + "SD.orbit(cam, cb_obj.delta_x, cb_obj.delta_y);\n" + draw,
        ),
    )
    play = Toggle(label="▶ Play", button_type="primary", width=90, name="play")
    step = (slider.end - slider.start) / frames
    play.js_on_change(
        "active",
        CustomJS(
            args={"slider": slider, "step": step},
            code="""
if (cb_obj.active) {
  if (slider.value >= slider.end) slider.value = slider.start;
  cb_obj.label = "❚❚ Pause";
  window.__sdPlay = setInterval(() => {
    const v = slider.value + step;
    if (v >= slider.end) { slider.value = slider.end; cb_obj.active = false; } else { slider.value = v; }
  }, 40);
} else {
  clearInterval(window.__sdPlay);
  cb_obj.label = "▶ Play";
}
""",
        ),
    )
    return column(f, row(play, slider, sizing_mode="stretch_width"), width=460)
