"""The module paths of strapdown 0.1's flat layout, still importable (private).

Release 0.1 kept forty modules side by side in ``strapdown/``; they now live in one folder per floor
(``docs/architecture.md``).  ``import strapdown.metrics`` or ``from strapdown.wahba import triad`` keep working:
a finder on ``sys.meta_path`` answers each old name below with the module at its new home, the very same module
object (``strapdown.metrics is strapdown.evaluate.metrics``), so nothing is defined twice and nothing is imported
before it is asked for.  New code imports the new paths; this table only grows.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys

MOVED = {
    "strapdown.attitude": "strapdown.rotations.attitude",
    "strapdown.average": "strapdown.rotations.average",
    "strapdown.cayley_klein": "strapdown.rotations.cayley_klein",
    "strapdown.compressed": "strapdown.rotations.compressed",
    "strapdown.davenport": "strapdown.rotations.davenport",
    "strapdown.decompose": "strapdown.rotations.decompose",
    "strapdown.euler": "strapdown.rotations.euler",
    "strapdown.frames": "strapdown.rotations.frames",
    "strapdown.interop": "strapdown.rotations.interop",
    "strapdown.matrix": "strapdown.rotations.matrix",
    "strapdown.mrp": "strapdown.rotations.mrp",
    "strapdown.quaternion": "strapdown.rotations.quaternion",
    "strapdown.rotvec": "strapdown.rotations.rotvec",
    "strapdown.wahba": "strapdown.rotations.wahba",
    "strapdown.integrate": "strapdown.propagate.integrate",
    "strapdown.interpolate": "strapdown.propagate.interpolate",
    "strapdown.broad": "strapdown.evaluate.broad",
    "strapdown.compare": "strapdown.evaluate.compare",
    "strapdown.metrics": "strapdown.evaluate.metrics",
    "strapdown.batch": "strapdown.apps.batch",
    "strapdown.demo": "strapdown.apps.demo",
    "strapdown.warmup": "strapdown.apps.warmup",
    "strapdown.fusion.attitude": "strapdown.fusion.offline",  # it imports the online estimator too
    "strapdown.io.pipeline": "strapdown.io.pipelines",
    "strapdown.io.plots": "strapdown.io.pipelines.plot",
    "strapdown.io.truth": "strapdown.io.pipelines.truth",
}


class _Loader(importlib.abc.Loader):
    def create_module(self, spec):
        return None  # a placeholder, replaced in sys.modules by exec_module

    def exec_module(self, module) -> None:
        # The import system returns whatever sys.modules holds under the name after exec_module: the real module.
        sys.modules[module.__name__] = importlib.import_module(MOVED[module.__name__])


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        if fullname not in MOVED:
            return None
        return importlib.machinery.ModuleSpec(fullname, _Loader())


def names(module: str, homes: dict[str, str]):
    """A module ``__getattr__`` for the names that left ``module`` since release 0.1 (``homes``: name -> module).

    ``from strapdown.io.units import check_plausible`` then still gives the function from its new home, imported
    when first asked for; the module's ``__all__`` lists only what it defines now.
    """

    def __getattr__(name: str):
        home = homes.get(name)
        if home is None:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        return getattr(importlib.import_module(home), name)

    return __getattr__


def install(parents: dict[str, object]) -> None:
    """Put the finder on ``sys.meta_path`` once.

    ``parents`` maps an old name whose last part is also a function of its parent package (``strapdown.integrate``
    is both) to the module already imported: registered up front, so that importing the old module path never
    replaces the function on its parent.
    """
    sys.modules.update(parents)
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.append(_Finder())
