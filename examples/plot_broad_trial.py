"""
The estimators on a BROAD trial, against the optical reference
==============================================================

BROAD (Laidig, Caruso, Cereatti and Seel, Data 6(7):72, 2021; CC BY 4.0) records a hand-held IMU with an
optical motion-capture reference.  This trial, ``29_disturbed_stationary_magnet_B``, rotates the sensor with
rest breaks and passes it by a magnet: the rests are where the gyro bias can be learnt directly, the magnet is
where a 9D filter must stop trusting its magnetometer.

Four 9D estimators run on the same readings with their default parameters: the
:class:`~strapdown.fusion.AttitudeEstimator`, its offline smoother :func:`~strapdown.fusion.attitude_offline`,
:class:`~strapdown.fusion.Madgwick` and :class:`~strapdown.fusion.Mahony`.  The figure shows the Euler angles
against the reference, and the total error (BROAD's measure, :func:`strapdown.evaluate.metrics.attitude_errors`) over
time, with the AttitudeEstimator's rest and magnetic-disturbance flags shaded.

BROAD lives beside the repository (``../shared/data/broad``, or set ``STRAPDOWN_BROAD`` to its folder).  When it
is absent the example runs on a simulated recording of the same kind instead (turns and rests with a magnet
passing, from :func:`strapdown.apps.demo.turns_and_rests`), so that it always draws its figure.
"""

import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from strapdown.evaluate.figures import angles_for_display, line_styles
from strapdown.evaluate.metrics import attitude_errors, rmse
from strapdown.fusion import FLAG_MAG_REJECTED, FLAG_REST, AttitudeEstimator, Madgwick, Mahony, attitude_offline

try:
    HERE = Path(__file__).resolve().parent
except NameError:  # run interactively
    HERE = Path.cwd()
BROAD = Path(os.environ.get("STRAPDOWN_BROAD", HERE.parent.parent / "shared" / "data" / "broad"))
TRIAL = BROAD / "data_mat" / "29_disturbed_stationary_magnet_B.mat"


def simulated_trial():
    """A hand-held sensor turned every way and put down between the turns, a magnet passing: the same kind."""
    from strapdown.apps.demo import turns_and_rests
    from strapdown.simulate import ImuModel, MagneticDisturbance, MagneticField, TriadModel, sample

    consumer = ImuModel.consumer_mems()
    imu = ImuModel(gyro=consumer.gyro, acc=consumer.acc, mag=TriadModel(noise_density=consumer.mag.noise_density))
    rate = 100.0
    data = sample(
        turns_and_rests(),
        rate,
        imu=imu,
        magnetic_field=MagneticField(declination_deg=0.0),
        disturbances=[MagneticDisturbance(80.0, 95.0, (35.0, -20.0, 25.0))],
        reference="ENU",
        body="FLU",
        seed=2,
    )
    movement = np.ones(len(data.gyro), dtype=bool)
    return "simulated (BROAD not found)", data.gyro, data.acc, data.mag, data.q_true[1:], movement, rate


if TRIAL.exists():
    from strapdown.evaluate.broad import load_trial

    trial = load_trial(TRIAL)
    name, gyr, acc, mag, truth, movement, rate = (
        trial.name, trial.gyro, trial.acc, trial.mag, trial.quat, trial.movement, trial.rate,
    )  # fmt: skip
else:
    name, gyr, acc, mag, truth, movement, rate = simulated_trial()
dt = 1.0 / rate
t = np.arange(len(gyr)) * dt

# %%
# Run the estimators (ENU, like BROAD's reference) and score them on the movement phases, as BROAD does.
main = AttitudeEstimator(frame="ENU").update(gyr, acc, mag, dt=dt)
runs = {
    "AttitudeEstimator": main,
    "attitude_offline": attitude_offline(gyr, acc, mag, dt=dt),
    "Madgwick": Madgwick(frame="ENU").update(gyr, acc, mag, dt=dt),
    "Mahony": Mahony(frame="ENU").update(gyr, acc, mag, dt=dt),
}
errors = {label: np.degrees(attitude_errors(est.q, truth)["total"]) for label, est in runs.items()}
print(f"{name}: total RMSE over the movement phases (degrees)")
for label, e in errors.items():
    print(f"  {label:18} {rmse(e, movement):6.2f}")

# %%
# The figure: the angles during 15 s of motion against the reference (drawn wide and grey under the
# estimates; a whole recording of hand-held turns would be a blur), then the error over the whole trial.
rest = (main.flags & FLAG_REST) > 0
disturbed = (main.flags & FLAG_MAG_REJECTED) > 0
moving = np.flatnonzero(movement & ~rest)
start = moving[len(moving) // 4] if moving.size else 0
window = slice(start, min(len(t), start + int(15 * rate)))
thin = slice(None, None, max(1, len(t) // 6000))  # a few thousand points per line are plenty for the eye


def shade(ax, mask, colour, label):
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
    for k, (a, b) in enumerate(zip(edges[::2], edges[1::2], strict=True)):
        ax.axvspan(t[a], t[b - 1], color=colour, lw=0, zorder=0, label=label if k == 0 else None)


fig = plt.figure(figsize=(11, 10), constrained_layout=True)
grid = fig.add_gridspec(4, 1, height_ratios=[1, 1, 1, 1.3])
axes = [fig.add_subplot(grid[0])]
axes += [fig.add_subplot(grid[i], sharex=axes[0]) for i in (1, 2)]
axes.append(fig.add_subplot(grid[3]))
ref_angles, _ = angles_for_display(truth[window])
styles = line_styles(len(runs))
for i, label in enumerate(("yaw [deg]", "pitch [deg]", "roll [deg]")):
    ax = axes[i]
    ax.plot(t[window], ref_angles[:, i], color="0.6", lw=4, alpha=0.6, zorder=1, label="optical reference")
    for (run, est), style in zip(runs.items(), styles, strict=True):
        v, _ = angles_for_display(est.q[window], align=ref_angles)  # on the reference's branch of yaw and roll
        ax.plot(t[window], v[:, i], zorder=2, label=run, **style)
    ax.set_ylabel(label)
    ax.grid(alpha=0.3)
axes[0].set_title(f"{name}: 9D estimators against the optical reference, {t[window][0]:.0f}-{t[window][-1]:.0f} s")
axes[0].legend(fontsize=8, ncol=5, loc="upper left")
axes[2].set_xlabel("time [s]")

ax = axes[3]
shade(ax, rest, "#dff0d8", "rest detected")
shade(ax, disturbed, "#f9d6d5", "magnetic disturbance detected")
for (run, e), style in zip(errors.items(), styles, strict=True):
    ax.plot(t[thin], e[thin], label=f"{run} ({rmse(e, movement):.2f}° RMS)", zorder=2, **style)
ax.set_yscale("log")
ax.set_ylim(0.05, 90)
ax.set_ylabel("total error [deg]")
ax.set_xlabel("time [s]")
ax.grid(alpha=0.3, which="both")
ax.axvspan(t[window][0], t[window][-1], color="0.85", lw=0, zorder=0, label="the window above")
ax.set_title("total error over the whole trial; shaded: the AttitudeEstimator's flags")
ax.legend(fontsize=8, ncol=3, loc="upper left")
plt.show()
