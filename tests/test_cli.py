"""The command line and the package as a newcomer meets them: run as subprocesses."""

import subprocess
import sys

import numpy as np
import pytest


def run(*args):
    return subprocess.run([sys.executable, "-m", "strapdown.cli", *args], capture_output=True, text=True, timeout=120)


def test_demo_prints_gajda_roll_every_45_degrees():
    res = run("demo")
    assert res.returncode == 0, res.stderr
    rows = [line.split() for line in res.stdout.splitlines() if line[:6].strip().replace(".", "").isdigit()]
    assert len(rows) == 9
    table = np.array([[float(x) for x in row] for row in rows])
    t, q, ypr, err = table[:, 0], table[:, 1:5], table[:, 5:8], table[:, 9]
    # closed form of a roll at 90°/s from yaw 30°, pitch 10°: yaw and pitch stay, roll steps by 45°
    np.testing.assert_allclose(t, np.arange(9) * 0.5)
    np.testing.assert_allclose(ypr[:, 0], 30.0)
    np.testing.assert_allclose(ypr[:, 1], 10.0)
    np.testing.assert_allclose(ypr[:, 2], [0, 45, 90, 135, 180, -135, -90, -45, 0])
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1, atol=1e-6)
    np.testing.assert_allclose(q[-1], -q[0], atol=1e-7)  # 360° flips the quaternion's sign
    assert err.max() < 1e-12


def test_demo_rejects_bad_rate():
    res = run("demo", "--roll-rate", "-5")
    assert res.returncode != 0
    assert "--roll-rate" in res.stderr


def test_version_and_help():
    from strapdown import __version__

    res = run("--version")
    assert res.returncode == 0 and __version__ in res.stdout
    res = run("demo", "--help")
    assert res.returncode == 0 and "Examples" in res.stdout


def test_import_is_fast_and_compiles_nothing():
    code = "import sys, strapdown; assert 'numba' not in sys.modules, 'numba imported at package import'"
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr


@pytest.mark.parametrize(
    "module", ["quaternion", "euler", "matrix", "rotvec", "compressed", "frames", "cayley_klein", "interop", "demo"]
)
def test_public_functions_have_examples(module):
    import importlib

    mod = importlib.import_module(f"strapdown.{module}")
    for name in getattr(mod, "__all__", ["gajda_roll", "format_roll_demo"]):
        obj = getattr(mod, name)
        if callable(obj):
            doc = obj.__doc__ or ""
            assert "Examples" in doc and ">>>" in doc, f"{module}.{name} has no example"
            assert "Parameters" in doc and "Returns" in doc, f"{module}.{name} lacks numpy-style sections"
