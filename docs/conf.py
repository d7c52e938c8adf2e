"""Sphinx configuration of the strapdown documentation (``make docs``)."""

import os
import re
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(HERE))

import _apigen
import _cligen

import strapdown

project = "strapdown"
author = "strapdown developers"
copyright = f"{time.gmtime().tm_year}, strapdown developers"
release = version = strapdown.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx.ext.intersphinx",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "auto_examples/*.ipynb", "auto_examples/*.py", "**/*.zip", "**/*.md5"]
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# The references are written from each module's __all__ and from the click commands before Sphinx reads a page.
_apigen.write(HERE / "api")
_cligen.write(HERE / "cli")

autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

intersphinx_mapping = {
    "python": ("https://docs.python.org/3", None),
    "numpy": ("https://numpy.org/doc/stable", None),
}
# intersphinx needs the network; a build offline (CI) must not fail for it
if os.environ.get("STRAPDOWN_DOCS_OFFLINE", "1") == "1":
    intersphinx_mapping = {}

html_theme = "pydata_sphinx_theme"
html_title = f"strapdown {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
}
html_static_path = []

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "matplotlib_animations": False,
    "reset_modules": ("matplotlib",),
    "show_memory": False,
    "plot_gallery": "True",
}


def _drop_empty_guide_glob(app, docname, source):
    # The topic guides (docs/guide/*.md) are written on other branches; until one exists the glob would match
    # nothing, which Sphinx reports as a warning (an error under -W).
    if docname == "index" and not any((HERE / "guide").glob("*.md")):
        start = source[0].find("```{toctree}\n:maxdepth: 1\n:caption: Topic guides")
        if start >= 0:
            end = source[0].index("```", source[0].index("guide/*", start)) + 3
            source[0] = source[0][:start] + source[0][end:]


# ``...`` literals and `...` roles (math among them) are left as they are; a bar elsewhere is text
_LITERAL = re.compile(r"(``.+?``|`[^`]+`)")


def _escape_bars(app, what, name, obj, options, lines):
    # Docstrings write |ω|, |q| - 1 for magnitudes; reStructuredText reads |...| as a substitution reference and
    # fails the build.  Escape bars in running text (not in literals, roles, grid tables or line blocks).
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        if "|" not in line or stripped.startswith(("|", "+-", "+=")):
            continue
        parts = _LITERAL.split(line)
        lines[i] = "".join(p if k % 2 else p.replace("|", "\\|") for k, p in enumerate(parts))


def _reread_index(app, env, added, changed, removed):
    # whether the guide toctree is kept depends on files outside index.md: read it again at every build
    return ["index"]


def setup(app):
    """Connect the build hooks."""
    app.connect("source-read", _drop_empty_guide_glob)
    app.connect("env-get-outdated", _reread_index)
    app.connect("autodoc-process-docstring", _escape_bars, priority=600)  # after numpydoc's own rewrite
