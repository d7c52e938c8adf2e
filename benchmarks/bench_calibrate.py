"""Accuracy of strapdown.calibrate: magnetometer Monte Carlo, Allan-interval coverage, and BROAD with calibration.

    python benchmarks/bench_calibrate.py [--runs 100] [--allan-runs 20] [--broad ../shared/data/broad/data_mat]
                                         [--fit-seconds 30] [--skip-broad] [--json results.json]

1. Magnetometer Monte Carlo (simulated, exact truth): hard iron up to 50 µT, soft iron with 20 % scale and 10 %
   cross-coupling, 0.3 µT noise per axis, 1500 readings over the sphere.  For each parameter the table gives the
   rms error, the mean reported sigma and the rms of error/sigma (1 when the reported uncertainty is right),
   and the calibrated norm's scatter over the noise it should have (1: constant within the noise).
2. Allan coverage: white noise N, flicker B and rate random walk K at known levels (3 h at 50 Hz, three axes):
   how often each 95 % interval holds the truth (should be about 0.95 or more).
3. BROAD (Laidig et al. 2021, CC BY 4.0; skipped when the data are absent): for each trial the magnetometer is
   fitted on its first rotations: the first ``--fit-seconds`` of movement, doubled until the fit accepts the
   motion (or the whole trial is used); the AttitudeEstimator (9D, defaults) runs on the raw readings, on the
   calibrated ones ("always"), and on the calibrated ones only when the fit is ``warranted`` (it cuts the
   field-norm scatter more than threefold), else raw ("if warranted").  A trial whose fit is refused stays raw.
   Then the same with a known distortion added to BROAD's (already calibrated) magnetometer, hard iron
   [30, -20, 40] µT and soft iron with 15 % scale and 8 % coupling: "distorted" is the estimator on the distorted
   readings, "recovered" on the distorted readings calibrated by a fit over the same first rotations.
   Figures are total RMSE in degrees over the movement samples.
The machine is shared: no timing is reported.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from strapdown.calibrate import InsufficientMotionError, allan, magnetometer
from strapdown.simulate.imu import TriadModel, corrupt

FIELD = 48.0


def symmetric_truth(a):
    values, vectors = np.linalg.eigh(a @ a.T)
    return (vectors / np.sqrt(values)) @ vectors.T


def mag_monte_carlo(runs: int, n: int = 1500, noise: float = 0.3) -> dict:
    err_b, sig_b, err_w, sig_w, norm_ratio = [], [], [], [], []
    for seed in range(runs):
        rng = np.random.default_rng(1000 + seed)
        bias = rng.uniform(-50, 50, 3)
        bias[rng.integers(3)] = 50.0 * rng.choice([-1, 1])
        soft = np.eye(3) + np.diag(rng.uniform(-0.2, 0.2, 3)) + rng.uniform(-0.1, 0.1, (3, 3)) * (1 - np.eye(3))
        model = TriadModel(bias=bias, soft_iron=soft, noise_density=noise / np.sqrt(100.0))
        u = rng.standard_normal((n, 3))
        m = corrupt(model, FIELD * u / np.linalg.norm(u, axis=1, keepdims=True), 0.01, "rate", rng)
        cal = magnetometer(m, field_strength=FIELD)
        truth = symmetric_truth(model.matrix)
        iu = np.triu_indices(3)
        err_b.append(cal.offset - bias)
        sig_b.append(cal.offset_sigma)
        err_w.append((cal.matrix - truth)[iu])
        sig_w.append(cal.matrix_sigma[iu])
        c = cal.apply(m)
        d = c / np.linalg.norm(c, axis=1, keepdims=True)
        expected = noise * np.sqrt(np.mean(np.sum((d @ truth) ** 2, axis=1)))
        norm_ratio.append(np.std(np.linalg.norm(c, axis=1)) / expected)
    err_b, sig_b, err_w, sig_w = map(np.array, (err_b, sig_b, err_w, sig_w))
    names = [f"hard iron {a} (µT)" for a in "xyz"] + [f"W{i}{j}" for i, j in zip(*np.triu_indices(3), strict=True)]
    err = np.hstack([err_b, err_w])
    sig = np.hstack([sig_b, sig_w])
    rows = []
    for k, name in enumerate(names):
        rows.append(
            {
                "parameter": name,
                "rms_error": float(np.sqrt(np.mean(err[:, k] ** 2))),
                "mean_sigma": float(np.mean(sig[:, k])),
                "rms_z": float(np.sqrt(np.mean((err[:, k] / sig[:, k]) ** 2))),
            }
        )
    return {"runs": runs, "rows": rows, "norm_scatter_over_noise_max": float(np.max(norm_ratio))}


def flicker(n, fs, b, rng, axes=3):
    big = 4 * n
    f = np.fft.rfftfreq(big, 1 / fs)
    psd = np.zeros_like(f)
    psd[1:] = b**2 / (2 * np.pi * f[1:])
    shape = (len(f), axes)
    spec = np.sqrt(big * fs * psd)[:, None] * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))
    return np.fft.irfft(spec / np.sqrt(2), big, axis=0)[:n]


def allan_coverage(runs: int, k_true: float) -> dict:
    n_true, b_true, fs = 1e-4, 3e-5, 50.0
    n = int(3 * 3600 * fs)
    hits = []
    for seed in range(runs):
        rng = np.random.default_rng(2000 + seed)
        x = n_true * np.sqrt(fs) * rng.standard_normal((n, 3)) + flicker(n, fs, b_true, rng)
        x += np.cumsum(k_true / np.sqrt(fs) * rng.standard_normal((n, 3)), axis=0)
        r = allan(x, fs)
        hits.append(
            [
                (iv[:, 0] <= t) & (t <= iv[:, 1])
                for iv, t in (
                    (r.arw_interval, n_true),
                    (r.bias_instability_interval, b_true),
                    (r.rate_random_walk_interval, k_true),
                )
            ]
        )
    cover = np.mean(hits, axis=(0, 2))
    return {
        "runs": runs,
        "N": n_true,
        "B": b_true,
        "K": k_true,
        "coverage": dict(zip("NBK", cover.tolist(), strict=True)),
    }


DISTORTION = np.array([[1.15, 0.08, -0.03], [0.02, 0.9, 0.05], [-0.04, 0.06, 1.1]]), np.array([30.0, -20.0, 40.0])


def first_rotations(mag, moving, fit_seconds):
    """The fit on the first stretch of movement that it accepts (doubling from fit_seconds), or the refusal."""
    seconds = fit_seconds
    while True:
        stop = min(int(np.searchsorted(moving, seconds)) + 1, len(mag))
        try:
            return magnetometer(mag[:stop]), float(min(seconds, moving[-1])), None
        except InsufficientMotionError as exc:
            if stop == len(mag):
                return None, float(moving[-1]), str(exc)
            seconds *= 2


def broad(folder: Path, fit_seconds: float) -> list[dict]:
    from strapdown.evaluate.broad import load_trials
    from strapdown.evaluate.metrics import rmse_errors
    from strapdown.fusion import attitude

    rows = []
    for trial in load_trials(folder):
        moving = np.cumsum(trial.movement) / trial.rate
        row = {"trial": trial.name}
        cal, row["fit_seconds"], refused = first_rotations(trial.mag, moving, fit_seconds)
        if refused:
            row["refused"] = refused
        if cal is not None:
            q = cal.quality
            row.update(
                hard_iron=np.round(cal.offset, 2).tolist(),
                coverage=q["coverage"],
                norm_scatter=[round(q["norm_scatter_raw"], 3), round(q["norm_scatter"], 3)],
                warranted=q["warranted"],
            )
        variants = {"raw": trial.mag}
        variants["always"] = trial.mag if cal is None else cal.apply(trial.mag)
        variants["if warranted"] = variants["always"] if cal is not None and cal.quality["warranted"] else trial.mag
        done = {}
        for name, m in variants.items():
            key = id(m)
            if key not in done:
                q = attitude(trial.gyro, trial.acc, m, dt=trial.dt).q
                done[key] = round(rmse_errors(q, trial.quat, trial.movement)["total"], 3)
            row[name] = done[key]
        soft, hard = DISTORTION
        distorted = trial.mag @ soft.T + hard
        cal_d, _, _ = first_rotations(distorted, moving, fit_seconds)
        for name, m in (("distorted", distorted), ("recovered", None if cal_d is None else cal_d.apply(distorted))):
            if m is not None:
                q = attitude(trial.gyro, trial.acc, m, dt=trial.dt).q
                row[name] = round(rmse_errors(q, trial.quat, trial.movement)["total"], 3)
        rows.append(row)
        note = "fit refused" if cal is None else f"{row['fit_seconds']:.0f} s, coverage {row['coverage']:.2f}, "
        if cal is not None:
            note += f"norm scatter {row['norm_scatter'][0]:.2f} -> {row['norm_scatter'][1]:.2f} µT"
        print(
            f"{trial.name:<46} raw {row['raw']:6.2f}  always {row['always']:6.2f}  "
            f"if warranted {row['if warranted']:6.2f} | distorted {row['distorted']:6.2f}  recovered "
            + (f"{row['recovered']:6.2f}" if "recovered" in row else "refused")
            + f"  ({note})",
            flush=True,
        )
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--allan-runs", type=int, default=20)
    default_broad = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "broad" / "data_mat"
    ap.add_argument("--broad", type=Path, default=default_broad)
    ap.add_argument("--fit-seconds", type=float, default=30.0)
    ap.add_argument("--skip-broad", action="store_true")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
    out = {}

    mc = mag_monte_carlo(args.runs)
    out["magnetometer"] = mc
    print(f"Magnetometer Monte Carlo, {mc['runs']} runs (1500 readings, 0.3 µT noise)")
    print(f"{'parameter':<20} {'rms error':>12} {'mean sigma':>12} {'rms err/sigma':>14}")
    for r in mc["rows"]:
        print(f"{r['parameter']:<20} {r['rms_error']:12.4g} {r['mean_sigma']:12.4g} {r['rms_z']:14.3f}")
    print(f"calibrated norm scatter / expected noise, worst run: {mc['norm_scatter_over_noise_max']:.3f}\n")

    out["allan"] = []
    for k in (1e-6, 3e-6) if args.allan_runs > 0 else ():
        cov = allan_coverage(args.allan_runs, k)
        out["allan"].append(cov)
        print(
            f"Allan 95 % interval coverage ({cov['runs']} runs x 3 axes, N={cov['N']:g}, B={cov['B']:g}, K={k:g}): "
            + ", ".join(f"{name} {v:.3f}" for name, v in cov["coverage"].items())
        )
    if not args.skip_broad:
        if args.broad.is_dir():
            print(f"\nBROAD, AttitudeEstimator 9D, mag fitted on the first {args.fit_seconds:g} s of movement")
            rows = broad(args.broad, args.fit_seconds)
            out["broad"] = rows
            for name in ("always", "if warranted"):
                worse = [r["trial"][:2] for r in rows if r[name] > r["raw"] + 0.05]
                mean = np.mean([r[name] for r in rows])
                print(
                    f"{name}: mean total RMSE {mean:.3f}° (raw {np.mean([r['raw'] for r in rows]):.3f}°); "
                    f"trials worse by > 0.05°: {', '.join(worse) or 'none'}"
                )
            fitted = [r for r in rows if "recovered" in r]
            print(
                f"distorted magnetometer: mean {np.mean([r['distorted'] for r in rows]):.3f}°; recovered on the "
                f"{len(fitted)} trials whose fit was accepted: {np.mean([r['recovered'] for r in fitted]):.3f}° "
                f"(raw on the same trials {np.mean([r['raw'] for r in fitted]):.3f}°)"
            )
        else:
            print(f"\nBROAD skipped: {args.broad} not found")
    if args.json:
        args.json.write_text(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
