"""The ``strapdown`` command line (click, from the ``cli`` extra).

Library commands: ``demo``, ``compare``, ``evaluate``.  File commands (the ``io`` extra): ``integrate``,
``estimate``, ``convert``, ``simulate``, ``plot``, and ``batch`` to run ``integrate``, ``estimate`` or ``convert`` on
many files at once (local cores or a Dask cluster) or one integration split across workers.

Building the command group imports nothing heavy: numpy, numba kernels, pyarrow and friends are imported by
the command that runs, so ``strapdown --help`` stays fast.
"""

from __future__ import annotations

import sys


def _build():
    import click

    from . import __version__

    @click.group(context_settings={"help_option_names": ["-h", "--help"]})
    @click.version_option(__version__, prog_name="strapdown")
    def cli():
        """Quaternion attitude determination from gyroscope, accelerometer and magnetometer data.

        \b
        Examples:
          strapdown integrate flight.csv --gyro-unit deg/s          # -> flight.integrate.csv
          strapdown estimate log.parquet -e tilt --frame ned -o att.parquet
          strapdown convert --from euler --seq ZYX --degrees 10 20 30 --to quat
          strapdown simulate sim.parquet --scenario aerobatic-show --imu consumer
          strapdown plot att.parquet --truth sim.parquet
          strapdown batch 'logs/**/*.parquet' estimate -e mahony --out results/
          strapdown demo
          strapdown compare --scenario hammerhead-loop
          strapdown evaluate path/to/broad/data_mat --estimator tilt
          strapdown --version
        """

    @cli.command()
    @click.option("--out", default="out", show_default=True, type=click.Path(file_okay=False), help="Output directory.")
    def demo(out):
        """Print the worked examples and write plots and a CSV to OUT.

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
    @_flight_options("--gyro", "increment")
    @click.option("--methods", default=None, help="Comma-separated subset of the methods (default: all).")
    @click.option("--out", default=None, type=click.Path(file_okay=False), help="Write PNG plots to this directory.")
    def compare(scenario, rate, gyro, imu, seed, methods, out):
        """Run every propagation method on a simulated scenario and print the comparison table.

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
        """Run an estimator over the BROAD trials in FOLDER with one parameter set; print RMSE per trial and group.

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

    _add_file_commands(cli)
    return cli


# ----------------------------------------------------------------------------------------------------------
# File commands.  Each turns its options into the keyword arguments of a strapdown.io function (the same
# translation serves `batch`), runs it with a progress bar, and turns bad input into a one-line error.

_FRAMES = ("ENU", "NED", "NWU")
_CHUNK_ROWS = 1 << 18  # as strapdown.io.pipeline.CHUNK_ROWS (not imported: --help stays light)
_FORMATS = ("csv", "parquet", "hdf5", "mat")


def _unit_option(kind: str, default_text: str):
    import click

    from .io.units import UNITS

    def check(ctx, param, value):
        if value is None:
            return None
        from .io.units import parse_unit

        try:
            return parse_unit(kind, value)
        except ValueError as exc:
            raise click.BadParameter(str(exc)) from None

    return click.option(
        f"--{kind}-unit",
        default=None,
        callback=check,
        metavar="|".join(UNITS[kind]),
        help=f"Unit of the {kind} columns (default: from the header, else {default_text}).",
    )


def _read_options(f, *, acc: bool = True, mag: bool = True):
    """The column-mapping, unit and check options shared by the file commands, outermost first."""
    import click

    opts = [
        click.option("--gyro", metavar="COLS", help="Gyro columns: gx,gy,gz or one (N, 3) array (default: detected)."),
        click.option("--acc", metavar="COLS", help="Accelerometer columns (default: detected).") if acc else None,
        click.option("--mag", metavar="COLS", help="Magnetometer columns (default: detected).") if mag else None,
        click.option("--time", "time_col", metavar="COL", help="Time column (default: t, time, timestamp, ...)."),
        click.option("--rate", type=float, metavar="HZ", help="Sample rate, for files without a time column."),
        _unit_option("gyro", "rad/s"),
        _unit_option("acc", "m/s2") if acc else None,
        _unit_option("mag", "uT") if mag else None,
        _unit_option("time", "s"),
        click.option(
            "--max-gap",
            default=10.0,
            show_default=True,
            metavar="K",
            help="Largest time step allowed, in sample periods (0: no check).",
        ),
        click.option("--no-unit-check", is_flag=True, help="Do not check that magnitudes fit the units."),
        click.option("--in-format", type=click.Choice(_FORMATS), help="Input format (default: from the suffix)."),
    ]
    for opt in reversed([o for o in opts if o is not None]):
        f = opt(f)
    return f


def _output_options(f, *, bias: bool = False):
    import click

    opts = [
        click.option(
            "-o", "--output", type=click.Path(dir_okay=False), help="Output file (.csv, .parquet, .h5, .mat)."
        ),
        click.option("--format", "out_format", type=click.Choice(_FORMATS), help="Output format (default: suffix)."),
        click.option("--euler", "seq", default="ZYX", show_default=True, help="Euler sequence of the angle columns."),
        click.option("--no-euler", is_flag=True, help="Write no Euler angles."),
        click.option("--radians", is_flag=True, help="Angles (and bias) in radians instead of degrees."),
        click.option(
            "--yaw-range",
            type=click.Choice(["signed", "positive"]),
            help="Outer angle in (-180, 180] or [0, 360) (default: positive for ZYX, Gajda's).",
        ),
        click.option("--no-bias", is_flag=True, help="Leave out the estimated gyro bias.") if bias else None,
        click.option("--no-flags", is_flag=True, help="Leave out the estimator's flags.") if bias else None,
        click.option(
            "--chunk-rows", default=_CHUNK_ROWS, show_default=True, help="Rows read and written at a time (memory)."
        ),
        click.option("-q", "--quiet", is_flag=True, help="No progress bar, no summary."),
    ]
    for opt in reversed([o for o in opts if o is not None]):
        f = opt(f)
    return f


def _flight_options(gyro_option: str, gyro_default: str):
    """Scenario, sample rate, gyro sample kind, IMU grade and seed: what compare and simulate fly."""
    import click

    opts = [
        click.option(
            "--scenario",
            type=click.Choice(list(_scenarios())),
            default="hammerhead-loop",
            show_default=True,
            help="What is flown.",
        ),
        click.option("--rate", default=100.0, show_default=True, help="Sample rate, Hz."),
        click.option(
            gyro_option,
            type=click.Choice(["rate", "average", "increment", "rotvec"]),
            default=gyro_default,
            show_default=True,
            help="What a gyro sample is.",
        ),
        click.option(
            "--imu",
            type=click.Choice(["ideal", "consumer", "tactical"]),
            default="ideal",
            show_default=True,
            help="Errors.",
        ),
        click.option("--seed", default=0, show_default=True, help="Seed of the sensor errors."),
    ]

    def apply(f):
        for opt in reversed(opts):
            f = opt(f)
        return f

    return apply


def _estimate_output_options(f):
    return _output_options(f, bias=True)


def _q0(text: str | None, option: str = "--q0"):
    """An initial attitude from the command line: w,x,y,z, or yaw,pitch,roll in degrees (ZYX)."""
    import click

    if not text:
        return None
    try:
        values = [float(v) for v in text.replace(" ", ",").split(",") if v]
    except ValueError:
        raise click.BadParameter(f"expected numbers, got {text!r}", param_hint=option) from None
    if len(values) == 4:
        return values
    if len(values) == 3:
        from .euler import from_euler

        return from_euler(values, "ZYX", degrees=True).tolist()
    raise click.BadParameter("give 4 numbers (w,x,y,z) or 3 (yaw,pitch,roll in degrees)", param_hint=option)


def _columns_spec(p: dict, extra=()):
    import click

    from .io import ImuColumns

    max_gap = p.get("max_gap", 10.0)
    if not max_gap >= 0:  # NaN included
        raise click.BadParameter(f"sample periods >= 0 (0: no check), got {max_gap}", param_hint="--max-gap")
    return ImuColumns(
        gyro=p.get("gyro"),
        acc=p.get("acc"),
        mag=p.get("mag"),
        time=p.get("time_col"),
        rate=p.get("rate"),
        gyro_unit=p.get("gyro_unit"),
        acc_unit=p.get("acc_unit"),
        mag_unit=p.get("mag_unit"),
        time_unit=p.get("time_unit"),
        extra=tuple(extra),
        max_gap=max_gap,
        unit_check=not p.get("no_unit_check", False),
        format=p.get("in_format"),
    )


def _output_spec(p: dict):
    import click

    from .io import Angles, OutputSpec

    try:
        angles = Angles(p.get("seq") or "ZYX", degrees=not p.get("radians"), yaw_range=p.get("yaw_range"))
    except ValueError as exc:
        raise click.BadParameter(str(exc), param_hint="--euler") from None
    return OutputSpec(
        euler=not p.get("no_euler"),
        angles=angles,
        bias=not p.get("no_bias"),
        flags=not p.get("no_flags"),
        format=p.get("out_format"),
    )


def _integrate_kwargs(p: dict) -> dict:
    return {
        "columns": _columns_spec(p),
        "out": _output_spec(p),
        "method": p.get("method"),
        "input": p.get("samples") or "rate",
        "rate_frame": p.get("rate_frame") or "body",
        "q0": _q0(p.get("q0")),
        "chunk_rows": _CHUNK_ROWS if p.get("chunk_rows") is None else p["chunk_rows"],
    }


def _estimate_kwargs(p: dict) -> dict:
    extra = [_assignment(a, "--extra", raw=True) for a in p.get("extra") or ()]
    mode = p.get("mode")
    return {
        "estimator": p.get("estimator") or "attitude",
        "params": dict(_assignment(a, "--param") for a in p.get("params") or ()),
        "frame": (p.get("frame") or "ENU").upper(),
        "mag": {"9d": True, "6d": False}.get(mode),
        "q0": _q0(p.get("q0")),
        "columns": _columns_spec(p, ((n, v.strip()) for n, v in extra)),
        "out": _output_spec(p),
        "chunk_rows": _CHUNK_ROWS if p.get("chunk_rows") is None else p["chunk_rows"],
    }


def _angles_in_out(p: dict):
    import click

    from .io import Angles

    try:
        base = Angles(p.get("seq") or "ZYX", degrees=bool(p.get("degrees")), yaw_range=p.get("yaw_range"))
        base = Angles(base.seq, base.degrees, base.yaw_range, p.get("gibbs") or "gajda")
        out = Angles(p.get("to_seq") or base.seq, base.degrees, base.yaw_range, base.gibbs)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None
    return base, out


def _convert_kwargs(p: dict) -> dict:
    angles_in, angles_out = _angles_in_out(p)
    source = p.get("source") or "quat"
    return {
        "source": source,
        "target": p.get("target") or ("euler" if source != "euler" else "quat"),
        "columns": p.get("columns"),
        "time_column": p.get("time_col"),
        "angles_in": angles_in,
        "angles_out": angles_out,
        "format": p.get("in_format"),
        "out_format": p.get("out_format"),
        "chunk_rows": _CHUNK_ROWS if p.get("chunk_rows") is None else p["chunk_rows"],
        "unit_from_names": p.get("degrees") is None,  # yaw_deg columns are degrees unless told otherwise
    }


_KWARGS = {"integrate": _integrate_kwargs, "estimate": _estimate_kwargs, "convert": _convert_kwargs}


class _Progress:
    """A tqdm bar on stderr that appears after a second, only on a terminal; a callable (done, total)."""

    def __init__(self, quiet: bool, unit: str = "rows"):
        self.quiet = quiet
        self.unit = unit
        self.bar = None

    def __call__(self, done: int, total: int | None) -> None:
        if self.quiet:
            return
        if self.bar is None:
            try:
                from tqdm import tqdm
            except ImportError:  # no bar without tqdm; the command works the same
                self.quiet = True
                return
            self.bar = tqdm(total=total, unit=self.unit, unit_scale=True, delay=1.0, disable=None, file=sys.stderr)
        self.bar.update(done - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _run_file(function, path, output, kwargs: dict, quiet: bool) -> None:
    """Run one file command: progress bar, summary line, and bad input as a one-line error (exit 1)."""
    import click

    bar = _Progress(quiet)
    try:
        report = function(path, output, progress=bar, **kwargs)
    except (ValueError, OSError, ImportError, RuntimeError) as exc:
        bar.close()
        raise click.ClickException(str(exc)) from None
    bar.close()
    if not quiet:
        if report.read:
            click.echo(f"read: {report.read}", err=True)
        for note in report.notes:
            click.echo(note, err=True)
        click.echo(f"written: {report.output} ({report.rows} rows, {report.seconds:.2f} s)")


def _input_argument():
    import click

    return click.argument("path", metavar="INPUT", type=click.Path(exists=True, dir_okay=False))


def _add_file_commands(cli) -> None:
    import click

    @cli.command()
    @_input_argument()
    @click.option(
        "-m",
        "--method",
        type=click.Choice(_methods()),
        help="Propagation method (default: exact; coning2 for increments).",
    )
    @click.option(
        "--samples",
        type=click.Choice(["rate", "average", "increment"]),
        default="rate",
        show_default=True,
        help="What a gyro sample is: the rate at its row's time, the mean rate or the angle over its step.",
    )
    @click.option("--rate-frame", type=click.Choice(["body", "reference"]), default="body", show_default=True)
    @click.option("--q0", metavar="W,X,Y,Z|YAW,PITCH,ROLL", help="Initial attitude (angles in degrees, ZYX).")
    @_read_options
    @_output_options
    def integrate(path, **p):
        """Integrate the gyro readings of INPUT into attitudes, streaming (any file size).

        Row k's sample acts from row k's time to row k+1's; output row k is the attitude at row k's time
        (the first is --q0, identity by default).  Columns: t, qw, qx, qy, qz and Euler angles.

        \b
        Examples:
          strapdown integrate flight.csv                                   # -> flight.integrate.csv
          strapdown integrate flight.csv --gyro wx,wy,wz --gyro-unit deg/s --time stamp --time-unit ms
          strapdown integrate imu.parquet -o att.parquet --rate 400 --method cayley --radians
          strapdown integrate dtheta.h5 --gyro imu/dtheta --samples increment --rate 200 --q0 30,0,0
        """
        from .io import integrate_file

        _run_file(integrate_file, path, p.get("output"), _integrate_kwargs(p), p["quiet"])

    @cli.command()
    @_input_argument()
    @click.option("-e", "--estimator", type=click.Choice(list(_estimators())), default="attitude", show_default=True)
    @click.option("-p", "--param", "params", multiple=True, metavar="NAME=VALUE", help="Set a parameter (repeatable).")
    @click.option(
        "--frame",
        type=click.Choice(_FRAMES, case_sensitive=False),
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
    @_read_options
    @_estimate_output_options
    def estimate(path, **p):
        """Run a fusion filter over INPUT and write its attitudes, bias and flags, streaming (any file size).

        One output row per input row: the attitude after that row's sample.  Parameters as for evaluate.

        \b
        Examples:
          strapdown estimate log.csv                                       # 9D if the file has a magnetometer
          strapdown estimate log.parquet -e madgwick -p beta=0.05 --frame ned -o att.parquet
          strapdown estimate broad/01_undisturbed_slow_rotation_A.mat -e mahony --9d
          strapdown estimate chair.csv -e tilt --extra known_acc=cx,cy,cz --acc-unit g
        """
        from .io import estimate_file

        _run_file(estimate_file, path, p.get("output"), _estimate_kwargs(p), p["quiet"])

    @cli.command(context_settings={"ignore_unknown_options": True})
    @click.argument("args", nargs=-1, type=click.UNPROCESSED, metavar="[INPUT | VALUES...]")
    @click.option("-o", "--output", type=click.Path(dir_okay=False), help="Output file (file mode).")
    @click.option("--from", "source", type=click.Choice(list(_representations())), default="quat", show_default=True)
    @click.option(
        "--to", "target", type=click.Choice([*_representations(), "all"]), help="Default: all (values), euler (files)."
    )
    @click.option("--seq", default="ZYX", show_default=True, help="Euler sequence (upper case intrinsic).")
    @click.option("--to-seq", help="Euler sequence of the output (default: --seq).")
    @click.option(
        "--degrees/--radians",
        default=None,
        help="Angles in degrees or radians, input and output (default: radians; in files, what the names say).",
    )
    @click.option("--yaw-range", type=click.Choice(["signed", "positive"]), help="Outer Euler angle range.")
    @click.option("--gibbs", type=click.Choice(["gajda", "rodrigues"]), default="gajda", show_default=True)
    @click.option("--columns", metavar="COLS", help="Input columns (file mode; default: the usual names).")
    @click.option("--time", "time_col", metavar="COL", help="Column copied first (default: a detected time column).")
    @click.option("--in-format", type=click.Choice(_FORMATS))
    @click.option("--format", "out_format", type=click.Choice(_FORMATS))
    @click.option("--chunk-rows", default=_CHUNK_ROWS, show_default=True)
    @click.option("-q", "--quiet", is_flag=True)
    def convert(args, **p):
        """Convert attitudes between representations: numbers on the command line, or the columns of a file.

        Representations: quat (w x y z), euler, matrix (9, row by row), rotvec, axis_angle (axis, angle),
        gibbs, cayley_klein (re/im of u11 u12 u21 u22), compressed (Liu et al.'s unique angles).

        \b
        Examples:
          strapdown convert --from euler --seq ZYX --degrees 10 20 30 --to quat
          strapdown convert --from quat 0.5 -0.5 0.5 0.5                 # every representation
          strapdown convert --from rotvec 0 0 3.14159 --to euler --seq zxz
          strapdown convert att.csv --from quat --to rotvec --degrees -o att_rotvec.parquet
          strapdown convert broad.mat --columns opt_quat --to euler --degrees --yaw-range signed
        """
        if len(args) == 1 and not _is_number(args[0]):
            from pathlib import Path

            from .io import convert_file

            if not Path(args[0]).is_file():
                raise click.BadParameter(f"no such file: {args[0]}", param_hint="INPUT")
            _run_file(convert_file, args[0], p.get("output"), _convert_kwargs(p), p["quiet"])
            return
        _convert_values(args, p)

    @cli.command()
    @click.argument("output", type=click.Path(dir_okay=False))
    @_flight_options("--samples", "average")
    @click.option("--reference", default="ENU", show_default=True, help="Frame of the truth (ENU, NED, NWU, ...).")
    @click.option("--body", default="FLU", show_default=True, help="Sensor axes (FLU, FRD, RFU, ...).")
    @click.option("--duration", type=float, help="Seconds (default: the whole scenario).")
    @_unit_option("gyro", "rad/s")
    @_unit_option("acc", "m/s2")
    @_unit_option("mag", "uT")
    @click.option("--no-truth", is_flag=True, help="Leave out the true attitude.")
    @click.option("--format", "out_format", type=click.Choice(_FORMATS))
    @click.option("-q", "--quiet", is_flag=True)
    def simulate(output, **p):
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
        from .io import simulate_file

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

    @cli.command()
    @_input_argument()
    @click.option("--truth", type=click.Path(exists=True, dir_okay=False), help="File with the true attitude.")
    @click.option("--out", type=click.Path(file_okay=False), help="Folder of the figures (default: beside INPUT).")
    @click.option("--euler", "seq", default="ZYX", show_default=True, help="Euler sequence of the angle figure.")
    @click.option("--radians", is_flag=True)
    @click.option("--yaw-range", type=click.Choice(["signed", "positive"]))
    @click.option("--max-points", default=200_000, show_default=True, help="Rows drawn at most (thinned evenly).")
    def plot(path, truth, out, seq, radians, yaw_range, max_points):
        """Write PNG figures of an attitude file: Euler angles, errors against --truth, and the gyro bias.

        \b
        Examples:
          strapdown plot flight.integrate.csv
          strapdown plot att.parquet --truth sim.parquet --out figures/
          strapdown plot att.csv --euler ZXY --yaw-range signed
        """
        from .io import Angles
        from .io.plots import plot_file

        try:
            written = plot_file(path, truth, out, angles=Angles(seq, not radians, yaw_range), max_points=max_points)
        except (ValueError, OSError, ImportError) as exc:
            raise click.ClickException(str(exc)) from None
        for f in written:
            click.echo(f"written: {f}")

    @cli.command(context_settings={"ignore_unknown_options": True, "allow_interspersed_args": False})
    @click.argument("pattern")
    @click.argument("command", type=click.Choice(list(_KWARGS)))
    @click.argument("args", nargs=-1, type=click.UNPROCESSED)
    @click.option("--out", type=click.Path(file_okay=False), help="Output folder (default: beside each input).")
    @click.option("-j", "--workers", type=int, help="Local processes (default: one per core).")
    @click.option("--scheduler", metavar="ADDRESS", help="Dask scheduler, e.g. tcp://10.0.0.5:8786 (dask extra).")
    @click.option("--split", type=int, help="integrate only: split each file into this many parts run in parallel.")
    @click.option("-q", "--quiet", is_flag=True)
    @click.pass_context
    def batch(ctx, pattern, command, args, out, workers, scheduler, split, quiet):
        """Run integrate, estimate or convert on every file matching PATTERN, in parallel.

        PATTERN is a glob (quote it; ** spans folders).  COMMAND's options follow it (batch's own options may
        come before PATTERN or among them).  Each output is
        written atomically beside its input, or under --out with the folders below the pattern's root kept.
        A file that fails is reported by name and the others go on; the exit code is 1 if any failed.
        With --split, each file's integration is cut into parts integrated at once and joined by a prefix
        product of the parts' end quaternions (exact, cayley, first- and second-order methods).

        \b
        Examples:
          strapdown batch 'logs/**/*.parquet' estimate -e mahony --frame ned --out results/
          strapdown batch 'data/*.csv' integrate --gyro-unit deg/s -j 8
          strapdown batch 'lake/**/*.parquet' estimate --scheduler tcp://scheduler:8786
          strapdown batch huge.parquet integrate --split 16 --scheduler tcp://scheduler:8786
        """
        _batch(ctx, pattern, command, args, out, workers, scheduler, split, quiet)


_BATCH_OPTIONS = {
    "--out": "out",
    "--workers": "workers",
    "-j": "workers",
    "--scheduler": "scheduler",
    "--split": "split",
}


def _batch_options_among(args, found: dict) -> list:
    """Take batch's own options out of COMMAND's arguments (they may follow PATTERN and COMMAND)."""
    import click

    rest, i = [], 0
    while i < len(args):
        name, eq, value = args[i].partition("=")
        if name in _BATCH_OPTIONS:
            if not eq:
                if i + 1 >= len(args):
                    raise click.UsageError(f"{name} needs a value")
                i += 1
                value = args[i]
            found[_BATCH_OPTIONS[name]] = value
        else:
            rest.append(args[i])
        i += 1
    return rest


def _batch(ctx, pattern, command, args, out, workers, scheduler, split, quiet) -> None:
    import click

    from .batch import Job, batch_outputs, check_split, expand, integrate_split, run_batch

    found = {"out": out, "workers": workers, "scheduler": scheduler, "split": split}
    args = _batch_options_among(args, found)
    out, scheduler = found["out"], found["scheduler"]
    try:
        workers = None if found["workers"] is None else int(found["workers"])
        split = None if found["split"] is None else int(found["split"])
    except ValueError:
        raise click.UsageError("--workers and --split take whole numbers") from None
    quiet = quiet or "-q" in args or "--quiet" in args
    files, root = expand(pattern)
    if not files:
        raise click.ClickException(f"no files match {pattern!r}")
    sub = ctx.parent.command.commands[command]
    try:
        sub_ctx = sub.make_context(command, [str(files[0]), *args], parent=ctx.parent)
    except click.ClickException as exc:
        raise click.UsageError(f"{command} options: {exc.format_message()}") from None
    params = dict(sub_ctx.params)
    if params.get("output"):
        raise click.UsageError("batch chooses each output's name: use batch --out FOLDER instead of -o")
    kwargs = _KWARGS[command](params)
    fmt = params.get("out_format")
    if split is not None and command != "integrate":
        raise click.UsageError("--split works with integrate only")
    if split is not None and split < 1:
        raise click.UsageError(f"--split takes a positive number of parts, got {split}")
    try:  # before any file is read: outputs that clash, and a split the method cannot take
        outputs = batch_outputs(files, command, root, out, fmt)
        if split is not None:
            check_split(split, kwargs["method"], kwargs["input"])
    except ValueError as exc:
        raise click.UsageError(str(exc)) from None
    if split:
        failed = 0
        for f, o in zip(files, outputs, strict=True):
            try:
                report = integrate_split(f, o, parts=split, scheduler=scheduler, workers=workers, **kwargs)
            except (ValueError, OSError, ImportError, RuntimeError) as exc:
                failed += 1
                click.echo(f"FAILED {f}: {exc}", err=True)
                continue
            if not quiet:
                click.echo(f"written: {report.output} ({report.rows} rows, {report.seconds:.2f} s, {split} parts)")
        if failed:
            raise click.ClickException(f"{failed} of {len(files)} files failed")
        return
    jobs = [Job(command, str(f), str(o), kwargs) for f, o in zip(files, outputs, strict=True)]
    bar = _Progress(quiet, unit="files")
    done = [0]

    def progress(result) -> None:
        done[0] += 1
        bar(done[0], len(jobs))

    try:
        results = run_batch(jobs, scheduler=scheduler, workers=workers, progress=progress)
    except (ValueError, OSError, ImportError) as exc:
        bar.close()
        raise click.ClickException(str(exc)) from None
    bar.close()
    bad = [r for r in results if not r.ok]
    for r in results:
        if r.ok and not quiet:
            click.echo(f"written: {r.output} ({r.rows} rows, {r.seconds:.2f} s)")
    for r in bad:
        click.echo(f"FAILED {r.input}: {r.error}", err=True)
    if bad:
        raise click.ClickException(f"{len(bad)} of {len(results)} files failed: {', '.join(r.input for r in bad)}")
    if not quiet:
        click.echo(f"{len(results)} files written", err=True)


def _is_number(text: str) -> bool:
    return isinstance(_value(text), float)


def _convert_values(args, p: dict) -> None:
    """Convert numbers from the command line: print the target representation(s), one per line."""
    import click
    import numpy as np

    from .io.pipeline import convert_values
    from .io.tables import REPRESENTATIONS, column_names

    bad = [a for a in args if not _is_number(a)]
    if bad:
        raise click.UsageError(f"expected numbers or one input file, got {' '.join(bad)} (an unknown option?)")
    source = p["source"]
    width = REPRESENTATIONS[source]
    if len(args) != width:
        raise click.UsageError(f"--from {source} takes {width} numbers, got {len(args)}")
    angles_in, angles_out = _angles_in_out(p)
    targets = list(REPRESENTATIONS) if p.get("target") in (None, "all") else [p["target"]]
    values = np.array([[float(a) for a in args]])
    if not np.isfinite(values).all():  # in a file a NaN row is an unknown attitude; typed here it is a mistake
        raise click.UsageError(f"the numbers must be finite, got {' '.join(args)}")
    try:
        results = {t: convert_values(values, source, t, angles_in, angles_out)[0] for t in targets}
    except ValueError as exc:
        raise click.ClickException(str(exc)) from None
    for t, v in results.items():
        numbers = " ".join(repr(float(x)) for x in v)
        if len(targets) == 1:
            click.echo(numbers)
        else:
            names = ",".join(column_names(t, angles_out))
            click.echo(f"{t:13} {numbers}    ({names})")


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


def _methods():
    from .integrate import METHODS

    return list(METHODS)


def _representations():
    from .io.tables import REPRESENTATIONS

    return REPRESENTATIONS


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
