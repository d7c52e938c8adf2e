"""``strapdown estimate``: a fusion filter over a file, streaming."""

from __future__ import annotations

import click

from ._options import (
    CHUNK_ROWS,
    assignment,
    columns_spec,
    estimate_output_options,
    estimators,
    frame_options,
    inputs_argument,
    list_params,
    one_or_many,
    output_spec,
    param_option,
    parse_params,
    parse_q0,
    read_options,
)
from ._run import run_file, say_compiling


def kwargs(p: dict) -> dict:
    """The keyword arguments of :func:`strapdown.io.estimate_file` from the parsed options (also for batch)."""
    extra = [assignment(a, "--extra", raw=True) for a in p.get("extra") or ()]
    mode = p.get("mode")
    return {
        "estimator": p.get("estimator") or "attitude",
        "params": parse_params(p.get("estimator") or "attitude", p.get("params")),
        "frame": p.get("frame") and p["frame"].upper(),
        "body": p.get("body"),
        "out_body": p.get("out_body"),
        "on_gap": p.get("on_gap") or "auto",
        "bridge": p.get("bridge"),
        "mag": {"9d": True, "6d": False}.get(mode),
        "q0": parse_q0(p.get("q0")),
        "columns": columns_spec(p, ((n, v.strip()) for n, v in extra)),
        "out": output_spec(p),
        "chunk_rows": CHUNK_ROWS if p.get("chunk_rows") is None else p["chunk_rows"],
        "noise": "adapt" if p.get("adapt_noise") else "default",
        **_calibration_kwargs(p),
    }


def _calibration_kwargs(p: dict) -> dict:
    """``calibration`` and ``declination`` (radians) from --calibration, --declination, --lat, --lon, --date."""
    out = {}
    if p.get("calibration"):
        from ..calibrate import load

        out["calibration"] = load(p["calibration"])
    text = p.get("declination")
    place = [p.get(k) for k in ("lat", "lon", "date")]
    if text is None:
        if any(v is not None for v in place):
            raise click.BadParameter("--lat, --lon and --date go with --declination auto", param_hint="--declination")
        return out
    import math

    if text.strip().lower() == "auto":
        if all(v is None for v in place):
            out["declination"] = "auto"  # the log's own GPS position and date (estimate_file)
            return out
        if any(v is None for v in place):
            raise click.BadParameter("auto takes --lat, --lon and --date together", param_hint="--declination")
        from ..calibrate import declination

        out["declination"] = float(declination(latitude=place[0], longitude=place[1], date=place[2], degrees=True))
        out["declination"] = math.radians(out["declination"])
    else:
        try:
            out["declination"] = math.radians(float(text))
        except ValueError:
            raise click.BadParameter(f"'auto' or degrees east, got {text!r}", param_hint="--declination") from None
    return out


def _list_params(ctx, param, value):
    if value:
        click.echo(list_params(ctx.params.get("estimator") or "attitude"))
        ctx.exit()


@click.command()
@inputs_argument()
@click.option(
    "-e", "--estimator", type=click.Choice(list(estimators())), default="attitude", show_default=True, is_eager=True
)
@param_option("angles and rates in degrees with the unit in the name: bias_limit_deg_s=5.")
@click.option(
    "--list-params",
    is_flag=True,
    expose_value=False,
    callback=_list_params,
    help="Print the estimator's parameters, defaults and units, and exit.",
)
@frame_options
@click.option("--9d", "mode", flag_value="9d", help="Require the magnetometer (default: use it when found).")
@click.option("--6d", "mode", flag_value="6d", help="Leave the magnetometer out.")
@click.option(
    "--extra",
    multiple=True,
    metavar="NAME=COLS",
    help="A further input of the estimator, e.g. known_acc=kx,ky,kz (tilt) (repeatable).",
)
@click.option("--q0", metavar="W,X,Y,Z|YAW,PITCH,ROLL", help="Initial attitude in --frame (default: first sample).")
@click.option("--calibration", type=click.Path(exists=True, dir_okay=False), help="Calibration JSON to apply.")
@click.option(
    "--declination",
    metavar="auto|DEG",
    help="Turn the 9D heading to true north (degrees east); auto: the World Magnetic Model's at the place and "
    "date the log's GPS records, or at --lat --lon --date.",
)
@click.option("--lat", type=float, help="Latitude, degrees (--declination auto).")
@click.option("--lon", type=float, help="Longitude, degrees (--declination auto).")
@click.option("--date", help="Date, YYYY-MM-DD or decimal year (--declination auto).")
@click.option(
    "--adapt-noise",
    is_flag=True,
    help="Noise parameters from the sensor: the --calibration's noise figures (calibrate allan/gyro), else the "
    "rests of the data; written into the metadata.",
)
@read_options
@estimate_output_options
def command(paths, **p):
    """Run a fusion filter over INPUT and write its attitudes, bias and flags, streaming (any file size).

    INPUT is one recording: a file, one file per sensor (Gyroscope.csv Accelerometer.csv ...), or an export
    folder.  One output row per gyro row: the attitude after that row's sample.  Sensors at lower rates leave
    rows without their sample, which the attitude estimator takes as such.  Output: t (s from the first
    sample), qw..qz (body to frame), Euler angles, bias_* (deg/s), flags and the boolean columns rest,
    acc_rejected, mag_rejected, inverted, bias_at_limit, saturated; the frame, body axes, units and the time origin are
    stored in the file (a CSV: "# key: value" lines above the header).

    \b
    Examples:
      strapdown estimate log.csv                                       # 9D if the file has a magnetometer
      strapdown estimate Gyroscope.csv Accelerometer.csv Magnetometer.csv
      strapdown estimate flight.ulg                                    # NED, FRD: the log's own convention
      strapdown estimate log.parquet -e madgwick -p beta=0.05 --frame ned -o att.parquet
      strapdown estimate drone.csv --body FRD --frame ENU -p bias_limit_deg_s=5
      strapdown estimate broad/01_undisturbed_slow_rotation_A.mat -e mahony --9d
      strapdown estimate chair.csv -e tilt --extra known_acc=cx,cy,cz --acc-unit g
      strapdown estimate -e attitude --list-params
      strapdown estimate log.csv --calibration cal.json --declination auto --lat 52.5 --lon 13.4 --date 2025-06-01
      strapdown estimate log.csv --calibration allan.json --adapt-noise     # the still recording's noise model
    """
    from ..io import estimate_file

    try:
        options = kwargs(p)
    except (ValueError, OSError, ImportError) as exc:  # a bad calibration file, a date out of the model's span
        raise click.ClickException(str(exc)) from None
    say_compiling([f"estimator:{options.get('estimator', 'attitude')}", "files"], p["quiet"])
    run_file(estimate_file, one_or_many(paths), p.get("output"), options, p["quiet"])
