"""The ``strapdown`` command line (click, from the ``cli`` extra).

Only ``demo`` exists so far; file commands come with the I/O work.
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
          strapdown --version
        """

    @cli.command()
    @click.option("--roll-rate", default=90.0, show_default=True, help="Roll rate of the example, deg/s.")
    def demo(roll_rate):
        r"""Print worked examples: Gajda's algorithm on a 360 deg roll.

        \b
        Examples:
          strapdown demo
          strapdown demo --roll-rate 30
        """
        if not roll_rate > 0:
            raise click.BadParameter("must be positive", param_hint="--roll-rate")
        from .demo import format_roll_demo, gajda_roll

        click.echo(format_roll_demo(gajda_roll(roll_rate_deg_s=roll_rate), roll_rate))

    return cli


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
