"""The platforms an FMU's binaries are built for, and the compilers that build them.

The host platform (the default) is compiled by the host's C compiler (``$CC``, else ``cc``: gcc on
our machines), as it always was. Every platform named in ``--platforms`` is cross-compiled from the
same generated C with zig's C compiler (clang with the C libraries of every target; PyPI
``ziglang``, the project's ``platforms`` extra): Linux against glibc 2.17 (RHEL 7 and newer),
Windows against the Universal C Runtime, macOS against zig's libSystem stubs.

Folder names: FMI 2.0 names ``linux64``, ``win64`` and ``darwin64`` (x86-64); for any other platform
FMI 2.0.4 (section 2.3, "FMU Distribution") says to use the FMI 3.0 platform tuple, which is how
``aarch64-linux`` and ``aarch64-darwin`` go into an FMI 2.0 FMU. ``fmi3`` holds each platform's
FMI 3.0 folder, for the FMI 3.0 build.
"""

from __future__ import annotations

import os
import platform as host_platform
import shutil
import sys
from dataclasses import dataclass
from importlib import metadata


@dataclass(frozen=True)
class Platform:
    """One target: its ``binaries/`` folder in FMI 2.0 and 3.0, zig's target and the library suffix."""

    name: str      # FMI 2.0 folder, the name --platforms takes
    fmi3: str      # FMI 3.0 platform tuple (folder)
    target: str    # zig cc -target
    suffix: str    # shared library file suffix
    machine: str   # the machine code: x86_64 or aarch64
    system: str    # linux, windows or darwin


PLATFORMS: dict[str, Platform] = {p.name: p for p in (
    Platform("linux64", "x86_64-linux", "x86_64-linux-gnu.2.17", ".so", "x86_64", "linux"),
    Platform("win64", "x86_64-windows", "x86_64-windows-gnu", ".dll", "x86_64", "windows"),
    Platform("darwin64", "x86_64-darwin", "x86_64-macos", ".dylib", "x86_64", "darwin"),
    Platform("aarch64-linux", "aarch64-linux", "aarch64-linux-gnu.2.17", ".so", "aarch64", "linux"),
    Platform("aarch64-darwin", "aarch64-darwin", "aarch64-macos", ".dylib", "aarch64", "darwin"),
)}

#: ``--platforms all`` for FMI 2.0.
ALL = ("linux64", "win64", "darwin64", "aarch64-linux", "aarch64-darwin")
#: The value naming the host platform, compiled by the host's C compiler.
HOST = "host"

#: Flags of the zig builds on top of the common CFLAGS: no debug information (the gcc build has
#: none either); -ffp-contract=off: no fused multiply-add where the target has it (aarch64), so
#: that every target rounds each operation as x86-64 does.
ZIG_FLAGS = ("-g0", "-ffp-contract=off")


def host_folder() -> str:
    """The ``binaries/`` folder name of this machine, by the FMI 2.0 convention as importers read it
    (FMPy looks for ``linux64`` on any 64-bit Linux, aarch64 included)."""
    bits = "64" if sys.maxsize > 2**32 else "32"
    names = {"Linux": "linux", "Darwin": "darwin", "Windows": "win"}
    system = host_platform.system()
    if system not in names:
        raise RuntimeError(f"platform {system!r}: no FMI 2.0 binaries folder name for it")
    return names[system] + bits


def host_suffix() -> str:
    return {"Darwin": ".dylib", "Windows": ".dll"}.get(host_platform.system(), ".so")


def parse(text: str) -> tuple[str, ...]:
    """``--platforms``: ``host``, ``all`` or a comma-separated list of platform names (``host``
    among them); in order, each once. ValueError names an unknown value and the allowed ones."""
    names: list[str] = []
    for item in (part.strip() for part in text.split(",")):
        expanded = ALL if item == "all" else (item,)
        for name in expanded:
            if name != HOST and name not in PLATFORMS:
                raise ValueError(f"--platforms: unknown platform {name!r}; expected {HOST}, all or a "
                                 f"comma-separated list of {HOST}, {', '.join(PLATFORMS)}")
            if name not in names:
                names.append(name)
    if HOST in names and host_folder() in names:
        raise ValueError(f"--platforms: {HOST} and {host_folder()} are the same folder; name one of them "
                         f"({HOST}: the host's C compiler, {host_folder()}: zig for {PLATFORMS[host_folder()].target})")
    return tuple(names)


def zig_command() -> list[str]:
    """How to run zig's C compiler: the ``ziglang`` package of this Python."""
    try:
        metadata.version("ziglang")
    except metadata.PackageNotFoundError:
        raise RuntimeError("cross-compiling needs zig's C compiler: pip install ziglang "
                           "(in this project: pip install -e '.[platforms]')") from None
    return [sys.executable, "-m", "ziglang", "cc"]


def zig_version() -> str:
    return metadata.version("ziglang")


def host_compiler() -> str:
    cc = os.environ.get("CC", "cc")
    if shutil.which(cc) is None:
        raise RuntimeError(f"C compiler {cc!r} not found on PATH (set CC, or install gcc)")
    return cc
