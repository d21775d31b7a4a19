"""What a built FMU is made from and what it records about that: the runtime files and compiler
flags, the input digest that decides whether an FMU is up to date, and the build record stored in
the FMU (``documentation/build.json``). Shared by both backends (``build``, ``omc``)."""

from __future__ import annotations

import hashlib
import json
import zipfile
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

from . import catalog, elementary

RUNTIME = Path(__file__).parent / "runtime"
#: The runtime's files in an FMU: the core (core.h, instance.c, state.c, cosim.c, ode23s) and the API
#: layer of its FMI version.
RUNTIME_CORE = ("model.h", "core.h", "finite.h", "contact.h", "ode23s.h", "ode23s.c", "instance.c", "state.c",
                "cosim.c")
RUNTIME_FILES = (*RUNTIME_CORE, "fmi2_api.c")
RUNTIME_FILES_3 = (*RUNTIME_CORE, "fmi3_api.c")
#: -fno-math-errno: libm calls are pure functions to the optimiser (the runtime never reads
#: errno), so it may drop or move them like any other operation.
CFLAGS = ("-O2", "-fno-math-errno", "-fPIC", "-shared", "-fvisibility=hidden", "-std=c99", "-D_POSIX_C_SOURCE=200809L")
BUILD_RECORD = "documentation/build.json"


@dataclass
class BuildResult:
    name: str
    path: Path
    rebuilt: bool
    seconds: float
    stages: dict[str, float] = field(default_factory=dict)  # translate, generate, compile, package [s]


def input_digest(name: str) -> str:
    """Digest of everything a built-in FMU of ``name`` is made from."""
    digest = hashlib.sha256(name.encode())
    files = sorted((catalog.MODELICA_ROOT / catalog.PACKAGE).rglob("*")) + sorted(Path(__file__).parent.glob("*.py"))
    files += [RUNTIME / f for f in sorted({*RUNTIME_FILES, *RUNTIME_FILES_3, elementary.HEADER})]
    for path in files:
        if path.is_file():
            digest.update(str(path.relative_to(path.parents[1])).encode())
            digest.update(path.read_bytes())
    for package in ("rumoca", "casadi"):
        digest.update(f"{package}=={metadata.version(package)}".encode())
    digest.update(" ".join(CFLAGS).encode())
    return digest.hexdigest()


def stored_elementary(fmu: Path) -> str:
    """The elementary functions an FMU built by this module computes with (its build record's
    ``elementary``; ``libm`` for an FMU that records none: built before the choice existed, or by
    another tool)."""
    try:
        with zipfile.ZipFile(fmu) as archive:
            choice = json.loads(archive.read(BUILD_RECORD)).get("elementary", elementary.DEFAULT)
    except (OSError, KeyError, ValueError, AttributeError, zipfile.BadZipFile):
        return elementary.DEFAULT
    return choice if choice in elementary.CHOICES else elementary.DEFAULT


def stored_digest(fmu: Path) -> str | None:
    """The input digest recorded in an FMU built by this module, or None."""
    try:
        with zipfile.ZipFile(fmu) as archive:
            return json.loads(archive.read(BUILD_RECORD))["input_sha256"]
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return None
