"""The layering of the package (docs/architecture.md), checked on its import graph.

Every ``import`` and ``from ... import`` of every module counts, those inside functions too (a lazy import is
still a dependency), read from the source with ``ast``: nothing is imported to find them.  The rules:

1. each module belongs to one floor, and imports only from its own floor or the floors below;
2. no module imports the top-level package ``strapdown`` (its ``__init__`` only gathers names for users);
3. the modules form no circle;
4. a private module (a name part starting with ``_``) is imported only from inside the package that holds it;
   ``strapdown._support`` is the private floor every floor shares, and a numba kernel module may import
   another (a kernel can only call a kernel).
"""

import ast
from pathlib import Path

import pytest

import strapdown

ROOT = Path(strapdown.__file__).parent

#: The floors, lowest first.  Two packages on one floor may not import each other.
FLOORS = [
    ["strapdown._support"],
    ["strapdown.rotations"],
    ["strapdown.propagate"],
    ["strapdown.simulate"],
    ["strapdown.fusion", "strapdown.calibrate"],
    ["strapdown.evaluate"],
    ["strapdown.io"],
    ["strapdown.apps"],
    ["strapdown.cli"],
]


def _modules() -> dict[str, tuple[Path, bool]]:
    out = {}
    for path in ROOT.rglob("*.py"):
        parts = ["strapdown", *path.relative_to(ROOT).with_suffix("").parts]
        package = parts[-1] == "__init__"
        if package:
            parts = parts[:-1]
        out[".".join(parts)] = (path, package)
    return out


MODULES = _modules()


def _imports(name: str, missing: list | None = None) -> set[str]:
    """The strapdown modules that module ``name`` imports (a package's ``__init__`` by the package's name).

    ``missing`` collects the imports that name no module at all (a relative import left one level short).
    """
    path, package = MODULES[name]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if package else name.split(".")[:-1]
                base = base[: len(base) - (node.level - 1)]
                base = ".".join([*base, *([node.module] if node.module else [])])
            else:
                base = node.module or ""
            # `from package import module` imports the module; `from module import name` the module
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base for a in node.names]
        else:
            continue
        if isinstance(node, ast.ImportFrom) and base.split(".")[0] == "strapdown" and base not in MODULES:
            if missing is not None:
                missing.append(f"{name}:{node.lineno} imports from {base}")
        for t in targets:
            if t.split(".")[0] == "strapdown":
                while t not in MODULES and "." in t:
                    t = t.rsplit(".", 1)[0]
                if t != name:
                    found.add(t)
    return found


GRAPH = {name: _imports(name) for name in MODULES}


def _floor(name: str) -> tuple[int, str] | None:
    for level, packages in enumerate(FLOORS):
        for p in packages:
            if name == p or name.startswith(p + "."):
                return level, p
    return None


def test_every_import_names_a_module():
    missing = []
    for name in MODULES:
        _imports(name, missing)
    assert not missing, "imports of modules that do not exist:\n" + "\n".join(missing)


def test_every_module_has_a_floor():
    homeless = sorted(n for n in MODULES if n != "strapdown" and _floor(n) is None)
    assert not homeless, f"modules outside every floor (place them in docs/architecture.md and FLOORS): {homeless}"


def test_imports_go_down_the_floors():
    climbing = []
    for name, targets in GRAPH.items():
        here = _floor(name)
        if here is None:
            continue
        for t in targets:
            there = _floor(t)
            if there is None:
                continue
            if there[0] > here[0] or (there[0] == here[0] and there[1] != here[1]):
                climbing.append(f"{name} -> {t}")
    assert not climbing, "imports that climb or cross a floor:\n" + "\n".join(sorted(climbing))


def test_nothing_imports_the_top_level_package():
    assert sorted(n for n, targets in GRAPH.items() if "strapdown" in targets) == []


def test_no_circles():
    # Tarjan's strongly connected components: every component of more than one module is a circle
    index, low, stack, on, circles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in GRAPH[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = []
            while True:
                w = stack.pop()
                on.discard(w)
                part.append(w)
                if w == v:
                    break
            if len(part) > 1:
                circles.append(sorted(part))

    for v in GRAPH:
        if v not in index:
            visit(v)
    assert not circles, "circles of imports: " + "; ".join(" <-> ".join(c) for c in circles)


def _private_home(name: str) -> str | None:
    """The package a private module belongs to (the part of its name before the first private part)."""
    parts = name.split(".")
    for i, part in enumerate(parts):
        if part.startswith("_") and part != "__init__":
            return ".".join(parts[:i])
    return None


def test_private_modules_stay_in_their_package():
    reaching = []
    for name, targets in GRAPH.items():
        for t in targets:
            home = _private_home(t)
            if home is None or t.startswith("strapdown._support"):
                continue
            kernels = t.endswith("_numba") and name.endswith("_numba")
            if not (name == home or name.startswith(home + ".")) and not kernels:
                reaching.append(f"{name} -> {t}")
    assert not reaching, "private modules imported from outside their package:\n" + "\n".join(sorted(reaching))


@pytest.mark.parametrize("bad", ["up", "circle", "private"])
def test_the_rules_catch_what_they_are_for(bad, monkeypatch):
    """Each rule fails on a graph made to break it (the checks above can fail)."""
    graph = {k: set(v) for k, v in GRAPH.items()}
    if bad == "up":
        graph["strapdown.rotations.quaternion"].add("strapdown.fusion")
        monkeypatch.setitem(globals(), "GRAPH", graph)
        with pytest.raises(AssertionError, match="climb"):
            test_imports_go_down_the_floors()
    elif bad == "circle":
        graph["strapdown.rotations.quaternion"].add("strapdown.rotations.attitude")
        monkeypatch.setitem(globals(), "GRAPH", graph)
        with pytest.raises(AssertionError):
            test_no_circles()
    else:
        graph["strapdown.io.readers"].add("strapdown.fusion._base")
        monkeypatch.setitem(globals(), "GRAPH", graph)
        with pytest.raises(AssertionError, match="private"):
            test_private_modules_stay_in_their_package()
