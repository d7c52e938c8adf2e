"""Every import path of release 0.1 still works after the move to one folder per floor.

``tests/data/api_0.1.json`` lists, module by module, the ``__all__`` of every public module of release 0.1 (the
flat layout, before ``docs/architecture.md``'s floors): the names users could import.  Each must still import from
its old path, and be the very object that its new home defines.
"""

import importlib
import json
from pathlib import Path

import pytest

import strapdown
from strapdown._support.moved import MOVED

BEFORE = json.loads((Path(__file__).parent / "data" / "api_0.1.json").read_text())
CLI = {"strapdown.cli", "strapdown.cli.batch"}  # the command modules keep their paths (tests/test_cli*.py)


@pytest.mark.parametrize("module", sorted(BEFORE))
def test_every_name_of_release_0_1_imports_from_its_old_path(module):
    mod = importlib.import_module(module)
    missing = [name for name in BEFORE[module] if not hasattr(mod, name)]
    assert not missing, f"{module} lost {missing}"


@pytest.mark.parametrize("old", sorted(MOVED))
def test_an_old_module_path_is_the_module_at_its_new_home(old):
    mod = importlib.import_module(old)
    assert mod is importlib.import_module(MOVED[old])
    # importing the old path never replaces a function of the same name on its parent package
    assert strapdown.integrate.__class__.__name__ == "function"
    assert callable(strapdown.fusion.attitude) and not isinstance(strapdown.fusion.attitude, type(mod))


def test_the_old_paths_are_importable_in_a_fresh_interpreter():
    import subprocess
    import sys

    code = (
        "import importlib, strapdown\n"
        "m = importlib.import_module('strapdown.integrate')\n"
        "from strapdown.metrics import rmse\n"
        "from strapdown.fusion.attitude import AttitudeEstimator\n"
        "import strapdown.fusion\n"
        "assert callable(strapdown.integrate) and m.__name__ == 'strapdown.propagate.integrate'\n"
        "assert strapdown.fusion.attitude.__name__ == 'attitude'\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "ok"


def test_the_old_keyword_gyr_still_works_and_says_its_new_name():
    import numpy as np

    from strapdown.calibrate import find_rests
    from strapdown.fusion import Mahony, MahonyParams, mahony

    rng = np.random.default_rng(0)
    gyro, acc = 0.01 * rng.standard_normal((200, 3)), np.tile([0.0, 0.0, 9.81], (200, 1))
    new = mahony(gyro=gyro, acc=acc, dt=0.01).q
    with pytest.warns(DeprecationWarning, match="gyr= is now gyro="):
        old = mahony(gyr=gyro, acc=acc, dt=0.01).q
    np.testing.assert_array_equal(old, new)
    with pytest.warns(DeprecationWarning):
        streamed = Mahony(MahonyParams()).update(gyr=gyro, acc=acc, dt=0.01).q
    np.testing.assert_array_equal(streamed, new)
    with pytest.raises(TypeError, match="both gyr= and gyro="):
        mahony(gyr=gyro, gyro=gyro, acc=acc, dt=0.01)
    with pytest.warns(DeprecationWarning):
        np.testing.assert_array_equal(find_rests(acc, gyr=gyro, fs=100.0), find_rests(acc, gyro=gyro, fs=100.0))
