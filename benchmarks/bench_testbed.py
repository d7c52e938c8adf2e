"""A simulated test-bed for the AttitudeEstimator, the TiltEstimator and VQF, side by side, per condition (issue 13).

    python benchmarks/bench_testbed.py [--seeds 3] [--params JSON] [--tilt-params JSON] [--no-long] [--json F]

Each condition varies one thing real data vary, from a common base: a consumer-grade MEMS IMU
(``ImuModel.consumer_mems()``: noise, bias, scale and cross-axis errors, quantisation; its magnetometer
calibrated, one condition without), 100 Hz,
a body turning every way and accelerating at about 1 m/s² (``RandomMotion``), the Earth's field, 120 s.  The
conditions: IMU grades (ideal, consumer, tactical), rates 50-1000 Hz, timestamp jitter and dropped rows (given to
our estimator as true times; VQF, which takes one interval, gets the nominal one), magnetic environments (a
magnet passing near the path, one carried along), a start while accelerating hard, long rests, turntables (30
and 90°/s), handheld motion (flicks to 900°/s with 2 g jolts; the same with a gyro clipping at 400°/s), and gyro
biases up to 5°/s.  Both estimators run at their defaults from the first sample.

The scores are RMSE in degrees over the samples after the first 10 s (from the first sample for the
accelerating start): 6D inclination (the heading of a 6D estimate is arbitrary), 9D total, and the inclination
and total of ``attitude_offline`` against offlineVQF's (both given the magnetometer), averaged over
``--seeds`` seeds.  Dropped rows are taken from the regular record (each kept row stamped with the end of its
own step, as a data-ready timestamp is), the simulator's clock gives the jitter.  The truth is exact.

After the table, the two turntables run for ten minutes (``long_turntables``; ``--no-long`` leaves them out), to
show where an estimator's learning goes on a motion that cannot tell a gyro bias from an accelerometer bias.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from strapdown.evaluate.metrics import attitude_errors
from strapdown.fusion import TiltParams, attitude, attitude_offline, tilt
from strapdown.simulate import (
    ClockModel,
    ConstantRotation,
    Handheld,
    ImuModel,
    MagneticDisturbance,
    MagneticField,
    RandomMotion,
    sample,
)
from strapdown.simulate.trajectories import Trajectory

FIELD = MagneticField(declination_deg=0.0)  # magnetic north is true north: the 9D truth is the field's heading


class WithRests(Trajectory):
    """A motion that stops: ``base`` replayed on a warped clock s(t) whose rate s' is 1 in motion and 0 at rest,
    with 1 s smoothstep transitions (so the body rate, ``base.rate(s) s'``, stays smooth).  ``base`` must not
    translate (its acceleration is not warped)."""

    def __init__(self, base: Trajectory, moving: float, resting: float, duration: float):
        self.duration = duration
        self._base = base
        grid = np.linspace(0.0, duration, int(duration * 1000) + 1)
        phase = np.mod(grid, moving + resting)
        ramp = np.clip(np.minimum(phase, moving - phase) / 1.0, 0.0, 1.0)  # 0-1-0 over each moving span
        speed = np.where(phase < moving, ramp * ramp * (3 - 2 * ramp), 0.0)
        self._grid, self._speed = grid, speed
        self._s = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(grid))])

    def _warp(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        return np.interp(t, self._grid, self._s), np.interp(t, self._grid, self._speed)

    def attitude(self, t):
        return self._base.attitude(self._warp(t)[0])

    def rate(self, t):
        s, speed = self._warp(t)
        return self._base.rate(s) * speed[:, None]


class Pendulum(Trajectory):
    """A pendulum of length ``length`` m swinging at its natural rate sqrt(g/L) with amplitude ``amplitude`` rad,
    its plane of swing turning about the vertical at ``precession`` rad/s so that it swings in every direction.

    The sensor is at the bob: its specific force points along the rod (to the small-angle approximation of the
    motion), so no single accelerometer sample tells the tilt, and the acceleration is as large as gravity's
    tangential part and turns with the body (a lever arm).  NED, FRD, as every trajectory.
    """

    def __init__(
        self,
        duration: float,
        length: float = 0.5,
        amplitude: float = np.radians(30.0),
        precession: float = np.radians(5.0),
        phase: float = 0.0,
    ):
        self.duration = duration
        self.length, self.amplitude, self.precession, self.phase = length, amplitude, precession, phase
        self.omega = np.sqrt(9.80665 / length)

    def _angles(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        theta = self.amplitude * np.cos(self.omega * t + self.phase)
        theta_dot = -self.amplitude * self.omega * np.sin(self.omega * t + self.phase)
        return t, theta, theta_dot, self.precession * t

    def attitude(self, t):
        _, theta, _, psi = self._angles(t)
        qz = np.column_stack([np.cos(psi / 2), 0 * psi, 0 * psi, np.sin(psi / 2)])
        qx = np.column_stack([np.cos(theta / 2), np.sin(theta / 2), 0 * theta, 0 * theta])
        from strapdown.rotations.quaternion import multiply

        return multiply(qz, qx)

    def rate(self, t):
        _, theta, theta_dot, _ = self._angles(t)
        return np.column_stack([theta_dot, self.precession * np.sin(theta), self.precession * np.cos(theta)])

    def _position(self, t):
        _, theta, _, psi = self._angles(t)
        # R_z(psi) R_x(theta) (0, 0, L): the bob below the pivot (NED z down)
        y, z = -np.sin(theta) * self.length, np.cos(theta) * self.length
        return np.column_stack([-np.sin(psi) * y, np.cos(psi) * y, z])

    def acceleration(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        h = 1e-3
        return (self._position(t + h) - 2.0 * self._position(t) + self._position(t - h)) / (h * h)


def consumer(calibrated_mag: bool = True, **gyro_changes) -> ImuModel:
    """The consumer preset, its magnetometer calibrated (hard and soft iron removed) unless asked otherwise."""
    imu = ImuModel.consumer_mems()
    imu = replace(imu, clock=ClockModel())  # no jitter unless a condition adds it
    if calibrated_mag:
        imu = replace(imu, mag=replace(imu.mag, bias=np.zeros(3), soft_iron=np.eye(3)))
    return replace(imu, gyro=replace(imu.gyro, **gyro_changes)) if gyro_changes else imu


def motion(seed: int, duration: float = 120.0, acceleration: float = 1.0) -> Trajectory:
    return RandomMotion(duration=duration, seed=seed, acceleration_scale=acceleration)


def conditions():
    """name -> function(seed) -> (trajectory, rate_hz, imu, disturbances, drop fraction, settle s[, params])."""
    deg = np.radians
    c = {}
    c["consumer, 100 Hz (base)"] = lambda s: (motion(s), 100.0, consumer(), (), 0.0, 10.0)
    c["  same, accelerometer bias not modelled"] = lambda s: (
        motion(s),
        100.0,
        consumer(),
        (),
        0.0,
        10.0,
        {"acc_bias_sigma_init": 0.0},
    )
    c["ideal IMU"] = lambda s: (motion(s), 100.0, ImuModel.ideal(), (), 0.0, 10.0)
    c["tactical IMU"] = lambda s: (motion(s), 100.0, ImuModel.tactical(), (), 0.0, 10.0)
    for rate in (50.0, 400.0, 1000.0):
        c[f"consumer, {rate:.0f} Hz"] = lambda s, rate=rate: (motion(s, 60.0), rate, consumer(), (), 0.0, 10.0)
    jitter = replace(consumer(), clock=ClockModel(jitter=1e-3))
    c["jitter 1 ms (true times)"] = lambda s: (motion(s), 100.0, jitter, (), 0.0, 10.0)
    c["10 % rows dropped"] = lambda s: (motion(s), 100.0, consumer(), (), 0.1, 10.0)
    passing = [MagneticDisturbance(40.0, 50.0, (30.0, 10.0, -20.0))]
    c["magnet passing, 10 s"] = lambda s: (motion(s), 100.0, consumer(), passing, 0.0, 10.0)
    carried = [MagneticDisturbance(40.0, 60.0, (20.0, -15.0, 10.0), frame="body")]
    c["magnet carried, 20 s"] = lambda s: (motion(s), 100.0, consumer(), carried, 0.0, 10.0)
    c["uncalibrated magnetometer"] = lambda s: (motion(s), 100.0, consumer(calibrated_mag=False), (), 0.0, 10.0)
    c["accelerating start (2 m/s²)"] = lambda s: (motion(s, 60.0, 2.0), 100.0, consumer(), (), 0.0, 0.0)
    c["long rests (20 s on, 40 s off)"] = lambda s: (
        WithRests(motion(s, acceleration=0.0), 20.0, 40.0, 240.0),
        100.0,
        consumer(bias=deg([1.0, -0.8, 0.6])),
        (),
        0.0,
        10.0,
    )
    # turntables: the bias about the vertical is unobservable in 6D (a rotation about gravity leaves the
    # accelerometer unchanged), so only the magnetometer's heading rate (9D) tells it
    for spin in (30.0, 90.0):
        c[f"turntable {spin:.0f}°/s"] = lambda s, spin=spin: (
            ConstantRotation(deg([0.0, 0.0, spin]), duration=120.0),
            100.0,
            consumer(),
            (),
            0.0,
            10.0,
        )
    # handheld: flicks to 900°/s with 2 g jolts (the accelerometer start and the bias regression must not learn
    # from a jolt: the acceleration noise term of step 3); clipped at 400°/s, the saturation bridge gives the
    # peaks' lost turn back (fusion/saturation.py)
    c["handheld, flicks to 900°/s"] = lambda s: (Handheld(120.0, seed=s), 100.0, consumer(), (), 0.0, 10.0)
    c["  same, gyro clipping at 400°/s"] = lambda s: (
        Handheld(120.0, seed=s),
        100.0,
        consumer(range=deg(400.0)),
        (),
        0.0,
        10.0,
    )
    c["pendulum (0.5 m, 30°)"] = lambda s: (Pendulum(120.0, phase=s), 100.0, consumer(), (), 0.0, 10.0)
    c["  same, ideal IMU"] = lambda s: (Pendulum(120.0, phase=s), 100.0, ImuModel.ideal(), (), 0.0, 10.0)
    c["gyro bias 5°/s (x)"] = lambda s: (motion(s), 100.0, consumer(bias=deg([5.0, 0.3, -0.2])), (), 0.0, 10.0)
    c["gyro bias 3-5°/s (all axes)"] = lambda s: (
        motion(s),
        100.0,
        consumer(bias=deg([4.0, -5.0, 3.0])),
        (),
        0.0,
        10.0,
    )
    return c


def run_condition(make, seed: int, tilt_params=None, params=None) -> dict:
    from vqf import VQF, offlineVQF

    traj, rate, imu, disturbances, drop, settle, *rest = make(seed)
    params = {**(params or {}), **(rest[0] if rest else {})}  # the condition's own override wins
    d = sample(
        traj,
        rate,
        gyro="average",
        imu=imu,
        reference="ENU",
        body="FLU",
        magnetic_field=FIELD,
        disturbances=disturbances,
        seed=seed,
    )
    t = d.t[1:]  # each sample's end (its data-ready time); the estimate after it is the truth there
    truth = d.q_true[1:]
    rows = np.ones(len(t), bool)
    if drop:
        rows = np.random.default_rng(seed + 100).random(len(t)) >= drop
        rows[0] = True
    g, a, m, tr = (np.ascontiguousarray(x[rows]) for x in (d.gyro, d.acc, d.mag, t))
    dt = 1.0 / rate
    est = {
        "ours 6D": attitude(g, a, t=tr, params=params).q,
        "ours 9D": attitude(g, a, m, t=tr, params=params).q,
        "VQF 6D": VQF(dt).updateBatch(g, a)["quat6D"],
        "Tilt 6D": tilt(g, a, t=tr, params=TiltParams(**(tilt_params or {}))).q,
        "VQF 9D": VQF(dt).updateBatch(g, a, m)["quat9D"],
    }
    est["ours offline 9D"] = est["ours offline 6D"] = attitude_offline(g, a, m, t=tr, params=params).q
    est["offlineVQF 9D"] = est["offlineVQF 6D"] = offlineVQF(g, a, m, dt)["quat9D"]
    scored = tr >= tr[0] + settle
    out = {}
    for name, q in est.items():
        e = attitude_errors(q, truth[rows])
        if "6D" in name:
            out[name] = float(np.degrees(np.sqrt(np.mean(e["inclination"][scored] ** 2))))
        else:
            out[name] = float(np.degrees(np.sqrt(np.mean(e["total"][scored] ** 2))))
    return out


def long_turntables(seed: int = 0, minutes: int = 10, params=None) -> dict:
    """The turntables for ten minutes: 6D inclination RMSE per two-minute window (not counted in the table).

    On a steady turn about the vertical a horizontal gyro bias and a horizontal accelerometer bias are both fixed in
    the body and tilt the estimate alike, so the motion cannot tell them apart, and what an estimator learns from it
    drifts along that split for as long as the turn lasts: two minutes (the table's records) show where an estimator
    is on the way, not where it goes.
    """
    from vqf import VQF

    out = {}
    for spin in (30.0, 90.0):
        d = sample(
            ConstantRotation(np.radians([0.0, 0.0, spin]), duration=60.0 * minutes),
            100.0,
            gyro="average",
            imu=consumer(),
            reference="ENU",
            body="FLU",
            seed=seed,
        )
        truth = d.q_true[1:]
        est = {
            "ours 6D": attitude(d.gyro, d.acc, dt=0.01, params=params).q,
            "VQF 6D": VQF(0.01).updateBatch(d.gyro, d.acc)["quat6D"],
            "Tilt 6D": tilt(d.gyro, d.acc, dt=0.01).q,
        }
        rows = {}
        for name, q in est.items():
            e = np.degrees(attitude_errors(q, truth)["inclination"])
            rows[name] = [float(np.sqrt(np.mean(w**2))) for w in np.array_split(e, minutes // 2)]
        out[f"turntable {spin:.0f}°/s"] = rows
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--tilt-params", type=json.loads, help="TiltParams overrides as JSON, e.g. '{\"tau_acc\": 2.5}'")
    ap.add_argument(
        "--params", type=json.loads, help="AttitudeParams overrides as JSON, e.g. '{\"gyro_acc_bias_significance\": 1}'"
    )
    ap.add_argument("--no-long", action="store_true", help="leave out the ten-minute turntables")
    ap.add_argument("--json")
    args = ap.parse_args(argv)
    try:
        import vqf  # noqa: F401
    except ImportError:
        print("vqf is not installed (pip install 'strapdown[bench]'): the test-bed compares against it")
        return 1
    t0 = time.perf_counter()
    # (ours, reference, mode) compared per condition
    pairs = (
        ("ours 6D", "VQF 6D", "6D"),
        ("Tilt 6D", "VQF 6D", "Tilt"),
        ("ours 9D", "VQF 9D", "9D"),
        ("ours offline 6D", "offlineVQF 6D", "off 6D"),
        ("ours offline 9D", "offlineVQF 9D", "off 9D"),
    )
    names = list(dict.fromkeys(n for pair in pairs for n in pair[:2]))
    short = {
        "ours offline 6D": "off 6D",
        "offlineVQF 6D": "oVQF 6D",
        "ours offline 9D": "off 9D",
        "offlineVQF 9D": "oVQF 9D",
    }
    print(
        "Simulated test-bed, RMSE in degrees (6D: inclination, 9D: total; offline likewise), "
        f"mean of {args.seeds} seeds"
    )
    print(f"{'condition':34}" + "".join(f"{short.get(n, n):>10}" for n in names) + "   better")
    results = {}
    wins = {mode: 0 for *_, mode in pairs}
    for label, make in conditions().items():
        per_seed = [run_condition(make, seed, args.tilt_params, args.params) for seed in range(args.seeds)]
        means = {n: float(np.mean([r[n] for r in per_seed])) for n in names}
        better = []
        for ours, ref, mode in pairs:
            wins[mode] += means[ours] < means[ref]
            better.append(f"{mode}: {'ours' if means[ours] < means[ref] else 'VQF'}")
        print(f"{label:34}" + "".join(f"{means[n]:10.3f}" for n in names) + "   " + ", ".join(better))
        results[label] = means
    n = len(results)
    print("ours better in " + ", ".join(f"{wins[mode]}/{n} conditions in {mode}" for mode in wins))
    long = {}
    if not args.no_long:
        long = long_turntables(params=args.params)
        print("\nThe turntables for ten minutes (seed 0; not counted above): 6D inclination RMSE per two minutes")
        for label, rows in long.items():
            for name, windows in rows.items():
                print(f"  {label:18} {name:8}" + "".join(f"{w:8.3f}" for w in windows))
    print(f"({time.perf_counter() - t0:.0f} s)")
    if args.json:
        Path(args.json).write_text(json.dumps({"conditions": results, "long_turntables": long}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
