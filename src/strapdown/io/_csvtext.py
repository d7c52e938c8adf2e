r"""CSV rows of a small table as text, the same bytes as pyarrow's CSV writer, without importing pyarrow (private).

A short ``strapdown estimate`` writes a few hundred rows: pyarrow's import (0.04-0.07 s) then costs more than
formatting them here.  :func:`csv_rows` gives the text pyarrow's ``write_csv`` gives (no header, ``\n`` after
each row) for columns of numbers, or None for anything else (strings, wide tables), which pyarrow then writes.

Numbers are written as Arrow writes them (arrow/util/formatting.cc): integers in decimal; floats as the shortest
digits that read back to the same value (Python's ``repr``, numpy's for float32, are those digits too), laid
out by double-conversion's ``ToShortest`` with Arrow's settings: positional when the decimal exponent is in
[-6, 10), else ``d.ddde±x``; ``nan``, ``inf``, ``-inf``; ``-0`` for negative zero; no trailing ``.0``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MAX_VALUES", "csv_rows", "float_text"]

#: At most this many values (rows x columns) are formatted here; a larger chunk goes to pyarrow.
MAX_VALUES = 1 << 15

# double-conversion's decimal_in_shortest_low and _high as Arrow's FloatToStringFormatter sets them
_LOW, _HIGH = -6, 10


def float_text(shortest: str) -> str:
    """Arrow's text for a float, from any text of its shortest round-trip digits (``repr``: ``1e-07``, ``100.0``).

    Examples
    --------
    >>> from strapdown.io._csvtext import float_text
    >>> [float_text(repr(x)) for x in (100.0, 1.5e-05, 1e-07, 1e10, -0.0, 0.1)]
    ['100', '0.000015', '1e-7', '1e+10', '-0', '0.1']
    """
    if shortest in ("nan", "inf", "-inf"):
        return shortest
    sign = "-" if shortest.startswith("-") else ""
    mantissa, _, exponent = shortest.lstrip("-").partition("e")
    whole, _, fraction = mantissa.partition(".")
    digits = whole + fraction
    point = len(whole) + int(exponent or 0)  # the value is 0.<digits> x 10^point
    stripped = digits.lstrip("0")
    point -= len(digits) - len(stripped)
    digits = stripped.rstrip("0")
    if not digits:
        return sign + "0"
    e = point - 1  # the exponent of d.ddd
    if _LOW <= e < _HIGH:
        if point <= 0:
            return f"{sign}0.{'0' * -point}{digits}"
        if point >= len(digits):
            return sign + digits + "0" * (point - len(digits))
        return f"{sign}{digits[:point]}.{digits[point:]}"
    rest = f".{digits[1:]}" if len(digits) > 1 else ""
    return f"{sign}{digits[0]}{rest}e{'+' if e >= 0 else '-'}{abs(e)}"


def _float64_texts(values: np.ndarray) -> list[str]:
    # repr is positional from 1e-4 to 1e16, Arrow from 1e-6 to 1e10: in the overlap only a trailing ".0" differs;
    # the values outside it (few) go through float_text
    out = [r[:-2] if r[-2:] == ".0" else r for r in map(repr, values.tolist())]
    size = np.abs(values)
    with np.errstate(invalid="ignore"):
        other = np.flatnonzero((size >= 1e10) | ((size < 1e-4) & (size > 0)))
    for i in other.tolist():
        out[i] = float_text(repr(float(values[i])))
    return out


def _column_texts(values: np.ndarray) -> list[str] | None:
    kind, size = values.dtype.kind, values.dtype.itemsize
    if values.ndim != 1:
        return None
    if kind in "iu":
        return [str(v) for v in values.tolist()]
    if kind == "f" and size == 8:
        return _float64_texts(values)
    if kind == "f" and size == 4:
        return [float_text(str(v)) if v == v else "nan" for v in values]  # numpy's shortest float32 digits
    return None


def csv_rows(columns) -> str | None:
    r"""The rows of ``columns`` (name -> 1-D array, equal lengths) as pyarrow's CSV writer writes them.

    Parameters
    ----------
    columns : mapping of str to numpy.ndarray
        Integer, float64 or float32 columns (booleans already as uint8).

    Returns
    -------
    str or None
        The text, or None when a column has another type or the table has more than :data:`MAX_VALUES`.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io._csvtext import csv_rows
    >>> csv_rows({"t": np.array([0.0, 0.01]), "n": np.array([3, -4]), "x": np.array([1e-7, 2.5], np.float32)})
    '0,3,1e-7\n0.01,-4,2.5\n'
    """
    arrays = [np.asarray(v) for v in columns.values()]
    if not arrays or sum(a.size for a in arrays) > MAX_VALUES:
        return None
    texts = []
    for a in arrays:
        t = _column_texts(a)
        if t is None:
            return None
        texts.append(t)
    return "".join(",".join(row) + "\n" for row in zip(*texts, strict=True))
