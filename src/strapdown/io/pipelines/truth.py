"""A truth for an attitude file: read, checked against the file's frames and put on its rows (``plot --truth``).

The estimate and the truth must describe the same thing: the same reference frame, the same body axes and the same
instants.  An estimate in NED/FRD against a truth in ENU/FLU shows a half turn as its "error"; this module reads
the frames each file declares (the metadata :mod:`strapdown.io.conventions` writes, a PX4 log's NED/FRD) and
re-expresses the truth in the estimate's frames when both are known and differ, saying so; when either side does not
say its frames, it refuses rather than guess, unless they are declared (``truth_frame``, ``truth_body``).  The truth
is then interpolated (slerp) onto the estimate's times: a log's own ``vehicle_attitude`` comes at its own rate.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..units import UNITS

__all__ = ["AlignedTruth", "align_truth", "write_aligned"]

_UNIT_SECONDS = UNITS["time"]  # s per unit


@dataclass
class AlignedTruth:
    """The truth on the estimate's rows.

    Attributes
    ----------
    t : numpy.ndarray, shape (n,)
        The estimate's times, s.
    q : numpy.ndarray, shape (n, 4)
        The true attitude at those times, in the estimate's frame and body axes (NaN outside the truth's span).
    rows : numpy.ndarray of bool, shape (n,)
        The estimate's rows inside the truth's span.
    note : str
        What was done: the re-expression, the interpolation.
    changed : bool
        Whether the truth differs from its file's rows (re-expressed or interpolated).
    """

    t: np.ndarray
    q: np.ndarray
    rows: np.ndarray
    note: str
    changed: bool


def _frames_of(path, fmt=None) -> tuple[str | None, str | None, dict]:
    from ..readers import read_metadata

    try:
        meta = read_metadata(path, fmt)
    except ValueError:
        meta = {}
    frame = meta.get("frame") or meta.get("reference")  # `strapdown simulate` names the truth's frame "reference"
    if frame and not frame.isalpha():  # "inertial (...)": an integration's own starting axes, not a named frame
        frame = None
    return (frame.upper() if frame else None), (meta.get("body") or "").upper() or None, meta


def _origin_seconds(meta: dict) -> tuple[str, float] | None:
    """(kind, seconds) of a stored time origin, when it is an absolute one (epoch or boot)."""
    if meta.get("time_origin_kind") not in ("epoch", "boot") or meta.get("time_origin_unit") not in _UNIT_SECONDS:
        return None
    return meta["time_origin_kind"], float(meta["time_origin"]) * _UNIT_SECONDS[meta["time_origin_unit"]]


def align_truth(estimate, truth, *, truth_frame: str | None = None, truth_body: str | None = None) -> AlignedTruth:
    """The truth of ``estimate`` from the file ``truth``, in the estimate's frames and on its rows.

    Parameters
    ----------
    estimate : path-like
        An output of ``strapdown estimate`` or ``integrate`` (``t``, ``qw..qz``, and its metadata).
    truth : path-like
        A file with true attitudes: a simulated log (``qw_true..``), any ``qw..qz`` table, a PX4 log.
    truth_frame, truth_body : str, optional
        The truth's frame and body axes, when its file does not say them (or says them wrong).

    Returns
    -------
    AlignedTruth
        Times, quaternions and a note.

    Raises
    ------
    ValueError
        When the frames cannot be checked (one side does not say them), or the times do not overlap.
    """
    from ...rotations.frames import change_frame
    from ..readers import read_table
    from ..reference import read_reference

    est_frame, est_body, est_meta = _frames_of(estimate)
    table = read_table(estimate)
    t = np.asarray(table["t"], dtype=np.float64)
    ref = read_reference(truth)
    _, _, truth_meta = _frames_of(truth)
    frame = (truth_frame or ref.frame or truth_meta.get("reference") or "").upper() or None
    body = (truth_body or ref.body or "").upper() or None
    notes = []
    reexpressed = False
    if est_frame is None and est_meta.get("frame", "").startswith("inertial"):
        notes.append("an integration's own reference: the frames are not checked")
    else:
        missing = [
            what
            for what, value in (
                (f"{estimate} its reference frame", est_frame),
                (f"{estimate} its body axes", est_body),
                (f"{truth} its reference frame (--truth-frame)", frame),
                (f"{truth} its body axes (--truth-body)", body),
            )
            if value is None
        ]
        if missing:
            raise ValueError(
                "cannot check that the estimate and the truth use the same frames: "
                + "; ".join(f"{m.split(' its ')[0]} does not say its {m.split(' its ')[1]}" for m in missing)
                + ".  A truth in other axes would show its rotation as the error: declare them"
            )
        if (frame, body) != (est_frame, est_body):
            notes.append(f"truth re-expressed from {frame}/{body} to {est_frame}/{est_body}")
            q = change_frame(ref.q, ref_from=frame, ref_to=est_frame, body_from=body, body_to=est_body)
            ref.q = q
            reexpressed = True
    # the same instant for t = 0: shift the truth when both files store absolute origins of one kind
    shift = 0.0
    # the truth's origin from its metadata, else from its own time column (epoch ns of a motion-capture table)
    a = _origin_seconds(est_meta)
    b = _origin_seconds(truth_meta) or _origin_seconds(ref.time_origin.metadata() if ref.time_origin else {})
    if a and b and a[0] == b[0]:
        shift = b[1] - a[1]
    rt = ref.t + shift
    same_rows = rt.shape == t.shape and np.allclose(rt, t, rtol=0, atol=1e-9)
    inside = np.ones(t.size, dtype=bool)
    if same_rows:
        q = ref.q
    else:
        inside = (t >= rt[0]) & (t <= rt[-1])
        if not inside.any():
            raise ValueError(
                f"the truth {truth} covers t = {rt[0]:.6g}..{rt[-1]:.6g} s and the estimate {estimate} "
                f"t = {t[0]:.6g}..{t[-1]:.6g} s: no instant in common"
            )
        q = np.full((t.size, 4), np.nan)
        q[inside] = ref.at(t[inside]) if shift == 0.0 else _shifted(ref, shift).at(t[inside])
        notes.append(f"truth ({ref.source}) interpolated onto the estimate's {int(inside.sum())} rows")
    changed = reexpressed or not same_rows
    return AlignedTruth(t, q, inside, "; ".join(notes), changed)


def _shifted(ref, shift: float):
    from dataclasses import replace

    return replace(ref, t=ref.t + shift)


def write_aligned(aligned: AlignedTruth, estimate, truth, folder) -> tuple[Path, Path]:
    """The estimate's rows inside the truth's span and the aligned truth, as two tables in ``folder``.

    Parameters
    ----------
    aligned : AlignedTruth
        From :func:`align_truth`.
    estimate, truth : path-like
        The two files (their names are kept, so that figures and titles name them).
    folder : path-like
        Where the two tables go (a scratch folder).

    Returns
    -------
    tuple of pathlib.Path
        The estimate's table and the truth's, row by row the same instants, for
        :func:`strapdown.io.pipelines.plot.plot_file`.
    """
    from ..readers import read_metadata, read_table
    from ..writers import write_table

    keep = aligned.rows
    meta = read_metadata(estimate)
    table = {k: np.asarray(v)[keep] for k, v in read_table(estimate).items()}
    est = write_table(Path(folder) / f"{Path(estimate).stem}.parquet", table, metadata=meta)
    q = aligned.q[keep]
    cols = {"t": aligned.t[keep], **{f"{c}_true": q[:, i] for i, c in enumerate(("qw", "qx", "qy", "qz"))}}
    frames = {k: meta[k] for k in ("frame", "body") if k in meta}
    return est, write_table(Path(folder) / f"{Path(truth).stem}.parquet", cols, metadata=frames)
