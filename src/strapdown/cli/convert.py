"""``strapdown convert``: attitudes between representations, typed numbers or file columns."""

from __future__ import annotations

import click

from ._options import CHUNK_ROWS, FORMATS, is_number, representations
from ._run import run_file


@click.command(context_settings={"ignore_unknown_options": True})
@click.argument("args", nargs=-1, type=click.UNPROCESSED, metavar="[INPUT | VALUES...]")
@click.option("-o", "--output", type=click.Path(dir_okay=False), help="Output file (file mode).")
@click.option("--from", "source", type=click.Choice(list(representations())), default="quat", show_default=True)
@click.option(
    "--to", "target", type=click.Choice([*representations(), "all"]), help="Default: all (values), euler (files)."
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
@click.option("--in-format", type=click.Choice(FORMATS))
@click.option("--format", "out_format", type=click.Choice(FORMATS))
@click.option("--chunk-rows", default=CHUNK_ROWS, show_default=True)
@click.option("-q", "--quiet", is_flag=True)
def command(args, **p):
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
    if len(args) == 1 and not is_number(args[0]):
        from pathlib import Path

        from ..io import convert_file

        if not Path(args[0]).is_file():
            raise click.BadParameter(f"no such file: {args[0]}", param_hint="INPUT")
        run_file(convert_file, args[0], p.get("output"), kwargs(p), p["quiet"])
        return
    _convert_values(args, p)


def _angles_in_out(p: dict):
    import click

    from ..io import Angles

    try:
        base = Angles(p.get("seq") or "ZYX", degrees=bool(p.get("degrees")), yaw_range=p.get("yaw_range"))
        base = Angles(base.seq, base.degrees, base.yaw_range, p.get("gibbs") or "gajda")
        out = Angles(p.get("to_seq") or base.seq, base.degrees, base.yaw_range, base.gibbs)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from None
    return base, out


def kwargs(p: dict) -> dict:
    """The keyword arguments of :func:`strapdown.io.convert_file` from the parsed options (also for batch)."""
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
        "chunk_rows": CHUNK_ROWS if p.get("chunk_rows") is None else p["chunk_rows"],
        "unit_from_names": p.get("degrees") is None,  # yaw_deg columns are degrees unless told otherwise
    }


def _convert_values(args, p: dict) -> None:
    """Convert numbers from the command line: print the target representation(s), one per line."""
    import click
    import numpy as np

    from ..io.pipelines.convert import RowError, convert_values
    from ..io.tables import REPRESENTATIONS, column_names

    bad = [a for a in args if not is_number(a)]
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
    except RowError as exc:
        raise click.UsageError(f"the numbers {' '.join(args)} hold {exc.problem}") from None
    except ValueError as exc:
        raise click.ClickException(str(exc)) from None
    for t, v in results.items():
        numbers = " ".join(repr(float(x)) for x in v)
        if len(targets) == 1:
            click.echo(numbers)
        else:
            names = ",".join(column_names(t, angles_out))
            click.echo(f"{t:13} {numbers}    ({names})")
