"""Kernels run uncompiled while numba has not compiled them (strapdown._support.uncompiled): the same numbers as the
compiled kernels, a short first call that compiles nothing, and a background worker that fills the cache."""

import json
import os
import subprocess
import sys

import numba
import numpy as np
import pytest

import strapdown
from strapdown._support import uncompiled
from strapdown.fusion import AttitudeEstimator, Complementary, Madgwick, Mahony, TiltEstimator
from strapdown.io.tables import OutputSpec, attitude_columns
from strapdown.simulate import ImuModel, MagneticDisturbance, RandomMotion, sample


@pytest.fixture
def data():
    d = sample(RandomMotion(12.0, seed=4), 100.0, imu=ImuModel.consumer_mems(), seed=2)
    return d


def _both(monkeypatch, run):
    """run() compiled and uncompiled (every routed kernel as its twin)."""
    monkeypatch.setenv("STRAPDOWN_UNCOMPILED", "never")
    compiled = run()
    monkeypatch.setenv("STRAPDOWN_UNCOMPILED", "always")
    before = uncompiled.fallbacks[0]
    twin = run()
    assert uncompiled.fallbacks[0] == before  # the twin itself ran, it did not hand over to the compiled kernel
    return compiled, twin


def _same_estimate(a, b):
    # numba may contract a * b + c into one rounding (fastmath "contract"): the last bits only
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-13)
    np.testing.assert_array_equal(a.flags, b.flags)
    if a.bias is not None:
        np.testing.assert_allclose(a.bias, b.bias, rtol=0, atol=1e-13)


def _clipped(gyro, limit):
    return np.clip(gyro, -limit, limit)


CASES = {
    "6D": lambda d: AttitudeEstimator().update(d.gyro, d.acc, t=d.t[1:]),
    "9D": lambda d: AttitudeEstimator().update(d.gyro, d.acc, d.mag, t=d.t[1:]),
    "9D float32": lambda d: AttitudeEstimator().update(
        d.gyro.astype(np.float32), d.acc.astype(np.float32), d.mag.astype(np.float32), t=d.t[1:]
    ),
    # a 0.3 s gap (rows dropped) and a gyro clipped at 0.5 rad/s (saturation bridged, flagged)
    "9D gap": lambda d: AttitudeEstimator().update(
        np.delete(d.gyro, np.s_[300:330], 0), np.delete(d.acc, np.s_[300:330], 0), t=np.delete(d.t[1:], np.s_[300:330])
    ),
    "6D clipped gyro": lambda d: AttitudeEstimator({"gyro_range": 0.5}).update(_clipped(d.gyro, 0.5), d.acc, t=d.t[1:]),
    "tilt": lambda d: TiltEstimator().update(d.gyro, d.acc, t=d.t[1:]),
    "mahony 9D": lambda d: Mahony().update(d.gyro, d.acc, d.mag, t=d.t[1:]),
    "madgwick 9D": lambda d: Madgwick().update(d.gyro, d.acc, d.mag, t=d.t[1:]),
    "complementary 9D": lambda d: Complementary().update(d.gyro, d.acc, d.mag, t=d.t[1:]),
}


@pytest.mark.parametrize("case", list(CASES))
def test_an_uncompiled_estimator_gives_the_compiled_numbers(monkeypatch, data, case):
    compiled, twin = _both(monkeypatch, lambda: CASES[case](data))
    _same_estimate(compiled, twin)


def test_an_uncompiled_estimator_continues_in_chunks_as_the_compiled_one(monkeypatch, data):
    magnet = MagneticDisturbance(4.0, 6.0, (30.0, 0.0, 0.0), frame="body")
    d = sample(RandomMotion(12.0, seed=5), 100.0, imu=ImuModel.consumer_mems(), seed=3, disturbances=[magnet])

    def chunks():
        f = AttitudeEstimator()
        pieces = ((0, 500), (500, 1200))
        parts = [f.update(d.gyro[a:b], d.acc[a:b], d.mag[a:b], t=d.t[1 + a : 1 + b]) for a, b in pieces]
        return np.concatenate([p.q for p in parts]), f.state

    (q_c, state_c), (q_t, state_t) = _both(monkeypatch, chunks)
    np.testing.assert_allclose(q_c, q_t, rtol=0, atol=1e-13)
    for key, value in state_c.items():  # the state a later chunk starts from is the same too
        if isinstance(value, str):
            assert state_t[key] == value
        else:
            np.testing.assert_allclose(np.asarray(state_t[key], float), np.asarray(value, float), rtol=0, atol=1e-12)


@pytest.mark.parametrize("method", ["exact", "first-order"])
def test_uncompiled_integration_gives_the_compiled_numbers(monkeypatch, data, method):
    compiled, twin = _both(monkeypatch, lambda: strapdown.integrate(data.gyro, 0.01, method=method, parallel=False))
    np.testing.assert_allclose(compiled, twin, rtol=0, atol=1e-14)


def test_uncompiled_conversions_and_columns_give_the_compiled_numbers(monkeypatch):
    q = strapdown.from_rotvec(np.random.default_rng(7).standard_normal((500, 3)))
    for run in (
        lambda: strapdown.multiply(q, q[::-1]),
        lambda: strapdown.from_matrix(strapdown.as_matrix(q)),
        lambda: strapdown.as_euler(q, "ZYX", degrees=True),
        lambda: strapdown.from_euler(strapdown.as_euler(q, "zxz"), "zxz"),
        lambda: attitude_columns(np.arange(500.0), q, OutputSpec(), check=False),
    ):
        compiled, twin = _both(monkeypatch, run)
        if isinstance(compiled, dict):
            assert compiled.keys() == twin.keys()
            for key in compiled:
                np.testing.assert_allclose(np.asarray(compiled[key]), np.asarray(twin[key]), rtol=0, atol=1e-12)
        else:
            np.testing.assert_allclose(compiled, twin, rtol=0, atol=1e-15)


# --- the choice and the hand-over -----------------------------------------------------------------------------


@numba.njit(error_model="numpy")
def _accumulate_then_divide(v, out):
    for i in range(v.shape[0]):
        out[i] += v[i]
    zero = 0
    return 1.0 / zero  # numba (numpy error model): inf; Python: ZeroDivisionError


@numba.njit
def _double(v, out):
    for i in range(v.shape[0]):
        out[i] = 2.0 * v[i]


def test_where_python_raises_the_compiled_kernel_answers_on_the_restored_arrays(monkeypatch):
    monkeypatch.setenv("STRAPDOWN_UNCOMPILED", "always")
    v, out = np.arange(5.0), np.ones(5)
    before = uncompiled.fallbacks[0]
    assert uncompiled.call(_accumulate_then_divide, v, out, python_seconds=0.0) == np.inf
    assert uncompiled.fallbacks[0] == before + 1
    np.testing.assert_array_equal(out, 1.0 + v)  # once: the twin's half-done writes were undone first


def test_a_short_call_runs_uncompiled_and_a_long_one_compiles(monkeypatch):
    monkeypatch.setenv("STRAPDOWN_UNCOMPILED", "auto")
    monkeypatch.setenv("STRAPDOWN_BACKGROUND_COMPILE", "0")
    v, out = np.arange(4.0), np.empty(4)
    kernel = numba.njit(_double.py_func)  # a kernel of its own, compiled for nothing yet
    uncompiled.call(kernel, v, out, python_seconds=0.5 * uncompiled.BUDGET_S)
    assert kernel.signatures == [] and list(out) == [0.0, 2.0, 4.0, 6.0]
    uncompiled.call(kernel, v, -out, python_seconds=2.0 * uncompiled.BUDGET_S)
    assert len(kernel.signatures) == 1
    monkeypatch.setenv("STRAPDOWN_UNCOMPILED", "never")
    other = numba.njit(_double.py_func)
    uncompiled.call(other, v, out, python_seconds=0.0)
    assert len(other.signatures) == 1


# --- on an empty cache, in new processes --------------------------------------------------------------------------

CHILD = r"""
import json, sys
import numpy as np
from strapdown._support.kernel_cache import count_compilations
compiled = count_compilations()
from strapdown._support import uncompiled
from strapdown.fusion import AttitudeEstimator
d = np.load(sys.argv[1])
est = AttitudeEstimator().update(d["gyro"], d["acc"], dt=0.01)
np.save(sys.argv[2], est.q)
waited = uncompiled.wait_for_background(300.0)
print(json.dumps({"compiled": compiled, "waited": waited}))
"""


def _child(tmp_path, cache, out, **env):
    env = dict(os.environ, STRAPDOWN_CACHE_DIR=str(cache), NUMBA_CACHE_DIR="", **env)
    env.pop("NUMBA_CACHE_DIR")  # the cache folder is STRAPDOWN_CACHE_DIR's
    args = [sys.executable, "-c", CHILD, str(tmp_path / "in.npz"), str(out)]
    done = subprocess.run(args, env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_a_first_update_on_an_empty_cache_compiles_nothing_and_the_worker_fills_the_cache(tmp_path, data):
    np.savez(tmp_path / "in.npz", gyro=data.gyro[:1000], acc=data.acc[:1000])
    compiled = AttitudeEstimator().update(data.gyro[:1000], data.acc[:1000], dt=0.01).q
    cache = tmp_path / "cache"
    on = {"STRAPDOWN_UNCOMPILED": "auto", "STRAPDOWN_BACKGROUND_COMPILE": "1"}
    first = _child(tmp_path, cache, tmp_path / "first.npy", **on)
    assert first["compiled"] == []  # no kernel compiled in the call's process ...
    np.testing.assert_allclose(np.load(tmp_path / "first.npy"), compiled, rtol=0, atol=1e-13)  # ... same numbers
    assert first["waited"]
    # the worker compiled them meanwhile: a later process finds them, compiles nothing, runs the compiled kernel
    second = _child(tmp_path, cache, tmp_path / "second.npy", STRAPDOWN_UNCOMPILED="never")
    assert second["compiled"] == []
    np.testing.assert_allclose(np.load(tmp_path / "second.npy"), compiled, rtol=0, atol=1e-13)


def test_a_mistyped_mode_is_named(monkeypatch):
    monkeypatch.setenv("STRAPDOWN_UNCOMPILED", "off")
    with pytest.raises(ValueError, match=r"STRAPDOWN_UNCOMPILED must be one of auto, never, always; .* 'off'"):
        uncompiled.call(_double, np.zeros(1), np.zeros(1), python_seconds=0.0)


def test_the_scan_build_a_call_did_not_run_is_compiled_for_the_next_process(tmp_path):
    # the thread policy picks the serial or the parallel scan by the load of the moment: a second process at
    # another load compiled the other build (5 kernels, 6 s) before the worker was given it too
    code = (
        "import json, numpy as np, strapdown\nfrom strapdown._support import kernel_cache, uncompiled\n"
        "strapdown.integrate(np.zeros((40000, 3)), 0.01, threads=1)\nuncompiled.wait_for_background(300.0)\n"
        "print(json.dumps([kernel_cache.cached('propagate/_integrate_numba.py', k) for k in ('scan_serial', 'scan')]))"
    )
    env = {**os.environ, "STRAPDOWN_CACHE_DIR": str(tmp_path), "STRAPDOWN_BACKGROUND_COMPILE": "1"}
    env.pop("NUMBA_CACHE_DIR", None)
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert json.loads(done.stdout.strip().splitlines()[-1]) == [True, True]
