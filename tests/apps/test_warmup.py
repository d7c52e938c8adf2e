"""The warm-up step (:mod:`strapdown.apps.warmup`, ``strapdown warmup``): which tasks run, and bad task names."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

from strapdown.apps.warmup import TASKS, warmup


def run(*args):
    return subprocess.run([sys.executable, "-m", "strapdown.cli", *args], capture_output=True, text=True, timeout=600)


def test_only_the_tasks_asked_for_run_once_per_dtype():
    times = warmup(dtypes=(np.float64, np.float32), tasks=["conversions"])
    assert set(times) == {"conversions float64", "conversions float32"}
    assert all(t >= 0 for t in times.values())


def test_an_unknown_task_is_named_with_the_known_ones():
    with pytest.raises(ValueError, match=r"'rotations'.*integrate, conversions, estimators"):
        warmup(tasks=["conversions", "rotations"])


def test_the_command_takes_the_tasks_of_the_module():
    res = run("warmup", "--help")
    assert res.returncode == 0, res.stderr
    for name, _ in TASKS:
        assert name in res.stdout
    res = run("warmup", "rotations")
    assert res.returncode == 2 and "'rotations' is not one of" in res.stderr


def test_the_command_runs_a_task_quietly():
    res = run("warmup", "conversions", "-q")
    assert res.returncode == 0, res.stderr
    assert res.stdout == ""


@pytest.mark.parametrize("task", [name for name, _ in TASKS])
def test_every_task_runs(task):
    # each task calls real entry points: a wrong import or a renamed argument shows here, not in `make demo`
    times = warmup(dtypes=(np.float64,), tasks=[task])
    assert list(times) == [f"{task} float64"]


def test_the_warmup_compiles_even_where_short_calls_would_run_uncompiled(tmp_path):
    # a first short call runs its kernel uncompiled (strapdown._support.uncompiled); the warm-up is there to compile
    code = (
        "import json\nfrom strapdown._support.kernel_cache import count_compilations, cached\n"
        "c = count_compilations()\n"
        "from strapdown.apps.warmup import warmup\nimport numpy\nwarmup(dtypes=(numpy.float64,), tasks=['files'])\n"
        "print(json.dumps([c, cached('io/_columns_numba.py', 'quat_euler_columns')]))"
    )
    env = {"STRAPDOWN_CACHE_DIR": str(tmp_path), "STRAPDOWN_UNCOMPILED": "auto", "STRAPDOWN_BACKGROUND_COMPILE": "0"}
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env={**os.environ, **env})
    assert res.returncode == 0, res.stderr
    compiled, cached = json.loads(res.stdout.strip().splitlines()[-1])
    assert "strapdown.io._columns_numba.quat_euler_columns" in compiled and cached
