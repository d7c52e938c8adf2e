"""PNG figures of an attitude file: Euler angles, errors against a truth, and the estimated gyro bias.

Reads the tables that ``strapdown integrate`` and ``strapdown estimate`` write (``t``, ``qw..qz``, ``bias_*``) and a
truth (``qw_true..qz_true`` of ``strapdown simulate``, or any ``qw..qz``), streaming and thinning long files to at
most ``max_points`` rows so that a figure of a day-long log stays small.  Needs matplotlib (``plot`` extra).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._files import atomic_path
from ._deps import need
from .readers import open_source, read_metadata
from .tables import Angles, column_names, to_values

__all__ = ["plot_file"]

_TRUTH_NAMES = (("qw_true", "qx_true", "qy_true", "qz_true"), ("qw", "qx", "qy", "qz"))


def _thinned(path, names, max_points: int, format=None) -> dict:
    """Every k-th row of the named fields, k chosen so that at most ``max_points`` rows are kept."""
    with open_source(path, format) as src:
        rows = src.count_rows()
        step = max(1, -(-rows // max_points)) if rows else 1
        keep = {n: [] for n in names}
        for row, cols in src.chunks(names, 1 << 20):
            first = (-row) % step  # the global rows 0, step, 2 step, ... that fall in this chunk
            for n in names:
                keep[n].append(cols[n][first::step])
    return {n: np.concatenate(v) if v else np.zeros(0) for n, v in keep.items()}


def _quat_names(fields, candidates) -> tuple | None:
    for names in candidates:
        if all(n in fields for n in names):
            return names
    return None


def plot_file(
    path,
    truth=None,
    out=None,
    *,
    angles: Angles | None = None,
    max_points: int = 200_000,
    format: str | None = None,
) -> list[Path]:
    """Write PNG figures of an attitude file: angles over time; errors (with a truth); bias (when present).

    Parameters
    ----------
    path : path-like
        An output of ``integrate`` or ``estimate`` (columns ``t``, ``qw``, ``qx``, ``qy``, ``qz``, optionally
        ``bias_x_*``...).
    truth : path-like, optional
        A file with the true attitude row by row (``qw_true``.. or ``qw``..), e.g. the input of a simulation.
    out : path-like, optional
        Folder for the figures (default: beside ``path``); files ``<stem>_angles.png``, ``<stem>_errors.png``,
        ``<stem>_bias.png``.
    angles : Angles, optional
        Euler sequence, unit and range of the angle figure (default: ZYX in degrees, Gajda's yaw range).
    max_points : int
        Rows drawn at most (long files are thinned evenly).
    format : str, optional
        Format of ``path`` and ``truth`` when the suffix does not tell it.

    Returns
    -------
    list of pathlib.Path
        The figures written (each atomically).

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import write_table
    >>> from strapdown.io.plots import plot_file
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> t = np.linspace(0, 1, 50)
    >>> q = {"t": t, "qw": np.cos(t / 2), "qx": np.sin(t / 2), "qy": 0 * t, "qz": 0 * t}
    >>> [p.name for p in plot_file(write_table(folder / "att.csv", q))]
    ['att_angles.png']
    """
    angles = angles or Angles()
    need("matplotlib", "plotting")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    out = path.parent if out is None else Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with open_source(path, format) as src:
        fields = dict(src.fields)
    qnames = _quat_names(fields, [("qw", "qx", "qy", "qz")])
    if qnames is None:
        raise ValueError(f"{path} has no quaternion columns qw, qx, qy, qz; it has: {', '.join(fields)}")
    bias_names = [n for n in fields if n.startswith("bias_")]
    tname = "t" if "t" in fields else None
    data = _thinned(path, [*([tname] if tname else []), *qnames, *bias_names], max_points, format)
    q = np.column_stack([data[n] for n in qnames])
    rows = len(q)
    t = data[tname] if tname else np.arange(rows, dtype=float)
    xlabel = "time [s]" if tname else "row"
    ok = np.isfinite(q).all(axis=1)
    written = []

    def save(fig, suffix: str) -> None:
        target = out / f"{path.stem}_{suffix}.png"
        with atomic_path(target) as tmp:
            fig.savefig(tmp, format="png", dpi=110)
        plt.close(fig)
        written.append(target)

    unit = "deg" if angles.degrees else "rad"
    values = np.full((rows, 3), np.nan)
    if ok.any():
        values[ok] = to_values("euler", q[ok], angles)
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(10, 7))
    for ax, name, v in zip(axes, column_names("euler", angles), values.T, strict=True):
        ax.plot(t, v, lw=0.8)
        ax.set_ylabel(name.replace(f"_{unit}", f" [{unit}]"))
    axes[0].set_title(f"{path.name}: Euler angles ({angles.seq})")
    axes[-1].set_xlabel(xlabel)
    save(fig, "angles")

    if truth is not None:
        from ..metrics import attitude_errors

        with open_source(truth, format) as src:
            tnames = _quat_names(src.fields, _TRUTH_NAMES)
            truth_rows = src.count_rows()
        if tnames is None:
            raise ValueError(f"{truth} has no true attitude (qw_true.. or qw..); it has: {', '.join(src.fields)}")
        if truth_rows != _rows(path, format):
            raise ValueError(
                f"{truth} has {truth_rows} rows but {path} has {_rows(path, format)}; the truth must match row by row"
            )
        ref = _thinned(truth, list(tnames), max_points, format)
        q_true = np.column_stack([ref[n] for n in tnames])
        q_true, note = _truth_in_frame_of(path, truth, q_true, format)
        title = f"{path.name}: attitude error against {Path(truth).name}{note}"
        errors = attitude_errors(q, q_true)
        fig, ax = plt.subplots(figsize=(10, 4))
        scale = 180 / np.pi if angles.degrees else 1.0
        for name in ("total", "heading", "inclination"):
            ax.plot(t, errors[name] * scale, lw=0.8, label=name)
        ax.set_ylabel(f"error [{unit}]")
        ax.set_xlabel(xlabel)
        ax.set_title(title)
        ax.legend()
        save(fig, "errors")

    if bias_names:
        fig, ax = plt.subplots(figsize=(10, 4))
        for n in bias_names:
            ax.plot(t, data[n], lw=0.8, label=n)
        ax.set_ylabel("gyro bias")
        ax.set_xlabel(xlabel)
        ax.set_title(f"{path.name}: estimated gyro bias")
        ax.legend()
        save(fig, "bias")
    return written


def _truth_in_frame_of(path, truth, q_true: np.ndarray, format=None) -> tuple[np.ndarray, str]:
    """The true attitudes re-expressed in the frame of ``path``'s attitudes, when both files name theirs.

    An estimate in NED against a simulated truth in ENU would otherwise show a half turn as its error.
    Returns the attitudes and a note for the figure ("" when nothing was changed).
    """
    ours, theirs = _frame_of(path, format, "frame"), _frame_of(truth, format, "reference", "frame")
    if not (ours and theirs and ours != theirs):
        return q_true, ""
    from ..frames import change_frame

    return change_frame(q_true, ref_from=theirs, ref_to=ours), f" (truth taken from {theirs} to {ours})"


def _frame_of(path, format, *keys: str) -> str | None:
    """The reference frame a file's metadata names under the first of ``keys`` present, upper case."""
    meta = read_metadata(path, format)
    for key in keys:
        if meta.get(key):
            return meta[key].upper()
    return None


def _rows(path, format) -> int:
    with open_source(path, format) as src:
        return src.count_rows()
