"""Accuracy figures of issue 16's rotation spline and synthetic IMU data (the tests assert bounds; this prints them).

    python benchmarks/accuracy_rotations.py

1. RotationSpline against scipy's RotationSpline on random data (60 knots at random times, independent uniformly
   random attitudes and random walks): largest differences of attitude (rad), rate and acceleration (relative to
   the largest value), with scipy iterated to convergence and with scipy's defaults (TOL 1e-9, 10 iterations).
2. The spline's body rates integrated back (RK4 from rates at 4, 8, 16 points per knot interval) over 10⁴ knots of
   smooth motion at 100 Hz: largest angle to the spline's attitudes at the knots.
3. Motion capture at 100 Hz (60 s, RandomMotion, rates to ~3 rad/s) -> sample_recorded -> strapdown.integrate:
   largest angle to the recorded samples, per gyro form and IMU rate; and the spline's rate against the true
   motion's, inside the record and at its ends.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation
from scipy.spatial.transform import RotationSpline as ScipySpline

from strapdown import angle_between, integrate
from strapdown.propagate.interpolate import RotationSpline
from strapdown.simulate import RandomMotion, sample_recorded


def random_walk(n, step, rng):
    steps = Rotation.from_rotvec(step * rng.standard_normal((n, 3)))
    out = [steps[0]]
    for s in steps[1:]:
        out.append(out[-1] * s)
    return Rotation.concatenate(out).as_quat(scalar_first=True)


def against_scipy(rng):
    print("1. RotationSpline vs scipy RotationSpline (60 knots, 5000 random times; 10 data sets each)")
    print(f"{'data':<22} {'scipy':<10} {'attitude rad':>13} {'rate rel':>10} {'accel rel':>10}")
    for label, make in (
        ("random walk 0.01 rad", lambda: random_walk(60, 0.01, rng)),
        ("random walk 0.3 rad", lambda: random_walk(60, 0.3, rng)),
        ("independent random", lambda: Rotation.random(60, rng=rng).as_quat(scalar_first=True)),
    ):
        for mode, tol, iters in (("converged", 1e-15, 5000), ("default", 1e-9, 10)):
            ScipySpline.TOL, ScipySpline.MAX_ITER = tol, iters
            worst = np.zeros(3)
            for _ in range(10):
                t = np.cumsum(rng.uniform(0.05, 1.0, 60))
                q = make()
                ours = RotationSpline(t, q)
                theirs = ScipySpline(t, Rotation.from_quat(q, scalar_first=True))
                tn = rng.uniform(t[0], t[-1], 5000)
                qa = theirs(tn).as_quat(scalar_first=True)
                worst[0] = max(worst[0], angle_between(ours(tn), qa).max())
                for k in (1, 2):
                    ref = theirs(tn, k)
                    worst[k] = max(worst[k], np.abs(ours(tn, k) - ref).max() / np.abs(ref).max())
            print(f"{label:<22} {mode:<10} {worst[0]:13.2e} {worst[1]:10.2e} {worst[2]:10.2e}")
    ScipySpline.TOL, ScipySpline.MAX_ITER = 1e-9, 10


def integrate_back():
    print("\n2. spline rates integrated back by RK4, 10^4 knots at 100 Hz: largest angle at the knots (rad)")
    n = 10_001
    t = np.arange(n) / 100.0
    q = RandomMotion(duration=t[-1] + 0.01, seed=1, rate_scale=2.0).attitude(t)
    s = RotationSpline(t, q)
    for sub in (4, 8, 16):
        ts = np.linspace(t[0], t[-1], (n - 1) * sub + 1)
        q_int = integrate(s(ts[:-1], 1), t=ts, q0=s(t[0]), method="rk4", input="rate")
        print(f"  {sub:>2} rate points per interval: {angle_between(q_int[::sub], q).max():.2e}")


def mocap():
    print("\n3. capture at 100 Hz, 60 s -> sample_recorded -> integrate: largest angle to the samples (rad)")
    t = np.arange(6001) / 100.0
    truth = RandomMotion(duration=60.0, seed=2, rate_scale=2.0)
    q = truth.attitude(t)
    data = sample_recorded(t, q, gyro="rotvec")
    print(f"  gyro='rotvec' at 100 Hz, exact:        {angle_between(data.integrate('exact'), q).max():.2e}")
    for rate in (100, 400, 1000):
        data = sample_recorded(t, q, float(rate), gyro="increment")
        step = rate // 100
        err = angle_between(data.integrate("coning2")[::step], q).max()
        print(f"  gyro='increment' at {rate:>4} Hz, coning2: {err:.2e}")
    data = sample_recorded(t, q, 100.0, gyro="rate")
    err = np.abs(data.gyro - truth.rate(t[:-1])).max(axis=-1)
    print(f"  spline rate vs true rate (rad/s), inside [20:-20]: {err[20:-20].max():.2e}; first interval: {err[0]:.2e}")


def main():
    rng = np.random.default_rng(16)
    against_scipy(rng)
    integrate_back()
    mocap()


if __name__ == "__main__":
    main()
