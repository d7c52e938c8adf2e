"""Write the command-line reference (``docs/cli/index.rst``) from the click commands themselves.

Run by ``conf.py`` at every build: every command the ``strapdown`` group lists gets a section with its
``--help`` text, so a command added later appears without editing the docs.
"""

from __future__ import annotations

from pathlib import Path

WIDTH = 100


def command_help() -> dict[str, str]:
    """``--help`` text by command name (``"strapdown"`` for the group itself), in the group's order."""
    import click

    from strapdown.cli import _build

    group = _build()
    ctx = click.Context(group, info_name="strapdown", terminal_width=WIDTH, max_content_width=WIDTH)
    helps = {"strapdown": group.get_help(ctx)}
    for name in group.list_commands(ctx):
        command = group.get_command(ctx, name)
        sub = click.Context(command, info_name=name, parent=ctx, terminal_width=WIDTH, max_content_width=WIDTH)
        helps[name] = command.get_help(sub)
    return helps


def page(helps: dict[str, str]) -> str:
    """The reStructuredText of the reference."""
    lines = [
        "Command-line reference",
        "======================",
        "",
        "Generated at every build from the commands' own ``--help``; the :doc:`files and command-line page",
        "<../files-and-cli>` explains what they are for.",
        "",
    ]
    for name, text in helps.items():
        title = "strapdown" if name == "strapdown" else f"strapdown {name}"
        lines += [f".. _cli-{name}:", "", title, "-" * len(title), "", ".. code-block:: text", ""]
        lines += [f"   {line}".rstrip() for line in text.splitlines()]
        lines.append("")
    return "\n".join(lines)


def write(out_dir: Path) -> Path:
    """Write ``index.rst`` into ``out_dir`` (unchanged text is not rewritten, so Sphinx does not rebuild it)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    path = out_dir / "index.rst"
    text = page(command_help())
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")
    return path
