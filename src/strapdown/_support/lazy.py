"""A package's names imported from their modules when first used (PEP 562) (private).

A package ``__init__`` that imports every module makes ``import strapdown.io.units`` (or any one module) pay for
all of them.  With :func:`exports` the package lists where each name lives instead, and a name's module is
imported at the first ``package.name`` or ``from package import name``; submodules are found as attributes
as they were when the package imported them.
"""

from __future__ import annotations

import importlib
import sys


def exports(package: str, home: dict[str, tuple[str, ...]]):
    """``(__getattr__, __dir__, __all__)`` for ``package``, whose public names ``home`` lists by module.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    home : dict of str to tuple of str
        Module (relative to the package, no dot) -> the names it gives the package.

    Returns
    -------
    tuple
        The package's module-level ``__getattr__`` and ``__dir__``, and ``__all__`` (sorted).

    Examples
    --------
    >>> from strapdown._support.lazy import exports
    >>> getattr_, dir_, all_ = exports("strapdown", {"quaternion": ("multiply",)})
    >>> all_, getattr_("multiply").__name__
    (['multiply'], 'multiply')
    """
    module_of = {name: module for module, names in home.items() for name in names}

    def __getattr__(name: str):
        module = module_of.get(name)
        if module is not None:
            value = getattr(importlib.import_module(f".{module}", package), name)
            setattr(sys.modules[package], name, value)  # once: later lookups find it without this function
            return value
        if not name.startswith("_"):  # a submodule, as it was an attribute after the package imported it
            try:
                return importlib.import_module(f".{name}", package)
            except ModuleNotFoundError as exc:
                if exc.name != f"{package}.{name}":
                    raise
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__():
        return sorted(set(vars(sys.modules[package])) | set(module_of))

    return __getattr__, __dir__, sorted(module_of)
