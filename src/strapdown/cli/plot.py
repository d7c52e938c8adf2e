"""``strapdown plot``: PNG figures of an attitude file."""

from __future__ import annotations

import click

from ._options import input_argument, writable_folder


@click.command()
@input_argument()
@click.option("--truth", type=click.Path(exists=True, dir_okay=False), help="File with the true attitude.")
@click.option("--out", type=click.Path(file_okay=False), help="Folder of the figures (default: beside INPUT).")
@click.option("--euler", "seq", default="ZYX", show_default=True, help="Euler sequence of the angle figure.")
@click.option("--radians", is_flag=True)
@click.option("--yaw-range", type=click.Choice(["signed", "positive"]))
@click.option(
    "--max-points",
    default=200_000,
    show_default=True,
    type=click.IntRange(min=2),
    help="Rows drawn at most (thinned evenly).",
)
def command(path, truth, out, seq, radians, yaw_range, max_points):
    """Write PNG figures of an attitude file: Euler angles, errors against --truth, and the gyro bias.

    \b
    Examples:
      strapdown plot flight.integrate.csv
      strapdown plot att.parquet --truth sim.parquet --out figures/
      strapdown plot att.csv --euler ZXY --yaw-range signed
    """
    from ..io import Angles
    from ..io.plots import plot_file

    if out:
        writable_folder(out, "--out")
    try:
        written = plot_file(path, truth, out, angles=Angles(seq, not radians, yaw_range), max_points=max_points)
    except (ValueError, OSError, ImportError) as exc:
        raise click.ClickException(str(exc)) from None
    for f in written:
        click.echo(f"written: {f}")
