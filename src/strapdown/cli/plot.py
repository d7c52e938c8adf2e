"""``strapdown plot``: PNG figures of an attitude file."""

from __future__ import annotations

import click

from ._options import input_argument, truth_options, writable_folder


@click.command()
@input_argument()
@truth_options("File with the true attitude: a simulated log, a qw..qz table, a PX4 log (its vehicle_attitude).")
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
def command(path, truth, truth_frame, truth_body, out, seq, radians, yaw_range, max_points):
    """Write PNG figures of an attitude file: Euler angles, errors against --truth, and the gyro bias.

    With --truth, the frames are checked first: the reference frame and body axes that the estimate's file
    records against those of the truth (its metadata, a PX4 log's NED/FRD, or --truth-frame and --truth-body).
    A truth in other frames is re-expressed in the estimate's, and said so; frames that a file does not record
    are refused, not guessed.  A truth at other instants (a log's own estimator) is interpolated onto the
    estimate's rows.

    \b
    Examples:
      strapdown plot flight.integrate.csv
      strapdown plot att.parquet --truth sim.parquet --out figures/
      strapdown plot flight.estimate.csv --truth flight.ulg           # the log's own vehicle_attitude
      strapdown plot att.csv --truth ref.csv --truth-frame ENU --truth-body FLU
      strapdown plot att.csv --euler ZXY --yaw-range signed
    """
    from pathlib import Path

    from .._support.files import scratch_dir
    from ..io import Angles
    from ..io.pipelines.plot import plot_file

    try:
        angles = Angles(seq, not radians, yaw_range)
    except ValueError as exc:
        raise click.BadParameter(str(exc), param_hint="--euler") from None
    folder = Path(out) if out else Path(path).parent
    writable_folder(folder, "--out")  # before the figures are drawn
    try:
        if truth is None:
            written = plot_file(path, None, folder, angles=angles, max_points=max_points)
        else:
            from ..io.pipelines.truth import align_truth, write_aligned

            aligned = align_truth(path, truth, truth_frame=truth_frame, truth_body=truth_body)
            if aligned.note:
                click.echo(f"truth: {aligned.note}", err=True)
            from ..io.readers import input_format
            from ..io.registry import formats

            # a log's own estimate is no table of quaternions: it goes through the aligned copy even when its
            # instants are the estimate's
            is_log = getattr(formats().get(input_format(Path(truth))), "reference", None) is not None
            if not aligned.changed and not is_log:
                written = plot_file(path, truth, folder, angles=angles, max_points=max_points)
            else:
                with scratch_dir(folder / Path(path).name) as scratch:
                    est, ref = write_aligned(aligned, path, truth, scratch)
                    names = (Path(path).name, Path(truth).name)  # the inputs, not the scratch copies
                    written = plot_file(est, ref, folder, angles=angles, max_points=max_points, names=names)
    except (ValueError, OSError, ImportError) as exc:
        # the readers suggest --in-format, which plot does not have: its attitude tables go by their suffix
        raise click.ClickException(
            str(exc).replace("name it with --in-format", "give it one of those suffixes")
        ) from None
    for f in written:
        click.echo(f"written: {f}")
