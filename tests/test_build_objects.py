"""fmubuild.objects: an FMU's C files compiled one by one and linked, the runtime's objects shared by
the FMUs of one build (issue 49's build goal) — and never shared where their bits could differ."""

from __future__ import annotations

import ctypes
import shutil
import threading
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from rover_cosim.fmubuild import build, objects, platforms

pytestmark = pytest.mark.skipif(shutil.which(platforms.host_compiler()) is None, reason="no C compiler on PATH")

RUNTIME_C = '#include "api.h"\nint runtime_twice(int x) { return API_FACTOR * x; }\n'
HEADER = "#define API_FACTOR 2\n"


def _sources(folder: Path, model_value: int, header: str = HEADER) -> Path:
    """A tiny FMU-like sources folder: a shared runtime file, a header and generated model code."""
    folder.mkdir(parents=True)
    (folder / "api.h").write_text(header)
    (folder / "runtime.c").write_text(RUNTIME_C)
    (folder / "model_code.c").write_text('#include "api.h"\nint runtime_twice(int x);\n'
                                         f"int model_value(void) {{ return runtime_twice({model_value}); }}\n")
    (folder / "fmu_prefix.h").write_text(f"/* differs per FMU: {model_value} */\n")
    return folder


def _toolchain(*extra: str) -> objects.Toolchain:
    return objects.Toolchain((platforms.host_compiler(),), (*build.CFLAGS, *extra), ("-lm",), "host cc")


def _shared(tmp_path: Path) -> objects.SharedObjects:
    folder = tmp_path / "shared"
    folder.mkdir()
    return objects.SharedObjects(folder, frozenset({"runtime.c"}))


def _value(library: Path) -> int:
    function = ctypes.CDLL(str(library)).model_value  # -fvisibility=hidden: exported by default below
    function.restype = ctypes.c_int
    return int(function())


def test_two_fmus_share_the_runtime_object_and_each_links_its_own_model(tmp_path):
    toolchain = _toolchain("-fvisibility=default")
    shared = _shared(tmp_path)
    libraries = []
    for value in (3, 5):
        sources = _sources(tmp_path / f"fmu{value}" / "sources", value)
        library = tmp_path / f"fmu{value}" / "out" / f"model{value}.so"
        library.parent.mkdir()
        objects.compile_library(toolchain, sources, library, jobs=2, shared=shared)
        libraries.append(library)
    assert [_value(lib) for lib in libraries] == [6, 10]
    assert len(list(shared.folder.glob("*.o"))) == 1  # runtime.c once; the model code never shared
    assert not list((tmp_path / "fmu3" / "out" / "objects").glob("runtime*"))


def test_a_header_or_a_flag_that_changes_the_bits_gives_its_own_object(tmp_path):
    toolchain = _toolchain()
    shared = _shared(tmp_path)
    first = _sources(tmp_path / "a", 1)
    other_header = _sources(tmp_path / "b", 1, header="#define API_FACTOR 3\n")
    key = objects.object_key(toolchain, first, "runtime.c")
    assert objects.object_key(toolchain, other_header, "runtime.c") != key
    assert objects.object_key(_toolchain("-O1"), first, "runtime.c") != key
    # the per-FMU prefix header is read only with FMIx_FUNCTION_PREFIX defined: not part of the key
    (first / "fmu_prefix.h").write_text("/* another FMU */\n")
    assert objects.object_key(toolchain, first, "runtime.c") == key
    for sources in (first, other_header):
        objects.compile_object(toolchain, sources, "runtime.c", tmp_path / "own", shared)
    assert len(list(shared.folder.glob("*.o"))) == 2


def test_a_prefix_define_shares_nothing(tmp_path):
    toolchain = _toolchain("-DFMI2_FUNCTION_PREFIX=model_")
    shared = _shared(tmp_path)
    sources = _sources(tmp_path / "s", 1)
    made = objects.compile_object(toolchain, sources, "runtime.c", tmp_path / "own", shared)
    assert made.parent == tmp_path / "own" and not list(shared.folder.glob("*.o"))


def test_builds_asking_at_once_compile_a_shared_object_once(tmp_path, monkeypatch):
    toolchain = _toolchain()
    shared = _shared(tmp_path)
    folders = [_sources(tmp_path / f"s{i}", i) for i in range(4)]
    calls = []
    lock = threading.Lock()
    run = objects._run

    def counting(command, cwd, what):
        with lock:
            calls.append(what)
        run(command, cwd, what)

    monkeypatch.setattr(objects, "_run", counting)
    with ThreadPoolExecutor(4) as pool:
        made = list(pool.map(lambda s: objects.compile_object(toolchain, s, "runtime.c", s.parent / "own", shared),
                             folders))
    assert len(set(made)) == 1 and made[0].parent == shared.folder and len(calls) == 1


def test_a_compiler_error_names_the_file_and_leaves_no_object(tmp_path):
    toolchain = _toolchain()
    shared = _shared(tmp_path)
    sources = _sources(tmp_path / "s", 1)
    (sources / "runtime.c").write_text("int broken(void) { return }\n")
    library = tmp_path / "out" / "model.so"
    library.parent.mkdir()
    with pytest.raises(objects.CompileError, match="runtime.c") as error:
        objects.compile_library(toolchain, sources, library, jobs=2, shared=shared)
    assert "error" in str(error.value)
    assert list(shared.folder.iterdir()) == [next(shared.folder.glob("*.lock"))]  # the lock file only
    assert not library.exists()


@pytest.mark.fmu
def test_an_fmu_built_with_the_others_has_the_library_it_has_built_alone(fmus, tmp_path):
    """The session's FMUs come from build_all, which shares the runtime's objects between them
    (or were up to date from `make fmus`, which does the same): RoverBody's library is byte for byte
    the one build_fmu makes for it alone."""
    alone = build.build_fmu("RoverBody", tmp_path)
    assert alone.rebuilt
    member = f"binaries/{build.host_folder()}/RoverBody{build.shared_library_suffix()}"
    libraries = []
    for fmu in (fmus["RoverBody"], alone.path):
        with zipfile.ZipFile(fmu) as archive:
            libraries.append(archive.read(member))
    assert libraries[0] == libraries[1]
