"""The worked examples printed by ``strapdown demo``, and the figures it writes.

1. Gajda's algorithm (1988, §2.3) step by step on a 360° roll at constant rate, checked against the closed form.
2. His conclusions 3a-3c put to the test: every propagation method on a hammerhead + loop, ideal gyro.
3. An aerobatic show with a realistic consumer MEMS IMU: every method, the table, plots and a CSV in ``out/``.
   Gyro errors dominate there.
4. Each estimator where it is meant to work.  The 9D AttitudeEstimator on a body that turns every way and
   rests in between, with a magnet passing by (:func:`turns_and_rests`): the rests teach it the gyro bias, the
   magnet is flagged and left out.  Then the aerobatic show given the kinematic acceleration (as air data
   would supply it): the AttitudeEstimator and the TiltEstimator hold the tilt to the accelerometer's own bias.
5. A lesson, labelled as one: in coordinated flight the accelerometer does not see gravity, so every filter
   that takes it for gravity (all of them, without the known acceleration) is pulled off.  The CSV's fused
   columns are the AttitudeEstimator's with the known acceleration.
6. The show written as a log file and its interactive report (``strapdown report``), whose path it prints.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._support.files import atomic_path
from ..rotations.euler import as_euler, from_euler
from ..rotations.quaternion import angle_between, multiply, norm
from ..rotations.rotvec import from_rotvec
from ..simulate.trajectories import Trajectory


@dataclass(frozen=True)
class RollDemo:
    """Result of :func:`gajda_roll`: one row per printed step.

    Attributes
    ----------
    t : numpy.ndarray, shape (m,)
        Times in seconds.
    q : numpy.ndarray, shape (m, 4)
        Attitudes from Gajda's loop.
    angles_deg : numpy.ndarray, shape (m, 3)
        Yaw, pitch, roll in degrees, Gajda's ranges (yaw in [0, 360)).
    error_rad : numpy.ndarray, shape (m,)
        Angle between the loop's attitude and the closed form ``q0 ⊗ [cos(pt/2), sin(pt/2), 0, 0]``.
    """

    t: np.ndarray
    q: np.ndarray
    angles_deg: np.ndarray
    error_rad: np.ndarray


def gajda_roll(
    yaw0_deg: float = 30.0,
    pitch0_deg: float = 10.0,
    roll0_deg: float = 0.0,
    roll_rate_deg_s: float = 90.0,
    steps_per_45deg: int = 50,
) -> RollDemo:
    """Run Gajda's five-stage algorithm through a 360° roll at constant rate about the body x axis.

    Parameters
    ----------
    yaw0_deg, pitch0_deg, roll0_deg : float
        Initial attitude (stage 1, Gajda 2.16).
    roll_rate_deg_s : float
        Constant body rate about x, degrees per second.
    steps_per_45deg : int
        Integration steps between printed rows.

    Returns
    -------
    RollDemo
        Rows every 45° of roll, from 0° to 360°.

    Examples
    --------
    >>> demo = gajda_roll()
    >>> demo.angles_deg[2].round(9)        # after 90 deg of roll: yaw and pitch unchanged
    array([30., 10., 90.])
    """
    dt = 45.0 / roll_rate_deg_s / steps_per_45deg
    omega = np.radians([roll_rate_deg_s, 0.0, 0.0])
    # Stage 1: the initial quaternion P from yaw, pitch, roll (Gajda 2.16).
    p = from_euler([yaw0_deg, pitch0_deg, roll0_deg], "ZYX", degrees=True)
    q0 = p
    # Stage 2: the rotation quaternion Q of omega over dt; constant here, so computed once.
    dq = from_rotvec(omega * dt)
    rows_t, rows_q = [0.0], [p]
    for k in range(1, 8 * steps_per_45deg + 1):
        p = multiply(p, dq)  # Stage 3: R = P ⊗ Q (2.14); stage 5: P = R for the next step.
        if k % steps_per_45deg == 0:
            rows_t.append(k * dt)
            rows_q.append(p)
    t = np.array(rows_t)
    q = np.array(rows_q)
    # Stage 4 (only when angles are wanted), robust atan2 form; Gajda's ranges.
    angles = as_euler(q, "ZYX", degrees=True, yaw_range="positive")
    half = 0.5 * omega[0] * t
    exact = multiply(q0, np.stack([np.cos(half), np.sin(half), 0 * half, 0 * half], axis=-1))
    return RollDemo(t=t, q=q, angles_deg=angles, error_rad=angle_between(q, exact))


def format_roll_demo(demo: RollDemo, roll_rate_deg_s: float = 90.0) -> str:
    """The printed table of :func:`gajda_roll`.

    Parameters
    ----------
    demo : RollDemo
        Output of :func:`gajda_roll`.
    roll_rate_deg_s : float
        The rate it was run with, for the header.

    Returns
    -------
    str
        A table with one line per row of ``demo``.

    Examples
    --------
    >>> print(format_roll_demo(gajda_roll()).splitlines()[0])
    Gajda's algorithm (1988): 360 deg roll at 90 deg/s about body x, exact step quaternion
    """
    lines = [
        f"Gajda's algorithm (1988): 360 deg roll at {roll_rate_deg_s:g} deg/s about body x, exact step quaternion",
        "stage 1: P = q(yaw) (x) q(pitch) (x) q(roll)  (2.16)",
        "stage 2: Q = [cos(|omega| dt/2), omega/|omega| sin(|omega| dt/2)]  (exact for a constant rate)",
        "stage 3: R = P (x) Q  (2.14)    stage 4: yaw in [0,360), pitch in [-90,90], roll in (-180,180]",
        "",
        f"{'t [s]':>6} {'w':>10} {'x':>10} {'y':>10} {'z':>10}   {'yaw':>8} {'pitch':>8} {'roll':>8}"
        f"   {'|q|-1':>9} {'error [rad]':>11}",
    ]
    n = norm(demo.q) - 1
    # Roll 180 - 1e-13 is printed as -180.000 after rounding: fold the rounded value back into (-180, 180].
    shown = demo.angles_deg.round(3)
    shown[shown <= -180] += 360
    shown[:, 0] %= 360
    for t, q, a, e, dn in zip(demo.t, demo.q, shown, demo.error_rad, n, strict=True):
        lines.append(
            f"{t:6.3f} {q[0]:10.7f} {q[1]:10.7f} {q[2]:10.7f} {q[3]:10.7f}   "
            f"{a[0]:8.3f} {a[1]:8.3f} {a[2]:8.3f}   {dn:9.1e} {e:11.1e}"
        )
    lines.append("")
    lines.append(
        f"After the full roll the quaternion is -q0 (a 360 deg turn flips its sign) and the angles are back; "
        f"largest error against the closed form: {demo.error_rad.max():.1e} rad."
    )
    return "\n".join(lines)


def write_csv(path, header: list[str], columns: np.ndarray) -> Path:
    """Write a CSV atomically: a temporary file beside the target, renamed when complete.

    Parameters
    ----------
    path : path-like
        Target file; its directory is created if missing.
    header : list of str
        Column names.
    columns : numpy.ndarray, shape (n, len(header))
        Values.

    Returns
    -------
    pathlib.Path
        ``path``, complete: values with 10 significant digits under one header line.

    Examples
    --------
    >>> import numpy as np, tempfile, pathlib
    >>> from strapdown.apps.demo import write_csv
    >>> p = write_csv(pathlib.Path(tempfile.mkdtemp()) / "x.csv", ["a", "b"], np.array([[1.0, 2.0]]))
    >>> p.read_text().splitlines()[0]
    'a,b'
    """
    path = Path(path)
    with atomic_path(path) as tmp:
        np.savetxt(tmp, columns, delimiter=",", header=",".join(header), comments="", fmt="%.10g")
    return path


def _triple(v) -> str:
    return " ".join(f"{x:+6.2f}" for x in v)


# (seconds, body axis, degrees): a hand-held sensor turned every way, put down between the turns
_TURNS = (
    (6.0, "z", 0.0), (2.5, "z", 90.0), (4.0, "z", 0.0), (1.5, "y", 40.0), (1.5, "x", -35.0), (5.0, "x", 0.0),
    (3.0, "z", -180.0), (1.0, "y", -40.0), (4.0, "y", 0.0), (2.0, "x", 120.0), (2.0, "x", -120.0), (3.0, "z", 0.0),
    (2.0, "y", 60.0), (2.0, "z", 135.0), (2.0, "y", -60.0), (6.0, "y", 0.0), (4.0, "z", 270.0), (1.5, "x", 30.0),
    (1.5, "y", 25.0), (5.0, "y", 0.0), (3.0, "x", -30.0), (2.0, "y", -25.0), (2.0, "z", -90.0), (8.0, "z", 0.0),
)  # fmt: skip


class _TurnsAndRests(Trajectory):
    """Rotations about body axes with a quintic smooth step, and rests between them; closed form throughout."""

    def __init__(self, segments=_TURNS, repeats: int = 2):
        seg = list(segments) * repeats
        self.durations = np.array([d for d, _, _ in seg])
        self.starts = np.r_[0.0, np.cumsum(self.durations)]
        self.duration = float(self.starts[-1])
        self.axes = np.array([np.eye(3)["xyz".index(ax)] for _, ax, _ in seg])
        self.angles = np.radians([a for _, _, a in seg])
        q = [np.array([1.0, 0.0, 0.0, 0.0])]
        for axis, angle in zip(self.axes, self.angles, strict=True):
            q.append(multiply(q[-1], from_rotvec(axis * angle)))
        self.q_starts = np.array(q)
        self.rest = self.angles == 0.0

    def _where(self, t):
        t = np.asarray(t, dtype=np.float64).reshape(-1)
        k = np.clip(np.searchsorted(self.starts, t, side="right") - 1, 0, len(self.durations) - 1)
        return k, np.clip((t - self.starts[k]) / self.durations[k], 0.0, 1.0)

    def attitude(self, t):
        k, u = self._where(t)
        step = (10 - 15 * u + 6 * u**2) * u**3  # quintic smooth step: rate and its derivative vanish at both ends
        return multiply(self.q_starts[k], from_rotvec(self.axes[k] * (self.angles[k] * step)[:, None]))

    def rate(self, t):
        k, u = self._where(t)
        slope = 30 * u**2 * (1 - u) ** 2 / self.durations[k]  # d(step)/dt
        return self.axes[k] * (self.angles[k] * slope)[:, None]  # about a body-fixed axis: the body rate itself

    def resting(self, t) -> np.ndarray:
        """True where the body is at rest (inside a rest segment)."""
        k, _ = self._where(t)
        return self.rest[k]


def turns_and_rests(repeats: int = 2):
    """A hand-held sensor turned about every axis and put down between the turns (NED/FRD, 74.5 s per repeat).

    Parameters
    ----------
    repeats : int
        How many times the sequence of 24 turns and rests is run.

    Returns
    -------
    strapdown.simulate.Trajectory
        A trajectory for :func:`strapdown.simulate.sample` (attitude and rate in closed form, no translation),
        with a ``resting(t)`` method telling where the body is at rest.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.apps.demo import turns_and_rests
    >>> motion = turns_and_rests(repeats=1)
    >>> motion.duration, bool(motion.resting([1.0])[0]), bool(motion.resting([7.0])[0])
    (74.5, True, False)
    """
    return _TurnsAndRests(repeats=repeats)


def _errors_deg(q, q_true) -> dict:
    from ..evaluate.metrics import attitude_errors

    return {k: np.degrees(v) for k, v in attitude_errors(q, q_true).items()}  # BROAD's measures


def _rms(x) -> float:
    return float(np.sqrt(np.nanmean(np.asarray(x) ** 2)))


def fusion_at_rest_and_turning(seed: int = 3) -> tuple[str, dict]:
    """The 9D estimators where they are meant to work: turns and rests, a consumer IMU, a magnet passing by.

    Parameters
    ----------
    seed : int
        Seeds the sensor errors.

    Returns
    -------
    text : str
        The table: total, heading and inclination RMS error, the gyro bias at the end, rests and disturbance
        found.
    result : dict
        ``t``, ``q_true`` (ENU), ``estimates`` (label to :class:`strapdown.fusion.Estimate`), ``bias_true``,
        ``resting`` and ``magnet`` (bool per sample), for the figure.
    """
    from ..fusion import (
        FLAG_MAG_REJECTED,
        FLAG_REST,
        AttitudeEstimator,
        Complementary,
        Madgwick,
        Mahony,
        attitude_offline,
    )
    from ..simulate import ImuModel, MagneticDisturbance, MagneticField, TriadModel, sample

    motion = turns_and_rests()
    magnet = MagneticDisturbance(80.0, 95.0, (35.0, -20.0, 25.0))
    consumer = ImuModel.consumer_mems()
    # a calibrated magnetometer (hard and soft iron removed, its noise left): a filter cannot tell an
    # uncalibrated one's heading error from the truth; magnetic north taken as north, so heading is comparable
    imu = ImuModel(gyro=consumer.gyro, acc=consumer.acc, mag=TriadModel(noise_density=consumer.mag.noise_density))
    field = MagneticField(declination_deg=0.0)
    data = sample(
        motion, 100.0, imu=imu, magnetic_field=field, disturbances=[magnet], reference="ENU", body="FLU", seed=seed
    )
    t, dt = data.t[1:], 0.01
    runs = {
        "AttitudeEstimator 9D": AttitudeEstimator().update(data.gyro, data.acc, data.mag, dt=dt),
        "attitude_offline 9D": attitude_offline(data.gyro, data.acc, data.mag, dt=dt),
        "Madgwick 9D": Madgwick().update(data.gyro, data.acc, data.mag, dt=dt),
        "Mahony 9D": Mahony().update(data.gyro, data.acc, data.mag, dt=dt),
        "Complementary 9D": Complementary().update(data.gyro, data.acc, data.mag, dt=dt),
    }
    resting = motion.resting(t)
    in_magnet = (t > magnet.start) & (t < magnet.stop)
    # the gyro bias in the FLU body axes of the readings (the model's bias is applied in the output axes)
    bias_true = np.asarray(imu.gyro.bias, dtype=float)
    lines = [
        "\nEach estimator where it is meant to work (1): a hand-held sensor turned every way and put down between the"
        f"\nturns ({motion.duration:.0f} s, consumer MEMS gyro and accelerometer at 100 Hz, calibrated magnetometer, a"
        f"\nmagnet near it from {magnet.start:g} to {magnet.stop:g} s), 9D, ENU. Errors in degrees (RMS), bias in °/s.",
        f"{'':22} {'total':>7} {'heading':>8} {'incl.':>7}   {'bias at the end':>20}   rests found  magnet flagged",
    ]
    for label, est in runs.items():
        e = _errors_deg(est.q, data.q_true[1:])
        bias = "" if est.bias is None else _triple(np.degrees(est.bias[-1]))
        flags = ""
        if est.flags is not None and "Attitude" in label:
            rest_found = ((est.flags & FLAG_REST) > 0)[resting].mean()
            flagged = ((est.flags & FLAG_MAG_REJECTED) > 0)[in_magnet].mean()
            flags = f"   {rest_found:10.0%}  {flagged:13.0%}"
        lines.append(
            f"{label:22} {_rms(e['total']):7.2f} {_rms(e['heading']):8.2f} {_rms(e['inclination']):7.2f}   "
            f"{bias:>20}{flags}"
        )
    lines.append(f"{'(true gyro bias)':22} {'':7} {'':8} {'':7}   {_triple(np.degrees(bias_true)):>20}")
    lines.append(
        "The rests teach the AttitudeEstimator the gyro bias on all three axes; the magnet is flagged and left out,"
        "\nso the heading holds.  (A bias that the sensor's scale errors and misalignment mimic in motion remains.)"
    )
    result = {"t": t, "q_true": data.q_true[1:], "estimates": runs, "bias_true": bias_true}
    result.update(resting=resting, magnet=in_magnet)
    return "\n".join(lines), result


def fusion_on_flight(data, ideal, gyro_bias) -> tuple[str, dict]:
    """The fusion filters on simulated flight readings: with the known acceleration, and without it (a lesson).

    Parameters
    ----------
    data : strapdown.simulate.ImuData
        Readings with sensor errors (``gyro="average"``), NED/FRD.
    ideal : strapdown.simulate.ImuData
        The same flight without errors: its specific force minus gravity is the kinematic acceleration.
    gyro_bias : array_like, shape (3,)
        The gyro's constant bias in the error model, rad/s (printed for comparison).

    Returns
    -------
    text : str
        The two tables.
    estimates : dict
        Attitude estimates (N, 4) by row label, NED.
    """
    from ..fusion import AttitudeEstimator, Complementary, Madgwick, Mahony, TiltEstimator
    from ..rotations.quaternion import rotate

    dt = np.diff(data.t)
    q_mid = ideal.q_true[1:] + ideal.q_true[:-1]
    q_mid /= np.linalg.norm(q_mid, axis=1, keepdims=True)
    known = ideal.acc + rotate(q_mid * [1.0, -1.0, -1.0, -1.0], [0.0, 0.0, 9.80665])  # f - g in body axes, NED
    aided = {
        "gyro only (exact)": (None, data.integrate("exact")[1:]),
        "Attitude 9D, known acc.": AttitudeEstimator(frame="NED").update(
            data.gyro, data.acc, data.mag, dt=dt, known_acc=known
        ),
        "TiltEstimator, known acc.": TiltEstimator(frame="NED").update(data.gyro, data.acc, dt=dt, known_acc=known),
    }
    lesson = {
        "Attitude 9D": AttitudeEstimator(frame="NED").update(data.gyro, data.acc, data.mag, dt=dt),
        "TiltEstimator 6D": TiltEstimator(frame="NED").update(data.gyro, data.acc, dt=dt),
        "Madgwick 9D": Madgwick(frame="NED").update(data.gyro, data.acc, data.mag, dt=dt),
        "Mahony 9D": Mahony(frame="NED").update(data.gyro, data.acc, data.mag, dt=dt),
        "Complementary 9D": Complementary(frame="NED").update(data.gyro, data.acc, data.mag, dt=dt),
    }
    header = f"{'':27} {'RMS':>7} {'max':>7}   bias estimate at the end"
    estimates = {}

    def rows(runs):
        out = []
        for label, est in runs.items():
            q = est[1] if isinstance(est, tuple) else est.q
            estimates[label] = q
            incl = _errors_deg(q, data.q_true[1:])["inclination"]
            bias = "" if isinstance(est, tuple) or est.bias is None else _triple(np.degrees(est.bias[-1]))
            out.append(f"{label:27} {_rms(incl):7.2f} {incl.max():7.1f}   {bias}")
        return out

    lines = [
        "\nEach estimator where it is meant to work (2): the aerobatic show, given the kinematic acceleration (air"
        "\ndata would supply it; the simulator's truth here).  Inclination error against the truth (degrees), gyro"
        " bias (°/s).",
        header,
        *rows(aided),
        f"{'(true gyro bias)':27} {'':7} {'':7}   {_triple(np.degrees(gyro_bias))}",
        "Given the kinematic acceleration the estimators hold the tilt to the accelerometer's own bias (10-20 mg,"
        "\nabout 1°) and learn the gyro bias on every axis.",
        "",
        "LESSON - what no accelerometer-trusting filter can do: the same flight WITHOUT the known acceleration.",
        "In coordinated flight the accelerometer reads lift, along the body's vertical axis, not gravity: it 'sees'",
        "a level attitude in every banked turn and loop, and every filter that takes it for gravity is pulled off.",
        header,
        *rows(lesson),
        "This is a limit of the physics, not of a filter: feed such a filter the kinematic acceleration"
        " (known_acc=),\nor trust the gyro alone for the manoeuvre.",
    ]
    return "\n".join(lines), estimates


def _fusion_figures(rest_result: dict, t_flight, q_flight_true, flight: dict) -> dict:
    """The fusion figures: turns and rests (angles, error, bias), and the flight with and without known acc."""
    from ..evaluate.figures import angles_for_display, line_styles, pyplot, shade

    plt = pyplot()
    figures = {}
    t, q_true, runs = rest_result["t"], rest_result["q_true"], rest_result["estimates"]
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(11, 9), constrained_layout=True)
    styles = line_styles(len(runs))
    ref, _ = angles_for_display(q_true)
    axes[0].plot(t, ref[:, 0], color="0.6", lw=4, alpha=0.6, zorder=1, label="truth")
    for (label, est), style in zip(runs.items(), styles, strict=True):
        yaw = angles_for_display(est.q, align=ref)[0][:, 0]
        axes[0].plot(t, yaw, label=label, zorder=2, **style)
    axes[0].set_ylabel("yaw [deg]")
    axes[0].set_title("where the 9D estimators are meant to work: turns and rests, a magnet passing (ENU)")
    axes[0].legend(fontsize=8, ncol=3, loc="upper left")
    ax = axes[1]
    shade(ax, t, rest_result["resting"], color="#dff0d8", zorder=0, label="at rest (truth)")
    shade(ax, t, rest_result["magnet"], color="#f9d6d5", zorder=0, label="magnet near (truth)")
    for (label, est), style in zip(runs.items(), styles, strict=True):
        e = _errors_deg(est.q, q_true)["total"]
        ax.plot(t, e, label=f"{label} ({_rms(e):.2f}° RMS)", zorder=2, **style)
    ax.set_yscale("log")
    ax.set_ylim(0.05, 90)
    ax.set_ylabel("total error [deg]")
    ax.legend(fontsize=8, ncol=3, loc="upper left")
    ax = axes[2]
    est = runs["AttitudeEstimator 9D"]
    for k, colour in enumerate(("C0", "C1", "C2")):
        b, sd = np.degrees(est.bias[:, k]), np.degrees(est.extra["bias_sigma"][:, k])
        ax.fill_between(t, b - 2 * sd, b + 2 * sd, color=colour, alpha=0.15, lw=0)
        ax.plot(t, b, color=colour, lw=1.2, label=f"bias {'xyz'[k]} ± 2σ")
        ax.axhline(np.degrees(rest_result["bias_true"][k]), color=colour, ls=":", lw=1)
    ax.set_ylabel("AttitudeEstimator\ngyro bias [deg/s]")
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=8, ncol=3, loc="upper right")
    for ax in axes:
        ax.grid(alpha=0.3, which="both")
    figures["turns_and_rests_fusion"] = fig

    fig, axes = plt.subplots(2, 1, sharex=True, sharey=True, figsize=(11, 8), constrained_layout=True)
    aided = ("gyro only (exact)", "Attitude 9D, known acc.", "TiltEstimator, known acc.")
    lesson = ("gyro only (exact)", "Attitude 9D", "TiltEstimator 6D", "Madgwick 9D", "Mahony 9D", "Complementary 9D")
    groups = (
        ("where they are meant to work: given the kinematic acceleration", aided),
        ("LESSON: without it, coordinated flight pulls every accelerometer-trusting filter off", lesson),
    )
    names = list(dict.fromkeys(n for _, members in groups for n in members))
    styles = dict(zip(names, line_styles(len(names)), strict=True))
    for ax, (title, members) in zip(axes, groups, strict=True):
        for label in members:
            incl = _errors_deg(flight[label], q_flight_true)["inclination"]
            ax.plot(t_flight, incl, label=f"{label} ({_rms(incl):.2f}° RMS)", **styles[label])
        ax.set_yscale("log")
        ax.set_ylim(0.01, 180)
        ax.set_title(title, fontsize=10, color="C3" if title.startswith("LESSON") else "k")
        ax.set_ylabel("inclination error [deg]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8, ncol=2, loc="lower right")
    axes[-1].set_xlabel("time [s]")
    fig.suptitle("aerobatic show, consumer MEMS IMU at 200 Hz (NED)")
    figures["aerobatic_show_fusion"] = fig
    return figures


def run(out_dir="out", echo=print) -> list[Path]:
    """Run the whole demo: print its parts and write plots (of the methods and the fusion) and a CSV to ``out_dir``.

    Parameters
    ----------
    out_dir : path-like
        Directory for the files.
    echo : callable
        Receives each block of text.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    from ..evaluate.compare import compare
    from ..simulate import ImuModel, aerobatic_show, hammerhead_loop, sample

    out_dir = Path(out_dir)
    echo(format_roll_demo(gajda_roll()))
    written = []

    data = sample(hammerhead_loop(), 100.0, gyro="increment")
    cmp = compare(data, title="\nGajda's conclusions 3a-3c: hammerhead + loop, ideal delta-angle gyro at 100 Hz")
    echo(cmp.table())
    written += cmp.plot(out_dir, prefix="hammerhead_loop")

    flight = aerobatic_show()
    imu = ImuModel.consumer_mems()
    data = sample(flight, 200.0, gyro="average", imu=imu, seed=1)
    cmp = compare(
        data, title="\nAerobatic show (76 s), consumer MEMS IMU at 200 Hz (bias, noise, scale, misalignment, LSB)"
    )
    echo(cmp.table())
    echo(
        "With a real MEMS gyro the sensor errors, not the method, set the accuracy: the gyro bias alone turns "
        "into degrees within a minute.\nThat is what fusing the accelerometer and magnetometer is for."
    )
    written += cmp.plot(out_dir, prefix="aerobatic_show")

    ideal = sample(flight, 200.0, gyro="average", seed=1)
    rest_text, rest_result = fusion_at_rest_and_turning()
    echo(rest_text)
    text, estimates = fusion_on_flight(data, ideal, imu.gyro.bias)
    echo(text)

    from ..evaluate.figures import save_figures

    figures = _fusion_figures(rest_result, data.t[1:], data.q_true[1:], estimates)
    written += save_figures({out_dir / f"{name}.png": fig for name, fig in figures.items()})

    from ..rotations.euler import as_euler
    from ..rotations.quaternion import angle_between

    # the estimate after sample k belongs to time t[k + 1]; there is none at t[0]
    fused = np.vstack([np.full((1, 4), np.nan), estimates["Attitude 9D, known acc."]])
    fused_error = np.r_[np.nan, angle_between(fused[1:], data.q_true[1:])]

    q = cmp.result("exact").q
    columns = np.column_stack(
        [
            data.t,
            data.q_true,
            as_euler(data.q_true, degrees=True, yaw_range="positive"),
            q,
            as_euler(q, degrees=True, yaw_range="positive"),
            np.degrees(cmp.result("exact").error),
            fused,
            np.degrees(fused_error),
        ]
    )
    header = ["t_s", "true_w", "true_x", "true_y", "true_z", "true_yaw_deg", "true_pitch_deg", "true_roll_deg"]
    header += ["exact_w", "exact_x", "exact_y", "exact_z", "exact_yaw_deg", "exact_pitch_deg", "exact_roll_deg"]
    header += ["exact_error_deg", "fused_w", "fused_x", "fused_y", "fused_z", "fused_error_deg"]
    written.append(write_csv(out_dir / "aerobatic_show.csv", header, columns))
    page = show_report(out_dir, echo)
    written += [page.parent / "aerobatic_show.parquet", page] if page is not None else []
    echo("\nwritten: " + ", ".join(str(p) for p in written))
    if page is not None:
        echo(f"\nthe interactive report: {page.resolve()} (open it in a browser; it needs no network)")
    return written


def show_report(out_dir, echo=print) -> Path | None:
    """The aerobatic show as a log file and its interactive page (``strapdown report``): two estimators, the truth.

    Returns the page, or None (said through ``echo``) when the ``report`` or ``io`` extra is not installed.
    """
    from ..io import simulate_file
    from .report import report_file

    out_dir = Path(out_dir)
    try:
        log = simulate_file(out_dir / "aerobatic_show.parquet", scenario="aerobatic-show", imu="consumer", rate=100.0)
        page = report_file(log.output, out_dir / "aerobatic_show.report.html", truth=log.output)
    except ImportError as exc:
        echo(f"\nno interactive report: {exc}")
        return None
    echo(
        f"\nThe show as a log ({log.output.name}, {page.rows} rows at 100 Hz) and its report: the attitude estimator "
        "against the truth, the sensors, the bias and a 3D view; `strapdown report` makes one of any log."
    )
    return page.output
