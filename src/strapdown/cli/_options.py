"""Options and helpers shared by the command modules (private).

Nothing heavy at import: click only.  Each option helper decorates a command function; the ``*_spec`` functions
turn parsed options into the objects of :mod:`strapdown.io`.
"""

from __future__ import annotations

import sys

FRAMES = ("ENU", "NED", "NWU")
CHUNK_ROWS = 1 << 18  # as strapdown.io.pipeline.CHUNK_ROWS (not imported: --help stays light)
FORMATS = ("csv", "parquet", "hdf5", "mat")


def unit_option(kind: str, default_text: str):
    import click

    from ..io.units import UNITS

    def check(ctx, param, value):
        if value is None:
            return None
        from ..io.units import parse_unit

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


def read_options(f, *, acc: bool = True, mag: bool = True):
    """The column-mapping, unit and check options shared by the file commands, outermost first."""
    import click

    opts = [
        click.option("--gyro", metavar="COLS", help="Gyro columns: gx,gy,gz or one (N, 3) array (default: detected)."),
        click.option("--acc", metavar="COLS", help="Accelerometer columns (default: detected).") if acc else None,
        click.option("--mag", metavar="COLS", help="Magnetometer columns (default: detected).") if mag else None,
        click.option("--time", "time_col", metavar="COL", help="Time column (default: t, time, timestamp, ...)."),
        click.option("--rate", type=float, metavar="HZ", help="Sample rate, for files without a time column."),
        unit_option("gyro", "rad/s"),
        unit_option("acc", "m/s2") if acc else None,
        unit_option("mag", "uT") if mag else None,
        unit_option("time", "s"),
        click.option(
            "--max-gap",
            default=10.0,
            show_default=True,
            metavar="K",
            help="Largest time step allowed, in sample periods (0: no check).",
        ),
        click.option("--no-unit-check", is_flag=True, help="Do not check that magnitudes fit the units."),
        click.option("--in-format", type=click.Choice(FORMATS), help="Input format (default: from the suffix)."),
    ]
    for opt in reversed([o for o in opts if o is not None]):
        f = opt(f)
    return f


def output_options(f, *, bias: bool = False):
    import click

    opts = [
        click.option(
            "-o", "--output", type=click.Path(dir_okay=False), help="Output file (.csv, .parquet, .h5, .mat)."
        ),
        click.option("--format", "out_format", type=click.Choice(FORMATS), help="Output format (default: suffix)."),
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
            "--chunk-rows", default=CHUNK_ROWS, show_default=True, help="Rows read and written at a time (memory)."
        ),
        click.option("-q", "--quiet", is_flag=True, help="No progress bar, no summary."),
    ]
    for opt in reversed([o for o in opts if o is not None]):
        f = opt(f)
    return f


def flight_options(gyro_option: str, gyro_default: str):
    """Scenario, sample rate, gyro sample kind, IMU grade and seed: what compare and simulate fly."""
    import click

    opts = [
        click.option(
            "--scenario",
            type=click.Choice(list(scenarios())),
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


def estimate_output_options(f):
    return output_options(f, bias=True)


def parse_q0(text: str | None, option: str = "--q0"):
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
        from ..euler import from_euler

        return from_euler(values, "ZYX", degrees=True).tolist()
    raise click.BadParameter("give 4 numbers (w,x,y,z) or 3 (yaw,pitch,roll in degrees)", param_hint=option)


def columns_spec(p: dict, extra=()):
    import click

    from ..io import ImuColumns

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


def output_spec(p: dict):
    import click

    from ..io import Angles, OutputSpec

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


class Progress:
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


def run_file(function, path, output, kwargs: dict, quiet: bool) -> None:
    """Run one file command: progress bar, summary line, and bad input as a one-line error (exit 1)."""
    import click

    bar = Progress(quiet)
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


def input_argument():
    import click

    return click.argument("path", metavar="INPUT", type=click.Path(exists=True, dir_okay=False))


def is_number(text: str) -> bool:
    return isinstance(parse_value(text), float)


def parse_value(text: str):
    """A parameter value from the command line: a number when it reads as one, else the text."""
    text = text.strip()
    try:
        return float(text)
    except ValueError:
        return text


def assignment(text: str, option: str, raw: bool = False):
    import click

    name, sep, value = text.partition("=")
    if not sep or not name.strip() or not value.strip():
        raise click.BadParameter(f"expected NAME=VALUE, got {text!r}", param_hint=option)
    return name.strip(), (value if raw else parse_value(value))


def estimators():
    from ..evaluate import ESTIMATORS

    return ESTIMATORS


def methods():
    from ..integrate import METHODS

    return list(METHODS)


def representations():
    from ..io.tables import REPRESENTATIONS

    return REPRESENTATIONS


def scenarios():
    from ..simulate.scenarios import SCENARIOS

    return SCENARIOS
