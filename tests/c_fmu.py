"""Compiling the test FMUs written in C under tests/fmus (the FMI headers FMPy ships) and zipping
them with their model description; shared by typed_fmu.py and ball_fmus.py."""

from __future__ import annotations

import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import fmpy

FOLDER = Path(__file__).with_name("fmus")


def compile_fmu(source: str, identifier: str, folder: Path, name: str, description: str,
                platform: str = fmpy.platform) -> Path | str:
    """``folder``/``name``.fmu with tests/fmus/``source`` compiled as binaries/``platform``/
    ``identifier``.so and ``description`` as its modelDescription.xml; or why it could not be
    built (no C compiler, or the compiler's message)."""
    compiler = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not compiler:
        return "no C compiler ($CC, cc or gcc) on PATH"
    headers = Path(fmpy.__file__).parent / "c-code"
    work = folder / f"{name}-build"
    work.mkdir(parents=True, exist_ok=True)
    library = work / f"{identifier}.so"
    done = subprocess.run([compiler, "-shared", "-fPIC", "-O1", f"-I{headers}", f"-I{FOLDER}", str(FOLDER / source),
                           "-o", str(library), "-lm"], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        return f"{compiler} failed: {done.stderr.strip()[:300]}"
    fmu = folder / f"{name}.fmu"
    with zipfile.ZipFile(fmu, "w") as archive:
        archive.writestr("modelDescription.xml", description)
        archive.write(library, f"binaries/{platform}/{identifier}.so")
    return fmu


def built_or_skip(built: Path | str) -> Path:
    """The FMU a build function made, or the test skipped with the reason it could not be built."""
    import pytest

    if isinstance(built, str):
        pytest.skip(f"the test FMU cannot be built here: {built}")
    return built
