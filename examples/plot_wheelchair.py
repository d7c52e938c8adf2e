"""
The Rowe wheelchair, with and without the known acceleration
============================================================

US Patent 6,377,906 (Rowe, 2002) estimates the tilt of a wheelchair: a body that drives, turns and rocks in
pitch and roll over bumps.  Its accelerometer reads gravity plus the chair's own acceleration (speeding up,
slowing down, and the centripetal acceleration of every turn), and an estimator that takes all of it for
gravity is tilted by it.  Wheel odometry knows the speed and the turn rate, and so that kinematic
acceleration: given as ``known_acc``, it is subtracted from the accelerometer before the tilt is corrected.

Here the known acceleration is the simulator's truth (specific force less gravity, at the middle of each
step); a real chair would compute it from its wheel speeds.  Both the patent's
:class:`~strapdown.fusion.TiltEstimator` and the :class:`~strapdown.fusion.AttitudeEstimator` (6D) run with and
without it, on a tactical-grade IMU: with a consumer MEMS accelerometer its own bias (10-20 mg, about 1°) would
remain whatever the filter does, and hide the effect (the README's figure, 2.3°, is that case).
"""

import matplotlib.pyplot as plt
import numpy as np

import strapdown as sd
from strapdown.evaluate.figures import line_styles
from strapdown.evaluate.metrics import attitude_errors
from strapdown.fusion import AttitudeEstimator, TiltEstimator
from strapdown.simulate import ImuModel, RockingPlatform, sample

chair = RockingPlatform(duration=180.0)
data = sample(chair, 100.0, imu=ImuModel.tactical(), reference="ENU", body="FLU", seed=3)
truth_only = sample(chair, 100.0, reference="ENU", body="FLU")  # the same ride, ideal sensors

# kinematic acceleration in body axes: specific force less gravity (+g up in ENU), at the middle of each step
q_mid = sd.quaternion.normalize(truth_only.q_true[1:] + truth_only.q_true[:-1])
known = truth_only.acc - sd.quaternion.rotate(sd.quaternion.conjugate(q_mid), [0.0, 0.0, 9.80665])
horizontal = np.linalg.norm(known[:, :2], axis=1).max()
false_tilt = np.degrees(np.arctan(horizontal / 9.81))
print(f"kinematic acceleration: horizontal up to {horizontal:.2f} m/s², {false_tilt:.1f}° of false tilt")

runs = {
    "TiltEstimator": TiltEstimator().update(data.gyro, data.acc, dt=0.01),
    "TiltEstimator, known acc.": TiltEstimator().update(data.gyro, data.acc, dt=0.01, known_acc=known),
    "AttitudeEstimator 6D": AttitudeEstimator().update(data.gyro, data.acc, dt=0.01),
    "AttitudeEstimator 6D, known acc.": AttitudeEstimator().update(data.gyro, data.acc, dt=0.01, known_acc=known),
}
t = data.t[1:]
settled = t > 60.0  # past the start-up and the first bias learning
incl = {label: np.degrees(attitude_errors(est.q, data.q_true[1:])["inclination"]) for label, est in runs.items()}
for label, e in incl.items():
    print(
        f"{label:34} inclination RMS after 60 s: {np.sqrt(np.mean(e[settled] ** 2)):.2f}°, max {e[settled].max():.2f}°"
    )

# %%
# Without the known acceleration every turn and every change of speed tilts the estimate; with it, what
# remains is the accelerometer's own bias, which no filter can tell from a tilt.
styles = line_styles(len(runs))
fig, axes = plt.subplots(3, 1, figsize=(10, 8.5), constrained_layout=True)
axes[1].sharex(axes[0])
truth_angles = sd.as_euler(data.q_true[1:], "ZYX", degrees=True)
window = (t > 100) & (t < 130)
for ax, k, name in ((axes[0], 1, "pitch"), (axes[1], 2, "roll")):
    ax.plot(t[window], truth_angles[window, k], color="0.6", lw=4, alpha=0.6, zorder=1, label="truth")
    for (label, est), style in zip(runs.items(), styles, strict=True):
        ax.plot(t[window], sd.as_euler(est.q[window], "ZYX", degrees=True)[:, k], label=label, zorder=2, **style)
    ax.set_ylabel(f"{name} [deg]")
    ax.grid(alpha=0.3)
axes[0].set_title("the wheelchair driving, turning and rocking: 30 s of pitch and roll")
axes[0].legend(fontsize=8, ncol=3, loc="upper left")
axes[1].set_xlabel("time [s]")
ax = axes[2]
for (label, e), style in zip(incl.items(), styles, strict=True):
    ax.plot(t, e, label=f"{label}: {np.sqrt(np.mean(e[settled] ** 2)):.2f}° RMS after 60 s", **style)
ax.set_yscale("log")
ax.set_ylim(0.01, 20)
ax.set_ylabel("inclination error [deg]")
ax.set_xlabel("time [s]")
ax.grid(alpha=0.3, which="both")
ax.legend(fontsize=8, ncol=2, loc="upper right")
plt.show()
