"""The API reference lists every public name: each module's ``__all__`` against the generated pages.

The pages come from ``docs/_apigen.py`` (what Sphinx runs); the modules are found here by walking the package on
its own, so a module the generator missed fails too.  When the site has been built (``make docs``; ``.ci/run``
builds it before the tests) the Sphinx inventory is checked as well: every name resolves to an entry.
"""

import importlib
import pkgutil
import re
import sys
import types
from pathlib import Path

import pytest

import strapdown

DOCS = Path(__file__).resolve().parents[1] / "docs"
sys.path.insert(0, str(DOCS))
apigen = pytest.importorskip("_apigen")


def public_modules():
    found = ["strapdown"]
    for info in pkgutil.walk_packages(strapdown.__path__, "strapdown."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            found.append(info.name)
    return {n: importlib.import_module(n) for n in found if hasattr(importlib.import_module(n), "__all__")}


MODULES = public_modules()
DIRECTIVE = re.compile(r"^\.\. auto(?:function|class|data)::\s+(\S+)\s*$", re.M)
LINK = re.compile(r":py:(?:obj|mod):`([^`<]+?) <([^>]+)>`")


def documented(pages: dict[str, str]) -> set[str]:
    return {name for text in pages.values() for name in DIRECTIVE.findall(text)}


def missing_names(pages: dict[str, str]) -> list[str]:
    """Public names without an entry: not documented on their module's page, nor linked to an entry elsewhere.

    A link counts only if its target is documented (or is a public module) and is the very same object.
    """
    entries = documented(pages)
    missing = []
    for name, mod in MODULES.items():
        text = pages.get(name, "")
        links = dict(LINK.findall(text))
        for public in mod.__all__:
            full = f"{name}.{public}"
            obj = getattr(mod, public)
            if full in entries:
                continue
            target = links.get(public)
            if target is None:
                missing.append(full)
            elif isinstance(obj, types.ModuleType):
                if target != obj.__name__ or target not in pages:
                    missing.append(full)
            else:
                home, _, attr = target.rpartition(".")
                if target not in entries or getattr(importlib.import_module(home), attr) is not obj:
                    missing.append(full)
    return missing


@pytest.fixture(scope="module")
def pages():
    modules = apigen.public_modules()
    return {m: apigen.module_page(m, modules) for m in modules}


def test_every_public_module_has_a_page(pages):
    assert sorted(pages) == sorted(MODULES)
    index = apigen.index_page(list(pages))
    for name in MODULES:
        assert re.search(rf"^   {re.escape(name)}$", index, re.M), f"{name} is not in the reference's index"


def test_every_public_name_is_in_the_reference(pages):
    assert missing_names(pages) == []
    # each object is documented once: a second entry would be a duplicate description (a warning under -W)
    names = [n for text in pages.values() for n in DIRECTIVE.findall(text)]
    assert len(names) == len(set(names))


def test_a_name_left_out_is_reported(pages):
    """The check can fail: drop one function's entry and one re-export's link, and both are reported."""
    cut = dict(pages)
    entry = ".. autofunction:: strapdown.rotations.quaternion.slerp\n"
    cut["strapdown.rotations.quaternion"] = cut["strapdown.rotations.quaternion"].replace(entry, "")
    cut["strapdown"] = re.sub(r":py:obj:`from_euler <[^>]+>`", "from_euler", cut["strapdown"])
    assert missing_names(cut) == ["strapdown.from_euler", "strapdown.rotations.quaternion.slerp"]


def test_built_inventory_has_every_name():
    inv_path = DOCS / "_build" / "html" / "objects.inv"
    if not inv_path.exists():
        pytest.skip("the site is not built (make docs)")
    src = Path(strapdown.__file__).parent
    if any(p.stat().st_mtime > inv_path.stat().st_mtime for p in src.rglob("*.py")):
        pytest.skip("the built site is older than the sources (make docs)")
    inventory = pytest.importorskip("sphinx.util.inventory")

    with open(inv_path, "rb") as f:
        inv = inventory.InventoryFile.load(f, "", lambda base, uri: uri)
    objects = {name for kind, table in inv.items() if kind.startswith("py:") for name in table}
    modules = apigen.public_modules()
    for name in MODULES:
        assert name in objects, f"{name} has no page in the built site"
        for entry in apigen.entries(name, modules):
            assert (entry.target or f"{name}.{entry.name}") in objects, f"{name}.{entry.name} is not in the site"


def test_every_command_is_in_the_command_line_reference():
    pytest.importorskip("click")
    cligen = pytest.importorskip("_cligen")
    from strapdown.cli import _build

    helps = cligen.command_help()
    text = cligen.page(helps)
    import click

    group = _build()
    names = group.list_commands(click.Context(group))
    assert names and set(helps) == {"strapdown", *names}
    for name in names:
        assert f"\nstrapdown {name}\n" in text, f"strapdown {name} has no section"
        assert f"Usage: strapdown {name}" in helps[name]
