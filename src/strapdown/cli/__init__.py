"""The ``strapdown`` command line (click, from the ``cli`` extra): one module per command, loaded when it runs.

Library commands: ``demo``, ``compare``, ``evaluate``, and ``warmup`` (compile the kernels once after an
install).  File commands (the ``io`` extra): ``integrate``, ``estimate``, ``convert``, ``simulate``, ``plot``,
``report`` (an interactive HTML page, the ``report`` extra), and ``batch`` to run ``integrate``, ``estimate`` or
``convert`` on many files at once (local cores or a Dask cluster) or one integration split across workers.

Each command lives in its own module of this package (``strapdown.cli.estimate`` ...), which defines a click
command named ``command``; :data:`COMMANDS` lists them with their one-line help.  The group imports a command's
module only when that command runs or prints its own help, so ``strapdown --help`` imports neither numba nor
pyarrow nor any command's dependencies.  To add a command: write ``strapdown/cli/<name>.py`` with a click command
``command`` and add one line to :data:`COMMANDS` (see ``docs/guide/command-line.md``).
"""

from __future__ import annotations

import importlib
import sys

#: Command name -> (module that defines ``command``, one-line help shown by ``strapdown --help``).
COMMANDS: dict[str, tuple[str, str]] = {
    "batch": ("strapdown.cli.batch", "Run integrate, estimate or convert on many files at once."),
    "calibrate": ("strapdown.cli.calibrate", "Fit sensor calibrations (mag, acc, gyro) and read the Allan curve."),
    "compare": ("strapdown.cli.compare", "Run every propagation method on a simulated scenario."),
    "convert": ("strapdown.cli.convert", "Convert attitudes between representations: numbers or files."),
    "demo": ("strapdown.cli.demo", "Print the worked examples and write plots and a CSV to OUT."),
    "estimate": ("strapdown.cli.estimate", "Run a fusion filter over INPUT: attitudes, bias and flags."),
    "evaluate": ("strapdown.cli.evaluate", "Run an estimator over the BROAD trials in FOLDER."),
    "integrate": ("strapdown.cli.integrate", "Integrate the gyro readings of INPUT into attitudes."),
    "plot": ("strapdown.cli.plot", "Write PNG figures of an attitude file."),
    "report": ("strapdown.cli.report", "Write an interactive HTML report of INPUT: plots, 3D view, errors."),
    "simulate": ("strapdown.cli.simulate", "Write a simulated IMU log to OUTPUT."),
    "warmup": ("strapdown.cli.warmup", "Compile the numba kernels once after an install."),
}

_EPILOG = """\b
Examples:
  strapdown integrate flight.csv --gyro-unit deg/s          # -> flight.integrate.csv
  strapdown estimate Gyroscope.csv Accelerometer.csv Magnetometer.csv --body FLU
  strapdown estimate log.parquet -e tilt --frame ned -o att.parquet
  strapdown convert --from euler --seq ZYX --degrees 10 20 30 --to quat
  strapdown simulate sim.parquet --scenario aerobatic-show --imu consumer
  strapdown plot att.parquet --truth sim.parquet
  strapdown report flight.ulg -o flight.html --open
  strapdown batch 'logs/**/*.parquet' estimate -e mahony --out results/
  strapdown demo
  strapdown compare --scenario hammerhead-loop
  strapdown evaluate path/to/broad/data_mat --estimator tilt
  strapdown warmup                                            # once after installing
  strapdown --version
"""


def load_command(name: str):
    """The click command ``name`` of :data:`COMMANDS`, importing its module (None for an unknown name)."""
    entry = COMMANDS.get(name)
    if entry is None:
        return None
    return importlib.import_module(entry[0]).command


def _build():
    """The ``strapdown`` click group; its commands are imported when first used."""
    import click

    class LazyGroup(click.Group):
        """A group whose commands are modules imported on demand (their help lines come from COMMANDS)."""

        def list_commands(self, ctx):
            return sorted(COMMANDS)

        def get_command(self, ctx, cmd_name):
            return load_command(cmd_name)

        def format_commands(self, ctx, formatter):
            # the listing must not import every command (and through them numpy, numba, pyarrow)
            rows = [(name, COMMANDS[name][1]) for name in self.list_commands(ctx)]
            with formatter.section("Commands"):
                formatter.write_dl(rows)

    @click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]}, epilog=_EPILOG)
    @click.version_option(_version(), prog_name="strapdown")
    def cli():
        """Quaternion attitude determination from gyroscope, accelerometer and magnetometer data."""

    return cli


def _version() -> str:
    # the package's version without importing the package's modules (the parent package is imported anyway)
    return sys.modules["strapdown"].__version__


#: Whether this process is the ``strapdown`` program (:func:`main` without arguments), which ends with its command.
RUNNING_AS_PROGRAM = False


def main(argv=None):
    """Entry point of the ``strapdown`` command.

    Parameters
    ----------
    argv : list of str, optional
        The arguments; by default the program's own (``sys.argv``), and then the process ends with the command.
    """
    try:
        cli = _build()
    except ModuleNotFoundError as exc:
        if exc.name != "click":
            raise
        sys.stderr.write("the strapdown command line needs click: pip install 'strapdown[cli]'\n")
        return 2
    global RUNNING_AS_PROGRAM
    RUNNING_AS_PROGRAM = argv is None
    try:
        return cli.main(args=argv, prog_name="strapdown")
    finally:
        if argv is None:
            _before_exit()


def _before_exit() -> None:
    """Leave what is alive now out of the interpreter's last garbage collection, just before the process ends.

    At exit CPython collects once more over every object still tracked, and after a numba kernel has been
    loaded those are numba's and llvmlite's type registries and compiler objects: 0.15-0.27 s of a 1 s
    ``strapdown estimate`` on the 2-core machine (``benchmarks/bench_cli.py``), to free memory the operating
    system takes back anyway.  :func:`gc.freeze` moves them out of that collection's reach.  The command has
    finished: its files are closed by their context managers, and atexit handlers still run.  Only when the
    process is the ``strapdown`` program (``argv`` not given), never for a caller running ``main([...])``
    in a process that goes on.
    """
    import gc

    gc.freeze()
