"""What the ``strapdown`` program does around a command: the exit it takes, and what it leaves alone."""

import subprocess
import sys

CODE = """
import gc, sys
from strapdown.cli import main
sys.argv = ["strapdown", "--version"]
try:
    main({argv})
except SystemExit as exc:
    assert not exc.code, exc.code
print(gc.get_freeze_count())
"""


def frozen_after(argv: str) -> int:
    res = subprocess.run([sys.executable, "-c", CODE.format(argv=argv)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    return int(res.stdout.split()[-1])


def test_the_program_leaves_its_objects_out_of_the_last_collection():
    # main() as the program (sys.argv): what is alive at the end is frozen, the interpreter's exit skips it
    assert frozen_after("") > 0


def test_a_caller_of_main_with_arguments_keeps_its_garbage_collection():
    # main([...]) inside a process that goes on: nothing frozen, every later collection as before
    assert frozen_after("['--version']") == 0
