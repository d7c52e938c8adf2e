"""Where strapdown's compiled numba kernels are kept, and when they are reused (private).

numba keeps a compiled kernel beside its source (``__pycache__``) and checks it against that one file: a kernel
that calls a kernel of another file is not recompiled when only the callee changed, and a read-only install (a
system site-packages) caches nothing.  strapdown's kernels instead go into one folder per *version of all the
kernels together*: the folder's name is a hash of every ``_*_numba.py`` file of the package, of numba's version
and of Python's.  So

* a change to any kernel (an upgrade, an edited checkout) compiles everything afresh, never mixing old and new;
* an upgrade that leaves the kernels as they were reuses what was compiled before;
* the folder is a user cache (``$XDG_CACHE_HOME/strapdown`` or ``~/.cache/strapdown``, or ``STRAPDOWN_CACHE_DIR``,
  or ``NUMBA_CACHE_DIR`` when that is set), writable wherever the package is installed.

Every kernel module imports this one before it defines a kernel; importing it puts the locator in front of
numba's own.  Folders of other kernel versions untouched for 90 days are removed.  :func:`cached` tells whether a
kernel has been compiled for this version (the command line's "compiling ..., once" notice).
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
import time
from pathlib import Path

import numba
from numba.core import caching, config

PACKAGE = Path(__file__).resolve().parents[1]  # src/strapdown
_STALE_S = 90 * 86400


def _kernel_files() -> list[Path]:
    return sorted(PACKAGE.rglob("_*_numba.py"))


def _version() -> str:
    """The hash that names this version of the kernels (every kernel file, numba, Python)."""
    h = hashlib.sha256(f"numba {numba.__version__} python {sys.version_info[:3]}".encode())
    for path in _kernel_files():
        h.update(str(path.relative_to(PACKAGE)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:20]


VERSION = _version()


def _user_cache() -> Path:
    if os.environ.get("XDG_CACHE_HOME"):
        return Path(os.environ["XDG_CACHE_HOME"])
    if sys.platform == "win32" and os.environ.get("LOCALAPPDATA"):
        return Path(os.environ["LOCALAPPDATA"])
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches"
    return Path.home() / ".cache"


def root() -> Path:
    """The folder that holds a folder per kernel version."""
    if config.CACHE_DIR:
        return Path(config.CACHE_DIR) / "strapdown"
    if os.environ.get("STRAPDOWN_CACHE_DIR"):
        return Path(os.environ["STRAPDOWN_CACHE_DIR"])
    return _user_cache() / "strapdown"


def folder() -> Path:
    """The folder of this version of the kernels."""
    return root() / f"numba-{VERSION}"


class KernelLocator(caching._SourceFileBackedLocatorMixin, caching._CacheLocator):
    """numba's cache locator for strapdown's kernels (module notes); other code keeps numba's own locators."""

    def __init__(self, py_func, py_file):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        relative = Path(py_file).resolve().relative_to(PACKAGE)
        self._cache_path = str(folder() / relative.parent)

    def get_cache_path(self):
        return self._cache_path

    def get_source_stamp(self):
        return VERSION  # the folder is this version's already; the stamp says so inside the index too

    @classmethod
    def from_function(cls, py_func, py_file):
        try:
            Path(py_file).resolve().relative_to(PACKAGE)
        except ValueError:
            return None  # not one of ours
        return super().from_function(py_func, py_file)


def cached(module_file: str, function: str) -> bool:
    """Whether ``function`` of the kernel module ``module_file`` (relative to the package) is compiled already.

    Parameters
    ----------
    module_file : str
        E.g. ``"fusion/_attitude_numba.py"``.
    function : str
        The kernel's name.

    Returns
    -------
    bool
        True when this kernel version's cache holds it (for any argument types).

    Examples
    --------
    >>> from strapdown._support.kernel_cache import cached
    >>> cached("fusion/_attitude_numba.py", "no_such_kernel")
    False
    """
    where = folder() / Path(module_file).parent
    stem = Path(module_file).stem
    return where.is_dir() and any(where.glob(f"{stem}.{function}-*.nbi"))


def _prune() -> None:
    """Remove the folders of other kernel versions that nothing has used for 90 days."""
    try:
        now = time.time()
        for other in root().glob("numba-*"):
            if other.name != f"numba-{VERSION}" and now - other.stat().st_mtime > _STALE_S:
                shutil.rmtree(other, ignore_errors=True)
    except OSError:
        pass


def install() -> None:
    """Put :class:`KernelLocator` first among numba's cache locators (once)."""
    impl = getattr(caching, "CacheImpl", None) or caching._CacheImpl  # numba >= 0.65 dropped the underscore
    classes = impl._locator_classes
    if KernelLocator not in classes:
        classes.insert(0, KernelLocator)
        _prune()
        try:  # a folder in use stays young (pruning goes by the folder's time)
            os.utime(folder())
        except OSError:
            pass


install()
