"""
Integration error orders and coning drift
=========================================

Two measurements of the propagation methods against the closed forms of math.md §6-§7, on exact simulated
readings (no sensor error), log-log with the theory drawn as lines:

* **convergence on a generic smooth motion**: the largest attitude error over 2 s of
  :class:`~strapdown.simulate.RandomMotion` as the sample interval h shrinks.  ``exact`` from start-of-step
  rates is first order (it holds the sample over the step), from increments second order; ``rk4`` from rates and
  ``coning2`` from increments are fourth order.
* **coning drift**: under pure coning (half-angle α, frequency Ω) an algorithm's attitude error grows
  linearly about the cone axis at the rate ρ α² Ω (ΩT)^p, T the update interval.  One-sample ``exact`` has
  ρ = -1/12, p = 2; ``coning2`` -1/960, p = 4; ``rk4`` +1/960, p = 4 (its stages use two samples per step):
  the two fourth-order methods drift equally fast in opposite directions.
"""

from fractions import Fraction

import matplotlib.pyplot as plt
import numpy as np

import strapdown as sd
from strapdown.simulate import Coning, RandomMotion, sample

# %%
# Convergence orders
# ------------------
motion = RandomMotion(duration=2.0, seed=4, rate_scale=2.0)
steps = np.array([0.04, 0.02, 0.01, 0.005])
cases = [("exact", "rate", 1), ("exact", "increment", 2), ("rk4", "rate", 4), ("coning2", "increment", 4)]
errors = {}
for method, gyro, order in cases:
    errs = []
    for h in steps:
        data = sample(motion, 1 / h, gyro=gyro)
        errs.append(sd.angle_between(data.integrate(method)[4:], data.q_true[4:]).max())
    errors[method, gyro, order] = np.array(errs)
    slope = np.polyfit(np.log(steps), np.log(errs), 1)[0]
    print(f"{method:8} from {gyro:9}: measured order {slope:4.2f} (theory {order})")

# %%
# Coning drift
# ------------
alpha, freq = np.radians(1.0), 10.0
omega = 2 * np.pi * freq
cone = Coning(alpha, freq, duration=6.0)
coning_cases = [("exact", "increment", 1, -1 / 12, 2), ("coning2", "increment", 2, -1 / 960, 4)]
coning_cases.append(("rk4", "rate", 2, 1 / 960, 4))
rates = np.array([200.0, 400.0, 800.0])
drift = {}
for method, gyro, samples, rho, power in coning_cases:
    slopes = []
    for rate in rates:
        data = sample(cone, rate, gyro=gyro)
        e = sd.as_rotvec(sd.multiply(data.integrate(method), sd.quaternion.conjugate(data.q_true)))
        half = len(e) // 2  # past the start-up, the x error grows linearly: fit its slope
        slopes.append(np.polyfit(data.t[half:], e[half:, 0], 1)[0])
    drift[method] = np.array(slopes)
    print(
        f"{method:8}: measured / predicted drift",
        np.round(drift[method] / (rho * alpha**2 * omega * (omega * samples / rates) ** power), 3),
    )

# %%
# The figure
# ----------
fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5), constrained_layout=True)
for ((method, gyro, order), errs), colour in zip(errors.items(), ["C0", "C1", "C2", "C3"], strict=True):
    a.loglog(steps, np.degrees(errs), "o", color=colour, label=f"{method} ({gyro})")
    anchor = np.degrees(errs[1]) / steps[1] ** order
    a.loglog(steps, anchor * steps**order, "--", color=colour, lw=1, label=f"h^{order}")
a.set_xlabel("sample interval h [s]")
a.set_ylabel("largest attitude error over 2 s [deg]")
a.set_title("convergence on a random smooth motion (points: measured, dashed: order)")
a.grid(alpha=0.3, which="both")
a.legend(fontsize=8, ncol=2)

dense = np.geomspace(rates[0] / 1.5, rates[-1] * 1.5, 50)
for (method, gyro, samples, rho, power), colour in zip(coning_cases, ["C0", "C3", "C2"], strict=True):
    x = omega / rates
    to_deg_h = np.degrees(1) * 3600
    fraction = Fraction(rho).limit_denominator(1000)
    marker = {"marker": "s", "fillstyle": "none", "ms": 10} if method == "rk4" else {"marker": "o"}
    b.loglog(x, np.abs(drift[method]) * to_deg_h, ls="", color=colour, label=f"{method} ({gyro}), measured", **marker)
    theory = np.abs(rho) * alpha**2 * omega * (omega * samples / dense) ** power * to_deg_h
    b.loglog(omega / dense, theory, "--", color=colour, lw=1, label=f"{fraction} α²Ω(ΩT)^{power}")
b.set_xlabel("Ω h (cone frequency × sample interval) [rad]")
b.set_ylabel("|coning drift| [deg/h]")
b.set_title(f"coning drift, α = 1°, f = {freq:g} Hz (dashed: math.md §6.3)")
b.grid(alpha=0.3, which="both")
b.legend(fontsize=8)
plt.show()
