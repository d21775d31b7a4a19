"""The ``omc`` backend: the same FMUs built by OpenModelica's ``buildModelFMU`` (FMI 2.0, Model
Exchange + Co-Simulation, CVODE as the Co-Simulation solver).

Used by ``make fmus`` when ``omc`` is on PATH (``BACKEND=auto``) or with ``BACKEND=omc``. Not
exercised by ``.ci/run`` (OpenModelica is not installable from our registries); the hosted CI
workflow ``.github/workflows/omc-fmus.yml`` builds the FMUs with it in OpenModelica's container.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
import time
import zipfile
from pathlib import Path

from . import source
from .artifact import BUILD_RECORD, BuildResult, input_digest, stored_digest

#: Simulation flags compiled into the FMU: CVODE for Co-Simulation.
FMI_FLAGS = "s:cvode"


def omc_version(omc: str) -> str:
    result = subprocess.run([omc, "--version"], capture_output=True, text=True, check=False)
    return result.stdout.strip() or result.stderr.strip()


def script(name: str) -> str:
    """The ``.mos`` script that loads the package and exports ``name``."""
    package = source.package_file().as_posix()
    return "\n".join([
        f'setCommandLineOptions("--fmiFlags={FMI_FLAGS}"); getErrorString();',
        f'if not loadFile("{package}") then print(getErrorString()); exit(1); end if;',
        (f'result := buildModelFMU({source.fmu_class(name)}, version="2.0", fmuType="me_cs", '
         f'fileNamePrefix="{name}", platforms={{"static"}});'),
        'print(getErrorString());',
        'if result == "" then exit(1); end if;',
        "",
    ])


def build_fmu_omc(name: str, out_dir: Path, *, force: bool = False) -> BuildResult:
    """Build ``out_dir/<name>.fmu`` with OpenModelica (skipped when up to date)."""
    omc = shutil.which("omc")
    if omc is None:
        raise RuntimeError("backend omc: `omc` (OpenModelica) is not on PATH; use BACKEND=builtin")
    started = time.perf_counter()
    out_dir = Path(out_dir)
    target = out_dir / f"{name}.fmu"
    version = omc_version(omc)
    digest = input_digest(name) + ":omc:" + version
    if not force and target.exists() and stored_digest(target) == digest:
        return BuildResult(name, target, False, time.perf_counter() - started)
    with tempfile.TemporaryDirectory(prefix=f"omc-{name}-") as tmp_name:
        tmp = Path(tmp_name)
        (tmp / "build.mos").write_text(script(name))
        t0 = time.perf_counter()
        result = subprocess.run([omc, "build.mos"], cwd=tmp, capture_output=True, text=True, check=False)
        seconds = time.perf_counter() - t0
        built = tmp / f"{name}.fmu"
        if result.returncode != 0 or not built.exists():
            raise RuntimeError(f"{name}: omc buildModelFMU failed (exit {result.returncode}):\n"
                               + (result.stdout + result.stderr)[-4000:])
        record = {"input_sha256": digest, "backend": "omc", "omc": version, "fmi_flags": FMI_FLAGS,
                  "model": source.fmu_class(name)}
        out_dir.mkdir(parents=True, exist_ok=True)
        partial = out_dir / f".{name}.fmu.partial"
        with zipfile.ZipFile(built) as original, zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as copy:
            for member in original.infolist():
                if member.filename != BUILD_RECORD:
                    copy.writestr(member, original.read(member))
            copy.writestr(BUILD_RECORD, json.dumps(record, indent=2) + "\n")
        os.replace(partial, target)
    return BuildResult(name, target, True, time.perf_counter() - started, {"omc": seconds})
