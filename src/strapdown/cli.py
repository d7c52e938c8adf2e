"""The ``strapdown`` command line (click, from the ``cli`` extra).

Commands so far: ``demo``, ``compare`` and ``evaluate``; file commands come with the I/O work.
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
          strapdown evaluate path/to/broad/data_mat --estimator tilt
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

    @cli.command()
    @click.argument("folder", type=click.Path(exists=True, file_okay=False))
    @click.option("-e", "--estimator", type=click.Choice(list(_estimators())), default="tilt", show_default=True)
    @click.option("--9d", "nine_d", is_flag=True, help="Give the estimator the magnetometer.")
    @click.option("-p", "--param", "params", multiple=True, metavar="NAME=VALUE", help="Set a parameter (repeatable).")
    @click.option(
        "-g", "--grid", multiple=True, metavar="NAME=V1,V2,...", help="Grid-search these values (repeatable)."
    )
    @click.option(
        "--objective",
        type=click.Choice(["inclination", "total", "heading"]),
        default="inclination",
        show_default=True,
        help="Mean RMSE the grid search ranks on.",
    )
    @click.option(
        "--start",
        type=click.Choice(["first-sample", "broad-example"]),
        default="first-sample",
        show_default=True,
        help="Initial attitude: the estimator's own, or BROAD's example code's (9D, to reproduce it).",
    )
    @click.option("--trials", default=None, help="Comma-separated trial names (default: every .mat in FOLDER).")
    @click.option("--keep-heading-offset", is_flag=True, help="In 6D, do not remove the mean heading offset.")
    @click.option("--csv", "csv_path", default=None, type=click.Path(dir_okay=False), help="Write per-trial rows here.")
    def evaluate(folder, estimator, nine_d, params, grid, objective, start, trials, keep_heading_offset, csv_path):
        r"""Run an estimator over the BROAD trials in FOLDER with one parameter set; print RMSE per trial and group.

        Errors follow the BROAD protocol (total, heading and inclination RMSE over the movement phases, in
        degrees).  With --grid, every combination is evaluated and ranked instead.

        \b
        Examples:
          strapdown evaluate broad/data_mat
          strapdown evaluate broad/data_mat -e mahony --9d -p kp=0.5 -p ki=0.001
          strapdown evaluate broad/data_mat -e madgwick --9d -p beta=0.12 -p variant=reference --start broad-example
          strapdown evaluate broad/data_mat -e tilt -g tau_acc=1,2,3 -g tau_bias=50,100
        """
        from .broad import load_trials
        from .evaluate import evaluate as run_evaluate
        from .evaluate import grid_search

        fixed = dict(_assignment(a, "--param") for a in params)
        ranges = {}
        for a in grid:
            name, value = _assignment(a, "--grid", raw=True)
            ranges[name] = [_value(v) for v in value.split(",") if v.strip()]
        names = [t.strip() for t in trials.split(",") if t.strip()] if trials else None
        heading = False if keep_heading_offset else None
        try:
            data = load_trials(folder, names)
            if ranges:
                found = grid_search(
                    estimator,
                    data,
                    ranges,
                    params=fixed,
                    mag=nine_d,
                    start=start,
                    objective=objective,
                    heading_offset=heading,
                )
                click.echo(found.table())
                return
            result = run_evaluate(estimator, data, params=fixed, mag=nine_d, start=start, heading_offset=heading)
        except (ValueError, FileNotFoundError) as exc:
            raise click.UsageError(str(exc)) from None
        click.echo(result.table())
        if csv_path:
            result.to_csv(csv_path)
            click.echo(f"written: {csv_path}")

    return cli


def _value(text: str):
    """A parameter value from the command line: a number when it reads as one, else the text."""
    text = text.strip()
    try:
        return float(text)
    except ValueError:
        return text


def _assignment(text: str, option: str, raw: bool = False):
    import click

    name, sep, value = text.partition("=")
    if not sep or not name.strip() or not value.strip():
        raise click.BadParameter(f"expected NAME=VALUE, got {text!r}", param_hint=option)
    return name.strip(), (value if raw else _value(value))


def _estimators():
    from .evaluate import ESTIMATORS

    return ESTIMATORS


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
