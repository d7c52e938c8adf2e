"""``strapdown simulate``: a simulated IMU log with its true attitude."""

from __future__ import annotations

import click

from ._options import FORMATS, check_samples, flight_options, unit_option, writable_file


@click.command()
@click.argument("output", type=click.Path(dir_okay=False))
@flight_options("--samples", "average")
@click.option("--reference", default="ENU", show_default=True, help="Frame of the truth (ENU, NED, NWU, ...).")
@click.option("--body", default="FLU", show_default=True, help="Sensor axes (FLU, FRD, RFU, ...).")
@click.option("--duration", type=float, help="Seconds (default: the whole scenario).")
@unit_option("gyro", "rad/s")
@unit_option("acc", "m/s2")
@unit_option("mag", "uT")
@click.option("--no-truth", is_flag=True, help="Leave out the true attitude.")
@click.option("--format", "out_format", type=click.Choice(FORMATS))
@click.option("-q", "--quiet", is_flag=True)
def command(output, **p):
    """Write a simulated IMU log to OUTPUT: t, gx..gz, ax..az, mx..mz and the true attitude qw_true..qz_true.

    Row k: the time at the start of sample k's step, the readings, and the true attitude at that time,
    which is what `strapdown integrate` computes for the row (give it --q0 from the first row).

    \b
    Examples:
      strapdown simulate loop.csv
      strapdown simulate show.parquet --scenario aerobatic-show --imu consumer --rate 200
      strapdown simulate chair.h5 --scenario rocking --reference NED --body FRD --gyro-unit deg/s --acc-unit g
      strapdown simulate dtheta.mat --samples increment --duration 10
    """
    import math

    from ..io import simulate_file
    from ..simulate.scenarios import scenario

    rate, duration = p["rate"], p["duration"]
    if not (math.isfinite(rate) and rate > 0):
        raise click.BadParameter(f"a positive number of Hz, got {rate}", param_hint="--rate")
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise click.BadParameter(f"a positive number of seconds, got {duration}", param_hint="--duration")
    check_samples(rate, scenario(p["scenario"]).duration if duration is None else duration)
    writable_file(output, "OUTPUT")
    kwargs = {
        "scenario": p["scenario"],
        "rate": p["rate"],
        "gyro": p["samples"],
        "imu": p["imu"],
        "seed": p["seed"],
        "reference": p["reference"],
        "body": p["body"],
        "duration": p["duration"],
        "gyro_unit": p["gyro_unit"] or "rad/s",
        "acc_unit": p["acc_unit"] or "m/s2",
        "mag_unit": p["mag_unit"] or "uT",
        "truth": not p["no_truth"],
        "format": p["out_format"],
    }
    try:
        report = simulate_file(output, **kwargs)
    except (ValueError, OSError, ImportError) as exc:
        raise click.ClickException(str(exc)) from None
    if not p["quiet"]:
        click.echo(f"simulated: {report.read}", err=True)
        click.echo(f"written: {report.output} ({report.rows} rows, {report.seconds:.2f} s)")
