"""NumPy <-> Arrow for flat numeric columns, through the buffers (private).

``pyarrow.array(ndarray)``, ``Array.to_numpy()`` and ``pyarrow.compute.fill_null`` import pandas when it is
installed (pyarrow checks whether its input is a pandas object), which costs 0.2-0.3 s: more than a short
``strapdown estimate`` needs for everything else.  Wrapping and reading the buffers themselves gives the same
arrays (zero copy where the layout allows) and imports nothing.
"""

from __future__ import annotations

import numpy as np

from .._support.deps import need


def from_numpy(values) -> object:
    """A 1-D NumPy array (numbers or booleans) as an Arrow array, without pyarrow's pandas check.

    Examples
    --------
    >>> import numpy as np
    >>> from strapdown.io._arrow import from_numpy, to_numpy
    >>> to_numpy(from_numpy(np.array([1.5, 2.0]))), from_numpy(np.array([True, False])).to_pylist()
    (array([1.5, 2. ]), [True, False])
    """
    pa = need("pyarrow", "writing tables")
    v = np.ascontiguousarray(values)
    if v.ndim != 1 or v.dtype.kind not in "biuf":
        return pa.array(v)  # anything else (strings, 2-D) the general way
    if v.dtype.kind == "b":  # Arrow packs booleans into bits, least significant first
        return pa.Array.from_buffers(pa.bool_(), len(v), [None, pa.py_buffer(np.packbits(v, bitorder="little"))])
    return pa.Array.from_buffers(pa.from_numpy_dtype(v.dtype), len(v), [None, pa.py_buffer(v)])


def to_numpy(array) -> np.ndarray:
    """A numeric Arrow array as float64, nulls as NaN, without pyarrow's pandas check.

    Integers past 2**53 round to the nearest float64 (an unchecked cast), as in the readers.
    """
    pa = need("pyarrow", "reading Arrow data")
    if hasattr(array, "combine_chunks"):
        array = array.combine_chunks()
    if not pa.types.is_float64(array.type):
        array = array.cast(pa.float64(), safe=False)
    n = len(array)
    if n == 0:
        return np.zeros(0)
    out = np.frombuffer(array.buffers()[1], dtype=np.float64, count=n, offset=array.offset * 8)
    if array.null_count:
        bits = np.frombuffer(array.buffers()[0], dtype=np.uint8)
        valid = np.unpackbits(bits, bitorder="little", count=array.offset + n)[array.offset :].astype(bool)
        out = np.where(valid, out, np.nan)
    return out
