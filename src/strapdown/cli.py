"""The ``strapdown`` command line (click, from the ``cli`` extra).

Commands so far: ``demo`` and ``compare``; file commands come with the I/O work.
"""

from __future__ import annotations

import sys


def _build():
    import click

    from . import __version__

    @click.group(context_settings={"help_option_names": ["-h", "--help"]})
    @click.version_option(__version__, prog_name="strapdown")
    def cli():
        r"""Quaternion attitude determination from gyroscope, accelerometer and magnetometer data.

        \b
        Examples:
          strapdown demo
          strapdown compare --scenario hammerhead-loop
          strapdown --version
        """

    @cli.command()
    @click.option("--out", default="out", show_default=True, type=click.Path(file_okay=False), help="Output directory.")
    def demo(out):
        r"""Print the worked examples and write plots and a CSV to OUT.

        Gajda's algorithm on a 360 deg roll, his conclusions tested on a hammerhead + loop, and an aerobatic
        show flown with a consumer MEMS IMU and integrated by every method.

        \b
        Examples:
          strapdown demo
          strapdown demo --out /tmp/strapdown-demo
        """
        from .demo import run

        run(out, echo=click.echo)

    @cli.command()
    @click.option(
        "--scenario",
        type=click.Choice(list(_scenarios())),
        default="hammerhead-loop",
        show_default=True,
        help="What is flown.",
    )
    @click.option("--rate", default=100.0, show_default=True, help="Sample rate, Hz.")
    @click.option(
        "--gyro",
        type=click.Choice(["rate", "average", "increment", "rotvec"]),
        default="increment",
        show_default=True,
        help="What a gyro sample is.",
    )
    @click.option(
        "--imu",
        type=click.Choice(["ideal", "consumer", "tactical"]),
        default="ideal",
        show_default=True,
        help="Errors.",
    )
    @click.option("--seed", default=0, show_default=True, help="Seed of the sensor errors.")
    @click.option("--methods", default=None, help="Comma-separated subset of the methods (default: all).")
    @click.option("--out", default=None, type=click.Path(file_okay=False), help="Write PNG plots to this directory.")
    def compare(scenario, rate, gyro, imu, seed, methods, out):
        r"""Run every propagation method on a simulated scenario and print the comparison table.

        \b
        Examples:
          strapdown compare
          strapdown compare --scenario coning --rate 200 --gyro increment
          strapdown compare --scenario aerobatic-show --imu consumer --gyro average --out plots/
          strapdown compare --methods exact,rk4,euler-angles
        """
        from . import METHODS
        from .compare import compare as run_compare
        from .simulate import ImuModel, sample
        from .simulate.scenarios import scenario as make

        if not rate > 0:
            raise click.BadParameter("must be positive", param_hint="--rate")
        chosen = None
        if methods:
            chosen = [m.strip() for m in methods.split(",") if m.strip()]
            unknown = [m for m in chosen if m not in METHODS]
            if unknown:
                raise click.BadParameter(
                    f"unknown {', '.join(unknown)}; choose from {', '.join(METHODS)}", param_hint="--methods"
                )
        model = {"ideal": ImuModel.ideal, "consumer": ImuModel.consumer_mems, "tactical": ImuModel.tactical}[imu]()
        data = sample(make(scenario), rate, gyro=gyro, imu=model, seed=seed)
        result = run_compare(data, chosen, title=f"{scenario}, {imu} IMU, {gyro} gyro at {rate:g} Hz")
        click.echo(result.table())
        if out:
            for path in result.plot(out, prefix=scenario.replace("-", "_")):
                click.echo(f"written: {path}")

    return cli


def _scenarios():
    from .simulate.scenarios import SCENARIOS

    return SCENARIOS


def main(argv=None):
    """Entry point of the ``strapdown`` command."""
    try:
        cli = _build()
    except ModuleNotFoundError as exc:
        if exc.name != "click":
            raise
        sys.stderr.write("the strapdown command line needs click: pip install 'strapdown[cli]'\n")
        return 2
    return cli.main(args=argv, prog_name="strapdown")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
