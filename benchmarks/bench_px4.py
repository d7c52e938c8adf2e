"""A PX4 log's own attitude (``vehicle_attitude``, PX4's EKF2) against strapdown's AttitudeEstimator on the same log.

    PYTHONPATH=src python benchmarks/bench_px4.py [LOG.ulg ...] [--skip 2.0]

For each log (default: the two real logs in tests/data/px4, vehicle on the ground) the IMU is read with
``strapdown.io.read_imu`` exactly as ``strapdown estimate`` reads it (sensor_combined, vehicle_magnetometer on the
gyro's rows, NaN rows between), the estimator runs online in NED with the defaults, 6D and 9D, and its attitude at
each ``vehicle_attitude`` sample (the gyro row at or after it) is compared with the log's.  Figures, in degrees,
after the first ``--skip`` seconds (both filters starting up):

* inclination RMS (6D and 9D), and the same 9D figures from the file ``strapdown estimate LOG`` writes (the
  command line, default options but ``--max-gap 0``), in the same run;
* total RMS of 9D as is;
* total RMS of 9D after one constant rotation about the vertical (PX4 refers heading to true north with the
  declination of its world magnetic model; strapdown's 9D heading is magnetic), and after the best constant
  rotation of any axis (the chordal mean of the error quaternions), which also absorbs a fixed mounting offset.

Accuracy, not speed: the numbers do not depend on the machine's load.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from strapdown.evaluate.metrics import attitude_errors, error_quaternion
from strapdown.fusion import AttitudeEstimator
from strapdown.io import ImuColumns, read_imu, read_reference
from strapdown.rotations.quaternion import conjugate, multiply

ROOT = Path(__file__).resolve().parents[1]


def _rms_deg(x: np.ndarray) -> float:
    return float(np.degrees(np.sqrt(np.mean(x**2))))


def _constant_alignment(e: np.ndarray, heading_only: bool) -> np.ndarray:
    """The constant reference-frame rotation that best explains the error quaternions e (chordal mean)."""
    e = e * np.where(e[:, :1] < 0, -1.0, 1.0)  # one hemisphere
    if heading_only:
        yaw = np.arctan2(
            np.mean(np.sin(2 * np.arctan2(e[:, 3], e[:, 0]))), np.mean(np.cos(2 * np.arctan2(e[:, 3], e[:, 0])))
        )
        return np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)])
    m = e.mean(axis=0)
    return m / np.linalg.norm(m)


def _cli_estimate(log: Path) -> np.ndarray:
    """The attitudes ``strapdown estimate LOG`` writes (default options; --max-gap 0 for the small log's gap)."""
    import subprocess
    import sys
    import tempfile

    from strapdown.io import read_table

    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "est.parquet"
        cmd = [sys.executable, "-m", "strapdown.cli", "estimate", str(log), "-o", str(out), "--max-gap", "0", "-q"]
        subprocess.run(cmd, check=True, capture_output=True)
        table = read_table(out)
    return np.column_stack([table[c] for c in ("qw", "qx", "qy", "qz")])


def compare(log: Path, skip: float, cli: bool = True) -> dict:
    """The figures of one log (see the module's description)."""
    data = read_imu(log, ImuColumns(max_gap=0), optional=("acc", "mag"))  # the small log has a 161 ms gap
    ref = read_reference(log)
    keep = (ref.t >= data.t[0] + skip) & (ref.t <= data.t[-1])
    rows = np.searchsorted(data.t, ref.t[keep])
    q_ref = ref.q[keep]
    out = {"log": log.name, "samples": int(keep.sum()), "seconds": float(data.t[-1])}
    runs = [("6D", None, None), ("9D", data.mag, None)]
    if cli:
        runs.append(("9D via `strapdown estimate`", data.mag, _cli_estimate(log)))
    for mode, mag, q_all in runs:
        if q_all is None:
            q_all = AttitudeEstimator(frame="NED").update(data.gyro, data.acc, mag, t=data.t).q
        q = q_all[rows]
        errors = attitude_errors(q, q_ref)
        out[f"{mode} inclination RMS"] = _rms_deg(errors["inclination"])
        if mode.startswith("9D"):
            out[f"{mode} total RMS"] = _rms_deg(errors["total"])
            e = error_quaternion(q, q_ref)
            for name, heading_only in (("heading", True), ("any axis", False)):
                align = _constant_alignment(e, heading_only)
                aligned = multiply(conjugate(align), q)
                out[f"{mode} total RMS, constant {name} aligned"] = _rms_deg(attitude_errors(aligned, q_ref)["total"])
                out[f"{mode} alignment ({name}), deg"] = float(np.degrees(2 * np.arccos(min(1.0, abs(align[0])))))
    return out


def main(argv=None) -> None:
    """Print the figures of each log."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("logs", nargs="*", type=Path, default=sorted((ROOT / "tests" / "data" / "px4").glob("*.ulg")))
    parser.add_argument("--skip", type=float, default=2.0, help="seconds left out at the start (default 2)")
    parser.add_argument("--no-cli", action="store_true", help="skip the run through `strapdown estimate`")
    args = parser.parse_args(argv)
    for log in args.logs:
        result = compare(log, args.skip, cli=not args.no_cli)
        print(
            f"{result.pop('log')}: {result.pop('samples')} vehicle_attitude samples over {result.pop('seconds'):.1f} s"
        )
        for key, value in result.items():
            print(f"  {key:66s} {value:8.3f}")


if __name__ == "__main__":
    main()
