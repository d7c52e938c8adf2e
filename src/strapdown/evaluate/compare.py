"""Every propagation method side by side on one set of readings: the test of Gajda's conclusions 3a-3c.

For each method :func:`compare` reports the final and the largest attitude error against the truth, the largest
``||q| - 1|``, the steps where a baseline came within ``singular_tol`` of its singular set (Gajda 3a), the largest
error when the same readings are integrated from an oblique start (3b, see below), and the time per step (3c).
:meth:`Comparison.plot` draws the angles and errors.

The oblique start is the rotation R that takes the reference direction (1, 1, 1)/√3 to the vertical (z).  From
``R ⊗ q0`` the same body rates fly the whole trajectory rotated by R.  For a body-rate quaternion update that
changes nothing but rounding, so its error must stay the same: accuracy independent of attitude.  For Euler
angles the singular points move: a flight whose nose sweeps the plane of a loop and a stall turn never points
along ±(1, 1, 1)/√3, so the rotated flight never passes the vertical and the Euler-angle method survives it.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..propagate.integrate import METHODS
from ..rotations.euler import as_euler
from ..rotations.quaternion import angle_between, multiply
from ..rotations.rotvec import from_rotvec
from ..simulate.sampling import ImuData

__all__ = ["GAJDA_SECONDS_PER_LOOP", "Comparison", "MethodResult", "ReferenceErrors", "compare", "reference_errors"]

GAJDA_SECONDS_PER_LOOP = 4e-3  # Gajda (1988) §3c: one loop with the angles, FORTRAN, 8 MHz IBM PC/XT + 8087


def _oblique_start() -> np.ndarray:
    v = np.ones(3) / np.sqrt(3.0)
    z = np.array([0.0, 0.0, 1.0])
    axis = np.cross(v, z)
    return from_rotvec(axis / np.linalg.norm(axis) * np.arccos(v @ z))


_ROTATED_START = _oblique_start()
_GAJDA_STEPS = 1_000_000  # steps timed for the per-loop figure


@dataclass
class MethodResult:
    """One method's run on the readings.

    Attributes
    ----------
    method : str
        The method.
    q : numpy.ndarray, shape (N + 1, 4)
        Its attitudes (NaN after a singular step of a baseline).
    error : numpy.ndarray, shape (N + 1,)
        Angle to the truth, rad.
    norm_error : float
        Largest ``||q| - 1|``.
    singular_steps : int
        Steps flagged singular.
    first_singular_time : float or None
        Time of the first, s.
    rotated_error : float
        Largest error from the oblique start, rad (NaN if that run went singular).
    ns_per_step : float
        Best of the timed runs, nanoseconds per sample.
    """

    method: str
    q: np.ndarray
    error: np.ndarray
    norm_error: float
    singular_steps: int
    first_singular_time: float | None
    rotated_error: float
    ns_per_step: float

    @property
    def final_error(self) -> float:
        """Error at the last sample, rad (NaN when the method stopped at a singularity)."""
        return float(self.error[-1])

    @property
    def max_error(self) -> float:
        """Largest error before any singular stop, rad."""
        finite = self.error[np.isfinite(self.error)]
        return float(finite.max()) if finite.size else float("nan")


@dataclass
class Comparison:
    """The results of :func:`compare`, with a printable table and plots."""

    data: ImuData
    results: list[MethodResult]
    title: str = ""
    ns_per_loop_with_angles: float = float("nan")

    def result(self, method: str) -> MethodResult:
        """The result of one method.

        Parameters
        ----------
        method : str
            Its name.

        Returns
        -------
        MethodResult
            Its attitudes, errors against the truth and timing; ``KeyError`` for a method not compared.

        Examples
        --------
        >>> from strapdown.evaluate.compare import compare
        >>> from strapdown.simulate import hammerhead_loop, sample
        >>> cmp = compare(sample(hammerhead_loop(), 50.0), methods=["exact"], timing_repeats=1)
        >>> cmp.result("exact").singular_steps
        0
        """
        for r in self.results:
            if r.method == method:
                return r
        raise KeyError(method)

    def table(self) -> str:
        """The comparison as a fixed-width text table (angles in degrees).

        Returns
        -------
        str
            One line per method, then Gajda's speed figure.

        Examples
        --------
        >>> from strapdown.evaluate.compare import compare
        >>> from strapdown.simulate import hammerhead_loop, sample
        >>> text = compare(sample(hammerhead_loop(), 50.0), methods=["exact"], timing_repeats=1).table()
        >>> "exact" in text and "ns/step" in text
        True
        """
        lines = [
            self.title,
            f"{'method':<17} {'final err':>10} {'max err':>10} {'max ||q|-1|':>12} {'singular':>16} "
            f"{'oblique start':>14} {'ns/step':>8}",
            f"{'':<17} {'[deg]':>10} {'[deg]':>10} {'':>12} {'steps (first)':>16} {'max err [deg]':>14}",
        ]
        for r in self.results:
            sing = "-" if r.singular_steps == 0 else f"{r.singular_steps} ({r.first_singular_time:.2f} s)"
            lines.append(
                f"{r.method:<17} {_deg(r.final_error):>10} {_deg(r.max_error):>10} {r.norm_error:>12.1e} {sing:>16} "
                f"{_deg(r.rotated_error):>14} {r.ns_per_step:>8.1f}"
            )
        if np.isfinite(self.ns_per_loop_with_angles):
            ratio = GAJDA_SECONDS_PER_LOOP / (self.ns_per_loop_with_angles * 1e-9)
            lines.append(
                "Gajda 3c: one loop with the angles took 4 ms on an 8 MHz PC/XT; here "
                f"{self.ns_per_loop_with_angles:.1f} ns ('exact' + as_euler, 10^6 steps), {ratio:,.0f} times faster."
            )
        return "\n".join(lines)

    def plot(self, directory, prefix: str = "compare") -> list[Path]:
        """Write two PNG figures: the Euler angles over time, and every method's error over time.

        Parameters
        ----------
        directory : path-like
            Created if missing.
        prefix : str
            File-name prefix.

        Returns
        -------
        list of pathlib.Path
            The files written (each written to a temporary file first, then renamed).
        """
        from .figures import plot_comparison  # every line its own style; both files or neither

        return plot_comparison(self, directory, prefix)


def _deg(x: float) -> str:
    return "-" if not np.isfinite(x) else f"{np.degrees(x):.2e}"


def _run(data: ImuData, method: str, q0) -> tuple[np.ndarray, list]:
    from ..propagate.integrate import AttitudeIntegrator

    options = {"on_singular": "nan"}
    if data.gyro_input == "increment":
        integ = AttitudeIntegrator(method, q0=q0, input="increment", **options)
        body = integ.update(data.gyro)
    else:
        integ = AttitudeIntegrator(method, q0=q0, input=data.gyro_input, t0=data.t[0], **options)
        body = integ.update(data.gyro, t=data.t[1:])
    rest = integ.finish()
    q = np.concatenate([np.asarray(q0, dtype=float)[None], body, rest])
    return q, integ.singular_steps


def compare(data: ImuData, methods=None, *, timing_repeats: int = 3, title: str = "") -> Comparison:
    """Run every propagation method on the same readings and measure it against the truth.

    Parameters
    ----------
    data : ImuData
        Readings and truth, e.g. from :func:`strapdown.simulate.sample`.
    methods : sequence of str, optional
        Default: every method in :data:`strapdown.METHODS`.
    timing_repeats : int
        Timed runs per method (the best counts).
    title : str
        For the table and plots.

    Returns
    -------
    Comparison
        Results in the order of ``methods``.

    Examples
    --------
    >>> from strapdown.evaluate.compare import compare
    >>> from strapdown.simulate import hammerhead_loop, sample
    >>> cmp = compare(sample(hammerhead_loop(), 50.0, gyro="increment"), methods=["exact", "euler-angles"],
    ...               timing_repeats=1)
    >>> cmp.result("exact").max_error < 1e-12, cmp.result("euler-angles").singular_steps > 0
    (True, True)
    """
    methods = list(METHODS if methods is None else methods)
    q0 = data.q_true[0]
    rotated_truth = multiply(_ROTATED_START, data.q_true)
    results = []
    n = data.gyro.shape[0]
    for method in methods:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            q, singular = _run(data, method, q0)
            best = np.inf
            for _ in range(max(1, timing_repeats)):
                start = time.perf_counter()
                _run(data, method, q0)
                best = min(best, time.perf_counter() - start)
            q_rot, _ = _run(data, method, rotated_truth[0])
        ok = np.isfinite(q).all(axis=-1)
        error = np.full(q.shape[0], np.nan)
        error[ok] = angle_between(q[ok], data.q_true[ok], check=False)
        norm_error = float(np.abs(np.linalg.norm(q[ok], axis=-1) - 1).max()) if ok.any() else float("nan")
        rot_ok = np.isfinite(q_rot).all(axis=-1)
        rotated_error = float(angle_between(q_rot, rotated_truth, check=False).max()) if rot_ok.all() else float("nan")
        first = min(s for _, s in singular) if singular else None
        results.append(
            MethodResult(
                method=method,
                q=q,
                error=error,
                norm_error=norm_error,
                singular_steps=len(singular),
                first_singular_time=None if first is None else float(data.t[first]),
                rotated_error=rotated_error,
                ns_per_step=best / n * 1e9,
            )
        )
    cmp = Comparison(data=data, results=results, title=title)
    if "exact" in methods:
        cmp.ns_per_loop_with_angles = _ns_per_loop(data, timing_repeats)
    return cmp


def _ns_per_loop(data: ImuData, repeats: int) -> float:
    """Gajda's loop (stages 2-4): the exact update and the angles, per step, over at least 10^6 steps."""
    from ..propagate.integrate import integrate

    reps = int(np.ceil(_GAJDA_STEPS / data.gyro.shape[0]))
    gyro = np.tile(data.gyro, (reps, 1))
    dt = float(np.median(np.diff(data.t)))
    options = {} if data.gyro_input == "increment" else {"dt": dt}
    best = np.inf
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        q = integrate(gyro, method="exact", input=data.gyro_input, **options)
        as_euler(q, "ZYX", yaw_range="positive")
        best = min(best, time.perf_counter() - start)
    return best / gyro.shape[0] * 1e9


@dataclass
class ReferenceErrors:
    """An attitude estimate against another one (an autopilot's), heading and inclination told apart.

    Attributes
    ----------
    rows : int
        The instants compared.
    total, heading, inclination : float
        RMS errors, degrees (:func:`strapdown.evaluate.metrics.attitude_errors`).
    heading_offset : float
        The constant part of the heading difference, degrees, as a compass heading: ours minus theirs,
        clockwise seen from above (the circular mean of the signed heading error).
    heading_rest : float
        The heading RMS once that offset is removed, degrees.
    declination : float or None
        The magnetic declination at the place and date, degrees east, when known.
    expected_offset : float or None
        The offset the declination explains: -declination when ours points to magnetic north and theirs to true
        north (a magnetic heading is the true one minus D), 0 when both point the same way.
    """

    rows: int
    total: float
    heading: float
    inclination: float
    heading_offset: float
    heading_rest: float
    declination: float | None = None
    expected_offset: float | None = None

    def text(self, ours: str = "ours", theirs: str = "theirs") -> str:
        """The comparison in a few lines, saying how much of the heading offset the declination explains."""
        lines = [
            f"{ours} against {theirs}, {self.rows} instants:",
            f"  total        {self.total:8.3f} deg RMS",
            f"  inclination  {self.inclination:8.3f} deg RMS",
            f"  heading      {self.heading:8.3f} deg RMS: a constant offset of {self.heading_offset:+.3f} deg "
            f"(ours - theirs, clockwise), {self.heading_rest:.3f} deg RMS about it",
        ]
        if self.expected_offset is not None:
            rest = _wrap_deg(self.heading_offset - self.expected_offset)
            # the declination is the offset when what is left of it is within the heading's own spread
            matches = abs(rest) <= max(1.0, self.heading_rest)
            lines.append(
                f"  declination  {self.declination:+8.3f} deg east: it explains {self.expected_offset:+.3f} deg of the "
                f"offset, {rest:+.3f} deg remain; "
                + ("the offset matches the declination" if matches else "the offset is not the declination")
            )
        return "\n".join(lines)


def _wrap_deg(a):
    return (np.asarray(a) + 180.0) % 360.0 - 180.0 if np.ndim(a) else float((a + 180.0) % 360.0 - 180.0)


def reference_errors(
    q_est, q_ref, frame: str, *, declination_deg: float | None = None, ours: str = "magnetic", theirs: str = "true"
) -> ReferenceErrors:
    """Total, heading and inclination RMS of an estimate against a reference, and their constant heading offset.

    Parameters
    ----------
    q_est, q_ref : array_like, shape (N, 4)
        The two attitudes at the same instants, body to the same frame (NaN rows are left out).
    frame : str
        That frame (``"NED"``, ``"ENU"``): whether its z points down or up, for the sense of the heading.
    declination_deg : float, optional
        The declination at the place and date, degrees east.
    ours, theirs : {"magnetic", "true", "free"}
        Which north each heading points to: the offset the declination explains is -D from magnetic to true.

    Returns
    -------
    ReferenceErrors
        The errors, degrees.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown import from_euler
    >>> from strapdown.evaluate.compare import reference_errors
    >>> theirs = from_euler(np.column_stack([np.linspace(0, 90, 50), np.zeros(50), np.zeros(50)]), "ZYX", degrees=True)
    >>> ours = from_euler(np.column_stack([np.linspace(0, 90, 50) - 4.0, np.zeros(50), np.full(50, 1.0)]), "ZYX",
    ...                   degrees=True)
    >>> r = reference_errors(ours, theirs, "NED", declination_deg=4.0)
    >>> round(r.heading_offset, 6), round(r.inclination, 6), r.expected_offset
    (-4.0, 1.0, -4.0)
    """
    from .metrics import attitude_errors, error_quaternion, rmse

    est, ref = np.asarray(q_est, dtype=np.float64), np.asarray(q_ref, dtype=np.float64)
    keep = np.isfinite(est).all(axis=1) & np.isfinite(ref).all(axis=1)
    est, ref = est[keep], ref[keep]
    if not keep.any():
        raise ValueError("no instant where both attitudes are known")
    errors = {k: float(np.degrees(rmse(v))) for k, v in attitude_errors(est, ref).items()}
    e = error_quaternion(est, ref)
    signed = 2 * np.arctan2(e[:, 3], e[:, 0])  # about the frame's z
    if frame.upper()[2:] not in ("D", "U"):
        raise ValueError(f"frame {frame!r}: its z axis must be vertical (D or U), as in NED, ENU, NWU")
    down = frame.upper()[2] == "D"  # a turn about a down z is clockwise seen from above: a compass heading's sense
    offset = float(np.arctan2(np.sin(signed).mean(), np.cos(signed).mean()))
    rest = np.angle(np.exp(1j * (signed - offset)))
    compass = float(np.degrees(offset) if down else -np.degrees(offset))
    expected = None
    if declination_deg is not None and "free" not in (ours, theirs):
        expected = {("magnetic", "true"): -declination_deg, ("true", "magnetic"): declination_deg}.get(
            (ours, theirs), 0.0
        )
    return ReferenceErrors(
        int(keep.sum()),
        errors["total"],
        errors["heading"],
        errors["inclination"],
        compass,
        float(np.degrees(np.sqrt(np.mean(rest**2)))),
        declination_deg,
        expected,
    )
