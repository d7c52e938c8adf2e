"""Kernel source rules that keep a cold first call short (issue 30; benchmarks/bench_coldstart.py measures it).

An array-to-array slice assignment (``a[i:j] = b[k:l]``) in a numba kernel makes numba compile its broadcasting
check, whose error message pulls in numba's string formatting: several seconds of compilation, once per cold
process, for one line.  Kernels copy with a loop instead (``fusion._kernels_numba.copy_into``).
"""

import ast
from pathlib import Path

import pytest

import strapdown

KERNELS = sorted(Path(strapdown.__file__).parent.rglob("_*_numba.py"))


def slice_assignments(source: str) -> list[str]:
    """Lines of `source` that assign a non-constant value to a slice of an array."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Assign):
            targets, value = node.targets, node.value
        elif isinstance(node, ast.AugAssign):
            targets, value = [node.target], node.value
        else:
            continue
        scalar = value.operand if isinstance(value, ast.UnaryOp) else value
        if isinstance(scalar, ast.Constant):
            continue  # a scalar fill needs no broadcasting check
        for target in targets:
            for part in target.elts if isinstance(target, ast.Tuple) else [target]:
                if isinstance(part, ast.Subscript) and any(isinstance(n, ast.Slice) for n in ast.walk(part.slice)):
                    found.append(f"line {node.lineno}: {ast.unparse(node)}")
    return found


def test_the_rule_finds_what_it_forbids():
    assert slice_assignments("x[:3] = y[2:5]\nx[0] = y[1]\nx[:] = 0.0\nx[1:], z = y[:2], 1\n") == [
        "line 1: x[:3] = y[2:5]",
        "line 4: x[1:], z = (y[:2], 1)",
    ]


def test_there_are_kernels_to_check():
    names = {p.name for p in KERNELS}
    assert {"_attitude_numba.py", "_tilt_numba.py", "_integrate_numba.py", "_euler_numba.py"} <= names


@pytest.mark.parametrize("path", KERNELS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_kernels_copy_arrays_with_loops(path):
    assert slice_assignments(path.read_text()) == [], f"{path}: copy with a loop (copy_into), not a slice assignment"
