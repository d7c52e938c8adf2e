"""Running one file command on the command line: its progress bar, its summary, bad input as one line (private)."""

from __future__ import annotations

import sys

from ._options import writable_file


class Progress:
    """A tqdm bar on stderr that appears after a second, only on a terminal; a callable (done, total).

    ``started``, when given, is called once, at the first report (the first chunk is through).
    """

    def __init__(self, quiet: bool, unit: str = "rows", started=None):
        self.quiet = quiet
        self.unit = unit
        self.bar = None
        self.started = started

    def __call__(self, done: int, total: int | None) -> None:
        if self.started is not None:
            self.started, started = None, self.started
            started()
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


class PausedCollection:
    """CPython's garbage collector paused while a file command starts, and resumed after its first chunk.

    Starting imports numba and loads its kernels: some 10^5 objects that live to the end, over which the
    collector meanwhile runs full passes (0.1-0.2 s of a 200-row ``strapdown estimate`` on the 2-core machine,
    by gc.callbacks), finding nothing to free.  :meth:`resume` (at the first progress report, or when the
    command ends) first freezes what exists when the process is the ``strapdown`` program (``gc.freeze``:
    those objects are left out of later collections; they live until the process ends), then turns
    collection back on as it was: a long file is collected as usual from its second chunk on.
    """

    def __init__(self):
        import gc

        self._was_enabled = gc.isenabled()
        self._paused = True
        gc.disable()

    def resume(self) -> None:
        """Collect again (once; later calls do nothing)."""
        import gc

        if not self._paused:
            return
        self._paused = False
        if sys.modules["strapdown.cli"].RUNNING_AS_PROGRAM:
            gc.freeze()
        if self._was_enabled:
            gc.enable()


def run_file(function, path, output, kwargs: dict, quiet: bool) -> None:
    """Run one file command: progress bar, summary line, and bad input as a one-line error (exit 1)."""
    import click

    if output:
        writable_file(output, "-o/--output")  # before reading: not a hidden temp's name after the whole run
    collector = PausedCollection()
    bar = Progress(quiet, started=collector.resume)
    try:
        report = function(path, output, progress=bar, **kwargs)
    except (ValueError, OSError, ImportError, RuntimeError) as exc:
        bar.close()
        raise click.ClickException(str(exc)) from None
    finally:
        collector.resume()
    bar.close()
    if not quiet and report.read:
        click.echo(f"read: {report.read}", err=True)
    for note in report.notes:
        if not quiet or note.startswith("warning:"):  # a warning is said even with -q
            click.echo(note, err=True)
    if not quiet:
        outputs = getattr(report, "outputs", None) or [report.output]
        more = f" in {len(outputs)} files: {', '.join(map(str, outputs))}" if len(outputs) > 1 else ""
        click.echo(f"written: {report.output} ({report.rows} rows{more}, {report.seconds:.2f} s)")


def say_compiling(needs, quiet: bool) -> None:
    """Say on stderr, once, that this run compiles kernels for this machine (strapdown.apps.warmup.FIRST_RUN)."""
    if quiet:
        return
    import click

    from ..apps.warmup import compiling_notice

    notice = compiling_notice(needs)
    if notice:
        click.echo(notice, err=True)
