"""``strapdown batch``: integrate, estimate or convert on many files, in parallel (local cores or Dask)."""

from __future__ import annotations

import importlib

import click

from ._run import Progress

#: The commands a batch runs; each module's ``kwargs`` turns the command's options into its function's arguments.
BATCH_COMMANDS = ("integrate", "estimate", "convert")


@click.command(context_settings={"ignore_unknown_options": True, "allow_interspersed_args": False})
@click.argument("pattern")
@click.argument("command", type=click.Choice(BATCH_COMMANDS))
@click.argument("args", nargs=-1, type=click.UNPROCESSED)
@click.option("--out", type=click.Path(file_okay=False), help="Output folder (default: beside each input).")
@click.option("-j", "--workers", type=int, help="Local processes (default: one per core).")
@click.option("--scheduler", metavar="ADDRESS", help="Dask scheduler, e.g. tcp://10.0.0.5:8786 (dask extra).")
@click.option("--split", type=int, help="integrate only: split each file into this many parts run in parallel.")
@click.option("-q", "--quiet", is_flag=True)
@click.pass_context
def command(ctx, pattern, command, args, out, workers, scheduler, split, quiet):
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
    from ..apps.batch import Job, batch_outputs, check_split, expand, integrate_split, run_batch

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
    from . import load_command

    sub = load_command(command)
    try:
        sub_ctx = sub.make_context(command, [str(files[0]), *args], parent=ctx.parent)
    except click.ClickException as exc:
        raise click.UsageError(f"{command} options: {exc.format_message()}") from None
    params = dict(sub_ctx.params)
    if params.get("output"):
        raise click.UsageError("batch chooses each output's name: use batch --out FOLDER instead of -o")
    kwargs = importlib.import_module(f"strapdown.cli.{command}").kwargs(params)
    fmt = params.get("out_format")
    if split is not None and command != "integrate":
        raise click.UsageError("--split works with integrate only")
    if split is not None and kwargs.get("on_gap", "auto") not in ("auto", "error"):
        raise click.UsageError("--split stops at gaps: leave out --on-gap")
    if split is not None and split < 1:
        raise click.UsageError(f"--split takes a positive number of parts, got {split}")
    try:  # before any file is read: outputs that clash, and a split the method cannot take
        outputs = batch_outputs(files, command, root, out, fmt)
        if split is not None:
            check_split(split, kwargs["method"], kwargs["input"])
    except ValueError as exc:
        raise click.UsageError(str(exc)) from None
    # absolute paths: a Dask worker runs in its own working folder, where relative ones name nothing
    files, outputs = [f.absolute() for f in files], [o.absolute() for o in outputs]
    if split:
        failed = 0
        for f, o in zip(files, outputs, strict=True):
            try:
                report = integrate_split(f, o, parts=split, scheduler=scheduler, workers=workers, **kwargs)
            except (ValueError, OSError, ImportError, RuntimeError) as exc:
                failed += 1
                click.echo(_failed(f, exc), err=True)
                continue
            if not quiet:
                click.echo(f"written: {report.output} ({report.rows} rows, {report.seconds:.2f} s, {split} parts)")
        if failed:
            raise click.ClickException(f"{failed} of {len(files)} files failed")
        return
    jobs = [Job(command, str(f), str(o), kwargs) for f, o in zip(files, outputs, strict=True)]
    bar = Progress(quiet, unit="files")
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
        click.echo(_failed(r.input, r.error), err=True)
    if bad:
        raise click.ClickException(f"{len(bad)} of {len(results)} files failed: {', '.join(r.input for r in bad)}")
    if not quiet:
        click.echo(f"{len(results)} files written", err=True)


def _failed(path, error) -> str:
    """One FAILED line: the file's name once (most messages start with it already)."""
    text = str(error)
    return f"FAILED {text}" if text.startswith(f"{path}: ") else f"FAILED {path}: {text}"
