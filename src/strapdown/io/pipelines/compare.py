"""An estimate against the log's own (``strapdown compare OURS LOG``): the autopilot's attitude beside ours.

The log's attitude (PX4 ``vehicle_attitude``, ArduPilot ATT, a ROS ``Imu`` orientation: whatever the format's
``reference`` reader gives, :func:`strapdown.io.read_reference`) is put on the estimate's frames and rows
(:func:`~strapdown.io.pipelines.truth.align_truth`: re-expressed when the frames differ, slerped onto the
estimate's times), and :func:`strapdown.evaluate.compare.reference_errors` tells total, inclination and heading
apart, the heading's constant offset from what varies about it.  The declination at the log's place and date
(its GPS, :func:`strapdown.io.reference.log_position`, and the World Magnetic Model when the ``geomag`` extra is
installed) says how much of that offset is magnetic against true north: our magnetic heading is the true one
minus D, unless the estimate was turned to true north (``--declination``, recorded in its metadata).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["compare_file"]


def compare_file(estimate, log, *, truth_frame: str | None = None, truth_body: str | None = None):
    """Our estimate against the attitude a log records, heading and inclination apart.

    Parameters
    ----------
    estimate : path-like
        An output of ``strapdown estimate`` (or ``integrate``) of that log.
    log : path-like
        The log (a ULog, or any file whose format reads a reference attitude), or a table of ``qw..qz``.
    truth_frame, truth_body : str, optional
        The log's frames, when it does not say them.

    Returns
    -------
    (ReferenceErrors, str)
        The errors (degrees), and a note on what was done to put the log's attitude on our rows.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown import from_euler
    >>> from strapdown.io import write_table
    >>> from strapdown.io.pipelines.compare import compare_file
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> t = np.arange(100) * 0.1
    >>> def table(yaw, roll):
    ...     q = from_euler(np.column_stack([yaw, 0 * t, roll]), "ZYX", degrees=True)
    ...     return {"t": t, **{c: q[:, i] for i, c in enumerate(("qw", "qx", "qy", "qz"))}}
    >>> meta = {"frame": "NED", "body": "FRD"}
    >>> ours = write_table(folder / "ours.csv", table(10 * t - 3.0, 0.5 + 0 * t), metadata=meta)
    >>> theirs = write_table(folder / "theirs.csv", table(10 * t, 0 * t), metadata=meta)
    >>> errors, _ = compare_file(ours, theirs)
    >>> round(errors.heading_offset, 6), round(errors.inclination, 6)
    (-3.0, 0.5)
    """
    from ...evaluate.compare import reference_errors
    from ..readers import read_metadata, read_table
    from .truth import align_truth

    aligned = align_truth(estimate, log, truth_frame=truth_frame, truth_body=truth_body)
    table = read_table(estimate)
    q = np.column_stack([np.asarray(table[c], dtype=np.float64) for c in ("qw", "qx", "qy", "qz")])
    meta = read_metadata(estimate)
    frame = (meta.get("frame") or truth_frame or "").upper()
    ours = meta.get("heading", "magnetic")
    declination, notes = _declination(log, meta)
    if aligned.note:
        notes.insert(0, aligned.note)
    errors = reference_errors(
        q[aligned.rows], aligned.q[aligned.rows], frame, declination_deg=declination, ours=ours, theirs="true"
    )
    return errors, "; ".join(notes)


def _declination(log, meta: dict) -> tuple[float | None, list]:
    """The declination at the log's place and date (degrees east), from the estimate's metadata or the log's GPS."""
    if "declination_deg" in meta:
        return float(meta["declination_deg"]), [
            f"declination as the estimate applied it ({meta.get('declination_place', 'given')})"
        ]
    try:
        from ...calibrate import declination
        from ..reference import log_position

        place = log_position(Path(log))
        if place is None:
            return None, ["the log records no position: the declination is not known"]
        d = float(
            declination(latitude=place.latitude_deg, longitude=place.longitude_deg, date=place.date, degrees=True)
        )
    except (ImportError, ValueError) as exc:  # no geomag extra, a date outside the model's span
        return None, [f"declination not known: {exc}"]
    return d, [f"declination from the World Magnetic Model at {place.describe()}"]
