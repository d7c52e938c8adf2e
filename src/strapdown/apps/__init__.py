"""Applications over the library: many files at once, the demo and the warm-up (floor 7).

* :mod:`.batch`: a file command over many files, locally or on a cluster, and one long file split in parts;
* :mod:`.demo`: ``strapdown demo`` (``make demo``): the worked examples, comparisons and figures;
* :mod:`.warmup`: compile the numba kernels ahead of their first call.

They import every floor below; only :mod:`strapdown.cli` imports them.
"""

from .._support.lazy import exports

# submodules and names imported when first used
__getattr__, __dir__, _names = exports(__name__, {})
__all__ = sorted([*_names, *["batch", "warmup"]])
