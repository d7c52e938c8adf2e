"""Restoring a corrupted ``.state`` gives a ValueError naming the entry, never a crash (issue 14).

The kernels index their state arrays without bounds checks: before the checks a short ``bias`` of the
TiltEstimator or a coning position of -5 corrupted the heap (exit 134 or SIGSEGV).  The cases run in a child
interpreter so that such a crash fails the test instead of killing pytest.
"""

import json

import numpy as np
import pytest

from conftest import run_isolated

ESTIMATOR_CASES = r"""
import json, numpy as np
from strapdown.fusion import TiltEstimator, Mahony, Madgwick, Complementary, AttitudeEstimator
g = np.zeros((40, 3)); a = np.tile([0.0, 0.0, 9.81], (40, 1)); m = np.tile([0.0, 20.0, -40.0], (40, 1))
results = []
for cls in (TiltEstimator, Mahony, Madgwick, Complementary, AttitudeEstimator):
    run = (lambda e: e.update(g, a, dt=0.01)) if cls is TiltEstimator else (lambda e: e.update(g, a, m, dt=0.01))
    est = cls(); run(est); good = est.state
    for key, value in good.items():
        if key.startswith("_"):
            continue
        shape = np.shape(value)
        bads = {"None": None, "short": np.zeros(max(int(np.prod(shape)) - 1, 0) or 2),
                "nan": np.full(shape, np.nan), "2d": np.zeros((2, *shape)), "text": "abc"}
        if key.startswith("q"):
            bads["x10"] = np.asarray(value) * 10
            bads["zero"] = np.zeros(shape)
        for what, bad in bads.items():
            st = dict(good); st[key] = bad
            try:
                est.state = st
                run(est)
                results.append([cls.__name__, key, what, "accepted", ""])
            except ValueError as exc:
                results.append([cls.__name__, key, what, "ValueError", str(exc)])
    for drop in ("q", "_use_mag"):
        st = dict(good); del st[drop]
        try:
            est.state = st; results.append([cls.__name__, drop, "missing", "accepted", ""])
        except ValueError as exc:
            results.append([cls.__name__, drop, "missing", "ValueError", str(exc)])
    est.state = good  # the untouched state still restores and runs
    q = run(est).q
    results.append([cls.__name__, "-", "good", "finite" if np.isfinite(q).all() else "nan", ""])
print(json.dumps(results))
"""

INTEGRATOR_CASES = r"""
import json, numpy as np
from strapdown import AttitudeIntegrator
rng = np.random.default_rng(5); g = 0.05 * rng.standard_normal((30, 3))
results = []
def attempt(label, make, corrupt, kw):
    it = make(); it.update(g[:13], **kw); st = it.state; corrupt(st)
    try:
        it.state = st; out = it.update(np.ones((200, 3)), **kw)
        results.append([label, "accepted", bool(np.isfinite(out).all())])
    except ValueError as exc:
        results.append([label, "ValueError", str(exc)])
inc = dict(); rate = dict(dt=0.01)
for method in ("coning3", "coning2", "coning1-prev"):
    mk = lambda method=method: AttitudeIntegrator(method, input="increment")
    for pos in (-5, 2, 7, 1.5, None):  # 13 increments taken: only 13 mod N is valid, and never 2
        attempt(f"{method} pos={pos}", mk, lambda st, pos=pos: st.extra.__setitem__("pos", pos), inc)
    attempt(f"{method} group short", mk, lambda st: st.extra.__setitem__("group", np.zeros((1, 0, 3))), inc)
    attempt(f"{method} alpha nan", mk, lambda st: st.extra.__setitem__("alpha", np.full((1, 3), np.nan)), inc)
    attempt(f"{method} extra missing", mk, lambda st: st.extra.pop("beta"), inc)
mk = lambda: AttitudeIntegrator("rk4")
attempt("rk4 buf_first=99", mk, lambda st: st.extra.__setitem__("buf_first", 99), rate)
attempt("rk4 buf_s short", mk, lambda st: st.extra.__setitem__("buf_s", st.extra["buf_s"][:, :1]), rate)
attempt("rk4 steps_out>steps_in", mk, lambda st: setattr(st, "steps_out", st.steps_in + 5), rate)
attempt("rk4 steps_in=-1", mk, lambda st: setattr(st, "steps_in", -1), rate)
for method in ("exact", "first-order", "dcm"):
    mk = lambda method=method: AttitudeIntegrator(method, q0=[0.9, 0.3, 0.2, 0.1])
    attempt(f"{method} q nan", mk, lambda st: setattr(st, "q", st.q * np.nan), rate)
    attempt(f"{method} q zero", mk, lambda st: setattr(st, "q", st.q * 0), rate)
    attempt(f"{method} q shape", mk, lambda st: setattr(st, "q", np.ones((1, 3))), rate)
    attempt(f"{method} t_end nan", mk, lambda st: setattr(st, "t_end", float("nan")), rate)
    attempt(f"{method} dtype", mk, lambda st: st.extra.__setitem__("dtype", "int8"), rate)
print(json.dumps(results))
"""


def _run(code):
    proc = run_isolated(code)
    assert proc.returncode == 0, f"the child interpreter died (exit {proc.returncode}):\n{proc.stderr[-2000:]}"
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def estimator_results():
    return _run(ESTIMATOR_CASES)


def test_corrupted_estimator_state_is_refused_by_name(estimator_results):
    checked = [r for r in estimator_results if r[2] != "good"]
    assert len(checked) > 150  # every entry of every estimator, several corruptions each
    for cls, key, what, outcome, message in checked:
        assert outcome == "ValueError", (cls, key, what)
        assert f"state[{key!r}]" in message or f"{key!r}" in message, (cls, key, what, message)


def test_untouched_estimator_state_still_runs(estimator_results):
    good = [r for r in estimator_results if r[2] == "good"]
    assert len(good) == 5 and all(r[3] == "finite" for r in good)


def test_non_unit_attitude_in_state_says_what_its_norm_is(estimator_results):
    msgs = {(r[0], r[1]): r[4] for r in estimator_results if r[2] == "x10"}
    assert "unit quaternion, got norm 10" in msgs[("Mahony", "q")]
    zero = {(r[0], r[1]): r[4] for r in estimator_results if r[2] == "zero"}
    assert "got norm 0" in zero[("TiltEstimator", "q_gyro")]


def test_corrupted_integrator_state_is_refused_by_name():
    results = _run(INTEGRATOR_CASES)
    by_label = {r[0]: r for r in results}
    for label, outcome, detail in results:
        assert outcome == "ValueError", (label, outcome, detail)
        assert "state." in detail, (label, detail)
    assert "state.extra['pos']" in by_label["coning3 pos=-5"][2]
    assert "state.steps_out mod 3 = 1, got 2" in by_label["coning3 pos=2"][2]
    assert "state.extra['buf_first']" in by_label["rk4 buf_first=99"][2]
    assert "NaN" in by_label["exact q nan"][2]


def test_valid_integrator_state_round_trips_for_every_method():
    from strapdown import METHODS, AttitudeIntegrator

    g = 0.05 * np.random.default_rng(2).standard_normal((25, 3))
    for method in METHODS:
        for inp in ("rate", "increment"):
            kw = {} if inp == "increment" else {"dt": 0.01}
            whole = AttitudeIntegrator(method, input=inp, q0=[0.9, 0.3, 0.2, 0.1])
            expected = np.concatenate([whole.update(g[:11], **kw), whole.update(g[11:], **kw)])
            first = AttitudeIntegrator(method, input=inp, q0=[0.9, 0.3, 0.2, 0.1])
            head = first.update(g[:11], **kw)
            second = AttitudeIntegrator(method, input=inp, q0=[0.9, 0.3, 0.2, 0.1])
            second.state = first.state
            np.testing.assert_array_equal(np.concatenate([head, second.update(g[11:], **kw)]), expected)


def test_a_state_restored_after_per_step_durations_keeps_the_timing():
    # the scalar-dt anchor of an earlier chunk stayed in the state after a chunk with per-step durations, so a
    # restored integrator timed the next scalar-dt chunk from the stale anchor (7 mrad off for rk4)
    from strapdown import AttitudeIntegrator

    g = 0.1 * np.random.default_rng(0).standard_normal((30, 3))

    def run(restore):
        a = AttitudeIntegrator("rk4")
        out = [a.update(g[:10], 0.01), a.update(g[10:20], np.full(10, 0.02))]
        if restore:
            b = AttitudeIntegrator("rk4")
            b.state = a.state
            a = b
        return np.concatenate([*out, a.update(g[20:], 0.01), a.finish()])

    np.testing.assert_array_equal(run(True), run(False))
