"""Compile an FMU's C files into its shared library: one compiler per file, then one link, and the
runtime's objects shared by the FMUs of one build.

Every FMU of a build carries the same runtime files (instance.c, ode23s.c, the API layer, ...) and
compiles them with the same flags; only the generated model code differs. ``build_all`` hands its
builds a folder for the objects they share (:class:`SharedObjects`): the first build that needs an
object compiles it there, under a lock, and the others link that file. An object is shared under the
SHA-256 of what decides its bits: the compiler command and flags, the file's text and the text of
every header in the sources folder but the prefix header, which a file reads only with
``FMI2_FUNCTION_PREFIX``/``FMI3_FUNCTION_PREFIX`` defined (the FMI way to compile several source
FMUs into one program; a command that defines one shares nothing). The folder lives only as long
as the build command: a fresh build compiles everything once.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import subprocess
import time
from collections.abc import Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

from . import prefix

#: Flags that make a file read the per-FMU prefix header: objects compiled with them are not shared.
_PREFIX_DEFINES = ("-DFMI2_FUNCTION_PREFIX", "-DFMI3_FUNCTION_PREFIX")
#: Link-only flags, left out of a compile to an object.
_LINK_ONLY = ("-shared",)


@dataclass(frozen=True)
class Toolchain:
    """How one platform's library is made: the compiler command (with its -target), the flags, the
    libraries linked and a name of the compiler and its version (part of a shared object's key)."""

    command: tuple[str, ...]
    flags: tuple[str, ...]
    libraries: tuple[str, ...]
    compiler: str


@dataclass(frozen=True)
class SharedObjects:
    """A folder of objects the FMUs of one build share, and the names of the files they may share
    (the runtime's, never the generated model code)."""

    folder: Path
    files: frozenset[str]


class CompileError(RuntimeError):
    """The compiler or the linker failed: ``what`` names the step and its file, ``returncode`` and
    ``output`` (the end of its standard error) are the tool's."""

    def __init__(self, what: str, returncode: int, output: str):
        super().__init__(f"{what} (exit {returncode}):\n{output}")
        self.what, self.returncode, self.output = what, returncode, output


def _run(command: Sequence[str], cwd: Path, what: str) -> None:
    result = subprocess.run(list(command), capture_output=True, text=True, check=False, cwd=cwd)
    if result.returncode != 0:
        raise CompileError(what, result.returncode, result.stderr[-4000:])


def object_key(toolchain: Toolchain, sources: Path, c_file: str) -> str:
    """The SHA-256 of what decides ``c_file``'s object: the command, the flags, the file and every
    header in ``sources`` but the prefix header."""
    digest = hashlib.sha256("\0".join((*toolchain.command, *toolchain.flags, toolchain.compiler)).encode())
    for path in [sources / c_file, *sorted(p for p in sources.glob("*.h") if p.name != prefix.HEADER)]:
        digest.update(b"\0" + path.name.encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()


def _compile_command(toolchain: Toolchain, c_file: str, target: Path) -> list[str]:
    flags = [f for f in toolchain.flags if f not in _LINK_ONLY]
    return [*toolchain.command, *flags, "-I", ".", "-c", c_file, "-o", str(target)]


def _shareable(toolchain: Toolchain, shared: SharedObjects | None, c_file: str) -> bool:
    return (shared is not None and c_file in shared.files
            and not any(f.startswith(_PREFIX_DEFINES) for f in toolchain.flags))


def compile_object(toolchain: Toolchain, sources: Path, c_file: str, out: Path,
                   shared: SharedObjects | None = None) -> Path:
    """The object of ``sources``/``c_file``: compiled into ``out``, or, for a file ``shared`` lists,
    taken from its folder (compiled there first by whichever build asks first)."""
    if not _shareable(toolchain, shared, c_file):
        out.mkdir(parents=True, exist_ok=True)
        target = out / f"{c_file}.o"
        _run(_compile_command(toolchain, c_file, target), sources, f"the C compiler failed on {c_file}")
        return target
    assert shared is not None
    key = object_key(toolchain, sources, c_file)
    target = shared.folder / f"{key}.o"
    with open(shared.folder / f"{key}.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            if not target.is_file():
                partial = shared.folder / f".{key}.partial.o"  # the lock makes the name ours
                try:
                    _run(_compile_command(toolchain, c_file, partial), sources,
                         f"the C compiler failed on {c_file}")
                    os.replace(partial, target)
                finally:
                    partial.unlink(missing_ok=True)
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
    return target


def _start_objects(pool: ThreadPoolExecutor, toolchain: Toolchain, sources: Path, out: Path,
                  shared: SharedObjects | None = None) -> list[Future[Path]]:
    """Submit the compile of every C file of ``sources`` to ``pool``, the largest first (the
    generated model code: it takes longest); the futures in the files' order."""
    c_files = sorted(p.name for p in sources.iterdir() if p.suffix == ".c")
    sizes = {f: (sources / f).stat().st_size for f in c_files}
    futures = {f: pool.submit(compile_object, toolchain, sources, f, out, shared)
               for f in sorted(c_files, key=lambda f: -sizes[f])}
    return [futures[f] for f in c_files]


def link(toolchain: Toolchain, objects: Sequence[Path], library: Path) -> None:
    """Link ``objects`` into the shared library ``library``."""
    _run([*toolchain.command, *toolchain.flags, *map(str, objects), "-o", str(library), *toolchain.libraries],
         library.parent, f"the linker failed on {library.name}")


def compile_library(toolchain: Toolchain, sources: Path, library: Path, jobs: int = 1,
                    shared: SharedObjects | None = None) -> float:
    """Compile every C file of ``sources`` (``jobs`` compilers at a time) and link them into
    ``library``; returns the seconds. CompileError names the file that failed."""
    started = time.perf_counter()
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures = _start_objects(pool, toolchain, sources, library.parent / "objects", shared)
    link(toolchain, [f.result() for f in futures], library)
    return time.perf_counter() - started
