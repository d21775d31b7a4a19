"""``rover-cosim soils``: the shipped soils and wheels, or one of them with every value and unit."""

from __future__ import annotations

import argparse
from pathlib import Path

from .command import Command, no_result_set
from .options import fail, path_text


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("name", nargs="?", type=path_text, default=None,
                        help="a soil or wheel (shipped name, TOML file or FILE:NAME)")


def run(args: argparse.Namespace) -> int:
    from rover_cosim.terramechanics import library

    if args.name is not None:
        return _one(args.name)
    for kind in ("soil", "wheel"):
        print(f"{kind}s (--{kind} NAME):")
        for name in library.names(kind):
            _, table = library.entry(kind, name)
            print(f"  {name:15s} {table.get('title', '')}")
            print(f"  {'':15s} source: {table.get('source', '')}")
    print(f"files: {library.SOILS}, {library.WHEELS}; `rover-cosim soils NAME` shows one")
    return 0


def _one(name: str) -> int:
    """One soil or wheel, every value with its unit, and its source."""
    import math
    from dataclasses import asdict

    from rover_cosim.terramechanics import library
    from rover_cosim.terramechanics.parameters import UNITS

    found = []
    problems = []
    for kind in ("soil", "wheel"):
        try:
            entry_name, table = library.entry(kind, name)
            found.append((kind, entry_name, table, library.build(kind, entry_name, table)))
        except ValueError as error:
            problems.append(f"as a {kind}: {error}")
            continue
    if not found:
        shipped = (f"soils: {', '.join(library.names('soil'))}; wheels: {', '.join(library.names('wheel'))}")
        if Path(name.rsplit(":", 1)[0]).is_file() or Path(name).is_file():  # a file of the user's: why not
            fail("soils", f"{name!r}: neither a soil nor a wheel: " + "; ".join(problems))
        else:
            fail("soils", f"{name!r}: no shipped soil or wheel of that name, and no such TOML file ({shipped})")
        return 2
    for kind, entry_name, table, built in found:
        print(f"{kind} {entry_name}: {table.get('title', '')}")
        print(f"  source: {table.get('source', '')}")
        for key, value in asdict(built).items():
            shown = f"{value:.6g}" + (f" rad ({math.degrees(value):.4g} deg)" if key in ("phi", "xc") else "")
            given = "" if key in table or f"{key}_deg" in table else "  (default" + (
                ": 45 deg - phi/2)" if key == "xc" else ": the paper's)")
            print(f"  {key:8s} {shown} {UNITS.get(key, '') if key not in ('phi', 'xc') else ''}{given}")
        for key, note in table.get("notes", {}).items():
            print(f"  note {key}: {note}")
    return 0


COMMAND = Command(
    "soils", help="the shipped soils and wheels (for --soil, --wheel), with their sources; `soils NAME` shows one "
    "with every value and its unit",
    summary="The shipped soils and wheels with their sources; one of them with every value and unit.",
    examples=("rover-cosim soils", "rover-cosim soils lete_sand"),
    arguments=arguments, run=run, result_sets=no_result_set)
