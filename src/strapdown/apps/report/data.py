"""What a report shows, computed at full rate: the readings, every estimator's run, the reference and the errors.

:func:`assemble` reads one recording whole through :class:`strapdown.io.ImuFile` (units fixed, every chunk
checked), turns the readings into the output's body axes as ``strapdown estimate`` does
(:func:`strapdown.io.conventions.resolve_axes`), applies the calibrations, cuts it at the gaps, runs each
estimator of :data:`strapdown.fusion.ESTIMATORS` over each segment, and puts the reference (a ``truth`` file, or
the log's own estimate) on the same rows and frames through :func:`strapdown.io.pipelines.truth.align_truth`, the
alignment ``strapdown plot --truth`` uses.  Every figure of the page is drawn from these arrays; only the drawing
is decimated (:mod:`.decimate`), never the numbers (RMS, bias), which are the library's own
(:func:`strapdown.evaluate.metrics.rmse_errors`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from ...io.pipelines import FileOptions

__all__ = ["EstimatorRun", "Recording", "ReportOptions", "assemble"]

_ROWS = 1 << 18  # rows per step of the progress bar (reading and estimating alike)


@dataclass(frozen=True)
class ReportOptions(FileOptions):
    """What ``strapdown report`` reads, runs and shows, besides the options of every file command.

    Attributes
    ----------
    estimators : tuple of str
        Keys of :data:`strapdown.fusion.ESTIMATORS`, shown side by side; the first is the main one (its bias,
        flags and the 3D view).
    params : mapping or parameter object, optional
        Parameters of the first estimator (a mapping overrides the defaults by name).
    truth : path-like, optional
        A file with the true attitude (a simulated log, a ``qw..qz`` table, a PX4 log); by default the log's own
        estimate where the input records one (a PX4 log's ``vehicle_attitude``).
    truth_frame, truth_body : str, optional
        The truth's frames when its file does not say them.
    mag : bool, optional
        Use the magnetometer: None where there is one, True to require it, False to leave it out.
    calibration : mapping of str to strapdown.calibrate.Calibration, optional
        Calibrations to apply (:func:`strapdown.calibrate.load`); a magnetometer's is shown before and after.
    fit_mag : bool
        Fit the magnetometer's calibration on this recording (:func:`strapdown.calibrate.magnetometer`) and
        apply it.
    allan : path-like, optional
        A recording at rest whose gyro Allan deviation is shown with its fitted noise terms.
    declination : float, optional
        Magnetic declination, radians east: the 9D heading turned to true north.
    points : int
        Time buckets per line of the page (:func:`.decimate.minmax_indices`): each keeps two samples.
    frames : int
        Attitudes the 3D view steps through, evenly in time.
    title : str, optional
        The page's title (default: the input's name).

    ``on_gap`` is ``"restart"`` by default here: every estimator starts afresh after a gap, which the page shows
    as a band; ``"error"`` stops at the first gap, as ``strapdown estimate`` does.
    """

    on_gap: str = "restart"
    estimators: tuple = ("attitude",)
    params: object = None
    truth: object = None
    truth_frame: str | None = None
    truth_body: str | None = None
    mag: bool | None = None
    calibration: object = None
    fit_mag: bool = False
    allan: object = None
    declination: float | None = None
    points: int = 2000
    frames: int = 1500
    title: str | None = None

    def __post_init__(self):
        super().__post_init__()
        from ...fusion.registry import ESTIMATORS

        names = (self.estimators,) if isinstance(self.estimators, str) else tuple(self.estimators)
        if not names:
            raise ValueError("estimators: name at least one")
        unknown = [n for n in names if n not in ESTIMATORS]
        if unknown:
            raise ValueError(f"unknown estimator {unknown[0]!r}; choose from {', '.join(ESTIMATORS)}")
        if len(set(names)) != len(names):
            raise ValueError(f"estimators: each once, got {', '.join(names)}")
        object.__setattr__(self, "estimators", names)
        if self.on_gap == "split":
            raise ValueError("a report is one page: on_gap is 'restart' (a band at each gap) or 'error'")
        for name in ("points", "frames"):
            value = getattr(self, name)
            if not (isinstance(value, int) and value >= 2):
                raise ValueError(f"{name} must be an integer >= 2, got {value!r}")


@dataclass
class EstimatorRun:
    """One estimator over the recording.

    Attributes
    ----------
    name : str
        Its key in :data:`strapdown.fusion.ESTIMATORS`.
    params : dataclass
        The parameters it ran with.
    mode : str
        ``"9D"`` or ``"6D"``.
    q : numpy.ndarray, shape (n, 4)
        Attitude after each row, body to ``Recording.axes.frame``.
    bias, bias_sigma : numpy.ndarray of shape (n, 3), or None
        Gyro bias and its standard deviation, rad/s, body axes (None where the estimator has none).
    flags : dict of str to numpy.ndarray of bool
        The named flags (:data:`strapdown.io.tables.FLAG_COLUMNS`) where the estimator reports them.
    heading : str
        ``"true"``, ``"magnetic"`` or ``"free"`` (6D: no north).
    errors : dict of str to numpy.ndarray, optional
        Total, heading and inclination error against the reference per row, rad (NaN outside its span).
    rmse : dict of str to float, optional
        Their RMS over the reference's span, degrees (:func:`strapdown.evaluate.metrics.rmse_errors`).
    """

    name: str
    params: object
    mode: str
    q: np.ndarray
    bias: np.ndarray | None
    bias_sigma: np.ndarray | None
    flags: dict
    heading: str = "free"
    errors: dict | None = None
    rmse: dict | None = None

    @property
    def final_bias(self) -> tuple[np.ndarray, np.ndarray | None] | None:
        """The last bias (deg/s) and its sigma, or None."""
        if self.bias is None:
            return None
        sigma = None if self.bias_sigma is None else np.degrees(self.bias_sigma[-1])
        return np.degrees(self.bias[-1]), sigma


@dataclass
class Recording:
    """One recording, ready to draw.

    Attributes
    ----------
    paths : list of pathlib.Path
        The input files.
    format : str
        The input format read.
    t : numpy.ndarray, shape (n,)
        Seconds from the first sample.
    gyro, acc, mag : numpy.ndarray of shape (n, 3), or None
        Calibrated readings in the output's body axes: rad/s, m/s², µT (NaN rows: no sample).
    mag_raw : numpy.ndarray of shape (n, 3), or None
        The magnetometer before its calibration (sensor axes), when one was applied.
    axes : strapdown.io.conventions.Axes
        Frame and body axes.
    segment : numpy.ndarray of int, shape (n,)
        The segment of each row (a new one after each gap).
    gaps : list of (float, float)
        The gaps, (time before, time after), s.
    runs : list of EstimatorRun
        One per estimator, the main one first.
    reference : numpy.ndarray of shape (n, 4), or None
        The reference attitude on the rows (NaN outside its span), in the run's frames.
    reference_label : str
        What the reference is.
    summary : list of (str, str)
        The page's summary, in order.
    notes : list of str
        What the reader and the alignment said.
    calibrations : dict
        By sensor, the calibrations applied.
    allan : strapdown.calibrate.AllanAnalysis or None
        The Allan analysis of ``options.allan``.
    rates : dict of str to float
        Sample rate of each sensor, Hz.
    """

    paths: list
    format: str
    t: np.ndarray
    gyro: np.ndarray
    acc: np.ndarray | None
    mag: np.ndarray | None
    mag_raw: np.ndarray | None
    axes: object
    segment: np.ndarray
    gaps: list
    runs: list = field(default_factory=list)
    reference: np.ndarray | None = None
    reference_label: str = ""
    summary: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    calibrations: dict = field(default_factory=dict)
    allan: object = None
    rates: dict = field(default_factory=dict)
    title: str = ""

    @property
    def main(self) -> EstimatorRun:
        """The first estimator's run."""
        return self.runs[0]


def assemble(path, options: ReportOptions | None = None, *, progress=None, **changes) -> Recording:
    """Read a recording, run the estimators and align the reference: everything the page shows.

    Parameters
    ----------
    path : path-like or sequence of path-like
        One recording: a file, an export folder, or one file per sensor.
    options, **changes
        :class:`ReportOptions`, whole or field by field.
    progress : callable, optional
        Called with (rows done, rows in all) while reading and estimating.

    Returns
    -------
    Recording
        The arrays at full rate and the summary.

    Raises
    ------
    ValueError
        For input the estimate command refuses (named file, column and line), an empty file, or a truth whose
        frames cannot be checked.
    """
    o = options or ReportOptions()
    if not isinstance(o, ReportOptions):
        raise TypeError(f"options must be a ReportOptions, got {type(o).__name__}")
    o = replace(o, **changes) if changes else o
    rec, imu_info = _read(path, o, progress)
    _estimate(rec, o, imu_info, progress)
    _reference(rec, path, o, imu_info)
    if o.allan is not None:
        rec.allan = _allan(o.allan, o)
    from .summary import summarise

    rec.summary = summarise(rec, o, imu_info)
    return rec


def _needs(o: ReportOptions) -> tuple[tuple, tuple, bool]:
    """(required, optional quantities, whether any estimator takes a magnetometer)."""
    from ...fusion.registry import ESTIMATORS

    takes_mag = any(ESTIMATORS[n].takes_mag for n in o.estimators)
    if o.mag and not takes_mag:
        raise ValueError(f"{', '.join(o.estimators)} take no magnetometer (6D only): leave out mag=True / --9d")
    require = ("gyro", "acc") + (("mag",) if o.mag else ())
    # a magnetometer is read when there is one, for its figures, even if it is left out of the estimate
    optional = () if o.mag else ("mag",)
    return require, optional, takes_mag and o.mag is not False


def _read(path, o: ReportOptions, progress):
    from ...calibrate import by_sensor
    from ...io import ImuFile
    from ...io.conventions import GapSplitter, resolve_axes, time_metadata
    from ...io.pipelines.estimate import calibrated, check_axes

    require, optional, use_mag = _needs(o)
    columns = replace(o.columns, max_gap=0) if o.on_gap == "restart" else o.columns  # gaps are cut here
    with ImuFile(path, columns, require=require, optional=optional) as imu:
        axes = resolve_axes(imu, o.frame, o.body, o.out_body)
        total = imu.rows
        parts = []
        done = 0
        for chunk in imu.chunks(_ROWS):
            parts.append(chunk)
            done += len(chunk)
            if progress is not None:
                progress(done, None if total is None else total * (1 + len(o.estimators)))
        if not parts or not sum(len(p) for p in parts):
            raise ValueError(f"{imu.path}: no rows to report")
        t = np.concatenate([p.t for p in parts])
        readings = {k: np.concatenate([getattr(p, k) for p in parts]) for k in imu.picks}
        info = {
            "describe": imu.describe(),
            "format": imu.format,
            "sparse": set(getattr(imu, "sparse", ()) or ()),
            "rate": imu.rate,
            "period": imu.period,
            "notes": list(imu.notes),
            "where": imu.where,
            "time_meta": time_metadata(imu, float(t[0])),
            "source_path": imu.path,
            "unit_check": o.columns.unit_check,
            "units": dict(imu.units),
        }
    info["use_mag"] = use_mag and "mag" in readings
    cal = dict(by_sensor(o.calibration))
    mag_raw = readings.get("mag")
    if o.fit_mag:
        cal["mag"] = _fit_mag(mag_raw, axes.sensor, info["source_path"])
    check_axes(cal, axes.sensor, axes.declared)
    gyro, acc, mag = calibrated(cal, readings["gyro"], readings.get("acc"), mag_raw)
    splitter = GapSplitter(o.columns.max_gap if o.on_gap == "restart" else 0, info["period"])
    segment = np.zeros(t.size, dtype=np.int64)
    segment[splitter(t)] = 1
    segment = np.cumsum(segment)
    rec = Recording(
        paths=[Path(p) for p in (path if isinstance(path, list | tuple) else [path])],
        format=info["format"],
        t=t - t[0],
        gyro=axes.rotate(gyro),
        acc=axes.rotate(acc),
        mag=axes.rotate(mag),
        mag_raw=mag_raw if "mag" in cal and mag_raw is not None else None,
        axes=axes,
        segment=segment,
        gaps=[(a - t[0], b - t[0]) for a, b in splitter.gaps],
        calibrations=cal,
    )
    rec.rates = _rates(rec, info)
    return rec, info


def _fit_mag(mag, sensor: str, path):
    from ...calibrate import magnetometer

    if mag is None:
        raise ValueError(f"{path}: no magnetometer readings to fit (fit_mag / --fit-mag)")
    rows = np.isfinite(mag).all(axis=1)
    try:
        return magnetometer(mag[rows], frame=sensor)
    except ValueError as exc:
        raise ValueError(f"{path}: the magnetometer fit failed: {exc}") from None


def _rates(rec: Recording, info: dict) -> dict:
    """Each sensor's mean sample rate over the recording (rows with a sample per second), Hz."""
    duration = float(rec.t[-1] - rec.t[0]) if rec.t.size > 1 else 0.0
    out = {}
    for kind in ("gyro", "acc", "mag"):
        x = getattr(rec, kind)
        if x is None:
            continue
        n = int(np.isfinite(x).all(axis=1).sum()) if kind in info["sparse"] else x.shape[0]
        out[kind] = (info["rate"] if info["rate"] and kind == "gyro" else (n - 1) / duration) if duration else 0.0
    return out


def _estimate(rec: Recording, o: ReportOptions, info: dict, progress) -> None:
    """Run every estimator over every segment, in steps of ``_ROWS`` rows (the progress bar's)."""
    from ...fusion.registry import ESTIMATORS, make_params
    from ...io.tables import FLAG_COLUMNS, flag_bits

    bits = flag_bits()
    n = rec.t.size
    done = n
    total = n * (1 + len(o.estimators))
    cuts = np.flatnonzero(np.diff(rec.segment)) + 1
    bounds = list(zip(np.r_[0, cuts], np.r_[cuts, n], strict=True))
    for k, name in enumerate(o.estimators):
        cls, _, takes_mag = ESTIMATORS[name]
        use_mag = takes_mag and info["use_mag"]
        if not cls.missing_samples and "mag" in info["sparse"] and use_mag and not o.mag:
            # a filter that needs every sensor on every row runs without the slower magnetometer, and says so
            use_mag = False
            rec.notes.append(f"{name} runs 6D: the magnetometer comes at a lower rate than the gyro")
        missing = info["sparse"] & ({"acc", "mag"} if use_mag else {"acc"})
        if missing and not cls.missing_samples:
            raise ValueError(
                f"{info['source_path']}: the {' and '.join(sorted(missing))} readings come at a lower rate than the "
                f"gyro (rows without a sample); {name} needs a sample of every sensor on every row: use -e attitude, "
                "which takes rows without a sample"
            )
        params = make_params(name, o.params if k == 0 else None)
        q = np.empty((n, 4))
        bias = np.empty((n, 3)) if cls.estimates_bias else None
        sigma = None
        flags = np.zeros(n, dtype=np.int64) if cls.reports_flags else None
        for a, b in bounds:
            est = cls(params, frame=rec.axes.frame)
            for s in range(a, b, _ROWS):
                e = min(s + _ROWS, b)
                timing = {"dt": 1.0 / info["rate"]} if info["rate"] else {"t": rec.t[s:e]}
                mag = rec.mag[s:e] if use_mag else None
                try:
                    out = est.update(rec.gyro[s:e], rec.acc[s:e], mag, **timing)
                except ValueError as exc:
                    i = getattr(exc, "sample", None)
                    where = info["where"](s if i is None else s + i)
                    raise ValueError(f"{info['source_path']}: {name} failed at {where}: {exc}") from None
                q[s:e] = out.q
                if bias is not None:
                    bias[s:e] = out.bias
                extra_sigma = out.extra.get("bias_sigma") if out.extra else None
                if extra_sigma is not None:
                    sigma = np.full((n, 3), np.nan) if sigma is None else sigma
                    sigma[s:e] = extra_sigma
                if flags is not None:
                    flags[s:e] = out.flags
                done += e - s
                if progress is not None:
                    progress(done, total)
        lost = np.flatnonzero(~np.isfinite(q).all(axis=1))
        if lost.size:
            raise ValueError(
                f"{info['source_path']}: the {name} estimator lost the attitude at {info['where'](int(lost[0]))}: "
                "a reading that large is not plausible; check that row and the units"
            )
        if o.declination is not None and use_mag:
            from ...calibrate import to_true_north

            q = to_true_north(q, o.declination, frame=rec.axes.frame)
        named = {}
        if flags is not None:
            named = {c: (flags & bits[c]) != 0 for c in FLAG_COLUMNS}
        limit = getattr(params, "bias_limit", None)
        if limit and bias is not None:  # clipped at the limit (Mahony-type), or beyond the prior (flag bit)
            named["bias_at_limit"] = named.get("bias_at_limit", False) | (np.abs(bias) >= limit * (1.0 - 1e-9)).any(
                axis=1
            )
        heading = ("true" if o.declination is not None else "magnetic") if use_mag else "free"
        rec.runs.append(EstimatorRun(name, params, "9D" if use_mag else "6D", q, bias, sigma, named, heading))


def _reference(rec: Recording, path, o: ReportOptions, info: dict) -> None:
    """The truth (or the log's own estimate) on the rows, and each run's errors against it."""
    from ...evaluate.metrics import attitude_errors, rmse_errors
    from ...io.reference import read_reference

    truth = o.truth
    label = "truth"
    if truth is None:
        if len(rec.paths) != 1 or rec.paths[0].is_dir():
            return
        try:  # the log's own estimate, where its format records one
            own = read_reference(rec.paths[0])
        except (ValueError, OSError):
            return
        truth, label = rec.paths[0], f"the log's own estimate ({own.source})"
    aligned = _aligned(rec, truth, o, info)
    rec.reference = aligned.q
    rec.reference_label = label if o.truth is None else f"truth: {Path(o.truth).name}"
    if aligned.note:
        rec.notes.append(aligned.note)
    mask = aligned.rows & np.isfinite(aligned.q).all(axis=1)
    if not mask.any():
        raise ValueError(f"the reference {truth} has no attitude on the recording's rows")
    for run in rec.runs:
        errors = attitude_errors(run.q[mask], aligned.q[mask])
        run.errors = {k: np.full(rec.t.size, np.nan) for k in errors}
        for k, v in errors.items():
            run.errors[k][mask] = v
        # a 6D heading is free: its offset from the reference's north is not an error
        run.rmse = rmse_errors(run.q[mask], aligned.q[mask], heading_offset=run.mode == "6D")
        run.rmse["max_total"] = float(np.degrees(np.nanmax(errors["total"])))


def _aligned(rec: Recording, truth, o: ReportOptions, info: dict):
    """:func:`strapdown.io.pipelines.truth.align_truth` on the main run, through a scratch table of its attitudes."""
    import tempfile

    from ...io.pipelines.truth import align_truth
    from ...io.writers import write_table

    meta = {**rec.axes.metadata(), **info["time_meta"]}
    q = rec.main.q
    with tempfile.TemporaryDirectory(prefix="strapdown-report-") as scratch:
        table = {"t": rec.t, "qw": q[:, 0], "qx": q[:, 1], "qy": q[:, 2], "qz": q[:, 3]}
        est = write_table(Path(scratch) / "estimate.parquet", table, metadata=meta)
        return align_truth(est, truth, truth_frame=o.truth_frame, truth_body=o.truth_body)


def _allan(path, o: ReportOptions):
    from ...calibrate import allan
    from ...io import ImuFile

    with ImuFile(path, require=("gyro",)) as imu:
        parts = [c for c in imu.chunks(_ROWS)]
        rate = imu.rate or (1.0 / imu.period if imu.period else None)
    if rate is None:
        raise ValueError(f"{path}: no sample rate for the Allan analysis: give a time column or --rate")
    return allan(np.concatenate([p.gyro for p in parts]), rate)
