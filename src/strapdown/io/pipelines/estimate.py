"""``strapdown estimate``: an estimator run over a file, streaming."""

from __future__ import annotations

import inspect
import time
from dataclasses import dataclass, replace

import numpy as np

from .._ahead import ReadAhead
from ..conventions import output_metadata, resolve_axes
from ..imu import ImuFile
from ..plausibility import gravity_warning
from ..tables import _attitude_columns, flag_bits
from ._common import (
    FileOptions,
    Report,
    Segments,
    culprit,
    gap_bridge,
    input_paths,
    metadata,
    options_of,
    output_path,
    read_columns,
    rows_text,
    with_progress,
)

__all__ = ["EstimateOptions", "estimate_file", "estimator_inputs"]


def estimator_inputs(cls) -> tuple[str, ...]:
    """The extra keyword inputs an estimator's ``update`` takes (``known_acc``, ``pitch_roll``, ...).

    Parameters
    ----------
    cls : type
        An estimator class.

    Returns
    -------
    tuple of str
        Keyword-only parameters other than the timing.

    Examples
    --------
    >>> from strapdown.fusion import Mahony, TiltEstimator
    >>> from strapdown.io.pipelines import estimator_inputs
    >>> estimator_inputs(TiltEstimator), estimator_inputs(Mahony)
    (('known_acc', 'pitch_roll'), ())
    """
    sig = inspect.signature(cls.update)
    skip = {"dt", "t", "degrees"}
    return tuple(n for n, p in sig.parameters.items() if p.kind is inspect.Parameter.KEYWORD_ONLY and n not in skip)


@dataclass(frozen=True)
class EstimateOptions(FileOptions):
    """The options of :func:`estimate_file` (and ``strapdown estimate``), besides those of every file command.

    Attributes
    ----------
    estimator : str
        A key of :data:`strapdown.fusion.ESTIMATORS` (default: the AttitudeEstimator).
    params : mapping or parameter object, optional
        Parameters (a mapping overrides the defaults by name; validated).
    mag : bool, optional
        Use the magnetometer (9D): None uses it when the file has one and the estimator takes one; True
        requires it; False leaves it out.
    q0 : array_like, shape (4,), optional
        Initial attitude in ``frame``; by default from the first sample.
    calibration : mapping of str to strapdown.calibrate.Calibration, optional
        Calibrations by sensor (``"gyro"``, ``"acc"``, ``"mag"``, as
        :func:`strapdown.calibrate.load` returns them), applied to the readings in their own axes before
        anything else.
    declination : float or "auto", optional
        Magnetic declination (radians, east positive): the 9D heading is turned from magnetic to true north.
        ``"auto"``: the World Magnetic Model's at the place and date the log records (its GPS:
        :func:`strapdown.io.reference.log_position`; the ``geomag`` extra), named in the notes and the metadata;
        a ValueError when the log records none.
        The metadata says which (``heading`` = ``true``, ``magnetic`` or ``free`` for 6D).
    noise : {"default", "adapt"}
        ``"adapt"``: the estimator's noise parameters from the sensor's noise model
        (:meth:`strapdown.calibrate.NoiseModel.estimator_params`), taken from the gyro calibration when it holds
        noise figures (``calibrate allan`` / ``calibrate gyro``), else measured on the rests of the first chunk;
        the figures and the parameters used go into the metadata (``noise_*``, ``noise_params``).  Parameters
        given in ``params`` win.  AttitudeEstimator and TiltEstimator only.

    The fields of :class:`FileOptions` (``columns``, ``out``, ``frame``, ``body``, ``out_body``, ``on_gap``,
    ``chunk_rows``) apply too; ``columns.extra`` gives the estimator's further inputs (``known_acc``,
    ``pitch_roll``).
    """

    estimator: str = "attitude"
    params: object = None
    mag: bool | None = None
    q0: object = None
    calibration: object = None
    declination: float | str | None = None
    noise: str = "default"


def estimate_file(path, output=None, options: EstimateOptions | None = None, *, progress=None, **changes) -> Report:
    """Run an estimator of :data:`strapdown.fusion.ESTIMATORS` over a file and write its attitudes, streaming.

    Parameters
    ----------
    path : path-like or sequence of path-like
        A file with gyro and accelerometer (and magnetometer) readings in any input format, or one file per
        sensor.
    output : path-like, optional
        Output file; by default ``<stem>.estimate.csv`` (``.parquet`` for Parquet input) beside the input.
    options, **changes
        What to run and how to read and write: :class:`EstimateOptions` (``estimator="mahony"``).

    Returns
    -------
    Report
        ``notes`` holds the gaps and a warning when the bias sits at its limit.

    Notes
    -----
    Output columns: ``t`` (s from the first sample), ``qw..qz``, Euler angles, ``bias_*`` (the unit in the
    name), ``flags`` (bit mask of :func:`strapdown.io.tables.flag_bits`) and one boolean column per flag:
    ``rest``, ``acc_rejected``, ``mag_rejected``, ``inverted``, ``bias_at_limit``, and ``heading_free``: True
    where no magnetometer sample has set the heading yet (every row of a 6D run; in 9D the rows before the first
    field, and after a restart until the next).  Under the default ``on_gap`` also ``gap`` and ``segment``
    (:class:`~strapdown.io.pipelines.FileOptions`).  Metadata: :mod:`strapdown.io.conventions`.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import estimate_file, read_table, write_table
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> n = 500
    >>> level = {"t": np.arange(n) * 0.01, "gx": np.zeros(n), "gy": np.zeros(n), "gz": np.zeros(n),
    ...          "ax": np.zeros(n), "ay": np.zeros(n), "az": np.full(n, 9.81)}
    >>> report = estimate_file(write_table(folder / "still.parquet", level), estimator="mahony")
    >>> table = read_table(report.output)
    >>> report.output.name, table["pitch_deg"][-1].round(9), table["roll_deg"][-1].round(9)
    ('still.estimate.parquet', np.float64(0.0), np.float64(0.0))
    """
    t_start = time.perf_counter()
    o = options_of(EstimateOptions, options, changes, "estimate_file")
    run = _Estimation(o)
    output = output_path(path, output, "estimate", o.out.format)
    columns = read_columns(o)
    with ImuFile(path, columns, require=run.require, optional=run.optional) as imu:
        meta = run.start(imu, path)
        out = Segments(imu, output, o.out, o.columns.max_gap, o.on_gap, meta, gap_bridge(o, imu))
        with out, ReadAhead(imu.chunks(o.chunk_rows)) as chunks:
            for seg, chunk in out.pieces(with_progress(chunks, imu.rows, progress)):
                out.write(seg, run.chunk(imu, path, out, seg, chunk))
        report = Report(input_paths(path)[0], out.outputs[0], out.rows, time.perf_counter() - t_start, imu.describe())
        report.notes.append(f"{o.estimator} {'9D' if run.use_mag else '6D'}, {run.axes.describe()}")
        report.notes.extend(run.warnings + out.notes)
        report.outputs = out.outputs
        return report


class _Estimation:
    """One estimator over the chunks of a file: what it needs from the file, and each chunk's output columns."""

    def __init__(self, o: EstimateOptions):
        from ...calibrate import by_sensor
        from ...fusion.registry import ESTIMATORS, make_params

        self.o = o
        self.params = make_params(o.estimator, o.params)  # also rejects an unknown estimator, listing the known ones
        self.cls, _, takes_mag = ESTIMATORS[o.estimator]
        allowed = estimator_inputs(self.cls)
        for name, _ in o.columns.extra:
            if name not in allowed:
                listing = ", ".join(allowed) or "none"
                raise ValueError(f"{o.estimator} takes no input {name!r} (--extra); its extra inputs: {listing}")
        if o.mag and not takes_mag:
            raise ValueError(f"{o.estimator} does not take a magnetometer (6D only): leave out --mag / --9d")
        extra_names = [name for name, _ in o.columns.extra]
        self.require = ("gyro",) + (() if "pitch_roll" in extra_names else ("acc",)) + (("mag",) if o.mag else ())
        self.optional = ("mag",) if (takes_mag and o.mag is None) else ()
        self.limit = getattr(self.params, "bias_limit", None)
        self.calibrations = by_sensor(o.calibration)
        self.est = None
        self.warned = False
        if o.noise not in ("default", "adapt"):
            raise ValueError(f"noise must be 'default' or 'adapt', got {o.noise!r}")
        if o.noise == "adapt" and o.estimator not in ("attitude", "tilt"):
            raise ValueError(f"noise='adapt' sets AttitudeEstimator and TiltEstimator parameters, not {o.estimator}'s")
        self.noise = None  # the NoiseModel in use, once known
        self.heading_known = False
        self.warnings: list[str] = []

    def start(self, imu, path) -> dict:
        """Check the file against the estimator and calibrations; the output's metadata."""
        o = self.o
        sparse = set(getattr(imu, "sparse", ()) or ())
        if sparse and not self.cls.missing_samples:
            raise ValueError(
                f"{path}: the {' and '.join(sorted(sparse))} readings come at a lower rate than the gyro (rows "
                f"without a sample); {o.estimator} needs a sample of every sensor on every row: use -e attitude, "
                "which takes rows without a sample"
            )
        self.axes = resolve_axes(imu, o.frame, o.body, o.out_body)
        self.use_mag = "mag" in imu.picks
        check_axes(self.calibrations, self.axes.sensor, self.axes.declared)
        upside_down = gravity_warning(imu, self.axes.sensor, self.axes.declared)
        self.warnings += [upside_down] if upside_down else []
        meta = metadata("estimate", estimator=o.estimator, mode="9D" if self.use_mag else "6D")
        self.declination = self._declination(imu, path)
        meta.update(heading_metadata(self.use_mag, self.declination, self.calibrations))
        if self.place is not None:
            meta["declination_place"] = self.place.describe()
        meta.update(self.axes.metadata())
        meta.update(output_metadata(o.out, bias=self.cls.estimates_bias, flags=self.cls.reports_flags))
        if o.out.flags:
            meta["heading_free"] = "True where no magnetometer sample has set the heading yet (every row in 6D)"
        gyro_cal = self.calibrations.get("gyro")
        if o.noise == "adapt" and gyro_cal is not None and _has_noise(gyro_cal):
            from ...calibrate import NoiseModel

            self._adapt(NoiseModel.from_calibration(gyro_cal, fs=imu.rate), meta)
        return meta

    def _adapt(self, model, meta: dict) -> None:
        """The parameters of a noise model (those given in params win), and both in the metadata."""
        from collections.abc import Mapping
        from dataclasses import fields

        self.noise = model
        p = self.o.params
        # a whole parameter object given: nothing is adapted; a mapping: its names are not
        given = set() if p is None else set(p) if isinstance(p, Mapping) else {f.name for f in fields(self.params)}
        changes = {k: v for k, v in model.estimator_params(self.o.estimator).items() if k not in given}
        self.params = replace(self.params, **changes)
        meta.update(model.metadata())
        meta["noise_params"] = ", ".join(f"{k}={v:.6g}" for k, v in sorted(changes.items())) or "none"

    def _declination(self, imu, path):
        """The declination in radians: as given, or (``"auto"``) the model's at the log's own place and date."""
        self.place = None
        given = self.o.declination
        if not isinstance(given, str):
            return given
        if given != "auto":
            raise ValueError(f"declination must be radians or 'auto', got {given!r}")
        if not self.use_mag:
            raise ValueError("a declination needs the magnetometer (9D): a 6D heading has no north to correct")
        from ...calibrate import declination
        from ..reference import log_position

        self.place = log_position(path, imu.format if imu.format != "files" else None)
        if self.place is None:
            raise ValueError(
                f"{path} records no GPS position and date (a GPS topic, a Location file): --declination auto "
                "needs --lat, --lon and --date for it"
            )
        p = self.place
        degrees = float(declination(latitude=p.latitude_deg, longitude=p.longitude_deg, date=p.date, degrees=True))
        self.warnings.append(f"declination {degrees:.3f}° east (World Magnetic Model at {p.describe()})")
        return float(np.radians(degrees))

    def chunk(self, imu, path, out: Segments, seg: int, chunk) -> dict:
        """The output columns of one chunk of one segment (a new segment starts the estimator afresh)."""
        o, axes = self.o, self.axes
        if seg != out.segment_of_estimator:
            if o.noise == "adapt" and self.noise is None:
                self._measure_noise(imu, chunk, out.meta)
            # a new segment starts from its own first sample; q0 is the first segment's only
            self.est = self.cls(self.params, q0=o.q0 if self.est is None else None, frame=axes.frame)
            out.segment_of_estimator = seg
            self.heading_known = False  # a restart knows no heading until its first field
        timing = {"dt": 1.0 / imu.rate} if imu.rate else {"t": chunk.t}
        extra = {k: axes.rotate(v) if k == "known_acc" else v for k, v in chunk.extra.items()}
        gyro, acc, mag = calibrated(self.calibrations, chunk.gyro, chunk.acc, chunk.mag if self.use_mag else None)
        mag = axes.rotate(mag) if self.use_mag else None
        try:
            e, free = self._update(axes.rotate(gyro), axes.rotate(acc), mag, timing, extra)
        except ValueError as exc:  # the estimator's own words name its arrays, not the file
            k = getattr(exc, "sample", None)  # strapdown._support.validate.SampleError: one sample of the chunk
            where = rows_text(imu, chunk) if k is None else imu.where(chunk.row + k)
            raise ValueError(f"{path}: {o.estimator} failed at {where}: {exc}") from None
        lost = np.flatnonzero(~np.isfinite(e.q).all(axis=1))
        if lost.size:
            raise ValueError(
                f"{path}: the {o.estimator} estimator lost the attitude at {culprit(imu, chunk, int(lost[0]))}: a "
                "reading that large is not plausible; check that row and the units"
            )
        at_limit = self._at_limit(e, imu, out, chunk)
        q = e.q
        if self.declination is not None:
            from ...calibrate import to_true_north

            q = to_true_north(q, self.declination, frame=axes.frame)
        cols = _attitude_columns(chunk.t, q, o.out, e.bias, e.flags, at_limit, check=False, t0=out.t_first)
        if o.out.flags:
            cols["heading_free"] = free
        return cols

    def _update(self, gyro, acc, mag, timing: dict, extra: dict):
        """The estimator's update on one chunk, and its rows whose heading is still free (no field has set it).

        In 6D every row's heading is free.  In 9D a row's heading is free until the first magnetometer sample
        has set it: for the AttitudeEstimator, until its first heading update (``mag_updates`` in its state,
        at most one block of ``1 / update_rate`` after the first sample), so the chunk is run in parts around
        that row (an update on parts equals one on the whole); for the others, until the first sample.
        """
        n = gyro.shape[0]
        if not self.use_mag or self.heading_known:
            return self.est.update(gyro, acc, mag, **timing, **extra), np.full(n, not self.use_mag)
        seen = np.isfinite(mag).all(axis=1)
        if not seen.any():
            return self.est.update(gyro, acc, mag, **timing, **extra), np.ones(n, dtype=bool)
        first = int(np.argmax(seen))

        def part(a, b):
            cut = {k: v[a:b] for k, v in timing.items() if k == "t"} or timing
            return self.est.update(gyro[a:b], acc[a:b], mag[a:b], **cut, **{k: v[a:b] for k, v in extra.items()})

        # the rows up to the first field and that field's own row (the heading it sets shows from the next)
        parts, free = [part(0, first + 1)], np.ones(n, dtype=bool)
        row = first + 1
        if "mag_updates" not in (self.est.state or {}):  # no way to tell its first heading update: the sample's
            self.heading_known = True
        else:
            self.heading_known = bool(self.est.state["mag_updates"])
        while row < n and not self.heading_known:
            parts.append(part(row, row + 1))
            self.heading_known = bool(self.est.state["mag_updates"])
            row += 1
        if row < n:
            parts.append(part(row, n))
        free[row:] = False
        return _joined(parts), free

    def _measure_noise(self, imu, chunk, meta: dict) -> None:
        """The noise model from the rests of the first chunk (the metadata is written with its first rows)."""
        from ...calibrate import noise_model

        fs = imu.rate or (1.0 / float(np.median(np.diff(chunk.t))) if len(chunk.t) > 1 else None)
        gyro, acc, _ = calibrated(self.calibrations, chunk.gyro, chunk.acc, None)
        model = noise_model(gyro, acc, fs=fs) if fs and acc is not None else None
        if model is None:
            self.noise = False
            meta["noise_source"] = "defaults (no rest in the first chunk)"
            return
        self._adapt(model, meta)

    def _at_limit(self, e, imu, out: Segments, chunk):
        """Rows whose bias sits at ``bias_limit``; the first one is named once in the notes."""
        if not self.limit or e.bias is None:
            return None
        # Mahony-type filters clip each axis at bias_limit (a bias there says the limit, not the gyro);
        # the AttitudeEstimator and TiltEstimator treat it as a prior's bound and set the flag bit
        at_limit = (np.abs(e.bias) >= self.limit * (1.0 - 1e-9)).any(axis=1)
        if e.flags is not None:
            at_limit |= (np.asarray(e.flags) & flag_bits()["bias_at_limit"]) != 0
        if at_limit.any() and not self.warned:
            self.warned = True
            i = int(np.argmax(at_limit))
            out.notes.append(_bias_warning(e.bias[i], self.limit, out.t(chunk)[i], imu.where(chunk.row + i)))
        return at_limit


def _has_noise(cal) -> bool:
    return "arw" in cal.quality or ("noise" in cal.quality and bool(cal.quality.get("fs")))


def _joined(parts):
    """One Estimate of the Estimates of consecutive rows."""
    from ...fusion.estimate import Estimate

    if len(parts) == 1:
        return parts[0]

    def cat(name):
        values = [getattr(p, name) for p in parts]
        return None if values[0] is None else np.concatenate(values)

    return Estimate(q=cat("q"), frame=parts[0].frame, bias=cat("bias"), flags=cat("flags"))


def _bias_warning(bias, limit: float, t: float, where: str) -> str:
    axis = "xyz"[int(np.argmax(np.abs(bias)))]
    return (
        f"warning: the gyro bias estimate reached bias_limit = {np.degrees(limit):.3g} deg/s (clipped there, or past "
        f"the bound of the estimator's prior) on the {axis} axis at "
        f"t = {t:.6g} s ({where}); the bias_at_limit column says where.  A bias that large is beyond what the "
        "estimator assumes of the sensor: check the gyro's unit (--gyro-unit), or raise -p bias_limit_deg_s=..."
    )


def check_axes(cal: dict, sensor: str, declared: str) -> None:
    """Refuse a calibration fitted in other named axes than the readings'.

    Its matrix and offset would act on the wrong components.  A calibration fitted in unnamed axes ("sensor")
    and readings whose axes are only assumed pass.
    """
    for c in cal.values():
        if c.frame != "sensor" and declared != "assumed" and c.frame != sensor:
            raise ValueError(
                f"the {c.sensor} calibration was fitted in {c.frame} axes, but these readings are in {sensor} axes "
                f"({declared}): fit it on readings in {sensor} axes, or give --body {c.frame} if that is what the "
                "file holds"
            )


def calibrated(cal: dict, gyro, acc, mag):
    """Rates (rad/s, not increments), specific force and field with each sensor's calibration applied."""
    pairs = (("gyro", gyro), ("acc", acc), ("mag", mag))
    return tuple(x if x is None or s not in cal else cal[s].apply(x) for s, x in pairs)


def heading_metadata(use_mag: bool, declination, cal: dict) -> dict:
    """What the output's heading refers to, for the file's metadata; refuses a declination without magnetometer."""
    if declination is not None and not use_mag:
        raise ValueError("a declination needs the magnetometer (9D): a 6D heading has no north to correct")
    items = {
        "heading": ("true" if declination is not None else "magnetic") if use_mag else "free",
        "declination_deg": None if declination is None else float(np.degrees(declination)),
        "calibration": ", ".join(sorted(cal)) or None,
    }
    return {k: str(v) for k, v in items.items() if v is not None}  # metadata values are text
