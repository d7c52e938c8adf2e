"""``strapdown calibrate``: fit sensor calibrations from recordings (mag, acc, gyro) and read the Allan curve."""

from __future__ import annotations

import click

from ._options import columns_spec, input_argument, read_options


def _mag_topic(path, p: dict, require: tuple) -> dict:
    """For a ULog's magnetometer fit without --mag-topic: the denser of ``sensor_mag`` and ``vehicle_magnetometer``.

    A fit wants every reading: some logs keep the raw ``sensor_mag`` at the sensor's rate and the fused
    ``vehicle_magnetometer`` at a few readings, others the other way round.
    """
    from pathlib import Path

    if "mag" not in require or p.get("mag_topic") or Path(path).suffix.lower() not in (".ulg", ".ulog"):
        return p
    try:
        from pyulog import ULog
    except ImportError:
        return p
    topics = ("sensor_mag", "vehicle_magnetometer")
    counts = {t: 0 for t in topics}
    for d in ULog(str(path), list(topics)).data_list:
        if d.multi_id == 0:
            counts[d.name] = len(d.data["timestamp"])
    best = max(topics, key=counts.get)
    return {**p, "mag_topic": best} if counts[best] else p


def _read(path, p: dict, require: tuple, optional: tuple = ()):
    """The whole recording: rate (Hz or None), and the readings of each kind read (SI units, file axes).

    Gaps stop the fit only with ``--on-gap error``; otherwise a fit takes the samples on both sides of each (it
    uses the readings, not their sequence, beyond finding rests) and says how many gaps there were.
    """
    from dataclasses import replace

    import numpy as np

    from ..io import ImuFile

    p = _mag_topic(path, p, require)
    columns = columns_spec(p)
    strict = p.get("on_gap") == "error"
    with ImuFile(path, columns if strict else replace(columns, max_gap=0), require=require, optional=optional) as imu:
        parts: dict = {}
        times = []
        for chunk in imu.chunks():
            times.append(chunk.t)
            for kind in (*require, *optional):
                x = getattr(chunk, kind, None)
                if x is not None:
                    parts.setdefault(kind, []).append(x)
        data = {k: np.concatenate(v) for k, v in parts.items()}
        t = np.concatenate(times)
        rate = imu.rate or (1.0 / float(np.median(np.diff(t))) if len(t) > 1 else None)
        steps = np.diff(t)
        gaps = int(np.count_nonzero(steps > columns.max_gap / rate)) if rate and columns.max_gap and not strict else 0
        if gaps:
            click.echo(
                f"warning: {path}: {gaps} gap(s) over {columns.max_gap:g} sample periods (the longest "
                f"{steps.max():.4g} s); the fit uses the samples on both sides (--on-gap error stops instead)",
                err=True,
            )
        return rate, data, getattr(imu, "body", None) or "sensor"  # h-io's readers name the axes of some formats


def _write(cal, output, path) -> None:
    """Write (or update) the calibration file, keeping other sensors' calibrations already in it."""
    from pathlib import Path

    from ..calibrate import load, save

    output = Path(output) if output else Path(path).with_suffix(".calibration.json")
    others = {}
    if output.exists():
        others = load(output)
        if cal.sensor in others:
            click.echo(f"replacing the {cal.sensor} calibration in {output}", err=True)
    others[cal.sensor] = cal
    save(output, *others.values())
    click.echo(f"written: {output} ({', '.join(sorted(others))})")


def _summary(cal) -> None:
    import numpy as np

    with np.printoptions(precision=5, suppress=True):
        click.echo(f"{cal.sensor} ({cal.method}), units {cal.units}, axes {cal.frame}")
        click.echo(f"  offset       {cal.offset}  ± {cal.offset_sigma}")
        for i, row in enumerate(cal.matrix):
            click.echo(f"  matrix[{i}]    {row}  ± {cal.matrix_sigma[i]}")
    for key, value in cal.quality.items():
        if key in ("rests", "faces") or (isinstance(value, list) and len(value) > 3):
            continue
        text = f"{value:.4g}" if isinstance(value, float) else str(value)
        click.echo(f"  {key}: {text}")


def _fit_and_write(fit, path, output) -> None:
    """Run a fit, print its summary and write it; bad input and refusals become one-line errors (exit 1)."""
    try:
        cal = fit()
    except (ValueError, OSError, ImportError) as exc:
        raise click.ClickException(str(exc)) from None
    _summary(cal)
    q = cal.quality
    if q.get("warranted") is False:
        click.echo(
            f"warning: the fit cuts the field-norm scatter only {q['norm_scatter_raw'] / q['norm_scatter']:.2f}-fold "
            f"({q['norm_scatter_raw']:.3g} -> {q['norm_scatter']:.3g} µT): the sensor may be calibrated already, or "
            "the field varies where it was turned; applying this fit may not help",
            err=True,
        )
    try:
        _write(cal, output, path)
    except (ValueError, OSError) as exc:  # an existing -o that is no calibration file, an unwritable folder
        raise click.ClickException(str(exc)) from None


_output = click.option("-o", "--output", type=click.Path(dir_okay=False), help="Calibration file (JSON).")


@click.group()
def command():
    """Fit sensor calibrations from a recording and write them to a JSON file for estimate --calibration.

    \b
    Examples:
      strapdown calibrate mag turning.csv -o cal.json            # turn the sensor through all directions
      strapdown calibrate mag turning.csv -o cal.json --lat 52.5 --lon 13.4 --date 2025-06-01
      strapdown calibrate acc six_faces.csv -o cal.json           # still on each face for a few seconds
      strapdown calibrate gyro still.csv -o cal.json              # bias from the rests
      strapdown calibrate allan still_3h.csv                      # ARW, bias instability, rate random walk
      strapdown estimate log.csv --calibration cal.json --declination auto --lat 52.5 --lon 13.4 --date 2025-06-01
    """


@command.command("mag")
@input_argument()
@_output
@click.option("--field-strength", type=float, metavar="UT", help="Local field strength, µT (default: fitted).")
@click.option("--lat", type=float, help="Latitude, degrees: the field strength from the World Magnetic Model.")
@click.option("--lon", type=float, help="Longitude, degrees (with --lat).")
@click.option("--date", help="Date (YYYY-MM-DD or decimal year), with --lat/--lon.")
@click.option("--no-robust", is_flag=True, help="Plain maximum-likelihood fit (no outlier down-weighting).")
@click.option(
    "--align-gyro",
    is_flag=True,
    help="Also turn the magnetometer axes onto the gyro's (uses the gyro of INPUT and the gyroscope "
    "calibration already in -o, if any, for its bias).",
)
@read_options
def mag_command(path, output, field_strength, lat, lon, date, no_robust, align_gyro, **p):
    """Hard and soft iron from INPUT, a recording that turns the sensor through all directions."""
    from ..calibrate import field, magnetometer

    def fit():
        strength = field_strength
        if lat is not None or lon is not None or date is not None:
            if None in (lat, lon, date) or field_strength is not None:
                raise ValueError("give --lat, --lon and --date together, instead of --field-strength")
            strength = float(field(latitude=lat, longitude=lon, date=date, degrees=True).strength)
        rate, data, axes = _read(path, p, ("mag",) + (("gyro",) if align_gyro else ()))
        gyro = {}
        if align_gyro:
            from pathlib import Path

            from ..calibrate import load

            target = Path(output) if output else Path(path).with_suffix(".calibration.json")
            bias = load(target).get("gyro") if target.exists() else None
            gyro = {"gyro": data["gyro"], "fs": rate, "gyro_bias": bias}
        return magnetometer(data["mag"], field_strength=strength, robust=not no_robust, frame=axes, **gyro)

    _fit_and_write(fit, path, output)


@command.command("acc")
@input_argument()
@_output
@click.option("--gravity", type=float, default=9.80665, show_default=True, help="Local gravity, m/s².")
@click.option("--min-rest", type=float, default=1.0, show_default=True, metavar="S", help="Shortest rest, s.")
@read_options
def acc_command(path, output, gravity, min_rest, **p):
    """Offsets, scale factors and coupling from the rests of INPUT (each face up in turn, or 9+ poses)."""
    from ..calibrate import accelerometer

    def fit():
        rate, data, axes = _read(path, p, ("acc",), ("gyro",))
        return accelerometer(
            data["acc"], fs=rate, gyro=data.get("gyro"), gravity=gravity, frame=axes, min_duration=min_rest
        )

    _fit_and_write(fit, path, output)


@command.command("gyro")
@input_argument()
@_output
@click.option("--min-rest", type=float, default=1.0, show_default=True, metavar="S", help="Shortest rest, s.")
@read_options
def gyro_command(path, output, min_rest, **p):
    """The gyro bias from the rests of INPUT."""
    from ..calibrate import gyroscope

    def fit():
        rate, data, axes = _read(path, p, ("gyro",), ("acc",))
        return gyroscope(data["gyro"], fs=rate, acc=data.get("acc"), frame=axes, min_duration=min_rest)

    _fit_and_write(fit, path, output)


@command.command("allan")
@input_argument()
@click.option("--sensor", type=click.Choice(["gyro", "acc"]), default="gyro", show_default=True)
@read_options
def allan_command(path, sensor, **p):
    """Angle random walk, bias instability and rate random walk of INPUT, a long recording at rest."""
    from ..calibrate import allan

    try:
        rate, data, _ = _read(path, p, (sensor,))
        if rate is None:
            raise ValueError(f"{path} has no sample rate: give --rate or a time column")
        result = allan(data[sensor], rate, units="rad/s" if sensor == "gyro" else "m/s^2")
    except (ValueError, OSError, ImportError) as exc:
        raise click.ClickException(str(exc)) from None
    click.echo(result.table())
    if sensor == "gyro":
        n = float(result.estimator_params()["bias_noise_rest"])
        click.echo(f"estimate: -p bias_noise_rest={n:.4g}   (AttitudeEstimator, rad/s·√s)")
