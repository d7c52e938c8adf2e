"""Options and helpers shared by the command modules (private).

Nothing heavy at import: click only.  Each option helper decorates a command function; the ``*_spec`` functions
turn parsed options into the objects of :mod:`strapdown.io`.
"""

from __future__ import annotations

FRAMES = ("ENU", "NED", "NWU")
CHUNK_ROWS = 1 << 18  # as strapdown.io.pipelines.CHUNK_ROWS (not imported: --help stays light)
FORMATS = ("csv", "parquet", "hdf5", "mat")


def choice_option(*decls: str, choices, help: str, default: str | None = None):
    """An option that takes one of ``choices``; the first is the default unless ``default`` says otherwise."""
    import click

    choices = list(choices)
    return click.option(
        *decls,
        type=click.Choice(choices),
        default=choices[0] if default is None else default,
        show_default=True,
        help=help,
    )


def param_option(units: str):
    """``-p/--param NAME=VALUE`` (repeatable) for an estimator's parameters; ``units`` says how angles are given."""
    import click

    return click.option(
        "-p", "--param", "params", multiple=True, metavar="NAME=VALUE", help=f"Set a parameter (repeatable); {units}"
    )


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
        click.option(
            "--gyro",
            metavar="[FILE:]COLS",
            help="Gyro columns: gx,gy,gz, one (N, 3) array, or numbers (2,3,4) in a file without a header; FILE: "
            "which of several inputs holds them (default: detected in each file).",
        ),
        click.option("--acc", metavar="[FILE:]COLS", help="Accelerometer columns (as --gyro).") if acc else None,
        click.option("--mag", metavar="[FILE:]COLS", help="Magnetometer columns (as --gyro).") if mag else None,
        click.option(
            "--time", "time_col", metavar="[FILE:]COL", help="Time column (default: t, time, timestamp, ...)."
        ),
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
        choice_option(
            "--on-gap",
            choices=("auto", "error", "split", "restart", "bridge"),
            help="At a gap over --max-gap: bridge the short ones and start afresh after the long ones (auto, each "
            "with a warning and a gap or segment column); stop; write a file per segment; start afresh after "
            "every gap; or bridge every gap.",
        ),
        click.option(
            "--bridge",
            type=click.FloatRange(min=0),
            metavar="S",
            help="With --on-gap auto: the longest gap bridged, s (default: from the gyro's noise and bias, about "
            "2 s for a quiet gyro).",
        ),
        click.option("--no-unit-check", is_flag=True, help="Do not check that magnitudes fit the units."),
        click.option("--topic", metavar="NAME", help="Bag or log topic of the IMU (listed when ambiguous)."),
        click.option("--mag-topic", metavar="NAME", help="Bag or log topic of the magnetometer."),
        click.option(
            "--in-format", type=click.Choice(input_formats()), help="Input format (default: from the suffix, folder)."
        ),
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
            "--float32",
            is_flag=True,
            help="Quaternions, angles and bias as float32: half the bytes (the float64 results rounded; t stays "
            "float64).",
        ),
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
        choice_option("--scenario", choices=scenarios(), default="hammerhead-loop", help="What is flown."),
        click.option("--rate", default=100.0, show_default=True, help="Sample rate, Hz."),
        choice_option(
            gyro_option,
            choices=("rate", "average", "increment", "rotvec"),
            default=gyro_default,
            help="What a gyro sample is.",
        ),
        choice_option("--imu", choices=("ideal", "consumer", "tactical"), help="Errors."),
        click.option(
            "--seed", default=0, show_default=True, type=click.IntRange(min=0), help="Seed of the sensor errors."
        ),
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
        from ..rotations.euler import from_euler

        return from_euler(values, "ZYX", degrees=True).tolist()
    raise click.BadParameter("give 4 numbers (w,x,y,z) or 3 (yaw,pitch,roll in degrees)", param_hint=option)


def columns_spec(p: dict, extra=()):
    import click

    from ..io import ImuColumns

    max_gap = p.get("max_gap", 10.0)
    if not max_gap >= 0:  # NaN included
        raise click.BadParameter(f"sample periods >= 0 (0: no check), got {max_gap}", param_hint="--max-gap")
    # topics only when given: readers without them (a CSV) keep their ImuColumns fields
    topics = {k: p[k] for k in ("topic", "mag_topic") if p.get(k)}
    return ImuColumns(
        **topics,
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
        float32=bool(p.get("float32")),
    )


def input_argument():
    import click

    return click.argument("path", metavar="INPUT", type=click.Path(exists=True, dir_okay=False))


def inputs_argument():
    """One recording: a file, several files (one per sensor), or an export folder."""
    import click

    return click.argument("paths", metavar="INPUT...", nargs=-1, required=True, type=click.Path(exists=True))


def truth_options(truth_help: str):
    """--truth FILE, --truth-frame and --truth-body: a file with the true attitude, and its frames if it lacks them."""
    import click

    def decorate(f):
        f = click.option(
            "--truth-body", metavar="AXES", help="The truth's body axes, when its file does not say them."
        )(f)
        f = click.option(
            "--truth-frame", metavar="FRAME", help="The truth's reference frame, when its file does not say it."
        )(f)
        return click.option("--truth", type=click.Path(exists=True, dir_okay=False), help=truth_help)(f)

    return decorate


def one_or_many(paths):
    """The path, or the list of paths of one recording given as several files."""
    return paths[0] if len(paths) == 1 else list(paths)


def frame_options(f, *, integrate: bool = False):
    """--frame, --body and --out-body: the reference frame and the axes of readings and attitudes."""
    import click

    frame_help = (
        "Reference frame that --q0 is in (default: the body axes at the first sample)."
        if integrate
        else "Reference frame of the output (default: the format's preset, e.g. NED for a PX4 log; else ENU)."
    )
    opts = [
        click.option("--frame", metavar="|".join(FRAMES) + "|...", callback=_frame, help=frame_help),
        click.option(
            "--body",
            metavar="AXES",
            help="Axes of the readings: FRD (PX4, ArduPilot), FLU (ROS REP 103), RFU (Android), ... "
            "(default: the format's preset, else those of the output).",
        ),
        click.option(
            "--out-body",
            metavar="AXES",
            help="Body axes of the output attitudes (default: FRD with NED, FLU with ENU and NWU: level is zero).",
        ),
    ]
    for opt in reversed(opts):
        f = opt(f)
    return f


def _frame(ctx, param, value):
    """A reference frame with a vertical z axis (the estimators' need): ENU, NED, NWU, ESU..., upper case."""
    import click

    if value is None:
        return None
    from ..rotations.frames import frame_matrix

    frame = value.upper()
    try:
        m = frame_matrix(frame, "NED")
    except ValueError as exc:
        raise click.BadParameter(str(exc).replace("src=", "")) from None
    if abs(m[2, 2]) != 1.0:
        raise click.BadParameter(f"{frame}: its z axis must be up (U) or down (D), as in ENU, NED, NWU")
    return frame


def input_formats():
    from ..io import readers

    return list(getattr(readers, "INPUT_FORMATS", FORMATS))


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
    from ..fusion.registry import ESTIMATORS

    return ESTIMATORS


def methods():
    from ..propagate.integrate import METHODS

    return list(METHODS)


def representations():
    from ..io.tables import REPRESENTATIONS

    return REPRESENTATIONS


def scenarios():
    from ..simulate.scenarios import SCENARIOS

    return SCENARIOS


# ----------------------------------------------------------------------------------------------------------
# Estimator parameters on the command line, in the library's units or in degrees with the unit in the name.

_DEG_SUFFIXES = ("_deg_s", "_dps", "_deg")  # longest first: bias_limit_deg_s is bias_limit in deg/s
_RAD_SUFFIXES = ("_rad_s", "_rad")
_UNIT_IN_DOC = r",\s*(rad/s·√s|rad/s|rad|1/s²|1/s|1/√s|√s|m/s²|µT|s)(?![\w/])"


def param_units(estimator: str) -> dict[str, str]:
    """Parameter name -> its unit as the parameter class documents it ("rad/s", "s", "1/s", "" when unstated)."""
    import dataclasses
    import re

    cls = estimators()[estimator][1]
    doc = cls.__doc__ or ""
    units = {}
    for f in dataclasses.fields(cls):
        m = re.search(rf"^\s*{f.name}\s*:.*\n((?:\s{{8,}}.*\n?)*)", doc, re.M)
        # numpydoc "name : float / Description, unit (default ...)": the first ", <unit>" of the description
        u = re.search(_UNIT_IN_DOC, " ".join(m.group(1).split())) if m else None
        units[f.name] = u.group(1) if u else ""
    return units


def param_name(estimator: str, name: str, option: str = "--param") -> tuple[str, float | None]:
    """(parameter, factor to the library's unit or None) of a command-line name such as ``bias_limit_deg_s``.

    A name ending in ``_deg``, ``_deg_s`` or ``_dps`` gives a parameter that the library takes in radians (rad,
    rad/s, rad/s·√s) in degrees instead, the unit of the outputs; ``_rad`` and ``_rad_s`` say radians.
    """
    import math

    import click

    units = param_units(estimator)
    for suffix, factor in [(s, math.pi / 180) for s in _DEG_SUFFIXES] + [(s, 1.0) for s in _RAD_SUFFIXES]:
        base = name[: -len(suffix)]
        if name.endswith(suffix) and base in units:
            if not units[base].startswith("rad"):
                raise click.BadParameter(
                    f"{base} of {estimator} is in {units[base] or 'no angular unit'}, not an angle or a rate: "
                    f"write {base}=VALUE",
                    param_hint=option,
                )
            return base, factor
    return name, None


def scaled(name: str, value, factor: float | None, option: str = "--param"):
    """``value`` in the library's unit (``factor`` from :func:`param_name`)."""
    import click

    if factor is None:
        return value
    if not isinstance(value, float):
        raise click.BadParameter(f"{name} takes a number, got {value!r}", param_hint=option)
    return value * factor


def parse_params(estimator: str, assignments, option: str = "--param") -> dict:
    """``NAME=VALUE`` options as parameters: ``bias_limit_deg_s=5`` (degrees, unit in the name), ``bias_limit=0.087``.

    Units in names as for :func:`param_name`.
    """
    import click

    out = {}
    for text in assignments or ():
        name, value = assignment(text, option)
        base, factor = param_name(estimator, name, option)
        if base in out:
            raise click.BadParameter(f"{base} is given twice", param_hint=option)
        out[base] = scaled(name, value, factor, option)
    return out


def list_params(estimator: str) -> str:
    """A table of an estimator's parameters: name, default, unit, and the default in degrees where angular."""
    import dataclasses
    import math

    cls = estimators()[estimator][1]
    units = param_units(estimator)
    lines = [f"{estimator} parameters (-p NAME=VALUE; angles and rates also as -p NAME_deg=... / NAME_deg_s=...):"]
    for f in dataclasses.fields(cls()):
        value = getattr(cls(), f.name)
        unit = units.get(f.name, "")
        deg = ""
        if unit.startswith("rad") and isinstance(value, float):
            suffix = "_deg" if unit == "rad" else "_deg_s"
            deg = f"    = {f.name}{suffix}={math.degrees(value):.6g}"
        shown = f"{value:.6g}" if isinstance(value, float) else str(value)
        lines.append(f"  {f.name:24} {shown:>14} {unit:10}{deg}")
    return "\n".join(lines)


def writable_folder(folder, option: str) -> None:
    """Refuse a folder that cannot be written before anything is computed (created when missing).

    A file is really created and removed: ``os.access`` says yes to root everywhere, also on a read-only mount
    or in ``/proc``, where the write after the computation would then fail.
    """
    import tempfile
    from pathlib import Path

    import click

    path = Path(folder)
    probe = path
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    problem = None if probe.is_dir() else "is not a folder"
    if problem is None:
        try:
            with tempfile.TemporaryFile(dir=probe, prefix=".strapdown-probe-"):
                pass
        except OSError as exc:
            problem = f"is not writable: {exc.strerror or exc}"
    if problem:
        raise click.BadParameter(f"cannot write into {path} ({probe} {problem})", param_hint=option)


def writable_file(file, option: str) -> None:
    """Refuse an output file that cannot be written (its folder, or the file itself, read-only) before computing."""
    import os
    from pathlib import Path

    import click

    path = Path(file)
    if path.is_dir():
        raise click.BadParameter(f"cannot write {path}: it is a folder", param_hint=option)
    if path.exists() and not os.access(path, os.W_OK):
        raise click.BadParameter(f"cannot write {path}: it is read-only", param_hint=option)
    writable_folder(path.parent if str(path.parent) else ".", option)


def check_samples(rate: float, seconds: float, option: str = "--rate") -> None:
    """Refuse a simulation too large to hold, before anything is allocated: say how many samples it means."""
    import click

    samples = rate * seconds
    if samples > MAX_SIMULATED_ROWS:
        raise click.BadParameter(
            f"{seconds:g} s at {rate:g} Hz would be {samples:.3g} samples; at most {MAX_SIMULATED_ROWS:.0e} are "
            "simulated at once (lower --rate or the duration)",
            param_hint=option,
        )


#: Rows a simulation may write at most: 10^8 rows of 17 columns are about 14 GB in memory.
MAX_SIMULATED_ROWS = 100_000_000
