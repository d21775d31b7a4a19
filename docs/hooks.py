"""MkDocs hooks: the reference pages that follow the code, generated at build time (never kept as
files, so they cannot drift): the command line from ``rover_cosim.cli``'s parser and the soil and
wheel library from its TOML files."""

from __future__ import annotations

import argparse
import tomllib
from importlib import resources
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


def on_files(files: Files, config: Any) -> Files:
    for path, make in GENERATED.items():
        files.append(File.generated(config, path, content=make()))
    return files
