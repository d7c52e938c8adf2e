"""Fusion filters: throughput against vqf, accuracy on BROAD, and the simulated bias study of issue 5.

    python benchmarks/bench_estimators.py [--n 1000000] [--repeat 5] [--broad DIR] [--json results.json]

Throughput: each filter on the same n samples (a random smooth motion sampled at 100 Hz, 6D and 9D), batch call,
best of --repeat; the reference is vqf.VQF.updateBatch (C++) on the same arrays in the same run.  Ratios are vqf
time / our time, so > 1 means faster than vqf.

BROAD (CC BY 4.0; Laidig et al. 2021), when the folder exists: the TiltEstimator's per-group table (6D, one
parameter set), the classic filters and vqf on the same protocol, and the reproduction of BROAD's published
Madgwick results (beta = 0.12, started as BROAD's example starts it) with both Madgwick variants, per trial.

Bias study: the patent's platform (strapdown.simulate.RockingPlatform) with a 1°/s gyro bias on every axis, ideal
sensors otherwise: the time after which both horizontal bias components stay within 1 % of the truth, and the
vertical component, rocking in place and driving (with and without the known kinematic acceleration).
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
from pathlib import Path

import numba
import numpy as np

import strapdown
from _timing import best_time
from strapdown.evaluate.evaluation import evaluate
from strapdown.fusion import TiltParams, complementary, madgwick, mahony, tilt

BROAD = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "broad"
FILTERS = {"TiltEstimator": tilt, "Mahony": mahony, "Madgwick": madgwick, "Complementary": complementary}


def inputs(n: int):
    """n samples of a random smooth motion at 100 Hz with consumer-grade errors (ENU/FLU)."""
    from strapdown.simulate import ImuModel, RandomMotion, sample

    data = sample(
        RandomMotion(duration=n / 100.0, seed=1),
        100.0,
        gyro="rate",
        imu=ImuModel.consumer_mems(),
        reference="ENU",
        body="FLU",
    )
    return [np.ascontiguousarray(x[:n]) for x in (data.gyro, data.acc, data.mag)]


def throughput(n: int, repeat: int) -> dict:
    gyr, acc, mag = inputs(n)
    dt = 0.01
    rows = {}
    try:
        from vqf import VQF

        rows["vqf 6D"] = best_time(lambda: VQF(dt).updateBatch(gyr, acc), repeat)
        rows["vqf 9D"] = best_time(lambda: VQF(dt).updateBatch(gyr, acc, mag), repeat)
    except ImportError:
        print("vqf is not installed (pip install 'strapdown[bench]'): no reference", file=sys.stderr)
    for name, f in FILTERS.items():
        f(gyr[:10], acc[:10], dt=dt)  # compile (or load the cache) outside the timing
        rows[f"{name} 6D"] = best_time(lambda f=f: f(gyr, acc, dt=dt), repeat)
        if name != "TiltEstimator":
            f(gyr[:10], acc[:10], mag[:10], dt=dt)
            rows[f"{name} 9D"] = best_time(lambda f=f: f(gyr, acc, mag, dt=dt), repeat)
    ref = rows.get("vqf 6D")
    print(f"\nThroughput, n = {n:,} samples, best of {repeat} (ratio = vqf 6D time / time)")
    print(f"{'':22} {'ms':>8} {'M samples/s':>12} {'vs vqf 6D':>10}")
    out = {}
    for name, t in rows.items():
        ratio = ref / t if ref else float("nan")
        out[name] = {"seconds": t, "samples_per_s": n / t, "vs_vqf_6d": ratio}
        print(f"{name:22} {t * 1e3:8.1f} {n / t / 1e6:12.2f} {ratio:10.2f}")
    return out


def vqf_runner(nine: bool):
    from vqf import VQF

    def run(trial):
        v = VQF(trial.dt)
        if nine:
            return v.updateBatch(trial.gyro, trial.acc, trial.mag)["quat9D"]
        return v.updateBatch(trial.gyro, trial.acc)["quat6D"]

    run.__name__ = f"vqf {'9D' if nine else '6D'} (defaults)"
    return run


def broad_throughput(trials, repeat: int) -> dict:
    """The same ratios on real data: all trials end to end (BROAD's IMU at 286 Hz)."""
    gyr = np.ascontiguousarray(np.concatenate([t.gyro for t in trials]))
    acc = np.ascontiguousarray(np.concatenate([t.acc for t in trials]))
    dt = trials[0].dt
    try:
        from vqf import VQF
    except ImportError:
        return {}
    ref = best_time(lambda: VQF(dt).updateBatch(gyr, acc), repeat)
    out = {"vqf 6D": len(gyr) / ref}
    print(f"\nThroughput on the {len(trials)} BROAD trials end to end ({len(gyr):,} samples), 6D, best of {repeat}")
    print(f"{'vqf 6D':22} {len(gyr) / ref / 1e6:8.2f} M samples/s")
    for name in ("TiltEstimator", "Mahony"):
        f = FILTERS[name]
        t = best_time(lambda f=f: f(gyr, acc, dt=dt), repeat)
        out[name] = len(gyr) / t
        print(f"{name + ' 6D':22} {len(gyr) / t / 1e6:8.2f} M samples/s, {ref / t:.2f}x vqf 6D")
    return out


def broad_results(folder: Path, repeat: int) -> dict:
    from strapdown.evaluate.broad import load_reference_results, load_trials

    trials = load_trials(folder / "data_mat")
    out = {"throughput": broad_throughput(trials, repeat)}
    ev = evaluate("tilt", trials)
    print("\n" + ev.table())
    out["tilt_6d"] = {"mean": {m: ev.mean(m) for m in ("total", "heading", "inclination")}, "groups": ev.groups()}

    print("\nSame protocol, defaults, mean RMSE over the trials (deg)")
    print(f"{'':34} {'total':>8} {'heading':>8} {'inclin.':>8}")
    runs = [
        ("tilt", False),
        ("complementary", False),
        ("mahony", False),
        ("madgwick", False),
        ("complementary", True),
        ("mahony", True),
        ("madgwick", True),
    ]
    table = [evaluate(name, trials, mag=nine) for name, nine in runs]
    try:
        table += [evaluate(vqf_runner(False), trials), evaluate(vqf_runner(True), trials, heading_offset=False)]
    except ImportError:
        pass
    for e in table:
        print(f"{e.label:34} {e.mean('total'):8.3f} {e.mean('heading'):8.3f} {e.mean('inclination'):8.3f}")
        out.setdefault("means", {})[e.label] = {m: e.mean(m) for m in ("total", "heading", "inclination")}

    ref = load_reference_results(folder / "reference_results" / "results_madgwick.mat")
    i = int(np.flatnonzero(np.isclose(ref["params"]["beta"], 0.12))[0])
    print("\nBROAD's published Madgwick results (beta = 0.12, BROAD example start), total RMSE per trial (deg)")
    runs = {
        v: evaluate("madgwick", trials, params={"beta": 0.12, "variant": v}, mag=True, start="broad-example")
        for v in ("reference", "corrected")
    }
    print(f"{'':46} {'published':>9} {'reference':>9} {'diff':>9} {'corrected':>9} {'diff':>9}")
    worst = {v: 0.0 for v in runs}
    for k, trial in enumerate(trials):
        pub = {m: ref[m][trial.name][i] for m in ("total", "heading", "inclination")}
        cells = []
        for v, e in runs.items():
            r = e.trials[k]
            worst[v] = max(worst[v], *(abs(r.get(m) - pub[m]) for m in pub))
            cells += [r.total, r.total - pub["total"]]
        print(f"{trial.name:46} {pub['total']:9.3f} {cells[0]:9.3f} {cells[1]:+9.1e} {cells[2]:9.3f} {cells[3]:+9.3f}")
    means = {v: e.mean("total") for v, e in runs.items()}
    pub_mean = float(np.mean([ref["total"][t.name][i] for t in trials]))
    print(f"{'mean':46} {pub_mean:9.3f} {means['reference']:9.3f} {'':9} {means['corrected']:9.3f}")
    print(
        f"largest difference to the published value over total/heading/inclination and all trials: reference "
        f"{worst['reference']:.2e} deg, corrected {worst['corrected']:.2f} deg"
    )
    out["madgwick_reproduction"] = {
        "worst_reference": worst["reference"],
        "worst_corrected": worst["corrected"],
        "mean_published": pub_mean,
        "mean": means,
    }
    return out


def bias_study() -> dict:
    from strapdown.evaluate.metrics import attitude_errors
    from strapdown.fusion import FLAG_REST
    from strapdown.rotations.quaternion import rotate
    from strapdown.simulate import ImuModel, RockingPlatform, TriadModel, sample

    bias = np.radians(1.0)
    duration = 1500.0
    print(f"\nBias study: RockingPlatform, 1 deg/s gyro bias on every axis, 100 Hz, {duration:.0f} s, ideal otherwise")
    print(
        f"{'':34} {'tau_bias':>8} {'1 % after':>10} {'/tau_bias':>9} {'bias x, y, z at end (deg/s)':>30} "
        f"{'incl. RMSE':>10}"
    )
    cases = [
        ("rocking in place", False, False),
        ("driving and turning", True, False),
        ("driving, known acceleration", True, True),
    ]
    out = {}
    for label, driving, known in cases:
        kw = {} if driving else {"speed": 0.0, "turn_rate": 0.0, "bump_amplitude": 0.0}
        traj = RockingPlatform(duration=duration, **kw)
        data = sample(traj, 100.0, gyro="rate", imu=ImuModel(gyro=TriadModel(bias=bias)), reference="ENU", body="FLU")
        known_acc = None
        if known:
            q_mid = data.q_true[1:] + data.q_true[:-1]
            q_mid /= np.linalg.norm(q_mid, axis=1, keepdims=True)
            known_acc = data.acc - rotate(q_mid * [1.0, -1.0, -1.0, -1.0], [0.0, 0.0, 9.80665])
        for tau_bias in (30.0, 100.0):
            est = tilt(data.gyro, data.acc, dt=0.01, params=TiltParams(tau_bias=tau_bias), known_acc=known_acc)
            ok = np.all(np.abs(est.bias[:, :2] - bias) <= 0.01 * bias, axis=1)
            bad = np.flatnonzero(~ok)
            after = (bad[-1] + 1) * 0.01 if len(bad) else 0.0
            converged = after < duration - 1.0
            second = slice(len(est) // 2, None)
            incl = np.degrees(attitude_errors(est.q[second], data.q_true[1:][second])["inclination"])
            rmse = float(np.sqrt(np.mean(incl**2)))
            end = np.degrees(est.bias[-1])
            when = f"{after:8.0f} s" if converged else "   never"
            ratio = f"{after / tau_bias:9.1f}" if converged else f"{'-':>9}"
            print(f"{label:34} {tau_bias:8.0f} {when:>10} {ratio} {np.array2string(end, precision=4):>30} {rmse:9.3f}°")
            out[f"{label}, tau_bias {tau_bias:g}"] = {
                "converged_after_s": after if converged else None,
                "bias_end_deg_s": end.tolist(),
                "rest_samples": int(np.count_nonzero(est.flags & FLAG_REST)),
                "inclination_rmse_deg": rmse,
            }
    print(
        "The vertical component is not observable in motion without a heading reference (it stays near 0);"
        " it is learnt at rest."
    )
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--broad", type=Path, default=BROAD)
    ap.add_argument("--skip-bias", action="store_true")
    ap.add_argument("--goal", type=float, default=3.0, help="goal: throughput ratio to vqf 6D (TiltEstimator, Mahony)")
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    print(
        f"strapdown {strapdown.__version__}, numpy {np.__version__}, numba {numba.__version__}, Python "
        f"{platform.python_version()}, {platform.machine()}"
    )
    results = {"throughput": throughput(args.n, args.repeat)}
    for name in ("TiltEstimator 6D", "Mahony 6D"):
        ratio = results["throughput"][name]["vs_vqf_6d"]
        verdict = "meets" if ratio >= args.goal else "MISSES"
        print(f"{name}: {ratio:.2f}x vqf 6D, {verdict} the goal of {args.goal:g}x")
    if (args.broad / "data_mat").is_dir():
        results["broad"] = broad_results(args.broad, args.repeat)
    else:
        print(f"\nBROAD not found at {args.broad}: accuracy tables skipped")
    if not args.skip_bias:
        results["bias"] = bias_study()
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=2, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
