"""A C test harness compiled with the FMU runtime's headers into a shared library for ctypes
(test_elementary.py, test_integrator.py); the calling test skips where no C compiler is found."""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from rover_cosim.fmubuild import elementary_constants

#: The FMUs' C runtime (fmubuild/runtime): its headers, and sources a harness compiles with.
RUNTIME = Path(elementary_constants.__file__).parent / "runtime"


def compiled(tmp_path_factory: pytest.TempPathFactory, name: str, *sources: Path) -> ctypes.CDLL:
    """``sources`` compiled (-O2, warnings as errors) and loaded; skips without a C compiler."""
    compiler = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if compiler is None:
        pytest.skip("no C compiler ($CC, cc or gcc) on PATH")
    library = tmp_path_factory.mktemp(name) / "harness.so"
    subprocess.run([compiler, "-O2", "-fno-math-errno", "-std=c99", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC",
                    "-I", str(RUNTIME), *[str(source) for source in sources], "-o", str(library), "-lm"], check=True)
    return ctypes.CDLL(str(library))
