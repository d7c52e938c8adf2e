"""``strapdown report``: an interactive page of one recording, in one HTML file that works offline."""

from __future__ import annotations

from pathlib import Path

import click

from ._options import (
    columns_spec,
    estimators,
    frame_options,
    inputs_argument,
    one_or_many,
    param_option,
    parse_params,
    read_options,
    truth_options,
)
from .estimate import _calibration_kwargs


def _estimator_list(ctx, param, value):
    names = tuple(n.strip() for n in (value or "attitude").split(",") if n.strip())
    known = list(estimators())
    for name in names:
        if name not in known:
            raise click.BadParameter(f"unknown estimator {name!r}; choose from {', '.join(known)}")
    if len(set(names)) != len(names) or not names:
        raise click.BadParameter(f"name each estimator once, got {value!r}")
    return names


@click.command()
@inputs_argument()
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="The page (default: <stem>.report.html).")
@click.option("--open", "open_page", is_flag=True, help="Open the page in the web browser when written.")
@click.option(
    "-e",
    "--estimators",
    default="attitude",
    show_default=True,
    metavar="A,B,...",
    callback=_estimator_list,
    help=f"Estimators side by side, the first the main one ({', '.join(estimators())}).",
)
@param_option("of the first estimator; angles and rates in degrees with the unit in the name: bias_limit_deg_s=5.")
@truth_options("The true attitude: a simulated log, a qw..qz table, a PX4 log (default: the log's own estimate).")
@frame_options
@click.option("--9d", "mode", flag_value="9d", help="Require the magnetometer (default: use it when found).")
@click.option("--6d", "mode", flag_value="6d", help="Leave the magnetometer out of the estimates.")
@click.option("--calibration", type=click.Path(exists=True, dir_okay=False), help="Calibration JSON to apply.")
@click.option("--fit-mag", is_flag=True, help="Fit the magnetometer's calibration on INPUT, apply and show it.")
@click.option(
    "--allan",
    type=click.Path(exists=True),
    metavar="STILL",
    help="A recording at rest: its gyro Allan deviation and fitted noise terms.",
)
@click.option("--declination", metavar="auto|DEG", help="Turn the 9D heading to true north (degrees east).")
@click.option("--lat", type=float, help="Latitude, degrees (--declination auto).")
@click.option("--lon", type=float, help="Longitude, degrees (--declination auto).")
@click.option("--date", help="Date, YYYY-MM-DD or decimal year (--declination auto).")
@click.option(
    "--points", default=2000, show_default=True, type=click.IntRange(min=2), help="Time buckets per line drawn."
)
@click.option("--frames", default=1500, show_default=True, type=click.IntRange(min=2), help="Attitudes of the 3D view.")
@click.option("--title", help="The page's title (default: the input's name).")
@click.option("-q", "--quiet", is_flag=True, help="No progress bar, no summary.")
@read_options
@click.pass_context
def command(ctx, paths, output, open_page, quiet, **p):
    """Write an interactive report of INPUT: one HTML file, every script inline, that opens offline.

    It runs the estimators over the recording and shows, on linked time axes: yaw, pitch and roll over the truth
    (--truth) or the log's own estimate, the errors, and lanes where the flags say rest, acc or mag rejected,
    inverted, bias at its limit, or a gap; the quaternion; the raw sensors (gyro, |acc| against g, |mag| and the
    magnetic dip: why a stretch was rejected); the gyro bias with its uncertainty; the estimators side by side
    with their error table; a 3D view of the body in its reference frame, driven by a time slider and a play
    button and synchronised with a cursor on every plot; with --calibration or --fit-mag the magnetometer before
    and after its fit, and with --allan the Allan deviation with its fitted lines.  Long logs are thinned for
    display keeping every peak (min-max per time bucket); the numbers are computed at full rate.

    INPUT is one recording: a file, one file per sensor, or an export folder.  At a gap over --max-gap every
    estimator starts afresh (--on-gap restart, the default here) and the page shows it; --on-gap error stops.

    \b
    Examples:
      strapdown report flight.ulg -o flight.html --open            # against the log's own vehicle_attitude
      strapdown report show.parquet --truth show.parquet -e attitude,mahony,tilt
      strapdown report phone_export/ --fit-mag
      strapdown report log.csv --calibration cal.json --allan still.csv
    """
    from ..apps.report import ReportOptions, default_report_path, report_file
    from ._run import run_file, say_compiling

    target = output or str(default_report_path(one_or_many(paths)))
    on_gap = p.get("on_gap")
    if ctx.get_parameter_source("on_gap") == click.core.ParameterSource.DEFAULT:
        on_gap = "restart"
    if on_gap == "split":
        raise click.BadParameter("a report is one page: restart (a band at each gap) or error", param_hint="--on-gap")
    names = p["estimators"]
    try:
        extra = _calibration_kwargs(p)
        mode = p.get("mode")
        options = ReportOptions(
            columns=columns_spec(p),
            frame=p.get("frame") and p["frame"].upper(),
            body=p.get("body"),
            out_body=p.get("out_body"),
            on_gap=on_gap,
            estimators=names,
            params=parse_params(names[0], p.get("params")),
            truth=p.get("truth"),
            truth_frame=p.get("truth_frame"),
            truth_body=p.get("truth_body"),
            mag={"9d": True, "6d": False}.get(mode),
            fit_mag=p.get("fit_mag", False),
            allan=p.get("allan"),
            points=p["points"],
            frames=p["frames"],
            title=p.get("title"),
            **extra,
        )
    except (ValueError, OSError, ImportError) as exc:
        raise click.ClickException(str(exc)) from None
    say_compiling([f"estimator:{n}" for n in names], quiet)
    run_file(report_file, one_or_many(paths), target, {"options": options}, quiet)
    if open_page:
        import webbrowser

        webbrowser.open(Path(target).resolve().as_uri())
