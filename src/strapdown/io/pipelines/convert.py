"""``strapdown convert``: attitudes of a file from one representation into another."""

from __future__ import annotations

import re
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ...rotations.values import _ANGULAR, REPRESENTATIONS, Angles, column_names, from_values, to_values
from ..readers import check_chunk_rows, open_source, require_rows
from ..writers import table_writer
from ._common import (
    CHUNK_ROWS,
    Progress,
    Report,
    metadata,
    output_path,
)

__all__ = ["convert_file", "convert_values"]

_QUAT_NAMES = (
    ("qw", "qx", "qy", "qz"),
    ("q_w", "q_x", "q_y", "q_z"),
    ("quat_w", "quat_x", "quat_y", "quat_z"),
    ("q0", "q1", "q2", "q3"),
    ("w", "x", "y", "z"),
)


_QUAT_ARRAYS = ("q", "quat", "quaternion", "quaternions", "opt_quat", "orientation")


_NORM_RANGE = (0.5, 2.0)  # quaternion norms taken as attitudes: rounding and hand-typed (1, 0, 0, 1) pass


def _angle_unit(fields) -> bool | None:
    """True (degrees) or False (radians) when every field's name ends in ``_deg`` or every one in ``_rad``."""
    ends = {m.group(1).lower() if (m := re.search(r"[_ ](deg|rad)$", f, re.IGNORECASE)) else None for f in fields}
    return {"deg": True, "rad": False}.get(ends.pop()) if len(ends) == 1 else None


def _representation_fields(fields: dict, rep: str, angles: Angles, given: str | None) -> tuple:
    from ..columns import describe_fields, pick_vector

    width = REPRESENTATIONS[rep]
    if given:
        return pick_vector(given, fields, "--columns", width=width).fields
    # the names this package writes, in the declared unit first and then in the other one
    candidates = [
        tuple(column_names(rep, angles)),
        tuple(column_names(rep, replace(angles, degrees=not angles.degrees))),
    ]
    if rep == "quat":
        candidates += list(_QUAT_NAMES)
    for names in candidates:
        if all(fields.get(n) == 1 for n in names):
            return names
    for name, w in fields.items():
        if w == width and (rep != "quat" or name.split("/")[-1].lower() in _QUAT_ARRAYS):
            return (name,)
    raise ValueError(
        f"no {rep} columns found (looked for {', '.join(candidates[0])}); name them with --columns.  The file has: "
        f"{describe_fields(fields)}"
    )


def convert_values(
    values: np.ndarray, source: str, target: str, angles_in: Angles, angles_out: Angles, *, unit_norm: bool = False
):
    """Convert an (N, width) array between representations; rows with NaN stay NaN (unknown attitudes).

    Parameters
    ----------
    values : numpy.ndarray, shape (N, REPRESENTATIONS[source])
        Input rows.
    source, target : str
        Keys of :data:`strapdown.io.tables.REPRESENTATIONS`.
    angles_in, angles_out : Angles
        Sequences and units of the input and output.
    unit_norm : bool
        Refuse a quaternion whose norm is outside 0.5 .. 2 (the rows of a file, where ``qw = 1e308`` is a damaged
        value); False: any scale is an attitude (numbers typed on the command line).

    Returns
    -------
    numpy.ndarray, shape (N, REPRESENTATIONS[target])
        The converted rows.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io.pipelines import convert_values
    >>> from strapdown.io.tables import Angles
    >>> convert_values(np.array([[90.0, 0, 0], [np.nan, 0, 0]]), "euler", "quat", Angles(), Angles()).round(6)
    array([[0.707107, 0.      , 0.      , 0.707107],
           [     nan,      nan,      nan,      nan]])
    """
    values = np.asarray(values, dtype=np.float64)
    unknown = np.isnan(values).any(axis=1)
    infinite = np.flatnonzero(~unknown & ~np.isfinite(values).all(axis=1))
    if infinite.size:
        raise RowError(int(infinite[0]), "an infinite value (a NaN row is an unknown attitude; inf is not)")
    ok = ~unknown
    if source == "quat":
        zero = np.flatnonzero(ok & ~(np.abs(values) > 0).any(axis=1))
        if zero.size:
            raise RowError(int(zero[0]), "a zero quaternion, which is no attitude")
    if source == "quat" and unit_norm:
        # in a file an attitude's quaternion has norm 1; one of norm 1e308 (or 1e-300) is a damaged value, not a
        # scaling (the norm from the largest component: the sum of squares would overflow)
        big = np.abs(values).max(axis=1)
        norm = big * np.sqrt(((values / np.where(big > 0, big, 1.0)[:, None]) ** 2).sum(axis=1))
        far = np.flatnonzero(ok & ~((norm > _NORM_RANGE[0]) & (norm < _NORM_RANGE[1])))
        if far.size:
            raise RowError(int(far[0]), f"a quaternion of norm {norm[far[0]]:.6g}, where an attitude's has norm 1")
    if source in _ANGULAR:
        # beyond about 1e9 turns' worth the angle has no digits left below a turn: no attitude can be read from it
        limit = 360.0 * 1e9 if angles_in.degrees else 2 * np.pi * 1e9
        angular = values[:, -1:] if source == "axis_angle" else values
        big = np.flatnonzero(ok & (np.abs(angular) > limit).any(axis=1))
        if big.size:
            unit = "deg" if angles_in.degrees else "rad"
            raise RowError(int(big[0]), f"an angle beyond ±{limit:.3g} {unit}: no digits are left below a turn")
    out = np.full((values.shape[0], REPRESENTATIONS[target]), np.nan)
    if ok.any():
        rows = values[ok]
        if source == "quat":
            # a quaternion's attitude does not depend on its scale: bring the largest component to 1 first, so
            # that 1e300 or 5e-324 components neither overflow nor underflow the norm (exact: a division)
            rows = rows / np.abs(rows).max(axis=1, keepdims=True)
        try:
            converted = to_values(target, from_values(source, rows, angles_in), angles_out)
        except ValueError:
            row, problem = _first_refused(rows, source, target, angles_in, angles_out)
            raise RowError(int(np.flatnonzero(ok)[row]), problem) from None
        bad = np.flatnonzero(~np.isfinite(converted).all(axis=1))
        if bad.size:  # a Gibbs vector of a half turn, say: no finite number says it
            row = int(np.flatnonzero(ok)[bad[0]])
            raise RowError(row, f"an attitude the {target} representation cannot hold ({converted[bad[0]].tolist()})")
        out[ok] = converted
    return out


def _first_refused(rows, source, target, angles_in, angles_out) -> tuple[int, str]:
    """The first row the conversion refuses, found by halving (only after a failure), and the reason.

    The library names its own arrays and their indices ("c[0] is not a rotation matrix"): the reason is given
    without that name, for the caller to put the file's line in front.
    """
    lo, hi = 0, len(rows)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        try:
            to_values(target, from_values(source, rows[lo:mid], angles_in), angles_out)
        except ValueError:
            hi = mid
        else:
            lo = mid
    try:
        to_values(target, from_values(source, rows[lo:hi], angles_in), angles_out)
    except ValueError as exc:
        reason = re.sub(r"^[A-Za-z_]\w*(\[0\])? (is )?", "", str(exc))
    else:  # pragma: no cover - the rows fail together but no row alone
        reason = "values the conversion refuses"
    return lo, f"values the {source} to {target} conversion refuses ({reason})"


class RowError(ValueError):
    """A bad input row: ``row`` (0-based within the array) and what is wrong with it, for the caller to place."""

    def __init__(self, row: int, problem: str):
        super().__init__(f"row {row} holds {problem}")
        self.row, self.problem = row, problem


def convert_file(
    path,
    output=None,
    *,
    source: str = "quat",
    target: str = "euler",
    columns: str | None = None,
    time_column: str | None = None,
    angles_in: Angles | None = None,
    angles_out: Angles | None = None,
    format: str | None = None,
    out_format: str | None = None,
    chunk_rows: int = CHUNK_ROWS,
    progress: Progress | None = None,
    unit_from_names: bool = True,
) -> Report:
    """Convert the attitudes in a file from one representation to another, streaming.

    Parameters
    ----------
    path : path-like
        CSV, Parquet, HDF5 or MATLAB file.
    output : path-like, optional
        Output file; by default ``<stem>.convert.csv`` (``.parquet`` for Parquet input) beside the input.
    source, target : str
        Keys of :data:`strapdown.io.tables.REPRESENTATIONS`.
    columns : str, optional
        The input columns, comma-separated, or one (N, k) array; by default the names this package writes
        (``qw,qx,qy,qz``, ``yaw_deg,pitch_deg,roll_deg``, ...) or, for quaternions, common alternatives.
    time_column : str, optional
        A column copied to the output first; by default a detected time column, if any.
    angles_in, angles_out : Angles, optional
        Euler sequence, unit and range of input and output (default: ``Angles()``, ZYX in degrees).
    format, out_format : str, optional
        Formats when the suffixes do not tell them.
    chunk_rows : int
        Rows per chunk.
    unit_from_names : bool
        Input columns whose names end in ``_deg`` or ``_rad`` hold angles in that unit: True takes it (for
        the input, and for the output too), False requires ``angles_in`` to agree (ValueError otherwise).

    Returns
    -------
    Report
        ``rows``: the rows converted; ``read``: the input columns and their representation.

    Examples
    --------
    >>> import numpy as np, pathlib, tempfile
    >>> from strapdown.io import convert_file, read_table, write_table
    >>> path = write_table(pathlib.Path(tempfile.mkdtemp()) / "q.csv",
    ...                    {"t": np.array([0.0, 1.0]), "qw": np.array([1.0, 0.0]), "qx": np.zeros(2),
    ...                     "qy": np.zeros(2), "qz": np.array([0.0, 1.0])})
    >>> table = read_table(convert_file(path, target="rotvec").output)
    >>> list(table), table["rotvec_z_deg"].round(9)
    (['t', 'rotvec_x_deg', 'rotvec_y_deg', 'rotvec_z_deg'], array([  0., 180.]))
    """
    from ..columns import detect_time, pick_vector

    t_start = time.perf_counter()
    chunk_rows = check_chunk_rows(chunk_rows)
    angles_in, angles_out = angles_in or Angles(), angles_out or Angles()
    output = output_path(path, output, "convert", out_format)
    with open_source(path, format) as src:
        try:
            fields = _representation_fields(src.fields, source, angles_in, columns)
        except ValueError as exc:
            raise ValueError(f"{path}: {exc}") from None
        named = _angle_unit(fields[-1:] if source == "axis_angle" else fields) if source in _ANGULAR else None
        if named is not None and named != angles_in.degrees:
            if not unit_from_names:
                unit = "degrees" if named else "radians"
                raise ValueError(
                    f"the columns {', '.join(fields)} are named in {unit}, but the angles were declared in "
                    f"{'degrees' if angles_in.degrees else 'radians'}; leave the unit out or declare {unit}"
                )
            # the names say the unit: reading yaw_deg as radians would be a silent, plausible-looking error
            angles_in, angles_out = replace(angles_in, degrees=named), replace(angles_out, degrees=named)
        names_out = column_names(target, angles_out)
        tcol = pick_vector(time_column, src.fields, "--time", width=1) if time_column else detect_time(src.fields)
        tname = tcol.fields[0] if tcol and tcol.fields[0] not in fields else None
        wanted = ([tname] if tname else []) + list(fields)
        done, unknown = 0, [0, 0, 0]  # NaN rows: count, first, last
        meta = metadata("convert", source=source, target=target)
        with table_writer(output, out_format, meta) as w:
            for row, cols in src.chunks(wanted, chunk_rows):
                values = cols[fields[0]] if len(fields) == 1 else np.column_stack([cols[f] for f in fields])
                try:
                    converted = convert_values(values, source, target, angles_in, angles_out, unit_norm=True)
                except RowError as exc:
                    raise ValueError(
                        f"{path}: {src.where(row + exc.row)} ({', '.join(fields)}) holds {exc.problem}"
                    ) from None
                nan = np.flatnonzero(np.isnan(values).reshape(len(values), -1).any(axis=1))
                if nan.size:  # an unknown attitude stays unknown, and is said (a damaged file writes them too)
                    unknown[0] += nan.size
                    unknown[1:] = [unknown[1] if unknown[0] > nan.size else row + nan[0], row + nan[-1]]
                table = {tname: cols[tname]} if tname else {}
                table.update(zip(names_out, converted.T, strict=True))
                w.write(table)
                done += len(values)
                if progress is not None:
                    progress(done, src.rows)
            require_rows(path, done)  # inside the writer's block, so that no output appears
        report = Report(Path(path), output, w.rows, time.perf_counter() - t_start, f"{source}: {','.join(fields)}")
        if unknown[0]:
            report.notes.append(
                f"warning: {path}: {unknown[0]} rows hold NaN ({src.where(unknown[1])} to {src.where(unknown[2])}): "
                "unknown attitudes, written as NaN"
            )
        return report
