"""Run an estimator over benchmark trials with one common parameter set, on the BROAD protocol.

For each trial the estimator runs from its first sample with ``dt = 1/rate``; the errors are those of
:mod:`strapdown.evaluate.metrics` (total, heading and inclination RMSE over the movement samples, NaN truth ignored),
and the score of a parameter set is the plain mean over trials, also reported per group of ``trials.json``.
Estimators without a magnetometer (6D) cannot know the heading, so by default their mean heading offset is
removed before the errors are taken (inclination is unaffected).

:func:`grid_search` evaluates every point of a parameter grid the same way and ranks them: one set for all
trials, never tuned per trial (BROAD's rule).
"""

from __future__ import annotations

import csv
import itertools
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, fields, replace

import numpy as np

from .._support.validate import SampleError
from ..fusion import Estimate
from ..fusion.registry import ESTIMATORS, make_params
from ..rotations.frames import frame_quaternion
from ..rotations.quaternion import multiply
from .broad import Trial, example_start, group_names, load_trials
from .metrics import rmse_errors

__all__ = ["Evaluation", "GridSearch", "TrialResult", "evaluate", "grid_search"]

STARTS = ("first-sample", "broad-example")
METRICS = ("total", "heading", "inclination")


@dataclass
class TrialResult:
    """The errors on one trial, degrees."""

    name: str
    groups: tuple
    total: float
    heading: float
    inclination: float
    seconds: float = 0.0

    def get(self, metric: str) -> float:
        """One of ``"total"``, ``"heading"``, ``"inclination"``."""
        return getattr(self, metric)


@dataclass
class Evaluation:
    """Per-trial errors of one estimator and parameter set, with means over trials and groups.

    Attributes
    ----------
    label : str
        What was run (estimator and parameters).
    trials : list of TrialResult
        One per trial, in the order run.
    group_order : list of str
        Group names in the order of ``trials.json``.
    heading_offset_removed : bool
        Whether each trial's mean heading offset was removed (6D).
    """

    label: str
    trials: list
    group_order: list = field(default_factory=list)
    heading_offset_removed: bool = False

    def mean(self, metric: str = "inclination") -> float:
        """Plain mean over the trials, degrees (BROAD's score)."""
        _check_metric(metric)
        return float(np.mean([r.get(metric) for r in self.trials]))

    def groups(self) -> dict[str, dict]:
        """Mean errors per group present: {group: {"n": trials, "total": ..., "heading": ..., "inclination": ...}}."""
        names = list(self.group_order)
        for r in self.trials:
            names += [g for g in r.groups if g not in names]
        out = {}
        for g in names:
            members = [r for r in self.trials if g in r.groups]
            if members:
                out[g] = {"n": len(members)} | {m: float(np.mean([r.get(m) for r in members])) for m in METRICS}
        return out

    def table(self) -> str:
        """Per-trial and per-group RMSE, degrees, as text."""
        width = max([len(r.name) for r in self.trials] + [24])
        head = f"{'':{width}}  {'total':>8}  {'heading':>8}  {'inclin.':>8}"
        lines = [
            self.label,
            f"RMSE in degrees{' (heading offset removed: 6D)' if self.heading_offset_removed else ''}",
            "",
            head,
        ]
        for r in self.trials:
            lines.append(f"{r.name:{width}}  {r.total:8.3f}  {r.heading:8.3f}  {r.inclination:8.3f}")
        lines += ["", f"{'group (trials)':{width}}  {'total':>8}  {'heading':>8}  {'inclin.':>8}"]
        for g, v in self.groups().items():
            name = f"{g} ({v['n']})"
            lines.append(f"{name:{width}}  {v['total']:8.3f}  {v['heading']:8.3f}  {v['inclination']:8.3f}")
        lines.append(
            f"{'mean over trials':{width}}  {self.mean('total'):8.3f}  {self.mean('heading'):8.3f}  "
            f"{self.mean('inclination'):8.3f}"
        )
        return "\n".join(lines)

    def to_csv(self, path) -> None:
        """Write one row per trial (name, groups, errors in degrees, run time in seconds), atomically."""
        from .._support.files import atomic_path

        with atomic_path(path) as tmp, open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["trial", "groups", "total_deg", "heading_deg", "inclination_deg", "seconds"])
            for r in self.trials:
                w.writerow(
                    [
                        r.name,
                        " ".join(r.groups),
                        f"{r.total:.6f}",
                        f"{r.heading:.6f}",
                        f"{r.inclination:.6f}",
                        f"{r.seconds:.4f}",
                    ]
                )


@dataclass
class GridSearch:
    """Every grid point's mean errors, best first.

    Attributes
    ----------
    estimator : str
        The estimator.
    objective : str
        The metric ranked on.
    points : list of dict
        ``{"params": {name: value}, "total": ..., "heading": ..., "inclination": ...}`` (mean degrees), sorted
        by the objective.
    """

    estimator: str
    objective: str
    points: list

    @property
    def best(self) -> dict:
        """The best grid point."""
        return self.points[0]

    def table(self, limit: int | None = 20) -> str:
        """The ranked grid as text (the best ``limit`` points; all with None)."""
        names = list(self.points[0]["params"]) if self.points else []
        head = "  ".join(f"{n:>12}" for n in names) + f"  {'total':>8}  {'heading':>8}  {'inclin.':>8}"
        lines = [f"{self.estimator}: {len(self.points)} grid points ranked by mean {self.objective} RMSE (deg)", head]
        for p in self.points[:limit]:
            vals = "  ".join(f"{_fmt(p['params'][n]):>12}" for n in names)
            lines.append(f"{vals}  {p['total']:8.3f}  {p['heading']:8.3f}  {p['inclination']:8.3f}")
        return "\n".join(lines)


def _fmt(v) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def _check_metric(metric: str) -> None:
    if metric not in METRICS:
        raise ValueError(f"metric must be one of {', '.join(METRICS)}, got {metric!r}")


def _runner(estimator, params, use_mag: bool, start: str) -> tuple[Callable[[Trial], np.ndarray], str]:
    """A function trial -> attitudes (sensor to ENU), and a label."""
    if callable(estimator):
        return (lambda trial: _as_q(estimator(trial))), getattr(estimator, "__name__", "custom estimator")
    cls, pcls, takes_mag = ESTIMATORS[estimator] if estimator in ESTIMATORS else (None, None, None)
    p = make_params(estimator, params)
    if use_mag and not takes_mag:
        raise ValueError(f"{estimator} does not take a magnetometer (6D only): run it without the magnetometer")
    if start not in STARTS:
        raise ValueError(f"start must be one of {', '.join(STARTS)}, got {start!r}")
    if start == "broad-example" and not use_mag:
        raise ValueError("start='broad-example' needs the magnetometer (mag=True), as BROAD's example does")
    nwu_to_enu = frame_quaternion("NWU", "ENU")

    def run(trial: Trial) -> np.ndarray:
        q0 = None
        if start == "broad-example":
            q0 = multiply(nwu_to_enu, example_start(trial.acc[0], trial.mag[0]))
        f = cls(p, q0=q0, frame="ENU")
        mag = trial.mag if use_mag else None
        try:
            return f.update(trial.gyro, trial.acc, mag, dt=trial.dt).q
        except SampleError as exc:  # the filter's words name its arrays and index: here, the trial and its sample
            raise ValueError(f"{trial.path or trial.name}: sample {exc.sample + 1} of {len(trial)}: {exc}") from None

    changed = [
        f"{f.name}={_fmt(getattr(p, f.name))}" for f in fields(p) if getattr(p, f.name) != getattr(pcls(), f.name)
    ]
    label = f"{estimator} {'9D' if use_mag else '6D'}" + (f" ({', '.join(changed)})" if changed else " (defaults)")
    if start != "first-sample":
        label += f", start: {start}"
    return run, label


def _as_q(result) -> np.ndarray:
    return result.q if isinstance(result, Estimate) else np.asarray(result, dtype=np.float64)


def _trials(trials) -> tuple[list[Trial], list[str]]:
    if isinstance(trials, (str, bytes)) or hasattr(trials, "__fspath__"):
        return load_trials(trials), group_names(trials)
    trials = list(trials)
    if not trials or not all(isinstance(t, Trial) for t in trials):
        raise ValueError("trials must be a BROAD folder or a non-empty sequence of Trial objects")
    groups = []
    if trials[0].path is not None:
        groups = group_names(trials[0].path.parent)
    return trials, groups


def evaluate(
    estimator="tilt",
    trials=None,
    *,
    params=None,
    mag: bool = False,
    start: str = "first-sample",
    heading_offset: bool | None = None,
    progress: Callable[[TrialResult], None] | None = None,
) -> Evaluation:
    """Run one estimator with one parameter set over trials and take the BROAD errors.

    Parameters
    ----------
    estimator : str or callable
        A key of :data:`ESTIMATORS`, or a function ``trial -> attitudes`` (an (N, 4) array or an
        :class:`~strapdown.fusion.Estimate`, sensor to ENU) for an estimator of your own.
    trials : path-like or sequence of Trial
        A BROAD folder (read with :func:`strapdown.evaluate.broad.load_trials`) or trials already loaded.
    params : parameter object or mapping, optional
        The common parameters (named estimators); a mapping overrides defaults by field name.
    mag : bool
        Give the estimator the magnetometer (9D).
    start : {"first-sample", "broad-example"}
        How a named estimator starts: from its own initialisation on the first sample, or from the quaternion
        of BROAD's example code (:func:`strapdown.evaluate.broad.example_start`; 9D, for reproducing published results).
    heading_offset : bool, optional
        Remove each trial's mean heading offset; by default when ``mag`` is False.
    progress : callable, optional
        Called with each trial's result as it finishes.

    Returns
    -------
    Evaluation
        Per-trial errors and the means.
    """
    if trials is None:
        raise ValueError("trials is required: a BROAD folder or a sequence of Trial objects")
    run, label = _runner(estimator, params, mag, start)
    trials, order = _trials(trials)
    remove = (not mag) if heading_offset is None else bool(heading_offset)
    results = []
    for trial in trials:
        t0 = time.perf_counter()
        q = run(trial)
        seconds = time.perf_counter() - t0
        if q.shape != trial.quat.shape:
            raise ValueError(f"the estimator returned shape {q.shape} on {trial.name}; expected {trial.quat.shape}")
        _check_estimate(q, trial)
        try:
            e = rmse_errors(q, trial.quat, trial.movement, heading_offset=remove)
        except ValueError as exc:  # the metric names its arrays: q_ref is the trial's opt_quat
            raise ValueError(f"{trial.name}: the true attitude cannot be scored: {exc}") from None
        if not all(np.isfinite(v) for v in e.values()):
            # a NaN score would rank nowhere and average everything it meets into NaN
            raise ValueError(
                f"{trial.name}: the errors are NaN ({', '.join(f'{k} {v:.3g}' for k, v in e.items())}): no movement "
                "sample has both a finite estimate and a unit true attitude"
            )
        r = TrialResult(trial.name, trial.groups, e["total"], e["heading"], e["inclination"], seconds)
        results.append(r)
        if progress is not None:
            progress(r)
    return Evaluation(label, results, order, remove)


def _check_estimate(q: np.ndarray, trial: Trial) -> None:
    """Refuse an estimate that lost the attitude: the errors skip NaN rows, so it would score well, not badly."""
    nan = ~np.isfinite(q).all(axis=1)
    counted = trial.movement & np.isfinite(trial.quat).all(axis=1)  # NaN where the truth is NaN counts nothing
    lost = np.flatnonzero(nan & counted)
    if not lost.size:
        return
    k = int(lost[0])
    while k > 0 and nan[k - 1]:  # where the estimate was lost, before the first sample that counts
        k -= 1
    readings = {"imu_gyr": trial.gyro[k], "imu_acc": trial.acc[k], "imu_mag": trial.mag[k]}
    # the reading most out of scale at that row, relative to its usual size (rad/s, m/s², µT)
    name = max(readings, key=lambda n: np.max(np.abs(readings[n])) / {"imu_gyr": 1, "imu_acc": 9.81, "imu_mag": 50}[n])
    raise ValueError(
        f"{trial.path or trial.name}: the estimate is lost (NaN) from sample {k + 1} of {len(trial)} on, where "
        f"{name} is {readings[name].tolist()}: a reading that large is not plausible"
    )


def grid_search(
    estimator: str,
    trials,
    grid: Mapping[str, Sequence],
    *,
    params=None,
    mag: bool = False,
    start: str = "first-sample",
    objective: str = "inclination",
    heading_offset: bool | None = None,
    progress: Callable[[dict], None] | None = None,
) -> GridSearch:
    """Evaluate every combination of the grid's values (one common set for all trials each) and rank them.

    Parameters
    ----------
    estimator : str
        A key of :data:`ESTIMATORS`.
    trials : path-like or sequence of Trial
        As for :func:`evaluate` (a folder is read once).
    grid : mapping of str to sequence
        Parameter name to the values to try.
    params : parameter object or mapping, optional
        The fixed parameters the grid varies from.
    mag, start, heading_offset
        As for :func:`evaluate`.
    objective : {"inclination", "total", "heading"}
        Mean RMSE to rank on.
    progress : callable, optional
        Called with each grid point's entry as it finishes.

    Returns
    -------
    GridSearch
        All points, best first.
    """
    _check_metric(objective)
    if not grid:
        raise ValueError("grid is empty: give at least one parameter and its values")
    for name, values in grid.items():
        if isinstance(values, (str, bytes)) or len(values) == 0:
            raise ValueError(f"grid[{name!r}] must be a non-empty sequence of values")
    base = make_params(estimator, params)
    make_params(estimator, {name: values[0] for name, values in grid.items()})  # names checked up front
    trials, _ = _trials(trials)
    points = []
    for combo in itertools.product(*grid.values()):
        chosen = dict(zip(grid, combo, strict=True))
        ev = evaluate(
            estimator, trials, params=replace(base, **chosen), mag=mag, start=start, heading_offset=heading_offset
        )
        point = {"params": chosen} | {m: ev.mean(m) for m in METRICS}
        points.append(point)
        if progress is not None:
            progress(point)
    points.sort(key=lambda p: p[objective])
    return GridSearch(estimator, objective, points)
