"""strapdown's numba cache (strapdown._support.kernel_cache): one folder per version of all the kernels, reused by
later processes, never mixing kernels of two versions, and the command line's notice before a first compile."""

import json
import os
import shutil
import subprocess
import sys

import pytest

from strapdown._support import kernel_cache

# A child compiles (or loads) the integrator's sequential loop and says how many strapdown kernels numba compiled.
CHILD = r"""
import json
from strapdown._support.kernel_cache import count_compilations
compiled = count_compilations()
import numpy as np, strapdown
from strapdown._support import kernel_cache
strapdown.integrate(np.zeros((10, 3)), 0.01, parallel=False)
print(json.dumps({"compiled": compiled, "folder": str(kernel_cache.folder()),
                  "cached": kernel_cache.cached("propagate/_integrate_numba.py", "sequential")}))
"""


def _child(cache, code=CHILD):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_a_second_process_loads_what_the_first_compiled(tmp_path):
    first = _child(tmp_path)
    assert "strapdown.propagate._integrate_numba.sequential" in first["compiled"]
    assert first["cached"] and first["folder"].startswith(str(tmp_path))
    second = _child(tmp_path)
    assert second["compiled"] == [] and second["cached"]


def test_the_cache_is_one_folder_per_version_of_all_kernels(tmp_path, monkeypatch):
    # a copy of the package whose kernels differ in one byte has another version, so nothing compiled for one
    # is loaded for the other (numba alone checks only the file that holds the kernel, not the kernels it calls)
    copy = tmp_path / "strapdown"
    shutil.copytree(kernel_cache.PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(kernel_cache, "PACKAGE", copy)
    same = kernel_cache._version()
    assert same == kernel_cache.VERSION
    kernel = copy / "rotations" / "_quaternion_numba.py"
    kernel.write_text(kernel.read_text() + "\n# a changed callee\n")
    assert kernel_cache._version() != same
    (copy / "rotations" / "quaternion.py").write_text("# not a kernel file\n")
    kernel.write_text(kernel.read_text().replace("\n# a changed callee\n", ""))
    assert kernel_cache._version() == same  # only the kernel files name the version


def test_only_strapdown_kernels_use_its_folder(tmp_path):
    def outside():
        return 1

    assert kernel_cache.KernelLocator.from_function(outside, __file__) is None
    from strapdown.rotations import _quaternion_numba as k

    loc = kernel_cache.KernelLocator.from_function(k.qmul.py_func, k.__file__)
    assert loc is not None and loc.get_cache_path().startswith(str(kernel_cache.folder()))
    assert loc.get_source_stamp() == kernel_cache.VERSION


def test_the_notice_names_what_a_first_run_compiles(tmp_path, monkeypatch):
    from strapdown.apps.warmup import FIRST_RUN, compiling_notice

    monkeypatch.setattr(kernel_cache, "folder", lambda: tmp_path / "empty")
    notice = compiling_notice(["estimator:attitude", "files"])
    assert notice.startswith("compiling the attitude estimator and the output columns for this machine, once")
    assert "in the background while a short input runs uncompiled" in notice
    assert f"about {FIRST_RUN['estimator:attitude'][2] + FIRST_RUN['files'][2]} s" in notice
    # once the kernels are in the folder, nothing is said
    for module, function in FIRST_RUN["estimator:attitude"][1] + FIRST_RUN["files"][1]:
        where = tmp_path / "empty" / os.path.dirname(module)
        where.mkdir(parents=True, exist_ok=True)
        (where / f"{os.path.basename(module)[:-3]}.{function}-12.py311.nbi").write_bytes(b"")
    assert compiling_notice(["estimator:attitude", "files"]) is None


@pytest.mark.parametrize("key", ["estimator:attitude", "estimator:tilt", "integrate", "files"])
def test_every_kernel_named_for_a_first_run_exists(key):
    import importlib

    for module, function in __import__("strapdown.apps.warmup", fromlist=["FIRST_RUN"]).FIRST_RUN[key][1]:
        name = "strapdown." + module[:-3].replace("/", ".")
        assert hasattr(importlib.import_module(name), function)
