"""``strapdown compare``: every propagation method on a simulated scenario."""

from __future__ import annotations

import click

from ._options import check_samples, flight_options, writable_folder


@click.command()
@flight_options("--gyro", "increment")
@click.option("--methods", default=None, help="Comma-separated subset of the methods (default: all).")
@click.option("--out", default=None, type=click.Path(file_okay=False), help="Write PNG plots to this directory.")
def command(scenario, rate, gyro, imu, seed, methods, out):
    """Run every propagation method on a simulated scenario and print the comparison table.

    \b
    Examples:
      strapdown compare
      strapdown compare --scenario coning --rate 200 --gyro increment
      strapdown compare --scenario aerobatic-show --imu consumer --gyro average --out plots/
      strapdown compare --methods exact,rk4,euler-angles
    """
    import math

    from .. import METHODS
    from ..compare import compare as run_compare
    from ..simulate import ImuModel, sample
    from ..simulate.scenarios import scenario as make

    if not (math.isfinite(rate) and rate > 0):
        raise click.BadParameter(f"a positive number of Hz, got {rate}", param_hint="--rate")
    flight = make(scenario)
    check_samples(rate, flight.duration)  # before sample() allocates them
    if out:
        writable_folder(out, "--out")  # before the computation, not after it
    chosen = None
    if methods:
        chosen = [m.strip() for m in methods.split(",") if m.strip()]
        unknown = [m for m in chosen if m not in METHODS]
        if unknown:
            raise click.BadParameter(
                f"unknown {', '.join(unknown)}; choose from {', '.join(METHODS)}", param_hint="--methods"
            )
    model = {"ideal": ImuModel.ideal, "consumer": ImuModel.consumer_mems, "tactical": ImuModel.tactical}[imu]()
    data = sample(flight, rate, gyro=gyro, imu=model, seed=seed)
    result = run_compare(data, chosen, title=f"{scenario}, {imu} IMU, {gyro} gyro at {rate:g} Hz")
    click.echo(result.table())
    if out:
        try:
            written = result.plot(out, prefix=scenario.replace("-", "_"))
        except OSError as exc:  # a full disk: checked writable, still not written
            raise click.ClickException(f"cannot write the figures into {out}: {exc}") from None
        for path in written:
            click.echo(f"written: {path}")
