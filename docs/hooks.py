"""MkDocs hooks: the reference pages that follow the code, generated at build time (never kept as
files, so they cannot drift): the command line from ``rover_cosim.cli``'s parser and the soil and
wheel library from its TOML files; and the Modelica package's ``UsersGuide``, set into the page
``guide/modelica.md`` from the package's own Documentation annotations."""

from __future__ import annotations

import argparse
import html
import re
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

from mkdocs.structure.files import File, Files


def cli_page() -> str:
    """Every ``rover-cosim`` command with its description and options, from the parser itself."""
    from rover_cosim.cli import build_parser

    parser = build_parser()
    lines = ["# Command line", "", "Generated from `rover_cosim.cli.build_parser()`.", "",
             "```text", parser.format_help().rstrip(), "```", ""]
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, sub in commands.choices.items():
        lines += [f"## rover-cosim {name}", "", "```text", sub.format_help().rstrip(), "```", ""]
    return "\n".join(lines)


def library_page() -> str:
    """The shipped soils and wheels: every value in SI, its title and source."""
    lines = ["# Soils and wheels", "", "Generated from the library files "
             "(`rover_cosim/terramechanics/library/*.toml`); `rover-cosim soils NAME` shows one with its notes.", ""]
    folder = resources.files("rover_cosim.terramechanics") / "library"
    for kind in ("soils", "wheels"):
        tables: dict[str, Any] = tomllib.loads((folder / f"{kind}.toml").read_text())
        lines += [f"## {kind.capitalize()}", ""]
        for name, table in tables.items():
            values = ", ".join(f"`{k}` = {v}" for k, v in table.items() if k not in ("title", "source", "notes"))
            lines += [f"### {name}", "", f"{table.get('title', '')}", "", f"Source: {table.get('source', '')}", "",
                      values or "(the paper's values)", ""]
    return "\n".join(lines)


GENERATED = {"reference/cli.md": cli_page, "reference/soils.md": library_page}

#: Where guide/modelica.md takes the UsersGuide.
USERS_GUIDE_MARK = "<!-- RoverTerramechanics.UsersGuide -->"


def users_guide() -> str:
    """Every class of ``RoverTerramechanics.UsersGuide``, in its package.order, as a section: its
    description, then its Documentation HTML (links to the guide's classes become links to the
    sections, links to other classes their names)."""
    from rover_cosim.fmubuild import source

    folder = source.MODELICA_ROOT / source.PACKAGE / "UsersGuide"
    sections = [_guide_html(folder / "package.mo"), ""]
    for name in (folder / "package.order").read_text().split():
        description = re.search(rf'^class {name} "(.*?)"', (folder / f"{name}.mo").read_text(), re.MULTILINE)
        if description is None:
            raise ValueError(f"{folder / name}.mo: expected 'class {name} \"description\"'")
        sections += [f"## {name}", "", f"*{html.escape(description.group(1))}*", "",
                     _guide_html(folder / f"{name}.mo"), ""]
    return "\n".join(sections)


def _guide_html(path: Path) -> str:
    """The Documentation HTML of a class of the guide, its links made to work on the site."""
    info = re.search(r'Documentation\(info="<html>(.*?)</html>"\)', path.read_text(), re.DOTALL)
    if info is None:
        raise ValueError(f"{path}: no Documentation(info=...)")
    body = info.group(1).replace('\\"', '"').strip()
    body = re.sub(r'<a\s+href="modelica://RoverTerramechanics\.UsersGuide\.(\w+)">',
                  lambda m: f'<a href="#{m.group(1).lower()}">', body)
    return re.sub(r'<a\s+href="modelica://[\w.]+">(.*?)</a>', r"<code>\1</code>", body, flags=re.DOTALL)


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    if page.file.src_uri == "guide/modelica.md":
        return markdown.replace(USERS_GUIDE_MARK, users_guide())
    return markdown


def on_files(files: Files, config: Any) -> Files:
    for path, make in GENERATED.items():
        files.append(File.generated(config, path, content=make()))
    return files
