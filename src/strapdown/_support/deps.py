"""Optional dependencies, imported when first needed with an install hint (private)."""

from __future__ import annotations

import functools
import importlib

# module -> the extra that installs it
_EXTRA = {
    "pyarrow": "io",
    "pyarrow.csv": "io",
    "pyarrow.parquet": "io",
    "h5py": "io",
    "scipy.io": "io",
    "pyulog": "ulog",
    "rosbags": "rosbag",
    "rosbags.highlevel": "rosbag",
    "rosbags.typesys": "rosbag",
    "tqdm": "cli",
    "matplotlib": "plot",
    "bokeh": "report",
    "distributed": "dask",
}


@functools.cache  # the readers ask at every chunk: a hit is a dictionary look-up, no import machinery
def need(module: str, what: str):
    """Import ``module`` or raise ImportError saying which extra to install for ``what``."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        extra = _EXTRA.get(module, "io")
        raise ImportError(f"{what} needs {module.split('.')[0]}: pip install 'strapdown[{extra}]'") from exc
