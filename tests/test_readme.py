"""The README's example runs and prints what its comments say."""

import contextlib
import io
import re
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_example_runs_and_matches_its_comments():
    text = README.read_text(encoding="utf-8")
    block = re.search(r"## Ten lines\s+```python\n(.*?)```", text, re.S).group(1)
    assert len(block.strip().splitlines()) <= 11
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(block, str(README), "exec"), {})
    lines = out.getvalue().splitlines()
    np.testing.assert_allclose(np.array(lines[0].strip("[]").split(), dtype=float), [30, 10, 90], atol=1e-9)
    vertical = np.array(lines[1].strip("[]").split(), dtype=float)
    assert np.isfinite(vertical).all() and vertical[1] == 90 and vertical[2] == 0


def test_every_self_contained_readme_block_runs():
    """Blocks that start with an import are complete programs; the others are fragments of one."""
    text = README.read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    complete = [b for b in blocks if b.lstrip().startswith(("import", "from"))]
    assert len(complete) >= 2
    for block in complete:
        with contextlib.redirect_stdout(io.StringIO()):
            exec(compile(block, str(README), "exec"), {})
