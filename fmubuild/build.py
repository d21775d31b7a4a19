"""Build FMUs: Modelica class → (built-in backend) rumoca → CasADi → C → FMI 2.0 FMU in ``fmus/``,
with the binaries of the host (its C compiler) or of the platforms asked for (zig, see
:mod:`fmubuild.platforms`), compiled in parallel from the same sources.

The FMU is assembled in a temporary folder and moved into place with one rename, so a failed
build (an unsupported construct, a compiler error) leaves the output folder as it was. A build is
skipped when the FMU already there was made from the same inputs for the same platforms (the
digest of the Modelica package, this builder, the pinned tool versions and each platform's
compiler and flags is stored in ``documentation/build.json``).
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import multiprocessing
import os
import shutil
import subprocess
import tempfile
import threading
import time
import zipfile
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path
from typing import Any

from rover_cosim.common.scratch import cache_folder

from . import catalog, codegen, description, description3, objects, ode, prefix, source
from .artifact import (
    BUILD_RECORD,
    CFLAGS,
    RUNTIME,
    RUNTIME_FILES,
    RUNTIME_FILES_3,
    BuildResult,
    input_digest,
    stored_digest,
)
from .catalog import fmu_models
from .elementary import DEFAULT as ELEMENTARY_DEFAULT
from .elementary import HEADER as ELEMENTARY_HEADER
from .elementary import RUNTIME_CALLERS, use_own_elementary
from .elementary import check as check_elementary
from .omc import build_fmu_omc
from .platforms import HOST, PLATFORMS, ZIG_FLAGS, host_compiler, host_folder, host_suffix, zig_command, zig_version
from .platforms import parse as parse_platforms

#: The FMUs ``make fmus`` builds: the classes of the Modelica package's FMU sub-package
#: (:func:`source.fmu_class`), in its package.order (``catalog.fmu_models``).
FMU_MODELS = fmu_models()

FMI_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
FMI3_HEADERS = ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")
#: The C files the FMUs of one build_all share the objects of: the runtime's (fmubuild.objects).
SHARED_FILES = frozenset(f for f in (*RUNTIME_FILES, *RUNTIME_FILES_3) if f.endswith(".c"))

#: The FMI versions build_fmu writes: their runtime API layer and standard headers.
FMI_VERSIONS = {2: (RUNTIME_FILES, FMI_HEADERS), 3: (RUNTIME_FILES_3, FMI3_HEADERS)}

#: sources/buildDescription.xml (FMI 3.0 schema; FMI 2.0.4 section 2.3 lets an FMI 2.0 FMU carry
#: it): the files to compile, the optional FMI2_FUNCTION_PREFIX, and the C math library to link.
BUILD_DESCRIPTION = "buildDescription.xml"


def build_description(name: str, c_files: Sequence[str], fmi_version: int = 2) -> str:
    """The text of sources/buildDescription.xml for the FMU ``name`` compiled from ``c_files``
    (the optional FMI2_FUNCTION_PREFIX for an FMI 2.0 FMU)."""
    from xml.sax.saxutils import quoteattr

    files = "\n".join(f"      <SourceFile name={quoteattr(f)}/>" for f in c_files)
    how = "Compile the C99 files into one shared library, linking the C math library: cc -shared -fPIC sources/*.c -lm"
    prefix_use = "Prefix of every external name of the FMU, to compile several source FMUs into one program"
    libm = "The C math library (exp, log, pow, sin, cos, ...): -lm where the C library lacks it (Linux)"
    prefix_line = (f'      <PreprocessorDefinition name="FMI2_FUNCTION_PREFIX" optional="true" '
                   f'description={quoteattr(prefix_use)}/>\n') if fmi_version == 2 else ""
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiBuildDescription fmiVersion="3.0">
  <BuildConfiguration modelIdentifier={quoteattr(name)} description={quoteattr(how)}>
    <SourceFileSet language="C99">
{files}
{prefix_line}    </SourceFileSet>
    <Library name="m" external="true" description={quoteattr(libm)}/>
  </BuildConfiguration>
</fmiBuildDescription>
"""



def platform_folder() -> str:
    """The ``binaries/`` folder name of this platform (FMI 2.0 convention)."""
    return host_folder()


def shared_library_suffix() -> str:
    return host_suffix()


def fmi_headers() -> Path:
    """The FMI 2.0 standard headers, unmodified (BSD-2-Clause, meant to travel with FMUs), as PyPI's
    fmu-manipulation-toolbox ships them (the FMI 2.0.1 release). Not FMPy's copy: FMPy changed its
    fmi2Functions.h to ignore FMI2_FUNCTION_PREFIX. Not copied into this repository."""
    spec = importlib.util.find_spec("fmu_manipulation_toolbox")
    if spec is None or spec.origin is None:
        raise RuntimeError("the FMI 2.0 standard headers come from fmu-manipulation-toolbox: pip install "
                           "fmu-manipulation-toolbox (a dependency of rover-cosim)")
    folder = Path(spec.origin).parent / "resources" / "fmi"
    missing = [h for h in FMI_HEADERS if not (folder / h).exists()]
    if missing:
        raise RuntimeError(f"FMI 2.0 headers {missing} not found in {folder}")
    if "fmi2PasteB(FMI2_FUNCTION_PREFIX, name)" not in (folder / "fmi2Functions.h").read_text():
        raise RuntimeError(f"{folder / 'fmi2Functions.h'} is not the standard header (no FMI2_FUNCTION_PREFIX)")
    return folder


def _default_experiment(name: str) -> source.Experiment | None:
    """The class's ``experiment`` annotation, for the model description's DefaultExperiment."""
    try:
        return source.experiment(source.fmu_class(name))
    except ValueError:
        return None


def _class_documentation(name: str) -> str:
    """The Documentation info (HTML) of the class ``name`` and of the records it uses, from our
    own Modelica files ("" where a class has none)."""
    import re

    parts = []
    for qualified in (source.fmu_class(name), f"{catalog.PACKAGE}.Parameters.SoilParameters",
                      f"{catalog.PACKAGE}.Parameters.WheelParameters"):
        text = source.class_file(qualified).read_text()
        found = re.search(r'info="(.*?)"\)', text, re.S)
        if found:
            inner = re.sub(r"</?html>", "", found.group(1)).replace('\\"', '"')
            parts.append(f"<h3>{qualified.rsplit('.', 1)[-1]}</h3>{inner}")
    return "\n".join(parts)


def _class_description(name: str) -> str:
    text = source.class_file(source.fmu_class(name)).read_text()
    head = text.split("\n", 3)
    for line in head:
        if line.strip().startswith(("model ", "block ")) and '"' in line:
            return line.split('"')[1]
    return name


def compiler() -> str:
    return host_compiler()


@dataclass(frozen=True)
class Target:
    """How one ``binaries/`` folder is compiled."""

    folder: str
    command: tuple[str, ...]   # the compiler (with its -target)
    flags: tuple[str, ...]
    libraries: tuple[str, ...]
    suffix: str
    compiler: str              # name and version, for the record and the digest

    def record(self) -> dict[str, object]:
        target = self.command[-1] if "-target" in self.command else "host"
        return {"compiler": self.compiler, "target": target, "cflags": list(self.flags),
                "libraries": list(self.libraries)}


def targets(platforms: Sequence[str]) -> list[Target]:
    """The targets of ``platforms`` (names as :func:`platforms.parse` takes them; ValueError names
    an unknown one)."""
    result = []
    for name in parse_platforms(",".join(platforms)):
        if name == HOST:
            cc = compiler()
            version = subprocess.run([cc, "--version"], capture_output=True, text=True, check=False).stdout
            result.append(Target(platform_folder(), (cc,), CFLAGS, ("-lm",), shared_library_suffix(),
                                 (version.splitlines() or [cc])[0]))
            continue
        spec = PLATFORMS[name]
        libraries = ("-lm",) if spec.system == "linux" else ()
        result.append(Target(name, (*zig_command(), "-target", spec.target), (*CFLAGS, *ZIG_FLAGS), libraries,
                             spec.suffix, f"zig cc {zig_version()} (PyPI ziglang)"))
    return result


def platforms_digest(name: str, chosen: Sequence[Target]) -> str:
    """What decides whether an FMU is up to date: its inputs and, per binaries folder, the compiler
    and its flags."""
    key = [(t.folder, t.command[-1], t.flags, t.libraries, t.compiler) for t in chosen]
    return hashlib.sha256((input_digest(name) + json.dumps(key)).encode()).hexdigest()


def _compile(name: str, target: Target, sources: Path, work: Path, jobs: int,
             shared: objects.SharedObjects | None) -> tuple[Path, float]:
    """Compile the C files of ``sources`` into ``work``/<folder>/<name><suffix>, ``jobs`` compilers
    at a time; returns the library and the seconds."""
    out = work / target.folder
    out.mkdir(parents=True)
    library = out / f"{name}{target.suffix}"
    toolchain = objects.Toolchain(target.command, target.flags, target.libraries, target.compiler)
    try:
        seconds = objects.compile_library(toolchain, sources, library, jobs, shared)
    except objects.CompileError as error:
        raise RuntimeError(f"{name}: {error.what} for {target.folder} ({target.compiler}, exit {error.returncode}):"
                           f"\n{error.output}") from None
    return library, seconds


#: A build's progress: called with the FMU's name and the stage just finished ("translate",
#: "generate", "compile <folder>", "package"); see :func:`steps_of`.
StepReport = Callable[[str, str], None]


def steps_of(platforms: Sequence[str]) -> int:
    """Stages one FMU's build reports: translate, generate, one compile per platform, package."""
    return 3 + len(targets(platforms))


def compile_targets(name: str, chosen: Sequence[Target], sources: Path, binaries: Path, work: Path,
                    jobs: int | None = None, step: StepReport | None = None,
                    shared: objects.SharedObjects | None = None) -> dict[str, float]:
    """Compile the sources for every target, ``jobs`` compilers at a time (default: one per CPU;
    the targets in parallel, and each target's files), into ``binaries``/<folder>/; returns the
    seconds per folder. The first failure is raised after the other compilers finished. ``step``
    hears of each target that finished; ``shared``: the runtime's objects shared with the other
    FMUs of a build (:mod:`fmubuild.objects`)."""
    jobs = max(1, jobs or os.cpu_count() or 1)
    workers = min(jobs, len(chosen))

    def compile_one(target: Target) -> tuple[Path, float]:
        done = _compile(name, target, sources, work, max(1, jobs // workers), shared)
        if step:
            step(name, f"compile {target.folder}")
        return done

    with ThreadPoolExecutor(max_workers=workers) as pool:
        futures = {t.folder: pool.submit(compile_one, t) for t in chosen}
    seconds: dict[str, float] = {}
    for folder, future in futures.items():
        library, took = future.result()
        (binaries / folder).mkdir(parents=True)
        shutil.copy2(library, binaries / folder / library.name)
        seconds[folder] = took
    return seconds


@contextmanager
def _one_build_at_a_time(lock: Path) -> Iterator[None]:
    """Hold the advisory lock file ``lock`` (created where missing, in the temporary folder: the FMUs'
    folder holds FMUs only): another process building the same FMU into the same folder (a second
    `make fmus`, a parallel test worker) waits, then finds it up to date. Where the platform has no
    ``fcntl`` (Windows) builds are not serialised; each FMU still appears whole (written to a partial
    file, then renamed)."""
    try:
        import fcntl
    except ImportError:
        yield
        return
    lock.parent.mkdir(parents=True, exist_ok=True)
    with open(lock, "a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def build_fmu(name: str, out_dir: Path, *, force: bool = False, platforms: Sequence[str] = (HOST,),
              compile_jobs: int | None = None, step: StepReport | None = None, fmi_version: int = 2,
              axles: int | None = None, elementary: str = ELEMENTARY_DEFAULT,
              shared_objects: objects.SharedObjects | None = None) -> BuildResult:
    """Build ``out_dir/<name>.fmu`` with the built-in backend (skipped when up to date) with binaries
    for ``platforms`` (``host``: this machine's, by its C compiler; other names: cross-compiled by
    zig, see :mod:`fmubuild.platforms`), ``compile_jobs`` compilers at a time; ``step`` hears of
    each stage as it ends. ``fmi_version`` 3: an FMI 3.0 FMU of the same model code (the runtime's
    FMI 3.0 layer, the FMI 3.0 model description and platform folders). ``axles``: a rover FMU
    built for that many wheels per side (:func:`source.variant_source`; None: the package's own).
    ``elementary``: ``libm`` (the C library's exp, log, sin, ...) or ``own`` (runtime/elementary.h's:
    the same bits on every host; :mod:`fmubuild.elementary`). ``shared_objects``: the runtime's
    objects shared with the other FMUs of a build (:mod:`fmubuild.objects`). One process at a time
    builds a given FMU into a given folder (``_one_build_at_a_time``)."""
    folder = hashlib.sha256(str(Path(out_dir).resolve()).encode()).hexdigest()[:16]
    with _one_build_at_a_time(Path(tempfile.gettempdir()) / "rover-cosim-build-locks" / f"{folder}-{name}.lock"):
        return _build_fmu(name, Path(out_dir), force=force, platforms=platforms, compile_jobs=compile_jobs,
                          step=step, fmi_version=fmi_version, axles=axles,
                          elementary=check_elementary(elementary), shared=shared_objects)


def _build_fmu(name: str, out_dir: Path, *, force: bool, platforms: Sequence[str], compile_jobs: int | None,
               step: StepReport | None, fmi_version: int, axles: int | None, elementary: str,
               shared: objects.SharedObjects | None) -> BuildResult:
    """build_fmu, the lock held."""
    _check_version(fmi_version)
    if axles is not None:
        source.variant_source(name, axles)  # a clear error for a model or count it cannot take
    variant = "" if axles is None or axles == source.DEFAULT_AXLES else f"-axles{axles}"
    started = time.perf_counter()
    out_dir = Path(out_dir)
    target = out_dir / f"{name}.fmu"
    chosen = targets(platforms)
    digest = (platforms_digest(name, chosen) + ("" if fmi_version == 2 else f"-fmi{fmi_version}") + variant
              + ("" if elementary == ELEMENTARY_DEFAULT else f"-elementary-{elementary}"))
    if not force and target.exists() and stored_digest(target) == digest:
        return BuildResult(name, target, False, time.perf_counter() - started)
    stages: dict[str, float] = {}
    with tempfile.TemporaryDirectory(prefix=f"fmubuild-{name}-") as tmp_name:
        tmp = Path(tmp_name)
        t0 = time.perf_counter()
        loaded = source.load_variant(name, axles) if variant and axles else source.load(source.fmu_class(name))
        model = ode.translate(loaded, name)
        model_layout = codegen.layout(model)
        stages["translate"] = time.perf_counter() - t0
        if step:
            step(name, "translate")

        t0 = time.perf_counter()
        root = tmp / "fmu"
        sources = root / "sources"
        version = metadata.version("rover-cosim")
        guid = _generate(name, model, model_layout, root, fmi_version, version, elementary)
        stages["generate"] = time.perf_counter() - t0
        if step:
            step(name, "generate")

        t0 = time.perf_counter()
        seconds = compile_targets(name, chosen, sources, root / "binaries", tmp / "compile", compile_jobs, step,
                                  shared)
        if fmi_version == 3:  # the FMI 3.0 platform tuples (x86_64-linux, ...) name the folders
            for folder in seconds:
                (root / "binaries" / folder).rename(root / "binaries" / fmi3_folder(folder))
        stages["compile"] = time.perf_counter() - t0
        stages.update({f"compile {folder}": s for folder, s in seconds.items()})

        t0 = time.perf_counter()
        # Inputs the Modelica source gives a start value: a system may leave them unconnected.
        optional = [v for v in model.inputs if model.variables[v].start is not None]
        host = [t for t in chosen if "-target" not in t.command]
        record = {"input_sha256": digest, "backend": "builtin", "model": source.fmu_class(name),
                  **({"structural": {"rover.nAxles": axles}, "variant_source": source.variant_source(name, axles)}
                     if variant and axles is not None else {}),
                  "optional_inputs": optional,
                  "guid": guid, "rover_cosim": version,
                  "tools": {p: metadata.version(p) for p in ("rumoca", "casadi")},
                  "cflags": list(host[0].flags if host else CFLAGS),
                  "fmi_version": fmi_version,
                  "elementary": elementary,
                  "platforms": {folder: {**t.record(), "library": f"binaries/{folder}/{name}{t.suffix}"}
                                for t in chosen
                                for folder in [t.folder if fmi_version == 2 else fmi3_folder(t.folder)]},
                  "states": model_layout.n_states, "inputs": model_layout.n_inputs,
                  "parameters": model_layout.n_parameters, "observed": model_layout.n_observed}
        (root / "documentation").mkdir()
        (root / BUILD_RECORD).write_text(json.dumps(record, indent=2) + "\n")
        (root / "documentation" / "index.html").write_text(
            description.documentation_html(model_layout, _class_description(name), _class_documentation(name),
                                           fmi_version))
        out_dir.mkdir(parents=True, exist_ok=True)
        partial = out_dir / f".{name}.fmu.partial"
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as archive:
            for path in sorted(root.rglob("*")):
                if path.is_file():
                    archive.write(path, path.relative_to(root).as_posix())
        os.replace(partial, target)
        stages["package"] = time.perf_counter() - t0
    if step:
        step(name, "package")
    return BuildResult(name, target, True, time.perf_counter() - started, stages)


def _check_version(fmi_version: int, backend: str = "builtin") -> None:
    if fmi_version not in FMI_VERSIONS:
        raise ValueError(f"FMI version {fmi_version!r}: expected one of {', '.join(map(str, FMI_VERSIONS))}")
    if fmi_version != 2 and backend == "omc":
        raise ValueError("FMI 3.0: the built-in backend only (--backend builtin)")


def _generate(name: str, model: ode.OdeModel, model_layout: codegen.ModelLayout, root: Path, fmi_version: int,
              version: str, elementary: str = ELEMENTARY_DEFAULT) -> str:
    """The FMU's sources (generated C, the runtime, the standard headers, the prefix header and the
    build description) and its modelDescription.xml in ``root``; returns the GUID (FMI 3.0: the
    instantiation token). ``elementary`` ``own``: the generated C and the runtime call
    runtime/elementary.h's functions, which the sources then hold."""
    runtime_files, headers_wanted = FMI_VERSIONS[fmi_version]
    sources = root / "sources"
    own = elementary == "own"
    guid = codegen.write_sources(model, model_layout, sources, own_elementary=own)
    for file in runtime_files:
        if own and file in RUNTIME_CALLERS:
            (sources / file).write_text(use_own_elementary((RUNTIME / file).read_text()))
        else:
            shutil.copy2(RUNTIME / file, sources / file)
    if own:
        shutil.copy2(RUNTIME / ELEMENTARY_HEADER, sources / ELEMENTARY_HEADER)
    headers = fmi_headers()
    for file in headers_wanted:
        shutil.copy2(headers / file, sources / file)
    c_texts = [p.read_text() for p in sorted(sources.glob("*.c"))]
    (sources / prefix.HEADER).write_text(prefix.prefix_header(prefix.external_names(c_texts)))
    (sources / BUILD_DESCRIPTION).write_text(build_description(name, sorted(p.name for p in sources.glob("*.c")),
                                                               fmi_version))
    source_files = sorted(p.name for p in sources.iterdir() if p.name != BUILD_DESCRIPTION)
    if fmi_version == 2:
        text = description.model_description(model_layout, guid, source_files, _class_description(name), version,
                                             _default_experiment(name))
    else:
        text = description3.model_description(model_layout, guid, _class_description(name), version,
                                              _default_experiment(name))
    (root / "modelDescription.xml").write_text(text)
    return guid


def fmi3_folder(folder: str) -> str:
    """The FMI 3.0 binaries folder of an FMI 2.0 one (``linux64`` -> ``x86_64-linux``)."""
    return PLATFORMS[folder].fmi3 if folder in PLATFORMS else folder


@dataclass(frozen=True)
class _BuildTask:
    """One FMU of build_all, as a pool's worker gets it."""

    name: str
    out_dir: Path
    force: bool
    backend: str
    platforms: tuple[str, ...]
    compile_jobs: int
    steps: Any          # a queue of the parent's (or _LocalSteps), or None
    fmi_version: int
    elementary: str
    shared: objects.SharedObjects | None


def _build_one(task: _BuildTask) -> BuildResult:
    """One FMU (in a pool's worker): its stages go to ``task.steps``."""
    if task.backend == "omc":
        return build_fmu_omc(task.name, task.out_dir, force=task.force)
    steps = task.steps
    step = (lambda fmu, stage: steps.put((fmu, stage))) if steps is not None else None
    return build_fmu(task.name, task.out_dir, force=task.force, platforms=task.platforms,
                     compile_jobs=task.compile_jobs, step=step, fmi_version=task.fmi_version,
                     elementary=task.elementary, shared_objects=task.shared)


class _LocalSteps:
    """A queue's ``put`` for builds in this process: the stage goes straight to ``step``."""

    def __init__(self, step: StepReport):
        self.step = step

    def put(self, item: tuple[str, str]) -> None:
        self.step(*item)


def _forward_steps(stack: ExitStack, context: Any, step: StepReport) -> Any:
    """A queue the pool's workers put their stages on, and a thread here that hands them to
    ``step`` until the stack closes."""
    manager = stack.enter_context(context.Manager())
    queue = manager.Queue()

    def forward() -> None:
        while (item := queue.get()) is not None:
            step(*item)

    thread = threading.Thread(target=forward, daemon=True)
    thread.start()
    stack.callback(thread.join)
    stack.callback(queue.put, None)
    return queue


def resolve_backend(backend: str) -> str:
    """``auto`` → ``omc`` where OpenModelica's ``omc`` is on PATH, else ``builtin``."""
    if backend not in ("auto", "builtin", "omc"):
        raise ValueError(f"backend={backend!r}: expected auto, builtin or omc")
    if backend == "auto":
        return "omc" if shutil.which("omc") else "builtin"
    if backend == "omc" and not shutil.which("omc"):
        raise RuntimeError("backend omc: `omc` (OpenModelica) is not on PATH; use BACKEND=builtin")
    return backend


def _check_platforms(backend: str, platforms: tuple[str, ...]) -> tuple[str, ...]:
    """``platforms`` if ``backend`` can build them and their compilers are there (said before any work)."""
    if backend == "omc" and platforms != (HOST,):
        raise ValueError(f"--platforms {','.join(platforms)}: the omc backend builds the host platform only "
                         "(use --backend builtin)")
    targets(platforms)
    return platforms


def _check_request(names: Sequence[str], backend: str, platforms: tuple[str, ...], fmi_version: int,
                   elementary: str) -> tuple[str, tuple[str, ...]]:
    """build_all's backend (``auto`` resolved) and platforms, once every choice was checked."""
    unknown = [n for n in names if n not in FMU_MODELS]
    if unknown:
        raise ValueError(f"model {unknown[0]!r}: expected one of {', '.join(FMU_MODELS)}")
    backend = resolve_backend(backend)
    _check_version(fmi_version, backend)
    check_elementary(elementary)
    if backend == "omc" and elementary != ELEMENTARY_DEFAULT:
        raise ValueError(f"--elementary {elementary}: the built-in backend only (--backend builtin)")
    return backend, _check_platforms(backend, platforms)


#: How long each FMU took to build on this machine the last time (seconds by name), in the user's
#: cache folder: build_all starts the longest builds first (longest processing time first), so
#: that the largest is not the last one started. Names not built here yet keep their order, first.
BUILD_SECONDS = "build-seconds.json"


def _build_seconds() -> dict[str, float]:
    try:
        found = json.loads((cache_folder() / BUILD_SECONDS).read_text())
    except (OSError, ValueError):
        return {}
    if not isinstance(found, dict):
        return {}
    return {str(k): float(v) for k, v in found.items() if isinstance(v, (int, float))}


def _remember_build_seconds(results: Sequence[BuildResult]) -> None:
    """Add the FMUs just built (not those up to date) to BUILD_SECONDS; a cache that cannot be
    written changes nothing."""
    built = {r.name: round(r.seconds, 3) for r in results if r.rebuilt}
    if not built:
        return
    target = cache_folder() / BUILD_SECONDS
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=target.parent, prefix=".build-seconds-", delete=False) as out:
            json.dump({**_build_seconds(), **built}, out, indent=1, sort_keys=True)
        os.replace(out.name, target)
    except OSError:
        pass


def build_order(names: Sequence[str], seconds: dict[str, float]) -> list[str]:
    """``names`` in the order to start their builds: those without a time first, as given, then
    the others by their time, longest first."""
    unknown = [n for n in names if n not in seconds]
    return unknown + sorted((n for n in names if n in seconds), key=lambda n: -seconds[n])


def build_all(names: Sequence[str] = FMU_MODELS, out_dir: Path = Path("fmus"), *, force: bool = False,
              jobs: int | None = None, backend: str = "builtin", platforms: Sequence[str] = (HOST,),
              report: Callable[[BuildResult], None] | None = None,
              step: StepReport | None = None, fmi_version: int = 2,
              elementary: str = ELEMENTARY_DEFAULT) -> list[BuildResult]:
    """Build several FMUs, ``jobs`` at a time (default: the number of CPUs; the longest builds of
    the last time started first, BUILD_SECONDS), each with binaries for ``platforms`` (see
    :func:`build_fmu`; the CPUs left to each build compile its platforms in parallel). The first
    failure is raised after the other builds finished; FMUs already built stay.
    ``report`` hears of each FMU built or up to date, ``step`` of each stage of a build as it ends
    (from the workers, through a queue)."""
    backend, platforms = _check_request(names, backend, tuple(platforms), fmi_version, elementary)
    cpus = os.cpu_count() or 1
    jobs = max(1, min(jobs or cpus, len(names)))
    compile_jobs = max(1, cpus // jobs)
    results: list[BuildResult] = []
    errors: list[BaseException] = []
    with ExitStack() as stack:
        folder = stack.enter_context(tempfile.TemporaryDirectory(prefix="fmubuild-objects-"))
        shared = objects.SharedObjects(Path(folder), SHARED_FILES)

        def task(name: str, steps: Any) -> _BuildTask:
            return _BuildTask(name, Path(out_dir), force, backend, platforms, compile_jobs, steps, fmi_version,
                              elementary, shared)

        if jobs == 1:
            local = _LocalSteps(step) if step else None
            for name in names:
                try:
                    results.append(_build_one(task(name, local)))
                    if report:
                        report(results[-1])
                except Exception as error:  # noqa: BLE001 - reported after the others
                    errors.append(error)
        else:
            # "spawn": a forked worker can deadlock on the locks of threads (rumoca's) in the parent.
            context = multiprocessing.get_context("spawn")
            steps = _forward_steps(stack, context, step) if step else None
            pool = stack.enter_context(ProcessPoolExecutor(max_workers=jobs, mp_context=context))
            futures = {n: pool.submit(_build_one, task(n, steps)) for n in build_order(names, _build_seconds())}
            for future in (futures[n] for n in names):  # reported in the order asked
                try:
                    results.append(future.result())
                    if report:
                        report(results[-1])
                except Exception as error:  # noqa: BLE001
                    errors.append(error)
    _remember_build_seconds(results)
    if errors:
        raise errors[0]
    return results
