"""``strapdown compare``: every propagation method on a simulated scenario, or our estimate against a log's own."""

from __future__ import annotations

import click

from ._options import check_samples, flight_options, writable_folder


@click.command()
@click.argument("files", nargs=-1, type=click.Path(exists=True), metavar="[OURS LOG]")
@flight_options("--gyro", "increment")
@click.option("--methods", default=None, help="Comma-separated subset of the methods (default: all).")
@click.option("--out", default=None, type=click.Path(file_okay=False), help="Write PNG plots to this directory.")
@click.option(
    "--log",
    type=click.Path(exists=True),
    help="A recording with its own attitude (a PX4 log's vehicle_attitude) instead of a simulation: its gyro "
    "integrated by each method from the logged attitude, against the logged attitude.",
)
@click.option("--topic", metavar="NAME", help="With --log: the IMU topic (default: the format's).")
@click.option("--truth-frame", metavar="FRAME", help="With OURS LOG: the log's reference frame, when it does not say.")
@click.option("--truth-body", metavar="AXES", help="With OURS LOG: the log's body axes, when it does not say.")
def command(files, scenario, rate, gyro, imu, seed, methods, out, log, topic, truth_frame, truth_body):
    """Every propagation method on a simulated scenario; or OURS against the attitude LOG records.

    Without files: run every method and print the comparison table.  Given OURS (an output of strapdown
    estimate) and LOG (the log it came from): our attitude against the log's own
    (PX4 vehicle_attitude, ArduPilot ATT, a ROS Imu orientation): total, inclination and heading errors, the
    heading's constant offset, and how much of it the declination at the log's place and date explains.

    \b
    Examples:
      strapdown compare
      strapdown compare --scenario coning --rate 200 --gyro increment
      strapdown compare --scenario aerobatic-show --imu consumer --gyro average --out plots/
      strapdown compare --methods exact,rk4,euler-angles
      strapdown compare --log flight.ulg                       # against the log's own vehicle_attitude
      strapdown compare flight.estimate.csv flight.ulg          # our estimate against the autopilot's
    """
    if files:
        _ours_against_log(files, truth_frame, truth_body)
        return
    import math
    from pathlib import Path

    from ..evaluate.compare import compare as run_compare
    from ..propagate.integrate import METHODS
    from ..simulate import ImuModel, sample
    from ..simulate.scenarios import scenario as make

    if not (math.isfinite(rate) and rate > 0):
        raise click.BadParameter(f"a positive number of Hz, got {rate}", param_hint="--rate")
    if not log:
        check_samples(rate, make(scenario).duration)  # before sample() allocates them
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
    if log:
        try:
            data, title = _logged(log, topic)
        except (ValueError, OSError, ImportError) as exc:
            raise click.ClickException(str(exc)) from None
        scenario = Path(log).stem
    else:
        model = {"ideal": ImuModel.ideal, "consumer": ImuModel.consumer_mems, "tactical": ImuModel.tactical}[imu]()
        try:
            data = sample(make(scenario), rate, gyro=gyro, imu=model, seed=seed)
        except ValueError as exc:  # a rate too low for one sample, say
            raise click.BadParameter(str(exc), param_hint="--rate") from None
        title = f"{scenario}, {imu} IMU, {gyro} gyro at {rate:g} Hz"
    result = run_compare(data, chosen, title=title)
    click.echo(result.table())
    if out:
        try:
            written = result.plot(out, prefix=scenario.replace("-", "_"))
        except OSError as exc:  # a full disk: checked writable, still not written
            raise click.ClickException(f"cannot write the figures into {out}: {exc}") from None
        for path in written:
            click.echo(f"written: {path}")


def _logged(path, topic):
    """A recording's gyro with its own attitude as the truth, as the ImuData that compare takes."""
    import numpy as np

    from ..io import ImuColumns, read_imu, read_reference
    from ..simulate.sampling import ImuData

    columns = ImuColumns(topic=topic, max_gap=0) if topic else ImuColumns(max_gap=0)
    imu = read_imu(path, columns)
    ref = read_reference(path, topic=topic)
    inside = (imu.t >= ref.t[0]) & (imu.t <= ref.t[-1])  # where the log's attitude says something
    if inside.sum() < 2:
        raise ValueError(f"{path}: the logged attitude ({ref.source}) does not cover the gyro's samples")
    t, g = imu.t[inside], imu.gyro[inside]
    q_true = ref.at(t)
    rate = 1.0 / float(np.median(np.diff(t)))
    empty = np.zeros((t.size - 1, 3))
    # row k's rate acts from t[k] to t[k+1] (the library's convention): N rows give N - 1 steps
    data = ImuData(t, g[:-1], empty, empty, q_true, "rate", ref.frame or "?", ref.body or "?", rate, t)
    title = f"{path}: {t.size} gyro rows at {rate:.4g} Hz against {ref.source}, {t[-1] - t[0]:.1f} s"
    return data, title


def _ours_against_log(files, truth_frame, truth_body) -> None:
    """``compare OURS LOG``: the errors, printed."""
    from pathlib import Path

    from ..io.pipelines.compare import compare_file

    if len(files) != 2:
        raise click.UsageError(f"give OURS and LOG (an estimate and the log it came from), got {len(files)} file(s)")
    ours, log = files
    try:
        errors, note = compare_file(ours, log, truth_frame=truth_frame, truth_body=truth_body)
    except (ValueError, OSError, ImportError) as exc:
        raise click.ClickException(str(exc)) from None
    if note:
        click.echo(note, err=True)
    click.echo(errors.text(Path(ours).name, Path(log).name))
