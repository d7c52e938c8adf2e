"""``strapdown estimate``: a fusion filter over a file, streaming."""

from __future__ import annotations

import click

from ._options import (
    CHUNK_ROWS,
    FRAMES,
    assignment,
    columns_spec,
    estimate_output_options,
    estimators,
    input_argument,
    output_spec,
    parse_q0,
    read_options,
    run_file,
)


def kwargs(p: dict) -> dict:
    """The keyword arguments of :func:`strapdown.io.estimate_file` from the parsed options (also for batch)."""
    extra = [assignment(a, "--extra", raw=True) for a in p.get("extra") or ()]
    mode = p.get("mode")
    return {
        "estimator": p.get("estimator") or "attitude",
        "params": dict(assignment(a, "--param") for a in p.get("params") or ()),
        "frame": (p.get("frame") or "ENU").upper(),
        "mag": {"9d": True, "6d": False}.get(mode),
        "q0": parse_q0(p.get("q0")),
        "columns": columns_spec(p, ((n, v.strip()) for n, v in extra)),
        "out": output_spec(p),
        "chunk_rows": CHUNK_ROWS if p.get("chunk_rows") is None else p["chunk_rows"],
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
        if any(v is None for v in place):
            raise click.BadParameter("auto needs --lat, --lon and --date", param_hint="--declination")
        from ..calibrate import declination

        out["declination"] = float(declination(latitude=place[0], longitude=place[1], date=place[2], degrees=True))
        out["declination"] = math.radians(out["declination"])
    else:
        try:
            out["declination"] = math.radians(float(text))
        except ValueError:
            raise click.BadParameter(f"'auto' or degrees east, got {text!r}", param_hint="--declination") from None
    return out


@click.command()
@input_argument()
@click.option("-e", "--estimator", type=click.Choice(list(estimators())), default="attitude", show_default=True)
@click.option("-p", "--param", "params", multiple=True, metavar="NAME=VALUE", help="Set a parameter (repeatable).")
@click.option(
    "--frame",
    type=click.Choice(FRAMES, case_sensitive=False),
    default="ENU",
    show_default=True,
    help="Reference frame of the output.",
)
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
@click.option("--declination", metavar="auto|DEG", help="Turn the 9D heading to true north (degrees east).")
@click.option("--lat", type=float, help="Latitude, degrees (--declination auto).")
@click.option("--lon", type=float, help="Longitude, degrees (--declination auto).")
@click.option("--date", help="Date, YYYY-MM-DD or decimal year (--declination auto).")
@read_options
@estimate_output_options
def command(path, **p):
    """Run a fusion filter over INPUT and write its attitudes, bias and flags, streaming (any file size).

    One output row per input row: the attitude after that row's sample.  Parameters as for evaluate.

    \b
    Examples:
      strapdown estimate log.csv                                       # 9D if the file has a magnetometer
      strapdown estimate log.parquet -e madgwick -p beta=0.05 --frame ned -o att.parquet
      strapdown estimate broad/01_undisturbed_slow_rotation_A.mat -e mahony --9d
      strapdown estimate chair.csv -e tilt --extra known_acc=cx,cy,cz --acc-unit g
      strapdown estimate log.csv --calibration cal.json --declination auto --lat 52.5 --lon 13.4 --date 2025-06-01
    """
    from ..io import estimate_file

    try:
        options = kwargs(p)
    except (ValueError, OSError, ImportError) as exc:  # a bad calibration file, a date out of the model's span
        raise click.ClickException(str(exc)) from None
    run_file(estimate_file, path, p.get("output"), options, p["quiet"])
