"""Write the API reference (``docs/api/*.rst``) from the ``__all__`` of every public module of strapdown.

Run by ``conf.py`` at every build, so a module or a name that lands later appears without editing the docs.  A
module is public when no part of its dotted name starts with an underscore and it defines ``__all__``.  Each name
is documented once, in its home module (where it is defined, private parts of the path stripped); every other
module that exports it links to that entry.  ``tests/test_docs.py`` checks the result against ``__all__``.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import types
from dataclasses import dataclass
from pathlib import Path

PACKAGE = "strapdown"


@dataclass(frozen=True)
class Entry:
    """One name of a module's ``__all__``: documented here (``target is None``) or a link to ``target``."""

    name: str
    kind: str  # "module", "function", "class", "data"
    target: str | None


def public_modules(package: str = PACKAGE) -> list[str]:
    """Dotted names of the public modules that define ``__all__``, the package first, then sorted."""
    root = importlib.import_module(package)
    names = [package]
    for info in pkgutil.walk_packages(root.__path__, package + "."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        names.append(info.name)
    return [n for n in sorted(set(names)) if hasattr(importlib.import_module(n), "__all__")]


def _public_home(module_name: str) -> str:
    parts = []
    for part in module_name.split("."):
        if part.startswith("_"):
            break
        parts.append(part)
    return ".".join(parts)


def entries(module_name: str, modules: list[str]) -> list[Entry]:
    """What the reference page of ``module_name`` holds, one entry per name of its ``__all__``."""
    mod = importlib.import_module(module_name)
    out = []
    for name in mod.__all__:
        obj = getattr(mod, name)
        if isinstance(obj, types.ModuleType):
            out.append(Entry(name, "module", obj.__name__))
            continue
        if inspect.isclass(obj) or inspect.isfunction(obj) or inspect.isbuiltin(obj):
            kind = "class" if inspect.isclass(obj) else "function"
            home = _public_home(getattr(obj, "__module__", "") or module_name)
            listed = home in modules and name in importlib.import_module(home).__all__
            target = f"{home}.{name}" if listed and home != module_name else None
            out.append(Entry(name, kind, target))
            continue
        # data: documented in the deepest module below this one that exports the same object
        deeper = [
            m
            for m in modules
            if m.startswith(module_name + ".")
            and name in importlib.import_module(m).__all__
            and getattr(importlib.import_module(m), name) is obj
        ]
        target = f"{max(deeper, key=lambda m: m.count('.'))}.{name}" if deeper else None
        out.append(Entry(name, "data", target))
    return out


def _summary(obj) -> str:
    doc = inspect.getdoc(obj) or ""
    line = doc.strip().split("\n\n")[0].replace("\n", " ").strip()
    return line.replace("|", "\\|")


def module_page(module_name: str, modules: list[str]) -> str:
    """The reStructuredText of one module's reference page."""
    mod = importlib.import_module(module_name)
    title = f"``{module_name}``"
    lines = [title, "=" * len(title), "", f".. automodule:: {module_name}", "   :no-members:", ""]
    items = entries(module_name, modules)
    lines += [".. list-table::", "   :widths: 30 70", ""]
    for e in items:
        if e.kind == "module":
            ref = f":py:mod:`{e.name} <{e.target}>`"
        else:
            ref = f":py:obj:`{e.name} <{e.target or module_name + '.' + e.name}>`"
        obj = getattr(mod, e.name)
        summary = _summary(obj) if e.kind in ("module", "function", "class") else ""
        if e.target and e.kind != "module":
            summary = f"{summary} (in :py:mod:`{e.target.rsplit('.', 1)[0]}`)".strip()
        lines += [f"   * - {ref}", f"     - {summary}"]
    lines.append("")
    directive = {"function": "autofunction", "class": "autoclass", "data": "autodata"}
    for e in items:
        if e.target is not None:
            continue
        lines.append(f".. {directive[e.kind]}:: {module_name}.{e.name}")
        if e.kind == "class":
            lines += ["   :members:", "   :show-inheritance:"]
            # a class that gathers the methods of a private strapdown base (Attitude's algebra) shows them too
            cls = getattr(mod, e.name)
            if any(b.__module__.startswith(PACKAGE + ".") and b.__name__ != cls.__name__ for b in cls.__mro__[1:-1]):
                lines += ["   :inherited-members:"]
        if e.kind == "data":
            lines += ["   :no-value:"]
        lines.append("")
    return "\n".join(lines)


def index_page(modules: list[str]) -> str:
    """The reference's table of contents: one page per public module."""
    lines = [
        "API reference",
        "=============",
        "",
        "Generated at every build from the ``__all__`` of each public module: every public name has an entry,",
        "documented once in the module that defines it and linked from the modules that re-export it.",
        "",
        ".. toctree::",
        "   :maxdepth: 1",
        "",
    ]
    lines += [f"   {m}" for m in modules]
    return "\n".join(lines) + "\n"


def write(out_dir: Path) -> list[Path]:
    """Write ``index.rst`` and one page per module into ``out_dir``, leaving files whose text is unchanged."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    modules = public_modules()
    pages = {"index": index_page(modules), **{m: module_page(m, modules) for m in modules}}
    written = []
    for stem, text in pages.items():
        path = out_dir / f"{stem}.rst"
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")
        written.append(path)
    for stale in out_dir.glob("*.rst"):
        if stale not in written:
            stale.unlink()
    return written
