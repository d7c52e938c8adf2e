"""
A lesson: coordinated flight and the accelerometer
==================================================

An aircraft in a coordinated turn or a loop pulls lift along its own vertical axis, and its accelerometer
reads that lift, not gravity: the specific force points "down" in body axes whatever the bank angle.  Every
filter that corrects its tilt towards the accelerometer is then pulled towards a level attitude, and no tuning
fixes that: the information is not in the readings.  The top panel measures it: the angle between what the
accelerometer reads and where gravity really is, in body axes.

Given the kinematic acceleration (``known_acc=``; air data or GNSS would supply it, the simulator's truth does
here) the :class:`~strapdown.fusion.AttitudeEstimator` and the :class:`~strapdown.fusion.TiltEstimator`
subtract it and track the tilt down to the accelerometer's own bias.  ``strapdown demo`` prints the same two
tables and writes this comparison as ``out/aerobatic_show_fusion.png``.
"""

import matplotlib.pyplot as plt
import numpy as np

import strapdown as sd
from strapdown.evaluate.figures import line_styles
from strapdown.evaluate.metrics import attitude_errors
from strapdown.fusion import AttitudeEstimator, Madgwick, TiltEstimator
from strapdown.simulate import ImuModel, aerobatic_show, sample

show = aerobatic_show()
data = sample(show, 100.0, imu=ImuModel.consumer_mems(), seed=1)  # NED/FRD
ideal = sample(show, 100.0, seed=1)
t = data.t[1:]

# specific force less gravity (-g along down in NED) in body axes, at the middle of each step
q_mid = sd.quaternion.normalize(ideal.q_true[1:] + ideal.q_true[:-1])
gravity_body = sd.quaternion.rotate(sd.quaternion.conjugate(q_mid), [0.0, 0.0, -9.80665])  # what rest would read
known = ideal.acc - gravity_body
cos = np.sum(ideal.acc * gravity_body, axis=1) / np.linalg.norm(ideal.acc, axis=1) / 9.80665
misread = np.degrees(np.arccos(np.clip(cos, -1, 1)))
print(f"the accelerometer points up to {misread.max():.0f}° away from gravity")

runs = {
    "gyro only": data.integrate("exact")[1:],
    "AttitudeEstimator 9D, known acc.": AttitudeEstimator(frame="NED")
    .update(data.gyro, data.acc, data.mag, dt=0.01, known_acc=known)
    .q,
    "TiltEstimator, known acc.": TiltEstimator(frame="NED").update(data.gyro, data.acc, dt=0.01, known_acc=known).q,
    "AttitudeEstimator 9D": AttitudeEstimator(frame="NED").update(data.gyro, data.acc, data.mag, dt=0.01).q,
    "TiltEstimator": TiltEstimator(frame="NED").update(data.gyro, data.acc, dt=0.01).q,
    "Madgwick 9D": Madgwick(frame="NED").update(data.gyro, data.acc, data.mag, dt=0.01).q,
}
incl = {label: np.degrees(attitude_errors(q, data.q_true[1:])["inclination"]) for label, q in runs.items()}
for label, e in incl.items():
    print(f"{label:34} inclination RMS {np.sqrt(np.mean(e**2)):6.2f}°")

# %%
fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 9), constrained_layout=True)
axes[0].plot(t, misread, color="k", lw=1)
axes[0].set_ylabel("accelerometer vs\ngravity [deg]")
axes[0].set_title("aerobatic show, consumer MEMS IMU: what the accelerometer reads is not gravity")
styles = dict(zip(runs, line_styles(len(runs)), strict=True))
panels = (
    (axes[1], ("gyro only", "AttitudeEstimator 9D, known acc.", "TiltEstimator, known acc."), "given the known acc."),
    (axes[2], ("gyro only", "AttitudeEstimator 9D", "TiltEstimator", "Madgwick 9D"), "LESSON: without it"),
)
for ax, members, title in panels:
    for label in members:
        e = incl[label]
        ax.plot(t, e, label=f"{label} ({np.sqrt(np.mean(e**2)):.1f}° RMS)", **styles[label])
    ax.set_yscale("log")
    ax.set_ylim(0.02, 180)
    ax.set_ylabel("inclination error [deg]")
    ax.set_title(title, fontsize=10, color="C3" if title.startswith("LESSON") else "k")
    ax.legend(fontsize=8, loc="lower right", ncol=2)
for ax in axes:
    ax.grid(alpha=0.3, which="both")
axes[-1].set_xlabel("time [s]")
plt.show()
