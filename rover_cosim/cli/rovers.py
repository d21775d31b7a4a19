"""``rover-cosim rovers``: the shipped rovers, or one of them with every value, its unit and its wheel."""

from __future__ import annotations

import argparse
from pathlib import Path

from .command import Command, no_result_set
from .options import fail, path_text


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("name", nargs="?", type=path_text, default=None,
                        help="a rover (shipped name, TOML file or FILE:NAME)")


def run(args: argparse.Namespace) -> int:
    from rover_cosim.terramechanics import library

    if args.name is not None:
        return _one(args.name)
    print("rovers (--rover NAME):")
    for name in library.names("rover"):
        _, table = library.entry("rover", name)
        rover = library.build_rover(name, table)
        print(f"  {name:10s} {table.get('title', '')}")
        print(f"  {'':10s} {rover.mass:g} kg on {rover.wheels} wheels, wheel {table.get('wheel', library.DEFAULT)}; "
              f"source: {table.get('source', '')}")
    print(f"file: {library.ROVERS}; `rover-cosim rovers NAME` shows one")
    return 0


def _one(name: str) -> int:
    """One rover: every value with its unit, its wheel, its static wheel load on the paper's soil's gravity."""
    from dataclasses import asdict

    from rover_cosim.terramechanics import library
    from rover_cosim.terramechanics.parameters import ROVER_UNITS

    try:
        entry_name, table = library.entry("rover", name)
        rover = library.build_rover(entry_name, table)
    except ValueError as error:
        if Path(name.rsplit(":", 1)[0]).is_file() or Path(name).is_file():
            fail("rovers", f"{name!r}: not a rover: {error}")
        else:
            fail("rovers", f"{name!r}: no shipped rover of that name, and no such TOML file (rovers: "
                 f"{', '.join(library.names('rover'))})")
        return 2
    print(f"rover {entry_name}: {table.get('title', '')}")
    print(f"  source: {table.get('source', '')}")
    print(f"  wheel    {table.get('wheel', library.DEFAULT)}  (--wheel replaces it)")
    for key, value in asdict(rover).items():
        shown = ", ".join(f"{v:g}" for v in value) if isinstance(value, tuple) else f"{value:.6g}"
        given = "" if key in table else "  (default: the paper's)"
        print(f"  {key:8s} {shown} {ROVER_UNITS[key]}{given}")
    print(f"  wheels   {rover.wheels} ({rover.axles} per side; the right side mirrors the left)")
    print(f"  static wheel load  {rover.static_wheel_load(1.62):.1f} N on the Moon (1.62 m/s^2), "
          f"{rover.static_wheel_load(3.71):.1f} N on Mars (3.71 m/s^2): the soil's gravity decides")
    for key, note in table.get("notes", {}).items():
        print(f"  note {key}: {note}")
    return 0


COMMAND = Command(
    "rovers", help="the shipped rovers (for --rover), with their sources; `rovers NAME` shows one with every value "
    "and its unit",
    summary="The shipped rovers with their sources; one of them with every value and unit.",
    examples=("rover-cosim rovers", "rover-cosim rovers viper"),
    arguments=arguments, run=run, result_sets=no_result_set)
