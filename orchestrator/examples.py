"""The example system files shipped with the package (``rover-cosim run NAME``)."""

from __future__ import annotations

from pathlib import Path

#: Folder of the shipped system files (package data; FMU paths in them are relative to --fmu-dir).
SYSTEMS_DIR = Path(__file__).parent / "systems"


def examples() -> dict[str, Path]:
    """Shipped example systems by name (the file's stem)."""
    return {path.stem: path for path in sorted(SYSTEMS_DIR.glob("*.toml"))}


def example(name: str) -> Path:
    """The shipped system file ``name``; ValueError listing the names for an unknown one."""
    found = examples()
    if name not in found:
        raise ValueError(f"example system {name!r}: expected one of {', '.join(found)}")
    return found[name]
