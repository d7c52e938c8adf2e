"""``strapdown integrate``: gyro readings of a file into attitudes, streaming."""

from __future__ import annotations

import click

from ._options import (
    CHUNK_ROWS,
    choice_option,
    columns_spec,
    frame_options,
    inputs_argument,
    methods,
    one_or_many,
    output_options,
    output_spec,
    parse_q0,
    read_options,
)
from ._run import run_file, say_compiling


def kwargs(p: dict) -> dict:
    """The keyword arguments of :func:`strapdown.io.integrate_file` from the parsed options (also for batch)."""
    return {
        "columns": columns_spec(p),
        "out": output_spec(p),
        "method": p.get("method"),
        "input": p.get("samples") or "rate",
        "rate_frame": p.get("rate_frame") or "body",
        "q0": parse_q0(p.get("q0")),
        "chunk_rows": CHUNK_ROWS if p.get("chunk_rows") is None else p["chunk_rows"],
        "frame": p.get("frame") and p["frame"].upper(),
        "body": p.get("body"),
        "out_body": p.get("out_body"),
        "on_gap": p.get("on_gap") or "auto",
        "bridge": p.get("bridge"),
    }


@click.command()
@inputs_argument()
@click.option(
    "-m",
    "--method",
    type=click.Choice(methods()),
    help="Propagation method (default: exact; coning2 for increments).",
)
@choice_option(
    "--samples",
    choices=("rate", "average", "increment"),
    help="What a gyro sample is: the rate at its row's time, the mean rate or the angle over its step.",
)
@click.option("--rate-frame", type=click.Choice(["body", "reference"]), default="body", show_default=True)
@click.option("--q0", metavar="W,X,Y,Z|YAW,PITCH,ROLL", help="Initial attitude (angles in degrees, ZYX).")
@lambda f: frame_options(f, integrate=True)
@read_options
@output_options
def command(paths, **p):
    """Integrate the gyro readings of INPUT into attitudes, streaming (any file size).

    Row k's sample acts from row k's time to row k+1's; output row k is the attitude at row k's time
    (the first is --q0, identity by default).  Columns: t (s from the first sample), qw, qx, qy, qz and Euler
    angles; the frame, body axes, units and time origin are stored in the file.

    \b
    Examples:
      strapdown integrate flight.csv                                   # -> flight.integrate.csv
      strapdown integrate flight.csv --gyro wx,wy,wz --gyro-unit deg/s --time stamp --time-unit ms
      strapdown integrate drone.csv --body FRD --frame NED --q0 90,0,0 --on-gap restart
      strapdown integrate imu.parquet -o att.parquet --rate 400 --method cayley --radians
      strapdown integrate dtheta.h5 --gyro imu/dtheta --samples increment --rate 200 --q0 30,0,0
    """
    from ..io import integrate_file

    say_compiling(["integrate", "files"], p["quiet"])
    run_file(integrate_file, one_or_many(paths), p.get("output"), kwargs(p), p["quiet"])
