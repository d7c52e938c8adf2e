"""Loader for the BROAD benchmark (Laidig, Caruso, Cereatti & Seel, Data 6(7):72, 2021; data CC BY 4.0).

BROAD (Berlin Robust Orientation Estimation Assessment Dataset) has 39 trials of a hand-held IMU with optical
ground truth: undisturbed rotation and translation at two speeds, with and without rest breaks, and disturbed
trials (tapping, vibration, magnets near the sensor).  Each trial is a MATLAB file with

* ``imu_gyr`` (N, 3) rad/s, ``imu_acc`` (N, 3) m/s², ``imu_mag`` (N, 3) µT, sensor axes; the gyro bias is left in;
* ``opt_quat`` (N, 4): the true attitude, sensor to ENU, scalar first, NaN where the markers were occluded;
* ``movement`` (N,): the samples whose errors count; ``sampling_rate`` in Hz (285.714 Hz).

A ``trials.json`` beside them names the groups each trial belongs to (``undisturbed``, ``rotation``, ``fast``,
``attached_magnet``, ...).  Reading needs scipy (the ``io`` extra).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["Trial", "example_start", "load_reference_results", "load_trial", "load_trials"]

_FIELDS = ("imu_gyr", "imu_acc", "imu_mag", "opt_quat", "movement", "sampling_rate")


def _loadmat(path: Path, **kwargs) -> dict:
    try:
        import scipy.io
    except ImportError:  # pragma: no cover - the io extra is missing
        raise ImportError("reading BROAD's .mat files needs scipy: pip install 'strapdown[io]'") from None
    try:
        return scipy.io.loadmat(str(path), **kwargs)
    except FileNotFoundError:
        raise FileNotFoundError(f"no such BROAD file: {path}") from None
    except Exception as exc:  # a corrupt or non-MATLAB file
        raise ValueError(f"{path} is not a readable MATLAB file: {exc}") from None


@dataclass
class Trial:
    """One BROAD trial.

    Attributes
    ----------
    name : str
        File stem, e.g. ``"01_undisturbed_slow_rotation_A"``.
    gyro, acc, mag : numpy.ndarray, shape (N, 3)
        Angular rate (rad/s), specific force (m/s²) and magnetic field (µT), sensor axes.
    quat : numpy.ndarray, shape (N, 4)
        True attitude, sensor to ENU, NaN rows where the optical truth is missing.
    movement : numpy.ndarray of bool, shape (N,)
        Samples that count for the error.
    rate : float
        Sampling rate, Hz.
    groups : tuple of str
        Groups from ``trials.json`` (empty when there is none).
    description : str
        Description from ``trials.json``.
    """

    name: str
    gyro: np.ndarray
    acc: np.ndarray
    mag: np.ndarray
    quat: np.ndarray
    movement: np.ndarray
    rate: float
    groups: tuple = ()
    description: str = ""
    path: Path | None = field(default=None, repr=False)

    @property
    def gyr(self) -> np.ndarray:
        """``gyro`` by its name of release 0.1 (BROAD's own files say ``imu_gyr``)."""
        return self.gyro

    @property
    def dt(self) -> float:
        """Sampling interval, s."""
        return 1.0 / self.rate

    def __len__(self) -> int:
        return self.gyro.shape[0]


def load_trial(path, groups=(), description: str = "") -> Trial:
    """Read one BROAD trial file.

    Parameters
    ----------
    path : str or path-like
        The ``.mat`` file.
    groups : sequence of str
        Its groups (see :func:`load_trials`, which takes them from ``trials.json``).
    description : str
        Its description.

    Returns
    -------
    Trial
        The trial, arrays contiguous float64 (``movement`` bool).
    """
    path = Path(path)
    d = _loadmat(path)
    missing = [f for f in _FIELDS if f not in d]
    if missing:
        raise ValueError(f"{path} is not a BROAD trial: it lacks {', '.join(missing)}")

    def triad(key, width=3):
        a = np.ascontiguousarray(d[key], dtype=np.float64)
        if a.ndim != 2 or a.shape[1] != width:
            raise ValueError(f"{path}: {key} must have shape (N, {width}), got {a.shape}")
        return a

    gyro, acc, mag, quat = triad("imu_gyr"), triad("imu_acc"), triad("imu_mag"), triad("opt_quat", 4)
    movement = np.asarray(d["movement"]).reshape(-1).astype(bool)
    n = gyro.shape[0]
    if not (acc.shape[0] == mag.shape[0] == quat.shape[0] == movement.shape[0] == n):
        raise ValueError(f"{path}: the fields have different lengths")
    for key, a in (("imu_gyr", gyro), ("imu_acc", acc), ("imu_mag", mag)):
        if not np.isfinite(a).all():
            raise ValueError(f"{path}: {key} holds NaN or infinite values")
    rate = _rate(path, d["sampling_rate"])
    # NaN rows are occluded markers (ignored); a zero or infinite row is no attitude and would make every error NaN
    known = ~np.isnan(quat).any(axis=1)
    bad = np.flatnonzero(known & ~(np.isfinite(quat).all(axis=1) & (np.abs(quat) > 0).any(axis=1)))
    if bad.size:
        raise ValueError(
            f"{path}: opt_quat row {bad[0] + 1} of {n} is {quat[bad[0]].tolist()} ({bad.size} such rows): a true "
            "attitude must be a finite non-zero quaternion, or NaN where the markers were lost"
        )
    if not (known & movement).any():
        raise ValueError(f"{path}: no movement sample has a true attitude (opt_quat NaN there): nothing to score")
    return Trial(path.stem, gyro, acc, mag, quat, movement, rate, tuple(groups), description, path)


def _rate(path: Path, value) -> float:
    """BROAD's ``sampling_rate``: one positive finite number of Hz."""
    a = np.asarray(value)
    if a.size != 1 or a.dtype.kind not in "iuf":
        shown = repr(a.tolist()) if a.size < 6 else f"an array of shape {a.shape}"
        raise ValueError(f"{path}: sampling_rate must be one number of Hz, got {shown}")
    rate = float(a.reshape(-1)[0])
    if not (np.isfinite(rate) and rate > 0):
        raise ValueError(f"{path}: sampling_rate must be a positive number of Hz, got {rate!r}")
    return rate


def _index(folder: Path) -> dict:
    """``trials.json``: {"trials": {name: {"groups": [...], "description": "..."}}, "groups": [{"name": ...}]}."""
    index = folder / "trials.json"
    if not index.exists():
        return {}
    try:
        data = json.loads(index.read_text())
    except (ValueError, UnicodeDecodeError) as exc:
        raise ValueError(f"{index} is not valid JSON: {exc}") from None
    if not isinstance(data, dict):
        raise ValueError(f"{index} must hold a JSON object with 'trials' and 'groups', got a {type(data).__name__}")
    trials, groups = data.get("trials", {}), data.get("groups", [])
    if not isinstance(trials, dict) or not all(isinstance(v, dict) for v in trials.values()):
        raise ValueError(f"{index}: 'trials' must map each trial name to an object with 'groups' and 'description'")
    for name, v in trials.items():
        g = v.get("groups", [])
        if not isinstance(g, list) or not all(isinstance(x, str) for x in g):
            raise ValueError(f"{index}: the groups of trial {name!r} must be a list of names, got {g!r}")
    if not isinstance(groups, list) or not all(isinstance(g, dict) and isinstance(g.get("name"), str) for g in groups):
        raise ValueError(f"{index}: 'groups' must be a list of objects with a 'name'")
    return data


def load_trials(folder, names=None) -> list[Trial]:
    """Read every BROAD trial in a folder (sorted by name), with groups from its ``trials.json``.

    Parameters
    ----------
    folder : str or path-like
        Folder with the ``.mat`` files (BROAD's ``data_mat``).
    names : sequence of str, optional
        Only these trials (file stems); an unknown name is an error.

    Returns
    -------
    list of Trial
        The trials.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"BROAD folder not found: {folder}")
    files = sorted(folder.glob("*.mat"))
    if not files:
        raise FileNotFoundError(f"no .mat trial files in {folder}")
    if names is not None:
        by_name = {f.stem: f for f in files}
        unknown = [n for n in names if n not in by_name]
        if unknown:
            raise ValueError(f"unknown trial(s) {', '.join(unknown)} in {folder}")
        files = [by_name[n] for n in names]
    meta = _index(folder).get("trials", {})
    return [
        load_trial(f, meta.get(f.stem, {}).get("groups", ()), meta.get(f.stem, {}).get("description", ""))
        for f in files
    ]


def group_names(folder) -> list[str]:
    """The group names of ``trials.json`` in its order (empty when there is no such file)."""
    return [g["name"] for g in _index(Path(folder)).get("groups", [])]


def load_reference_results(path) -> dict:
    """Read one of BROAD's published parameter-grid results (e.g. ``results_madgwick.mat``).

    Parameters
    ----------
    path : str or path-like
        The file.

    Returns
    -------
    dict
        ``"params"``: {parameter name: array of the grid values}; ``"total"``, ``"heading"``,
        ``"inclination"``: {trial name: RMSE in degrees per grid point}.
    """
    d = _loadmat(Path(path), squeeze_me=True, struct_as_record=False)
    out = {}
    pv = d["param_values"]
    out["params"] = {name: np.atleast_1d(getattr(pv, name)).astype(float) for name in pv._fieldnames}
    for kind in ("total", "heading", "inclination"):
        s = d[f"{kind}_rmse_deg"]
        out[kind] = {
            name.removeprefix("trial_"): np.atleast_1d(getattr(s, name)).astype(float) for name in s._fieldnames
        }
    return out


def example_start(acc, mag) -> np.ndarray:
    """The initial quaternion of BROAD's example code, which its published Madgwick/Mahony results start from.

    The example builds ``z = a``, ``x = (z × -m) × z``, ``y = z × x`` (up, south and east in sensor axes),
    stacks them normalised as the *columns* of a matrix M and hands the quaternion of M to a filter computing
    in NWU.  The sensor-to-NWU matrix R has north, west and up as its *rows*, so ``M = Rᵀ diag(-1, -1, 1)``: the
    inverse attitude after a half turn about the vertical.  It is right only when the sensor is level facing
    east or west; otherwise the filters start off in tilt and heading and converge during the first seconds,
    which the published errors include.  Use this only to reproduce them.

    Parameters
    ----------
    acc, mag : array_like, shape (3,)
        First accelerometer and magnetometer samples.

    Returns
    -------
    numpy.ndarray, shape (4,)
        The quaternion, as the example gives it to a filter computing in NWU.
    """
    from ..rotations.matrix import from_matrix

    z = np.asarray(acc, dtype=np.float64).reshape(3)
    m = np.asarray(mag, dtype=np.float64).reshape(3)
    x = np.cross(np.cross(z, -m), z)
    y = np.cross(z, x)
    cols = [v / np.linalg.norm(v) for v in (x, y, z)]
    return from_matrix(np.column_stack(cols))
