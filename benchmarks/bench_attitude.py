"""The AttitudeEstimator against VQF: accuracy on BROAD, robustness, simulated checks, throughput (issue 7).

    python benchmarks/bench_attitude.py [--broad DIR] [--n 1000000] [--repeat 5] [--skip-surface] [--json F]
                                        [--only accuracy,surface,irregular,logo,lever,simulated,throughput]
                                        [--trials 01,06]

Accuracy: the 22 BROAD trials (CC BY 4.0; Laidig et al. 2021), official metric, one parameter set for all
trials (the defaults), online 6D and 9D and offline 9D, with vqf's VQF and offlineVQF (defaults) run in the same
process; per-group means (trials.json).  6D errors are taken after removing each trial's mean heading offset.

Robustness: mean 9D total and 6D inclination RMSE over a grid of the two main time constants, tau_acc and tau_mag,
and a two-fold held-out check: the time constants chosen on half of the trials, scored on the other half.

Leave-one-group-out (issue 13): every default this round moved or added, chosen on all of BROAD's 9 kinds of
trial but one and scored on the one left out; the pooled held-out mean next to the in-sample ones.

Irregular sampling (issue 13): each trial as recorded, with 10 % of its rows dropped at random (the true times of
the rest passed as ``t``), and with 10 % of its accelerometer and 10 % of its magnetometer rows NaN ("no sample");
the mean errors of the AttitudeEstimator online and offline and of the TiltEstimator, and their change.

Lever arm (issue 29): per trial, a least-squares fit of the accelerometer against the optical truth's gravity,
a - R^T g = ω̇ × r + ω × (ω × r) + b (ω̇ by central differences, 5-sample mean), next to a bias-only fit, and the
AttitudeEstimator's own lever-arm estimate at the end of the trial: the sensor's offset r from the point the board
turns about, which the accelerometer-bias states read as a bias when it is not modelled.

Simulated checks (strapdown.simulate, ideal sensors but for what is named): a 0.5°/s gyro bias on every axis on a
platform rocking and turning in place and on a body turning every way; a magnet near the sensor for 10 s.

Throughput: batch calls on the BROAD recordings end to end and on 10^6 simulated samples at 100 Hz, best of
--repeat, with vqf.VQF.updateBatch timed in the same run.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numba
import numpy as np

import strapdown
from strapdown.evaluate.evaluation import evaluate
from strapdown.fusion import AttitudeParams, TiltParams, attitude, attitude_offline

BROAD = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "broad"
METRICS = ("total", "heading", "inclination")


def vqf_runs():
    from vqf import VQF, offlineVQF

    def v6(t):
        return VQF(t.dt).updateBatch(t.gyro, t.acc)["quat6D"]

    def v9(t):
        return VQF(t.dt).updateBatch(t.gyro, t.acc, t.mag)["quat9D"]

    def off(t):
        return offlineVQF(t.gyro, t.acc, t.mag, t.dt)["quat9D"]

    return v6, v9, off


def accuracy(trials) -> dict:
    runs = {
        "ours 6D": evaluate("attitude", trials),
        "ours 9D": evaluate("attitude", trials, mag=True),
        "ours offline 9D": evaluate(
            lambda t: attitude_offline(t.gyro, t.acc, t.mag, dt=t.dt), trials, heading_offset=False
        ),
    }
    try:
        v6, v9, off = vqf_runs()
        runs["VQF 6D"] = evaluate(v6, trials)
        runs["VQF 9D"] = evaluate(v9, trials, heading_offset=False)
        runs["VQF offline 9D"] = evaluate(off, trials, heading_offset=False)
    except ImportError:
        print("vqf is not installed (pip install 'strapdown[bench]'): no reference", file=sys.stderr)
    print("\nBROAD, mean RMSE over the trials (deg), defaults for all trials; 6D: inclination, 9D: total")
    names = list(runs)
    groups = runs["ours 9D"].groups()
    head = f"{'group (trials)':26}" + "".join(f"{n:>16}" for n in names)
    print(head)
    out = {n: {} for n in names}
    for g, info in groups.items():
        row = f"{g + ' (' + str(info['n']) + ')':26}"
        for n in names:
            metric = "inclination" if "6D" in n else "total"
            v = runs[n].groups()[g][metric]
            out[n][g] = {m: runs[n].groups()[g][m] for m in METRICS}
            row += f"{v:16.3f}"
        print(row)
    print("\nmeans over all trials (total / heading / inclination)")
    for n in names:
        means = {m: runs[n].mean(m) for m in METRICS}
        out[n]["mean"] = means
        print(f"  {n:18} {means['total']:6.3f} / {means['heading']:6.3f} / {means['inclination']:6.3f}")
    # issue 13: no figure worse than at the start of the round (9D 1.942, 6D 0.644, offline 9D 1.668, offline
    # inclination 0.585, all measured in this environment), and offline inclination below offline VQF's
    goals = [
        ("ours 9D", "total", 1.942),
        ("ours 6D", "inclination", 0.644),
        ("ours offline 9D", "total", 1.668),
        ("ours offline 9D", "inclination", 0.585),
    ]
    if "VQF offline 9D" in out:
        goals.append(("ours offline 9D", "inclination", out["VQF offline 9D"]["mean"]["inclination"]))
    for n, m, goal in goals:
        v = out[n]["mean"][m]
        print(f"  issue 13 goal: {n} mean {m} {v:.3f} <= {goal:.3f}: {'met' if v <= goal else 'MISSED'}")
    return out


def surface(trials) -> dict:
    taus_acc = [2.0, 2.5, 3.0, 3.5, 4.0, 5.0]
    taus_mag = [10.0, 15.0, 20.0, 30.0, 40.0]
    print(
        "\nRobustness: mean 9D total RMSE (deg) over tau_acc (rows, s) and tau_mag (columns, s); last column: 6D "
        "inclination"
    )
    print(f"{'':8}" + "".join(f"{t:8.0f}" for t in taus_mag) + f"{'6D incl':>10}")
    grid = {}
    per_trial = {}  # (tau_acc, tau_mag) -> per-trial 9D total RMSE, for the held-out check below
    for ta in taus_acc:
        row = []
        for tm in taus_mag:
            ev = evaluate("attitude", trials, params={"tau_acc": ta, "tau_mag": tm}, mag=True)
            per_trial[ta, tm] = np.array([r.total for r in ev.trials])
            row.append(ev.mean("total"))
        six = evaluate("attitude", trials, params={"tau_acc": ta}).mean("inclination")
        grid[ta] = {"total_9d": dict(zip(taus_mag, row, strict=True)), "inclination_6d": six}
        print(f"{ta:8.1f}" + "".join(f"{v:8.3f}" for v in row) + f"{six:10.3f}")
    values = np.array([list(g["total_9d"].values()) for g in grid.values()])
    print(f"9D total over the grid: {values.min():.3f}-{values.max():.3f} deg (defaults tau_acc 3.5, tau_mag 20)")
    grid["held_out"] = held_out(trials, per_trial, (3.5, 20.0))
    return grid


def held_out(trials, per_trial: dict, defaults: tuple) -> dict:
    """Two-fold check of how the choice of the time constants carries over to trials it was not made on.

    The trials are split by the parity of their number (each half has slow and fast, rotation and translation,
    disturbed and undisturbed trials).  On each half the grid point with the lowest mean 9D total RMSE is chosen;
    its mean on the other half is compared with the defaults' (chosen on all 22) and with the best possible there.
    The other parameters stay at their defaults, which were chosen on all trials too.
    """
    odd = np.array([int(t.name.split("_")[0]) % 2 == 1 for t in trials])
    try:
        vqf9 = np.array([r.total for r in evaluate(vqf_runs()[1], trials, heading_offset=False).trials])
    except ImportError:
        vqf9 = None
    print("\nHeld out: tau_acc, tau_mag chosen on one half of the trials (by number parity), 9D total on the other")
    out = {}
    pooled = np.empty(len(trials))
    for train, test, label in ((odd, ~odd, "odd -> even"), (~odd, odd, "even -> odd")):
        chosen = min(per_trial, key=lambda k: per_trial[k][train].mean())
        best = min(per_trial, key=lambda k: per_trial[k][test].mean())
        got, dflt, opt = (per_trial[k][test].mean() for k in (chosen, defaults, best))
        pooled[test] = per_trial[chosen][test]
        ref = f", VQF {vqf9[test].mean():.3f}" if vqf9 is not None else ""
        print(
            f"  {label}: chosen {chosen[0]:g} s, {chosen[1]:g} s -> {got:.3f} deg on the held-out "
            f"{int(test.sum())} trials (defaults {dflt:.3f}, best there {opt:.3f} at {best[0]:g} s, {best[1]:g} s{ref})"
        )
        out[label] = {"chosen": chosen, "held_out_total": float(got), "defaults": float(dflt), "best": float(opt)}
    ref = f" (VQF {vqf9.mean():.3f})" if vqf9 is not None else ""
    print(f"  every trial scored held out: mean 9D total {pooled.mean():.3f} deg{ref}")
    out["pooled"] = float(pooled.mean())
    return out


def logo_group(trial) -> str:
    """The trial's kind, for leave-one-group-out: its name without number, take letter, breaks or magnet distance
    (9 disjoint groups: slow/fast rotation, slow/fast translation, combined, tapping, vibration, stationary and
    attached magnet)."""
    import re

    kind = trial.name.split("_", 1)[1]
    kind = re.sub(r"_[A-D]$", "", kind)
    kind = re.sub(r"_\d+cm$", "", kind)
    return kind.replace("_with_breaks", "")


# the defaults this round moved or added, their grids, and the metric each is chosen on
LOGO_GRIDS = {
    "bias_noise_acc_factor": ([0.0, 0.03, 0.1, 0.3, 1.0], "6D", "inclination"),
    "acc_bias_sigma_init": ([0.0, 0.03, 0.1, 0.2], "6D", "inclination"),
    "acc_bias_noise_acc_factor": ([0.03, 0.1, 0.3, 1.0], "6D", "inclination"),
    "lever_arm_sigma_init": ([0.0, 0.05, 0.1, 0.2], "6D", "inclination"),
    "9D lever_arm_sigma_init": ([0.0, 0.05, 0.1, 0.2], "9D", "total"),
    "acc_bias_significance": ([0.0, 0.5, 1.0, 2.0], "6D", "inclination"),
    "9D acc_bias_significance": ([0.0, 0.5, 1.0, 2.0], "9D", "total"),
    "gyro_acc_bias_significance": ([0.0, 0.25, 0.5, 0.7, 1.0], "6D", "inclination"),
    "9D gyro_acc_bias_significance": ([0.0, 0.25, 0.5, 0.7, 1.0], "9D", "total"),
    "update_rate": ([2.0, 3.0, 4.0, 5.0, 10.0], "6D", "inclination"),
    "9D update_rate": ([2.0, 3.0, 4.0, 5.0, 10.0], "9D", "total"),
    "offline_acc_bias_significance": ([0.0, 0.5, 1.0, 2.0], "offline", "total"),
    "offline_heading_tau": ([20.0, 30.0, 60.0, 100.0], "offline", "total"),
    "offline_time_factor": ([1.0, 1.5, 2.0, 3.0], "offline", "inclination"),
    "tilt tau_acc": ([2.0, 2.5, 3.0, 3.5, 4.0], "tilt", "inclination"),
    "tilt tau_bias": ([50.0, 100.0, 200.0], "tilt", "inclination"),
    "tilt acc_bias_sigma": ([0.0, 0.1, 0.2, 0.5], "tilt", "inclination"),
    "tilt scale_sigma_init": ([0.0, 0.002, 0.005, 0.01, 0.02], "tilt", "inclination"),
}


def leave_one_group_out(trials, tilt_only: bool = False, grids=None) -> dict:
    """For each default this round moved: chosen on all groups but one, scored on the one left out (issue 13).

    One parameter at a time, the others at their defaults.  For every left-out group the grid value with the
    lowest mean over the other groups' trials is chosen and scored on the left-out trials; the pooled held-out
    mean (every trial scored by a choice made without its group) is printed next to the in-sample mean of the
    default and of the best value on all trials.  ``grids``: the names of LOGO_GRIDS to run (default: all).
    """
    groups = np.array([logo_group(t) for t in trials])
    print(f"\nLeave-one-group-out on BROAD ({len(set(groups))} groups: {', '.join(sorted(set(groups)))})")
    out = {}
    for name, (values, mode, metric) in LOGO_GRIDS.items():
        if (tilt_only and mode != "tilt") or (grids and name not in grids):
            continue
        per = {}
        key = name.split()[-1]  # the parameter ("tilt tau_acc", "9D acc_bias_significance": the same one elsewhere)
        for v in values:
            if mode == "offline":
                ev = evaluate(
                    lambda t, v=v, key=key: attitude_offline(t.gyro, t.acc, t.mag, dt=t.dt, params={key: v}),
                    trials,
                    heading_offset=False,
                )
            elif mode == "tilt":
                ev = evaluate("tilt", trials, params={key: v})
            else:
                ev = evaluate("attitude", trials, params={key: v}, mag=mode == "9D")
            per[v] = np.array([r.get(metric) for r in ev.trials])
        held = np.empty(len(trials))
        chosen = {}
        for g in sorted(set(groups)):
            out_g = groups == g
            pick = min(values, key=lambda v: per[v][~out_g].mean())
            chosen[g] = pick
            held[out_g] = per[pick][out_g]
        default = getattr(TiltParams() if mode == "tilt" else AttitudeParams(), name.split()[-1])
        best = min(values, key=lambda v: per[v].mean())
        grid = ", ".join(f"{v:g}: {per[v].mean():.3f}" for v in values)
        print(f"  {name} ({mode} {metric}); in-sample means {grid}")
        picks = ", ".join(f"{g} -> {chosen[g]:g}" for g in sorted(chosen))
        print(
            f"    held out (pooled): {held.mean():.3f} deg; default {default:g} in-sample {per[default].mean():.3f}, "
            f"best in-sample {best:g} {per[best].mean():.3f}; choices: {picks}"
        )
        out[name] = {
            "held_out": float(held.mean()),
            "default": default,
            "default_in_sample": float(per[default].mean()),
            "grid": {str(v): float(per[v].mean()) for v in values},
            "choices": {g: float(v) for g, v in chosen.items()},
        }
    return out


def _skew(v):
    z = np.zeros(len(v))
    rows = [[z, -v[:, 2], v[:, 1]], [v[:, 2], z, -v[:, 0]], [-v[:, 1], v[:, 0], z]]
    return np.stack([np.stack(r, -1) for r in rows], -2)


def lever_arms(trials) -> dict:
    """The lever arm BROAD's accelerometer shows against the optical truth, and the estimator's (module notes)."""
    from strapdown.fusion import AttitudeEstimator
    from strapdown.rotations.quaternion import conjugate, rotate

    print("\nLever arm: least-squares fit of a - R^T g = ω̇ × r + ω × (ω × r) + b (sensor axes; cm, m/s²)")
    print(f"  {'trial':40} {'fitted r':>22} {'b':>22} {'RMS: b only':>12} {'r and b':>8} {'estimator r':>22}")
    out = {}
    kernel = np.ones(5) / 5.0
    for t in trials:
        ok = np.all(np.isfinite(t.quat), axis=1)
        wd = np.gradient(t.gyro, t.dt, axis=0)
        wd = np.column_stack([np.convolve(wd[:, i], kernel, mode="same") for i in range(3)])[ok]
        w = t.gyro[ok]
        up = rotate(conjugate(t.quat[ok]), np.tile([0.0, 0.0, 9.80665], (int(ok.sum()), 1)))  # ENU: +g up
        y = (t.acc[ok] - up).reshape(-1)
        W = _skew(w)
        M = _skew(wd) + W @ W
        eye = np.broadcast_to(np.eye(3), M.shape)
        A = np.concatenate([M, eye], axis=-1).reshape(-1, 6)
        sol = np.linalg.lstsq(A, y, rcond=None)[0]
        bias_only = np.linalg.lstsq(eye.reshape(-1, 3), y, rcond=None)[0]
        rms_b = float(np.sqrt(np.mean((y - eye.reshape(-1, 3) @ bias_only) ** 2)))
        rms_rb = float(np.sqrt(np.mean((y - A @ sol) ** 2)))
        est = AttitudeEstimator()
        est.update(t.gyro, t.acc, dt=t.dt)
        r, b, e = (
            np.array2string(v, precision=2, suppress_small=True) for v in (sol[:3] * 100, sol[3:], est.lever_arm * 100)
        )
        print(f"  {t.name[:40]:40} {r:>22} {b:>22} {rms_b:12.3f} {rms_rb:8.3f} {e:>22}")
        out[t.name] = {
            "r_cm": (sol[:3] * 100).tolist(),
            "b": sol[3:].tolist(),
            "estimator_r_cm": (est.lever_arm * 100).tolist(),
        }
    return out


def simulated() -> dict:
    from strapdown.evaluate.metrics import attitude_errors
    from strapdown.fusion import FLAG_MAG_REJECTED
    from strapdown.simulate import (
        ImuModel,
        MagneticDisturbance,
        MagneticField,
        RandomMotion,
        RockingPlatform,
        TriadModel,
        sample,
    )

    field = MagneticField(declination_deg=0.0)
    bias = np.radians(0.5)
    out = {}
    print(
        "\nSimulated: 0.5 deg/s gyro bias on every axis, 100 Hz; seconds until each component stays within 0.05 deg/s"
    )
    cases = [
        ("rocking and turning in place", RockingPlatform(duration=300.0, speed=0.0, bump_amplitude=0.0)),
        ("turning every way", RandomMotion(duration=300.0, seed=3, acceleration_scale=0.0)),
    ]
    for label, traj in cases:
        d = sample(
            traj,
            100.0,
            gyro="average",
            imu=ImuModel(gyro=TriadModel(bias=bias)),
            reference="ENU",
            body="FLU",
            magnetic_field=field,
        )
        for mode, mag in (("6D", None), ("9D", d.mag)):
            est = attitude(d.gyro, d.acc, mag, dt=0.01)
            ok = np.abs(est.bias - bias) < np.radians(0.05)
            times = [float((np.flatnonzero(~ok[:, i])[-1] + 1) * 0.01) if (~ok[:, i]).any() else 0.0 for i in range(3)]
            text = ", ".join("never" if tt >= 300.0 else f"{tt:.0f} s" for tt in times)
            print(
                f"  {label:30} {mode}: x, y, z within 0.05 deg/s after {text}; final sigma z "
                f"{np.degrees(est.extra['bias_sigma'][-1, 2]):.3f} deg/s"
            )
            out[f"{label} {mode}"] = times
    magnet = MagneticDisturbance(50.0, 60.0, (30.0, 10.0, -20.0))
    d = sample(
        RandomMotion(duration=120.0, seed=5, acceleration_scale=0.0),
        100.0,
        gyro="average",
        reference="ENU",
        body="FLU",
        magnetic_field=field,
        disturbances=[magnet],
    )
    t = np.arange(1, len(d.gyro) + 1) * 0.01
    print("  magnet of 30/10/-20 uT near the sensor from 50 to 60 s (field 50 uT):")
    for label, p in (
        ("rejection", AttitudeParams()),
        ("no rejection", AttitudeParams(mag_norm_threshold=10.0, mag_dip_threshold=3.0)),
    ):
        est = attitude(d.gyro, d.acc, d.mag, dt=0.01, params=p)
        flagged = (est.flags & FLAG_MAG_REJECTED) > 0
        heading = np.degrees(attitude_errors(est.q, d.q_true[1:])["heading"])
        inside = flagged[(t > 50.5) & (t < 59.5)].mean()
        outside = flagged[(t < 49.5) | (t > 62)].mean()
        print(
            f"    {label:13} flagged {inside:.0%} of the magnet's time, {outside:.1%} outside; heading error max "
            f"{heading[t >= 50].max():.2f} deg from 50 s on ({heading[t < 50].max():.2f} before)"
        )
        out[f"magnet {label}"] = {"flagged": float(inside), "heading_max": float(heading[t >= 50].max())}
    return out


def irregular_inputs(trial, seed: int, fraction: float = 0.1):
    """Three versions of a trial: as recorded, with rows dropped at random (their true times kept) and with NaN
    accelerometer and magnetometer rows (independently); each (label, gyr, acc, mag, timing, rows kept)."""
    rng = np.random.default_rng(seed)
    n = len(trial)
    keep = rng.random(n) >= fraction
    keep[0] = True
    acc, mag = trial.acc.copy(), trial.mag.copy()
    for arr in (acc, mag):
        gone = rng.random(n) < fraction
        gone[0] = False
        arr[gone] = np.nan
    every = np.ones(n, bool)
    times = np.arange(n) * trial.dt
    return [
        ("regular", trial.gyro, trial.acc, trial.mag, {"dt": trial.dt}, every),
        (f"{fraction:.0%} rows dropped", trial.gyro[keep], trial.acc[keep], trial.mag[keep], {"t": times[keep]}, keep),
        (f"{fraction:.0%} acc/mag NaN", trial.gyro, acc, mag, {"dt": trial.dt}, every),
    ]


def irregular(trials) -> dict:
    """BROAD with irregular sampling: each variant's mean RMSE against the regular record's (issue 13)."""
    from strapdown.evaluate.metrics import rmse_errors
    from strapdown.fusion import tilt

    cols = ("ours 9D total", "ours 6D incl.", "offline 9D total", "offline incl.", "Tilt 6D incl.")
    table: dict = {}
    for trial in trials:
        for label, g, a, m, timing, rows in irregular_inputs(trial, seed=int(trial.name[:2])):
            truth, moving = trial.quat[rows], trial.movement[rows]
            nine = rmse_errors(attitude(g, a, m, **timing).q, truth, moving)["total"]
            six = rmse_errors(attitude(g, a, **timing).q, truth, moving, heading_offset=True)["inclination"]
            off = rmse_errors(attitude_offline(g, a, m, **timing).q, truth, moving)
            til = rmse_errors(tilt(g, a, **timing).q, truth, moving, heading_offset=True)["inclination"]
            table.setdefault(label, []).append([nine, six, off["total"], off["inclination"], til])
    print(f"\nIrregular sampling on BROAD ({len(trials)} trials), mean RMSE (deg); in brackets: change from regular")
    print(f"{'':22}" + "".join(f"{c:>22}" for c in cols))
    regular = np.mean(table["regular"], axis=0)
    out = {}
    for label, rows in table.items():
        means = np.mean(rows, axis=0)
        cells = "".join(
            f"{v:14.3f} ({(v / r - 1) * 100:+4.1f} %)" if np.isfinite(v) else f"{'-':>22}"
            for v, r in zip(means, regular, strict=True)
        )
        print(f"{label:22}{cells}")
        out[label] = dict(zip(cols, map(float, means), strict=True))
    worst = max(
        (v / r - 1)
        for label, rows in table.items()
        for v, r in zip(np.mean(rows, axis=0)[:4], regular[:4], strict=True)
    )
    print(
        f"  issue 13 goal: each AttitudeEstimator figure within 10 % of the regular one: worst {worst:+.1%}, "
        f"{'met' if worst <= 0.10 else 'MISSED'}"
    )
    worst = max(np.mean(rows, axis=0)[4] / regular[4] - 1 for rows in table.values())
    print(f"  the same for the TiltEstimator: worst {worst:+.1%}, {'met' if worst <= 0.10 else 'MISSED'}")
    return out


def throughput(trials, n: int, repeat: int) -> dict:
    sys.path.insert(0, str(Path(__file__).parent))
    from bench_estimators import inputs

    out = {}
    sets = []
    if trials:
        cat = [np.ascontiguousarray(np.concatenate([getattr(t, k) for t in trials])) for k in ("gyr", "acc", "mag")]
        sets.append((f"BROAD recordings ({len(cat[0]):,} samples, 286 Hz)", cat, trials[0].dt))
    sets.append((f"simulated, {n:,} samples at 100 Hz", inputs(n), 0.01))
    try:
        from vqf import VQF
    except ImportError:
        VQF = None
    print(f"\nThroughput, best of {repeat}, interleaved (ratio: vqf time / our time; load: {os.getloadavg()[0]:.1f})")
    for label, (g, a, m), dt in sets:
        attitude(g[:100], a[:100], dt=dt)
        attitude(g[:100], a[:100], m[:100], dt=dt)
        row = {}
        for mode, mag in (("6D", None), ("9D", m)):
            args = (g, a) if mag is None else (g, a, mag)
            runs = {"ours": lambda g=g, a=a, mag=mag, dt=dt: attitude(g, a, mag, dt=dt)}
            if VQF is not None:
                runs["vqf"] = lambda args=args, dt=dt: VQF(dt).updateBatch(*args)
            # interleaved, so that both see the same load; best wall time and best process (CPU) time
            wall = {k: np.inf for k in runs}
            cpu = {k: np.inf for k in runs}
            for _ in range(repeat):
                for k, f in runs.items():
                    w0, c0 = time.perf_counter(), time.process_time()
                    f()
                    wall[k] = min(wall[k], time.perf_counter() - w0)
                    cpu[k] = min(cpu[k], time.process_time() - c0)
            ours, ref = wall["ours"], wall.get("vqf")
            row[mode] = {
                "ours_samples_per_s": len(g) / ours,
                "vqf_samples_per_s": len(g) / ref if ref else None,
                "ratio": ref / ours if ref else None,
                "ratio_cpu": cpu["vqf"] / cpu["ours"] if ref else None,
            }
            extra = f", vqf {len(g) / ref / 1e6:5.2f} M/s, {ref / ours:.2f}x (CPU time {cpu['vqf'] / cpu['ours']:.2f}x)"
            print(f"  {label:44} {mode}: ours {len(g) / ours / 1e6:6.2f} M samples/s{extra if ref else ''}")
        out[label] = row
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--broad", type=Path, default=BROAD)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--skip-surface", action="store_true")
    ap.add_argument(
        "--only",
        help="comma-separated sections: accuracy, surface, irregular, logo (or logo-tilt: the TiltEstimator's "
        "grids alone), lever, simulated, throughput (default: all)",
    )
    ap.add_argument("--grids", help="with logo: comma-separated names of LOGO_GRIDS to run (default: all)")
    ap.add_argument("--trials", help="comma-separated trial numbers to use (default: all 22), e.g. 01,06,21")
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    print(
        f"strapdown {strapdown.__version__}, numpy {np.__version__}, numba {numba.__version__}, Python "
        f"{platform.python_version()}, {platform.machine()}"
    )
    t0 = time.perf_counter()
    results = {}
    trials = []
    every = {"accuracy", "surface", "irregular", "logo", "lever", "simulated", "throughput"}  # and logo-tilt
    sections = set(args.only.split(",")) if args.only else every
    if args.skip_surface:
        sections.discard("surface")
    if (args.broad / "data_mat").is_dir():
        from strapdown.evaluate.broad import load_trials

        trials = load_trials(args.broad / "data_mat")
        if args.trials:
            wanted = args.trials.split(",")
            trials = [t for t in trials if t.name.split("_")[0] in wanted]
        if "accuracy" in sections:
            results["accuracy"] = accuracy(trials)
        if "surface" in sections:
            results["surface"] = surface(trials)
        if "irregular" in sections:
            results["irregular"] = irregular(trials)
        if "logo" in sections:
            results["leave_one_group_out"] = leave_one_group_out(
                trials, grids=args.grids.split(",") if args.grids else None
            )
        elif "logo-tilt" in sections:  # the TiltEstimator's grids alone (fast)
            results["leave_one_group_out"] = leave_one_group_out(trials, tilt_only=True)
        if "lever" in sections:
            results["lever"] = lever_arms(trials)
    else:
        print(f"BROAD not found at {args.broad}: accuracy skipped")
    if "simulated" in sections:
        results["simulated"] = simulated()
    if "throughput" in sections:
        results["throughput"] = throughput(trials, args.n, args.repeat)
    print(f"\n({time.perf_counter() - t0:.0f} s)")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=2, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())
