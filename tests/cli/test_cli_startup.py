"""What the ``strapdown`` program does around a command: garbage collection paused while it starts, the exit.

Speed is measured in benchmarks/bench_cli.py; here only what must hold: collection is on again after every
command, and objects are frozen (left out of later collections) only in the program, never in a process that
calls ``main([...])`` and goes on.
"""

import subprocess
import sys

import numpy as np
import pytest

CODE = """
import gc, sys
from strapdown.cli import main
sys.argv = ["strapdown", *{args!r}]
try:
    main({argv})
except SystemExit as exc:
    code = exc.code
print(code or 0, gc.isenabled(), gc.get_freeze_count())
"""


def after(args, as_program: bool):
    """(exit code, collection enabled, objects frozen) once ``main`` returns, in a new process."""
    code = CODE.format(args=list(args), argv="" if as_program else repr(list(args)))
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    status, enabled, frozen = res.stdout.split()[-3:]
    return int(status), enabled == "True", int(frozen)


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    path = tmp_path_factory.mktemp("startup") / "log.csv"
    n = 200
    cols = np.column_stack([np.arange(n) * 0.01, np.zeros((n, 3)), np.tile([0.0, 0.0, 9.81], (n, 1))])
    np.savetxt(path, cols, delimiter=",", header="t,gx,gy,gz,ax,ay,az", comments="", fmt="%.9g")
    return path


def test_the_program_collects_again_after_its_start_and_freezes_what_it_keeps(log):
    status, enabled, frozen = after(["estimate", str(log), "-o", str(log.with_name("a.csv")), "-q"], True)
    assert (status, enabled) == (0, True) and frozen > 0


def test_a_caller_of_main_keeps_its_collection_as_it_was(log):
    status, enabled, frozen = after(["estimate", str(log), "-o", str(log.with_name("b.csv")), "-q"], False)
    assert (status, enabled, frozen) == (0, True, 0)


def test_collection_is_on_again_after_a_command_that_fails(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("t,gx,gy,gz,ax,ay,az\n0,0,0,0,0,0,9.81\n0.01,0,0,x,0,0,9.81\n")
    status, enabled, frozen = after(["estimate", str(bad), "-q"], False)
    assert (status, enabled, frozen) == (1, True, 0)


def test_a_command_without_files_leaves_collection_alone():
    assert after(["--version"], False) == (0, True, 0)
    status, enabled, frozen = after(["--version"], True)
    assert (status, enabled) == (0, True) and frozen > 0  # frozen only at the program's exit
