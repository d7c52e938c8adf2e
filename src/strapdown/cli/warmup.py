"""``strapdown warmup``: compile the numba kernels once after an install (:mod:`strapdown.apps.warmup`)."""

from __future__ import annotations

import click

from ..apps.warmup import TASKS


@click.command()
@click.argument("tasks", nargs=-1, metavar="[TASK]...", type=click.Choice([name for name, _ in TASKS]))
@click.option("-q", "--quiet", is_flag=True, help="Print nothing.")
def command(tasks, quiet):
    """Compile the kernels of the common calls now, so that no later call waits for numba to compile.

    numba compiles each kernel at its first call and caches the machine code in a user cache folder, one per
    version of the kernels (~/.cache/strapdown, or STRAPDOWN_CACHE_DIR or NUMBA_CACHE_DIR): the first `strapdown
    estimate` after an install compiles for several seconds and says so, later ones load the cache.  Run this once
    after installing to move that wait here (all tasks: about a minute).
    TASKS: integrate, conversions, estimators, files (default: all); `strapdown estimate` uses estimators,
    conversions and files, `strapdown integrate` integrate and files.

    \b
    Examples:
      strapdown warmup
      strapdown warmup estimators conversions files
    """
    from ..apps.warmup import warmup

    times = warmup(quiet=quiet, tasks=list(tasks) or None)
    if not quiet:
        click.echo(f"{'total':24s} {sum(times.values()):7.2f} s")
