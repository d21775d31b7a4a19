"""Build FMUs: Modelica class → (built-in backend) rumoca → CasADi → C → FMI 2.0 FMU in ``fmus/``.

The FMU is assembled in a temporary folder and moved into place with one rename, so a failed
build (an unsupported construct, a compiler error) leaves the output folder as it was. A build is
skipped when the FMU already there was made from the same inputs (the digest of the Modelica
package, this builder and the pinned tool versions is stored in ``documentation/build.json``).
"""

from __future__ import annotations

import json
import multiprocessing
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from importlib import metadata
from pathlib import Path

from . import codegen, description, ode, source
from .artifact import BUILD_RECORD, CFLAGS, RUNTIME, RUNTIME_FILES, BuildResult, input_digest, stored_digest
from .omc import build_fmu_omc

#: The FMUs ``make fmus`` builds (classes of the Modelica package).
FMU_MODELS = ("SingleWheel", "Rover", "RoverBody", "Wheel", "SteerableRover", "SteerableRoverBody")

FMI_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")


def platform_folder() -> str:
    """The ``binaries/`` folder name of this platform (FMI 2.0 convention)."""
    bits = "64" if sys.maxsize > 2**32 else "32"
    system = platform.system()
    if system == "Linux":
        return "linux" + bits
    if system == "Darwin":
        return "darwin" + bits
    if system == "Windows":
        return "win" + bits
    raise RuntimeError(f"platform {system!r}: no FMI 2.0 binaries folder name for it")


def shared_library_suffix() -> str:
    return {"Darwin": ".dylib", "Windows": ".dll"}.get(platform.system(), ".so")


def fmi_headers() -> Path:
    """The FMI 2.0 standard headers, as shipped with FMPy (not copied into this repository)."""
    import fmpy  # its c-code folder holds the FMI standard headers

    folder = Path(fmpy.__file__).parent / "c-code"
    missing = [h for h in FMI_HEADERS if not (folder / h).exists()]
    if missing:
        raise RuntimeError(f"FMI 2.0 headers {missing} not found in {folder} (is FMPy installed?)")
    return folder


def _default_experiment(name: str) -> source.Experiment | None:
    """The class's ``experiment`` annotation, for the model description's DefaultExperiment."""
    try:
        return source.experiment(f"{source.PACKAGE}.{name}")
    except ValueError:
        return None


def _class_documentation(name: str) -> str:
    """The Documentation info (HTML) of the class ``name`` and of the records it uses, from our
    own Modelica files ("" where a class has none)."""
    import re

    parts = []
    for qualified in (f"{source.PACKAGE}.{name}", f"{source.PACKAGE}.Parameters.SoilParameters",
                      f"{source.PACKAGE}.Parameters.WheelParameters"):
        text = source.class_file(qualified).read_text()
        found = re.search(r'info="(.*?)"\)', text, re.S)
        if found:
            inner = re.sub(r"</?html>", "", found.group(1)).replace('\\"', '"')
            parts.append(f"<h3>{qualified.rsplit('.', 1)[-1]}</h3>{inner}")
    return "\n".join(parts)


def _class_description(name: str) -> str:
    text = source.class_file(f"{source.PACKAGE}.{name}").read_text()
    head = text.split("\n", 3)
    for line in head:
        if line.strip().startswith(("model ", "block ")) and '"' in line:
            return line.split('"')[1]
    return name


def compiler() -> str:
    cc = os.environ.get("CC", "cc")
    if shutil.which(cc) is None:
        raise RuntimeError(f"C compiler {cc!r} not found on PATH (set CC, or install gcc)")
    return cc


def build_fmu(name: str, out_dir: Path, *, force: bool = False) -> BuildResult:
    """Build ``out_dir/<name>.fmu`` with the built-in backend (skipped when up to date)."""
    started = time.perf_counter()
    out_dir = Path(out_dir)
    target = out_dir / f"{name}.fmu"
    digest = input_digest(name)
    if not force and target.exists() and stored_digest(target) == digest:
        return BuildResult(name, target, False, time.perf_counter() - started)
    stages: dict[str, float] = {}
    with tempfile.TemporaryDirectory(prefix=f"fmubuild-{name}-") as tmp_name:
        tmp = Path(tmp_name)
        t0 = time.perf_counter()
        model = ode.translate(source.load(f"{source.PACKAGE}.{name}"), name)
        model_layout = codegen.layout(model)
        stages["translate"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        root = tmp / "fmu"
        sources = root / "sources"
        guid = codegen.write_sources(model, model_layout, sources)
        for file in RUNTIME_FILES:
            shutil.copy2(RUNTIME / file, sources / file)
        headers = fmi_headers()
        for file in FMI_HEADERS:
            shutil.copy2(headers / file, sources / file)
        source_files = sorted(p.name for p in sources.iterdir())
        version = metadata.version("rover-cosim")
        (root / "modelDescription.xml").write_text(
            description.model_description(model_layout, guid, source_files, _class_description(name), version,
                                          _default_experiment(name)))
        stages["generate"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        binaries = root / "binaries" / platform_folder()
        binaries.mkdir(parents=True)
        library = binaries / f"{name}{shared_library_suffix()}"
        c_files = [str(sources / f) for f in source_files if f.endswith(".c")]
        command = [compiler(), *CFLAGS, "-I", str(sources), *c_files,
                   "-o", str(library), "-lm"]
        result = subprocess.run(command, capture_output=True, text=True, check=False)
        if result.returncode != 0:
            raise RuntimeError(f"{name}: the C compiler failed ({' '.join(command[:1])}, exit {result.returncode}):\n"
                               + result.stderr[-4000:])
        stages["compile"] = time.perf_counter() - t0

        t0 = time.perf_counter()
        # Inputs the Modelica source gives a start value: a system may leave them unconnected.
        optional = [v for v in model.inputs if model.variables[v].start is not None]
        record = {"input_sha256": digest, "backend": "builtin", "model": f"{source.PACKAGE}.{name}",
                  "optional_inputs": optional,
                  "guid": guid, "rover_cosim": version,
                  "tools": {p: metadata.version(p) for p in ("rumoca", "casadi")}, "cflags": list(CFLAGS),
                  "states": model_layout.n_states, "inputs": model_layout.n_inputs,
                  "parameters": model_layout.n_parameters, "observed": model_layout.n_observed}
        (root / "documentation").mkdir()
        (root / BUILD_RECORD).write_text(json.dumps(record, indent=2) + "\n")
        (root / "documentation" / "index.html").write_text(
            description.documentation_html(model_layout, _class_description(name), _class_documentation(name)))
        out_dir.mkdir(parents=True, exist_ok=True)
        partial = out_dir / f".{name}.fmu.partial"
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as archive:
            for path in sorted(root.rglob("*")):
                if path.is_file():
                    archive.write(path, path.relative_to(root).as_posix())
        os.replace(partial, target)
        stages["package"] = time.perf_counter() - t0
    return BuildResult(name, target, True, time.perf_counter() - started, stages)


def _build_one(args: tuple[str, Path, bool, str]) -> BuildResult:
    name, out_dir, force, backend = args
    if backend == "omc":
        return build_fmu_omc(name, out_dir, force=force)
    return build_fmu(name, out_dir, force=force)


def resolve_backend(backend: str) -> str:
    """``auto`` → ``omc`` where OpenModelica's ``omc`` is on PATH, else ``builtin``."""
    if backend not in ("auto", "builtin", "omc"):
        raise ValueError(f"backend={backend!r}: expected auto, builtin or omc")
    if backend == "auto":
        return "omc" if shutil.which("omc") else "builtin"
    if backend == "omc" and not shutil.which("omc"):
        raise RuntimeError("backend omc: `omc` (OpenModelica) is not on PATH; use BACKEND=builtin")
    return backend


def build_all(names: Sequence[str] = FMU_MODELS, out_dir: Path = Path("fmus"), *, force: bool = False,
              jobs: int | None = None, backend: str = "builtin",
              report: Callable[[BuildResult], None] | None = None) -> list[BuildResult]:
    """Build several FMUs, ``jobs`` at a time (default: the number of CPUs). The first failure
    is raised after the other builds finished; FMUs already built stay."""
    unknown = [n for n in names if n not in FMU_MODELS]
    if unknown:
        raise ValueError(f"model {unknown[0]!r}: expected one of {', '.join(FMU_MODELS)}")
    backend = resolve_backend(backend)
    jobs = max(1, min(jobs or os.cpu_count() or 1, len(names)))
    tasks = [(n, Path(out_dir), force, backend) for n in names]
    results: list[BuildResult] = []
    errors: list[BaseException] = []
    if jobs == 1:
        for task in tasks:
            try:
                results.append(_build_one(task))
                if report:
                    report(results[-1])
            except Exception as error:  # noqa: BLE001 - reported after the others
                errors.append(error)
    else:
        # "spawn": a forked worker can deadlock on the locks of threads (rumoca's) in the parent.
        with ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn")) as pool:
            futures = [pool.submit(_build_one, task) for task in tasks]
            for future in futures:
                try:
                    results.append(future.result())
                    if report:
                        report(results[-1])
                except Exception as error:  # noqa: BLE001
                    errors.append(error)
    if errors:
        raise errors[0]
    return results
