"""The worked examples printed by ``strapdown demo``.

1. Gajda's algorithm (1988, §2.3) step by step on a 360° roll at constant rate, checked against the closed form.
2. His conclusions 3a-3c put to the test: every propagation method on a hammerhead + loop, ideal gyro.
3. An aerobatic show with a realistic consumer MEMS IMU: every method, the table, plots and a CSV in ``out/``.
   Gyro errors dominate there.
4. The fusion filters on the same flight.  In coordinated flight the accelerometer does not see gravity, so
   filters that trust it fail; given the kinematic acceleration (as air data would supply it), the
   AttitudeEstimator and the TiltEstimator track the tilt down to the accelerometer's own bias and learn the
   gyro bias.  The CSV's fused columns are the AttitudeEstimator's.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ._files import atomic_path
from .euler import as_euler, from_euler
from .quaternion import angle_between, multiply, norm
from .rotvec import from_rotvec


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
        The file written.

    Examples
    --------
    >>> import numpy as np, tempfile, pathlib
    >>> from strapdown.demo import write_csv
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


def fusion_on_flight(data, ideal, gyro_bias) -> tuple[str, dict]:
    """Every fusion filter on simulated flight readings; a table of their errors against the truth.

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
        The table.
    estimates : dict
        Attitude estimates (N, 4) by row label, NED.
    """
    from .fusion import AttitudeEstimator, Complementary, Madgwick, Mahony, TiltEstimator
    from .metrics import attitude_errors
    from .quaternion import rotate

    dt = np.diff(data.t)
    q_mid = ideal.q_true[1:] + ideal.q_true[:-1]
    q_mid /= np.linalg.norm(q_mid, axis=1, keepdims=True)
    known = ideal.acc + rotate(q_mid * [1.0, -1.0, -1.0, -1.0], [0.0, 0.0, 9.80665])  # f - g in body axes, NED
    runs = {
        "gyro only (exact)": (None, data.integrate("exact")[1:]),
        "Attitude 9D, known acc.": AttitudeEstimator(frame="NED").update(
            data.gyro, data.acc, data.mag, dt=dt, known_acc=known
        ),
        "TiltEstimator, known acc.": TiltEstimator(frame="NED").update(data.gyro, data.acc, dt=dt, known_acc=known),
        "Attitude 9D": AttitudeEstimator(frame="NED").update(data.gyro, data.acc, data.mag, dt=dt),
        "TiltEstimator 6D": TiltEstimator(frame="NED").update(data.gyro, data.acc, dt=dt),
        "Madgwick 9D": Madgwick(frame="NED").update(data.gyro, data.acc, data.mag, dt=dt),
        "Mahony 9D": Mahony(frame="NED").update(data.gyro, data.acc, data.mag, dt=dt),
        "Complementary 9D": Complementary(frame="NED").update(data.gyro, data.acc, data.mag, dt=dt),
    }
    lines = [
        "\nFusion on the same flight: inclination error against the truth (degrees), gyro bias (°/s)",
        f"{'':27} {'RMS':>7} {'max':>7}   bias estimate at the end",
    ]
    estimates = {}
    for label, est in runs.items():
        q = est[1] if isinstance(est, tuple) else est.q
        estimates[label] = q
        e = {k: np.degrees(v) for k, v in attitude_errors(q, data.q_true[1:]).items()}  # BROAD's measures
        bias = "" if isinstance(est, tuple) or est.bias is None else _triple(np.degrees(est.bias[-1]))
        incl = e["inclination"]
        lines.append(f"{label:27} {np.sqrt(np.mean(incl**2)):7.2f} {incl.max():7.1f}   {bias}")
    lines.append(f"{'(true gyro bias)':27} {'':7} {'':7}   {_triple(np.degrees(gyro_bias))}")
    lines.append(
        "In coordinated flight the accelerometer reads lift, not gravity: the filters that trust it are pulled off."
        "\nGiven the kinematic acceleration (air data; the simulator's truth here) the estimators hold the tilt to"
        " the\naccelerometer's own bias (10-20 mg, about 1°) and learn the gyro bias on every axis."
    )
    return "\n".join(lines), estimates


def run(out_dir="out", echo=print) -> list[Path]:
    """Run the whole demo: print the three parts and write plots and a CSV to ``out_dir``.

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
    from .compare import compare
    from .simulate import ImuModel, aerobatic_show, hammerhead_loop, sample

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
    text, estimates = fusion_on_flight(data, ideal, imu.gyro.bias)
    echo(text)

    from .euler import as_euler
    from .quaternion import angle_between

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
    echo("\nwritten: " + ", ".join(str(p) for p in written))
    return written
