"""The report's summary and its error table: what was read, how, what was run and what it found, as text.

The same items go into the page (:mod:`.page`) and into its machine-readable block (``results``), so a test or a
script reads the numbers a person sees.
"""

from __future__ import annotations

import dataclasses

import numpy as np

__all__ = ["error_rows", "results", "summarise"]


def _hz(rate: float) -> str:
    return f"{rate:.4g} Hz"


def summarise(rec, o, info: dict) -> list[tuple[str, str]]:
    """The summary of a :class:`~.data.Recording`: (item, text) pairs in the page's order."""
    n = rec.t.size
    duration = float(rec.t[-1]) if n else 0.0
    items = [
        ("Input", ", ".join(p.name for p in rec.paths)),
        ("Format", rec.format),
        ("Read", info["describe"]),
        ("Sensors", ", ".join(f"{k} {_hz(r)}" for k, r in rec.rates.items())),
        ("Duration", f"{duration:.6g} s, {n} rows"),
        ("Frames", f"{rec.axes.describe()} (reference {rec.axes.frame}, body {rec.axes.body})"),
        ("Gaps", _gaps(rec, o)),
        ("Checks", _checks(info)),
    ]
    for run in rec.runs:
        items.append((f"Estimator {run.name}", f"{run.mode}; {_params(run.params)}"))
    for run in rec.runs:
        final = run.final_bias
        if final is not None:
            items.append((f"Bias found ({run.name})", _bias(*final)))
    items.append(("Heading", ", ".join(f"{r.name}: {r.heading}" for r in rec.runs) + _declination(o)))
    items.append(("Reference", rec.reference_label or "none (give --truth for errors)"))
    if rec.calibrations:
        fitted = " (fitted on this recording)" if o.fit_mag else ""
        items.append(("Calibration", ", ".join(sorted(rec.calibrations)) + fitted))
    for note in rec.notes:
        items.append(("Note", note))
    return items


def _gaps(rec, o) -> str:
    limit = o.columns.max_gap
    if not rec.gaps:
        return f"none over {limit:g} sample periods" if limit else "not checked (max_gap 0)"
    listing = "; ".join(f"{a:.6g} s -> {b:.6g} s" for a, b in rec.gaps[:5])
    more = f" and {len(rec.gaps) - 5} more" if len(rec.gaps) > 5 else ""
    return f"{len(rec.gaps)} over {limit:g} sample periods, every estimator started afresh after each: {listing}{more}"


def _checks(info: dict) -> str:
    units = ", ".join(f"{k} in {u}" for k, u in info["units"].items())
    done = "times increasing, every value finite, magnitudes within what sensors read"
    if info["unit_check"]:
        done += f", units fit the magnitudes ({units})"
    else:
        done += f"; units taken as declared, not checked ({units})"
    notes = "; ".join(info["notes"])
    return f"passed: {done}" + (f"; {notes}" if notes else "")


def _params(params) -> str:
    parts = []
    for f in dataclasses.fields(params):
        value = getattr(params, f.name)
        parts.append(f"{f.name}={value:.6g}" if isinstance(value, float) else f"{f.name}={value}")
    return ", ".join(parts)


def _bias(bias, sigma) -> str:
    if sigma is None:
        return "[" + ", ".join(f"{b:.4f}" for b in bias) + "] deg/s (x, y, z body)"
    return "[" + ", ".join(f"{b:.4f} ± {s:.4f}" for b, s in zip(bias, sigma, strict=True)) + "] deg/s (x, y, z body)"


def _declination(o) -> str:
    return "" if o.declination is None else f" (declination {np.degrees(o.declination):.3f}° applied)"


#: The error table's columns: key of EstimatorRun.rmse -> header.
ERROR_COLUMNS = {
    "total": "RMS total (deg)",
    "heading": "RMS heading (deg)",
    "inclination": "RMS inclination (deg)",
    "max_total": "max total (deg)",
}


def error_rows(rec) -> list[dict]:
    """One row per estimator: its name, mode, RMS errors (degrees) and final bias (deg/s)."""
    rows = []
    for run in rec.runs:
        row = {"estimator": run.name, "mode": run.mode, "north": run.heading}
        if run.rmse is not None:
            row.update({k: float(run.rmse[k]) for k in ERROR_COLUMNS})
            if run.mode == "6D":
                row["note"] = "mean heading offset removed (6D)"
        final = run.final_bias
        if final is not None:
            row["bias_deg_s"] = [float(b) for b in final[0]]
            if final[1] is not None:
                row["bias_sigma_deg_s"] = [float(s) for s in final[1]]
        rows.append(row)
    return rows


def results(rec) -> dict:
    """The page's numbers, machine-readable: summary items, error rows, frames (for the ``results`` JSON block)."""
    return {
        "title": rec.title,
        "frame": rec.axes.frame,
        "body": rec.axes.body,
        "rows": int(rec.t.size),
        "duration_s": float(rec.t[-1]),
        "reference": rec.reference_label or None,
        "estimators": error_rows(rec),
        "summary": [list(item) for item in rec.summary],
        "gaps": [list(g) for g in rec.gaps],
        # the Allan analysis' fitted terms, per gyro axis, in the units of strapdown.calibrate.allan (rad, s)
        "allan": None
        if rec.allan is None
        else {k: getattr(rec.allan, k).tolist() for k in ("arw", "bias_instability", "rate_random_walk")},
    }
