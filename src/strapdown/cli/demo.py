"""``strapdown demo``: the worked examples, printed, with plots and a CSV."""

from __future__ import annotations

import click

from ._options import writable_folder


@click.command()
@click.option("--out", default="out", show_default=True, type=click.Path(file_okay=False), help="Output directory.")
def command(out):
    """Print the worked examples and write plots and a CSV to OUT.

    Gajda's algorithm on a 360 deg roll, his conclusions tested on a hammerhead + loop, and an aerobatic
    show flown with a consumer MEMS IMU and integrated by every method, then fused; the show as a log file
    and its interactive report (an HTML page), whose path it prints last.

    \b
    Examples:
      strapdown demo
      strapdown demo --out /tmp/strapdown-demo
    """
    from ..apps.demo import run

    writable_folder(out, "--out")  # before the computation, not after it
    try:
        run(out, echo=click.echo)
    except OSError as exc:  # a full disk: checked writable, still not written
        raise click.ClickException(f"cannot write into {out}: {exc}") from None
