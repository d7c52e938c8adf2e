"""The calibration tab: the magnetometer's points before and after its fit on a sphere, and the Allan curve.

The magnetometer figure projects both clouds (the raw readings, off-centre and squashed by hard and soft iron,
and the calibrated ones, which should lie on the sphere of the field's strength) with the camera of the 3D view;
a drag turns it.  The Allan figure shows the measured deviation of each gyro axis, the fitted model and its three
straight lines: angle random walk N/√τ, the bias-instability floor 0.664 B and the rate random walk K √(τ/3)
(IEEE Std 952-1997, Annex C; :func:`strapdown.calibrate.allan`).
"""

from __future__ import annotations

import numpy as np

from .view3d import CAMERA, _basis, script

__all__ = ["allan_figure", "mag_figure"]

_CLOUD = 3000  # points per cloud, evenly over the recording


def _sphere(radius: float) -> dict:
    """A wire sphere: three great circles and two parallels, one line with NaN between the circles."""
    s = np.linspace(0, 2 * np.pi, 73)
    c, z0 = np.cos(s), np.zeros_like(s)
    circles = [(c, np.sin(s), z0), (c, z0, np.sin(s)), (z0, c, np.sin(s))]
    for h in (-0.5, 0.5):
        w = np.sqrt(1 - h * h)
        circles.append((w * c, w * np.sin(s), np.full_like(s, h)))
    parts = [np.column_stack(p) * radius for p in circles]
    pts = np.vstack([np.vstack([p, np.full((1, 3), np.nan)]) for p in parts])
    return {"x": pts[:, 0].tolist(), "y": pts[:, 1].tolist(), "z": pts[:, 2].tolist()}


def _cloud(v: np.ndarray) -> dict:
    rows = np.flatnonzero(np.isfinite(v).all(axis=1))
    rows = rows[np.linspace(0, rows.size - 1, min(_CLOUD, rows.size)).astype(int)] if rows.size else rows
    return {"x": v[rows, 0].tolist(), "y": v[rows, 1].tolist(), "z": v[rows, 2].tolist()}


def _project(cloud: dict, camera: dict) -> dict:
    _, r, u = _basis(camera)
    p = np.column_stack([cloud["x"], cloud["y"], cloud["z"]]) if cloud["x"] else np.zeros((0, 3))
    return {"x": (p @ r).tolist(), "y": (p @ u).tolist()}


def mag_figure(raw: np.ndarray, calibrated: np.ndarray, cal):
    """The raw and calibrated magnetometer clouds on the sphere of the fitted field strength (µT, sensor axes)."""
    from bokeh.models import ColumnDataSource, CustomJS

    from .widgets import orbit_figure

    radius = float(cal.quality.get("field_strength") or np.nanmedian(np.linalg.norm(calibrated, axis=1)))
    clouds = {"raw": _cloud(raw), "calibrated": _cloud(calibrated), "sphere": _sphere(radius)}
    sources = {k: ColumnDataSource(_project(v, CAMERA)) for k, v in clouds.items()}
    extent = 1.15 * max(radius, float(np.nanmax(np.abs(raw))) if np.isfinite(raw).any() else radius)
    title = f"magnetometer (µT, {cal.frame} axes): raw and calibrated, sphere of {radius:.1f} µT (drag to turn)"
    f = orbit_figure(520, extent, title, "mag-sphere")
    f.line("x", "y", source=sources["sphere"], line_color="#b0b5bd")
    f.scatter("x", "y", source=sources["raw"], size=3, color="#999999", alpha=0.6, legend_label="raw")
    f.scatter("x", "y", source=sources["calibrated"], size=3, color="#1f77b4", alpha=0.7, legend_label="calibrated")
    f.legend.location = "top_left"
    state = f"const cam = (window.__sdMagCam = window.__sdMagCam || {{az: {CAMERA['az']!r}, el: {CAMERA['el']!r}}});\n"
    code = (
        script()
        + state
        + """SD.orbit(cam, cb_obj.delta_x, cb_obj.delta_y);
const p = SD.points({clouds}, cam);
for (const [name, src] of Object.entries(sources)) src.data = p[name];
"""
    )
    f.js_on_event("pan", CustomJS(args={"clouds": clouds, "sources": sources}, code=code))
    return f


def allan_figure(analysis):
    """The Allan deviation of each gyro axis (deg/h against s), the fitted model and its three lines."""
    from bokeh.plotting import figure

    from .timeplots import AXIS_COLOURS

    to = np.degrees(1.0) * 3600.0  # rad/s -> deg/h
    taus = analysis.taus
    f = figure(
        width=620,
        height=420,
        x_axis_type="log",
        y_axis_type="log",
        title=f"gyro Allan deviation ({analysis.duration:.0f} s at {analysis.fs:g} Hz)",
        tools="pan,wheel_zoom,box_zoom,reset,save",
        name="allan",
    )
    f.xaxis.axis_label = "τ (s)"
    f.yaxis.axis_label = "σ (deg/h)"
    f.toolbar.logo = None
    for i in range(analysis.adev.shape[1]):
        colour = AXIS_COLOURS[i % 3]
        axis = "xyz"[i] if i < 3 else str(i)
        f.scatter(taus, analysis.adev[:, i] * to, color=colour, size=5, legend_label=f"{axis} measured")
        f.line(taus, analysis.fitted[:, i] * to, line_color=colour, line_width=2, legend_label=f"{axis} fitted")
        terms = {
            "N/√τ": analysis.arw[i] / np.sqrt(taus),
            "0.664 B": np.full(taus.shape, np.sqrt(2 * np.log(2) / np.pi) * analysis.bias_instability[i]),
            "K √(τ/3)": analysis.rate_random_walk[i] * np.sqrt(taus / 3),
        }
        for (name, values), dash in zip(terms.items(), ("dashed", "dotted", "dashdot"), strict=True):
            if np.all(values > 0):
                f.line(taus, values * to, line_color=colour, line_dash=dash, alpha=0.7, legend_label=f"{axis} {name}")
    f.legend.click_policy = "hide"
    f.legend.label_text_font_size = "9px"
    f.add_layout(f.legend[0], "right")
    return f
