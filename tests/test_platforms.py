"""FMUs for every host (issue 31, parts 2 and 5): Wheel built with ``--platforms all`` carries
binaries for linux64 (glibc 2.17), win64, darwin64, aarch64-linux and aarch64-darwin, all compiled
from the same generated C by zig's C compiler (PyPI ``ziglang``).

A small FMI 2.0 importer of our own (tests/importer/fmi2_importer.c, compiled for each target by
zig) runs one Co-Simulation scenario on the linux64 binary natively, on the aarch64-linux binary
under qemu-user and on the win64 binary under wine, and the printed values (%.17g) are compared.
The macOS binaries cannot run here (no macOS, no Darwin emulator): they are checked for their
Mach-O header (architecture, dynamic library) and their exported fmi2 functions.

Each test skips, naming what it lacks, where zig, wine64, qemu-aarch64 or the aarch64 C library
(Debian ``libc6-arm64-cross``) is missing; ``.ci/system-packages`` installs them for CI.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from collections.abc import Sequence
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy.validation import validate_fmu

from rover_cosim.fmubuild import build, platforms, prefix

IMPORTER = Path(__file__).with_name("importer") / "fmi2_importer.c"
AARCH64_SYSROOT = Path("/usr/aarch64-linux-gnu")

#: Every function an FMI 2.0 ME + CS binary exports.
FMI2_FUNCTIONS = frozenset("fmi2" + name for name in (
    "GetTypesPlatform GetVersion SetDebugLogging Instantiate FreeInstance SetupExperiment "
    "EnterInitializationMode ExitInitializationMode Terminate Reset GetReal GetInteger GetBoolean GetString "
    "SetReal SetInteger SetBoolean SetString GetFMUstate SetFMUstate FreeFMUstate SerializedFMUstateSize "
    "SerializeFMUstate DeSerializeFMUstate GetDirectionalDerivative EnterEventMode NewDiscreteStates "
    "EnterContinuousTimeMode CompletedIntegratorStep SetTime SetContinuousStates GetDerivatives "
    "GetEventIndicators GetContinuousStates GetNominalsOfContinuousStates SetRealInputDerivatives "
    "GetRealOutputDerivatives DoStep CancelStep GetStatus GetRealStatus GetIntegerStatus GetBooleanStatus "
    "GetStringStatus").split())

#: The scenario: a wheel under 424 N rolling at 0.5 m/s, a torque step 20 -> 80 N m at 1 s, a
#: lateral velocity from 1.5 s; 200 steps of 10 ms.
STEPS, STEP_SIZE = 200, 0.01
PARAMETERS = {"W": 424.0, "v_hub": 0.5, "tau": 20.0}
CHANGES = ((100, "tau", 80.0), (150, "v_lat", 0.05))
OUTPUTS = ("omega", "slip", "sinkage", "Fx", "Fz", "Tx", "Fy")


def zig_or_skip() -> list[str]:
    if importlib.util.find_spec("ziglang") is None:
        pytest.skip("zig's C compiler is not installed (pip install -e '.[platforms]')")
    return [sys.executable, "-m", "ziglang", "cc"]


def wine_or_skip() -> str:
    for candidate in (shutil.which("wine64"), shutil.which("wine"), "/usr/lib/wine/wine64"):
        if candidate and Path(candidate).is_file():
            return candidate
    pytest.skip("wine is not installed (Debian package wine64)")


def qemu_or_skip() -> str:
    qemu = shutil.which("qemu-aarch64")
    if qemu is None:
        pytest.skip("qemu-aarch64 is not installed (Debian package qemu-user)")
    if not (AARCH64_SYSROOT / "lib" / "ld-linux-aarch64.so.1").exists():
        pytest.skip(f"no aarch64 C library in {AARCH64_SYSROOT} (Debian package libc6-arm64-cross)")
    return qemu


@pytest.fixture(scope="module")
def wheel_all(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Wheel.fmu built with --platforms all, unpacked (the FMU beside the folder)."""
    zig_or_skip()
    out = tmp_path_factory.mktemp("all")
    result = build.build_fmu("Wheel", out, platforms=platforms.ALL)
    folder = out / "Wheel"
    fmpy.extract(str(result.path), str(folder))
    return folder


@pytest.fixture(scope="module")
def wheel_host(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Wheel.fmu built for the host by its C compiler (the default), unpacked."""
    out = tmp_path_factory.mktemp("host")
    result = build.build_fmu("Wheel", out)
    folder = out / "Wheel"
    fmpy.extract(str(result.path), str(folder))
    return folder


def compile_importer(target: str, folder: Path, headers: Path) -> Path:
    """tests/importer/fmi2_importer.c compiled by zig for ``target`` into ``folder``."""
    suffix = ".exe" if "windows" in target else ""
    program = folder / f"fmi2_importer-{target}{suffix}"
    if not program.exists():
        libraries = ["-ldl"] if "linux" in target else []
        subprocess.run([*zig_or_skip(), "-target", target, "-O1", "-g0", "-std=c99", "-D_POSIX_C_SOURCE=200809L",
                        "-I", str(headers), str(IMPORTER), "-o", str(program), *libraries],
                       check=True, capture_output=True, text=True, cwd=folder)
    return program


def scenario(folder: Path, extra: dict[str, float] | None = None) -> list[str]:
    """The importer's arguments after the library: GUID, prefix, steps, step size, commands
    (``extra``: values set besides PARAMETERS)."""
    md = fmpy.read_model_description(str(folder))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    commands = [word for name, value in (PARAMETERS | (extra or {})).items()
                for word in ("set", str(refs[name]), repr(value))]
    commands += [word for step, name, value in CHANGES for word in ("at", str(step), str(refs[name]), repr(value))]
    commands += [word for name in OUTPUTS for word in ("out", str(refs[name]))]
    return [md.guid, "-", str(STEPS), repr(STEP_SIZE), *commands]


def run(command: Sequence[str], cwd: Path, env: dict[str, str] | None = None) -> np.ndarray:
    """The importer's table (time, then OUTPUTS per step); fails with its messages."""
    done = subprocess.run(list(command), capture_output=True, text=True, cwd=cwd, env=env, check=False, timeout=600)
    assert done.returncode == 0, f"{' '.join(command[:3])}: exit {done.returncode}\n{done.stderr[-2000:]}"
    table = np.array([[float(v) for v in line.split()] for line in done.stdout.splitlines()])
    assert table.shape == (STEPS, 1 + len(OUTPUTS))
    return table


@pytest.fixture(scope="module")
def linux64_run(wheel_all: Path) -> np.ndarray:
    importer = compile_importer("x86_64-linux-gnu.2.17", wheel_all, wheel_all / "sources")
    return run([str(importer), str(wheel_all / "binaries" / "linux64" / "Wheel.so"), *scenario(wheel_all)], wheel_all)


# --- the build ----------------------------------------------------------------------------------

def test_every_platform_is_in_the_fmu_and_its_build_record(wheel_all: Path):
    for name in platforms.ALL:
        spec = platforms.PLATFORMS[name]
        assert (wheel_all / "binaries" / name / f"Wheel{spec.suffix}").is_file(), name
    record = json.loads((wheel_all / build.BUILD_RECORD).read_text())
    assert list(record["platforms"]) == list(platforms.ALL)
    for name, entry in record["platforms"].items():
        assert entry["target"] == platforms.PLATFORMS[name].target
        assert entry["compiler"].startswith("zig cc ") and "-ffp-contract=off" in entry["cflags"]
    assert set(fmpy.supported_platforms(str(wheel_all))) >= {"linux64", "win64", "darwin64", "c-code"}
    assert validate_fmu(str(wheel_all.parent / "Wheel.fmu")) == []


def test_the_up_to_date_check_accounts_for_the_platforms(wheel_all: Path, tmp_path: Path):
    all_targets, host_targets = build.targets(platforms.ALL), build.targets((platforms.HOST,))
    assert build.platforms_digest("Wheel", all_targets) != build.platforms_digest("Wheel", host_targets)
    assert build.platforms_digest("Wheel", all_targets) != build.platforms_digest("Wheel", all_targets[:-1])
    fmu = wheel_all.parent / "Wheel.fmu"
    before = fmu.stat().st_mtime_ns
    again = build.build_fmu("Wheel", wheel_all.parent, platforms=platforms.ALL)
    assert not again.rebuilt and fmu.stat().st_mtime_ns == before


def test_an_unknown_platform_is_named_with_the_allowed_ones():
    with pytest.raises(ValueError, match=r"unknown platform 'win32'; expected host, all or .*linux64, win64"):
        platforms.parse("linux64,win32")
    assert platforms.parse("all,win64") == platforms.ALL
    assert platforms.parse("host") == ("host",)
    with pytest.raises(ValueError, match="the same folder"):
        platforms.parse(f"host,{platforms.host_folder()}")
    with pytest.raises(ValueError, match="unknown platform 'x86_64-linux'"):
        build.build_fmu("Wheel", Path("never-written"), platforms=("x86_64-linux",))
    assert not Path("never-written").exists()


def test_cli_refuses_an_unknown_platform_in_one_line(tmp_path: Path):
    done = subprocess.run([sys.executable, "-P", "-m", "rover_cosim", "build-fmus", "--out", str(tmp_path),
                           "--platforms", "linux64,beos", "Wheel"], capture_output=True, text=True, check=False)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "rover-cosim build-fmus: --platforms: unknown platform 'beos'; expected host, all or a comma-separated "
        "list of host, linux64, win64, darwin64, aarch64-linux, aarch64-darwin"]
    assert not list(tmp_path.iterdir())


# --- linux64: glibc 2.17, and the same results as the host build ---------------------------------

def glibc_versions(library: Path) -> list[tuple[int, ...]]:
    text = subprocess.run(["readelf", "--dyn-syms", "-W", str(library)], capture_output=True, text=True,
                          check=True).stdout
    return sorted({tuple(int(p) for p in v.split(".")) for v in re.findall(r"@GLIBC_([0-9.]+)", text)})


@pytest.mark.skipif(shutil.which("readelf") is None, reason="readelf (binutils) not on PATH")
def test_linux_binaries_need_glibc_2_17_at_most_and_link_libm(wheel_all: Path):
    for name in ("linux64", "aarch64-linux"):
        library = wheel_all / "binaries" / name / "Wheel.so"
        versions = glibc_versions(library)
        assert versions and max(versions) <= (2, 17), f"{name} needs GLIBC_{'.'.join(map(str, max(versions)))}"
        dynamic = subprocess.run(["readelf", "-d", str(library)], capture_output=True, text=True, check=True).stdout
        assert "[libm.so.6]" in dynamic, name


def test_linux64_agrees_bit_for_bit_with_the_host_build(wheel_all: Path, wheel_host: Path, linux64_run: np.ndarray):
    """zig's glibc-2.17 build and gcc's host build (-O2 both, no FMA on x86-64) give equal bits."""
    if platforms.host_folder() != "linux64":
        pytest.skip("the host is not linux64")
    importer = compile_importer("x86_64-linux-gnu.2.17", wheel_all, wheel_all / "sources")
    host = run([str(importer), str(wheel_host / "binaries" / "linux64" / "Wheel.so"), *scenario(wheel_host)],
               wheel_host)
    np.testing.assert_array_equal(host, linux64_run)
    assert np.all(np.isfinite(host)) and host[-1, 1 + OUTPUTS.index("Fx")] > 100


# --- the foreign binaries, run ------------------------------------------------------------------

def test_aarch64_linux_under_qemu_agrees_bit_for_bit_with_linux64(wheel_all: Path, linux64_run: np.ndarray):
    """aarch64 is built with -ffp-contract=off (no fused multiply-add), and glibc's libm gives the
    same bits on both machines for what the wheel calls: the results are equal, not just close."""
    qemu = qemu_or_skip()
    importer = compile_importer("aarch64-linux-gnu.2.17", wheel_all, wheel_all / "sources")
    table = run([qemu, "-L", str(AARCH64_SYSROOT), str(importer),
                 str(wheel_all / "binaries" / "aarch64-linux" / "Wheel.so"), *scenario(wheel_all)], wheel_all)
    np.testing.assert_array_equal(table, linux64_run)


def test_win64_under_wine_agrees_with_linux64(wheel_all: Path, linux64_run: np.ndarray, tmp_path: Path):
    """Tolerance 1e-12 relative (plus 1e-12 absolute for values crossing zero), not bit equality:
    the Windows build calls the Universal C Runtime's exp, log, pow, atan2, ... (under wine, wine's
    ucrtbase), which round differently from glibc's in the last bit now and then; the sinkage
    Newton solve and the integrator carry that on. Measured: at most 5e-14 relative."""
    wine = wine_or_skip()
    folder = tmp_path / "win64"
    folder.mkdir()
    shutil.copy2(wheel_all / "binaries" / "win64" / "Wheel.dll", folder / "Wheel.dll")
    importer = compile_importer("x86_64-windows-gnu", folder, wheel_all / "sources")
    env = {**os.environ, "WINEPREFIX": str(tmp_path / "wineprefix"), "WINEDEBUG": "-all"}
    table = run([wine, importer.name, "Wheel.dll", *scenario(wheel_all)], folder, env)
    np.testing.assert_allclose(table, linux64_run, rtol=1e-12, atol=1e-12)


# --- the FMUs' own elementary functions: the same bits on every host ------------------------------

#: The targets an own-elementary Wheel is built for here (the ones that can run here).
OWN_TARGETS = ("linux64", "win64", "aarch64-linux")


@pytest.fixture(scope="module")
def wheel_own(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Wheel.fmu built with --elementary own for OWN_TARGETS, unpacked."""
    zig_or_skip()
    out = tmp_path_factory.mktemp("own")
    result = build.build_fmu("Wheel", out, platforms=OWN_TARGETS, elementary="own")
    folder = out / "Wheel"
    fmpy.extract(str(result.path), str(folder))
    return folder


#: A wheel in a rut: its contact is CasADi's node-by-node code (runtime/contact.h covers the wheel
#: without one), where the elementary functions are called per node.
IN_A_RUT = {"rutDepth": 0.005}


def test_with_its_own_elementary_functions_every_host_gives_the_same_bits(wheel_all: Path, wheel_own: Path,
                                                                          linux64_run: np.ndarray, tmp_path: Path):
    """--elementary own: linux64 (zig), the host's gcc build, aarch64 under qemu and win64 under wine
    (whose C library rounds differently, see the test above) give equal tables, on the paper's wheel
    (runtime/contact.h's quadrature) and in a rut (CasADi's, with an elementary call per node); and
    the own functions compute the same wheel as the C library's (1e-12)."""
    wine, qemu = wine_or_skip(), qemu_or_skip()
    md = json.loads((wheel_own / "documentation" / "build.json").read_text())
    assert md["elementary"] == "own" and "-elementary-own" in md["input_sha256"]
    linux = compile_importer("x86_64-linux-gnu.2.17", wheel_own, wheel_own / "sources")
    linux_libm = compile_importer("x86_64-linux-gnu.2.17", wheel_all, wheel_all / "sources")
    arm = compile_importer("aarch64-linux-gnu.2.17", wheel_own, wheel_own / "sources")
    folder = tmp_path / "win64"
    folder.mkdir()
    shutil.copy2(wheel_own / "binaries" / "win64" / "Wheel.dll", folder / "Wheel.dll")
    windows = compile_importer("x86_64-windows-gnu", folder, wheel_own / "sources")
    env = {**os.environ, "WINEPREFIX": str(tmp_path / "wineprefix"), "WINEDEBUG": "-all"}
    host = None
    if platforms.host_folder() == "linux64":  # and the host's C compiler's build (gcc here, not zig)
        host = build.build_fmu("Wheel", tmp_path / "host", elementary="own")
        fmpy.extract(str(host.path), str(tmp_path / "host" / "Wheel"))
    for extra in (None, IN_A_RUT):
        own = run([str(linux), str(wheel_own / "binaries" / "linux64" / "Wheel.so"), *scenario(wheel_own, extra)],
                  wheel_own)
        assert np.all(np.isfinite(own)) and own[-1, 1 + OUTPUTS.index("Fx")] > 100
        libm = linux64_run if extra is None else run(
            [str(linux_libm), str(wheel_all / "binaries" / "linux64" / "Wheel.so"), *scenario(wheel_all, extra)],
            wheel_all)
        np.testing.assert_allclose(own, libm, rtol=1e-12, atol=1e-12)
        if extra is not None:  # the own functions round differently from glibc's somewhere in the run
            assert not np.array_equal(own, libm)
        np.testing.assert_array_equal(
            run([qemu, "-L", str(AARCH64_SYSROOT), str(arm), str(wheel_own / "binaries" / "aarch64-linux" / "Wheel.so"),
                 *scenario(wheel_own, extra)], wheel_own), own)
        np.testing.assert_array_equal(run([wine, windows.name, "Wheel.dll", *scenario(wheel_own, extra)], folder, env),
                                      own)
        if host is not None:
            np.testing.assert_array_equal(
                run([str(linux), str(tmp_path / "host" / "Wheel" / "binaries" / "linux64" / "Wheel.so"),
                     *scenario(wheel_own, extra)], wheel_own), own)


def pe_exports(library: Path) -> set[str]:
    text = subprocess.run(["objdump", "-p", str(library)], capture_output=True, text=True, check=True).stdout
    table = text.split("[Ordinal/Name Pointer] Table", 1)[-1]
    return set(re.findall(r"^\s*\[\s*\d+\]\s+(\w+)\s*$", table, re.M))


def elf_exports(library: Path) -> set[str]:
    text = subprocess.run(["readelf", "--dyn-syms", "-W", str(library)], capture_output=True, text=True,
                          check=True).stdout
    return {f[7].split("@")[0] for f in (line.split() for line in text.splitlines())
            if len(f) >= 8 and f[3] == "FUNC" and f[4] == "GLOBAL" and f[6] != "UND"}


@pytest.mark.skipif(shutil.which("objdump") is None or shutil.which("readelf") is None,
                    reason="objdump/readelf (binutils) not on PATH")
def test_linux_and_windows_binaries_export_the_fmi2_functions_and_nothing_else(wheel_all: Path):
    assert pe_exports(wheel_all / "binaries" / "win64" / "Wheel.dll") == FMI2_FUNCTIONS
    for name in ("linux64", "aarch64-linux"):
        assert elf_exports(wheel_all / "binaries" / name / "Wheel.so") == FMI2_FUNCTIONS, name


# --- macOS: built, of the right architecture, exporting the fmi2 functions -----------------------

MH_MAGIC_64, MH_DYLIB, LC_SYMTAB = 0xFEEDFACF, 6, 0x2
CPU_TYPES = {"x86_64": 0x01000007, "aarch64": 0x0100000C}


def mach_o(library: Path) -> tuple[int, int, set[str]]:
    """CPU type, file type and the external defined symbols (leading underscore removed) of a
    64-bit little-endian Mach-O file."""
    data = library.read_bytes()
    magic, cpu, _, filetype, ncmds, _, _, _ = struct.unpack_from("<8I", data, 0)
    assert magic == MH_MAGIC_64, f"{library}: not a 64-bit Mach-O file"
    offset, names = 32, set()
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<2I", data, offset)
        if cmd == LC_SYMTAB:
            symoff, nsyms, stroff, _ = struct.unpack_from("<4I", data, offset + 8)
            for i in range(nsyms):
                strx, ntype, _, _, _ = struct.unpack_from("<IBBHQ", data, symoff + 16 * i)
                external, private, defined = ntype & 0x01, ntype & 0x10, (ntype & 0x0E) == 0x0E
                if external and defined and not private:
                    name = data[stroff + strx:data.index(b"\0", stroff + strx)].decode()
                    names.add(name[1:] if name.startswith("_") else name)
        offset += size
    return cpu, filetype, names


@pytest.mark.parametrize("name", ["darwin64", "aarch64-darwin"])
def test_darwin_binaries_are_dylibs_of_their_architecture_exporting_the_fmi2_functions(wheel_all: Path, name: str):
    """Built only: they cannot run here (no macOS machine, no Darwin emulator in Debian)."""
    cpu, filetype, exported = mach_o(wheel_all / "binaries" / name / "Wheel.dylib")
    assert cpu == CPU_TYPES[platforms.PLATFORMS[name].machine]
    assert filetype == MH_DYLIB
    # besides the linker's own __mh_dylib_header and ___dso_handle: the fmi2 functions alone
    assert {n for n in exported if not n.startswith("_")} == FMI2_FUNCTIONS


# --- the sources: standard headers, prefix, plain compilers -------------------------------------

def test_the_shipped_headers_are_the_standard_ones_and_honour_the_prefix(wheel_all: Path):
    header = (wheel_all / "sources" / "fmi2Functions.h").read_text()
    assert "#define fmi2FullName(name) fmi2PasteB(FMI2_FUNCTION_PREFIX, name)" in header
    assert "This definition has been changed" not in header  # FMPy's modified copy says so


def test_build_description_declares_the_sources_and_the_math_library(wheel_all: Path):
    configurations = fmpy.model_description.read_build_description(str(wheel_all), validate=True)
    files = sorted(p.name for p in (wheel_all / "sources").glob("*.c"))
    assert [c.modelIdentifier for c in configurations] == ["Wheel"]
    assert configurations[0].sourceFileSets[0].sourceFiles == files
    root = ET.parse(wheel_all / "sources" / "buildDescription.xml").getroot()
    assert [lib.get("name") for lib in root.iter("Library")] == ["m"]


def compile_objects(sources: Path, out: Path, defines: Sequence[str] = ()) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    objects = []
    for c_file in sorted(sources.glob("*.c")):
        target = out / f"{c_file.stem}.o"
        subprocess.run([build.compiler(), "-c", *build.CFLAGS[:2], "-fPIC", "-std=c99", "-D_POSIX_C_SOURCE=200809L",
                        *defines, "-I", str(sources), str(c_file), "-o", str(target)], check=True)
        objects.append(target)
    return objects


@pytest.mark.skipif(shutil.which("nm") is None, reason="nm (binutils) not on PATH")
def test_two_source_fmus_link_into_one_library_with_their_prefixes(wheel_all: Path, wheel_host: Path,
                                                                    linux64_run: np.ndarray, tmp_path: Path):
    """FMI2_FUNCTION_PREFIX with the standard header: Wheel and RoverBody compiled with their own
    prefixes link into one library (112 multiple definitions before, 68 once the fmi2 functions
    were prefixed), every external symbol carries its FMU's prefix, and Wheel run through its
    prefixed functions gives the bits of its own binary."""
    if platforms.host_folder() != "linux64":
        pytest.skip("the host is not linux64")
    body = build.build_fmu("RoverBody", tmp_path / "body")
    fmpy.extract(str(body.path), str(tmp_path / "RoverBody"))
    objects = compile_objects(wheel_all / "sources", tmp_path / "o-wheel", ["-DFMI2_FUNCTION_PREFIX=Wheel_"])
    objects += compile_objects(tmp_path / "RoverBody" / "sources", tmp_path / "o-body",
                               ["-DFMI2_FUNCTION_PREFIX=RoverBody_"])
    symbols = subprocess.run(["nm", "-g", "--defined-only", *map(str, objects)], capture_output=True, text=True,
                             check=True).stdout
    names = [line.split()[-1] for line in symbols.splitlines() if re.match(r"^[0-9a-f]+ [A-Z] ", line)]
    assert len(names) > 2 * len(FMI2_FUNCTIONS)
    assert [n for n in names if not n.startswith(("Wheel_", "RoverBody_"))] == []
    library = tmp_path / "both.so"
    subprocess.run([build.compiler(), "-shared", *map(str, objects), "-o", str(library), "-lm"], check=True)
    importer = compile_importer("x86_64-linux-gnu.2.17", wheel_all, wheel_all / "sources")
    arguments = scenario(wheel_all)
    arguments[1] = "Wheel_"
    np.testing.assert_array_equal(run([str(importer), str(library), *arguments], tmp_path), linux64_run)
    # RoverBody from the same library: instantiated and stepped through its own prefix.
    md = fmpy.read_model_description(str(tmp_path / "RoverBody"))
    x = next(v.valueReference for v in md.modelVariables if v.name == "x")
    done = subprocess.run([str(importer), str(library), md.guid, "RoverBody_", "10", "0.01", "out", str(x)],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr
    assert len(done.stdout.splitlines()) == 10


def test_prefix_header_names_every_external_definition():
    names = prefix.external_names(["int model_evaluate(const double **arg) {\n    return 0;\n}\n",
                                   "static int helper(void) { return 1; }\nconst ModelInfo model_info = {\n",
                                   "fmi2Status fmi2DoStep(fmi2Component c) {\n", "casadi_real casadi_sq(double x)"])
    assert names == ["model_evaluate", "model_info"]
    header = prefix.prefix_header(names)
    assert "#define model_info ROVER_COSIM_PREFIXED(FMI2_FUNCTION_PREFIX, model_info)" in header


@pytest.mark.skipif(shutil.which("readelf") is None, reason="readelf (binutils) not on PATH")
def test_plain_cc_of_the_sources_links_libm_and_runs_where_the_host_has_none(wheel_all: Path, wheel_host: Path,
                                                                              linux64_run: np.ndarray,
                                                                              tmp_path: Path):
    """`cc -shared -fPIC sources/*.c -lm`, as buildDescription.xml says: the library records its
    need of libm, so our importer (which links no libm) loads it."""
    if platforms.host_folder() != "linux64":
        pytest.skip("the host is not linux64")
    sources = wheel_all / "sources"
    library = tmp_path / "Wheel.so"
    subprocess.run([build.compiler(), "-shared", "-fPIC", "-O2", "-I", str(sources),
                    *map(str, sorted(sources.glob("*.c"))), "-o", str(library), "-lm"], check=True)
    assert "[libm.so.6]" in subprocess.run(["readelf", "-d", str(library)], capture_output=True, text=True,
                                           check=True).stdout
    importer = compile_importer("x86_64-linux-gnu.2.17", wheel_all, sources)
    np.testing.assert_array_equal(run([str(importer), str(library), *scenario(wheel_all)], tmp_path), linux64_run)


@pytest.mark.skipif(shutil.which("cmake") is None, reason="cmake not on PATH (fmpy compile needs it)")
def test_fmpy_compile_of_the_sources_runs_where_the_host_has_no_libm(wheel_all: Path, linux64_run: np.ndarray,
                                                                      tmp_path: Path):
    """FMPy 0.3.32's `fmpy compile` links no libm: its c-code/CMakeLists.txt lists none, it reads
    neither buildDescription.xml for FMI 2.0 nor any <Library> for FMI 3.0, and the CLI drops
    --cmake-options. Its library loads in Python (which has libm) but not in a host without libm
    (fmuCheck: undefined symbol: sincos); nothing in the sources can add the DT_NEEDED entry with
    GNU ld. The FMU says what to link (buildDescription.xml, the documentation); with FMPy that is
    ``build_platform_binary(..., cmake_options={"CMAKE_C_STANDARD_LIBRARIES:STRING": "-lm"})``
    (or ``LDFLAGS="-Wl,--no-as-needed -lm" fmpy compile``), checked here: the library then runs in
    our importer (no libm of its own) with the bits of the linux64 binary."""
    from fmpy.build import build_platform_binary

    if platforms.host_folder() != "linux64":
        pytest.skip("the host is not linux64")
    folder = tmp_path / "Wheel"
    shutil.copytree(wheel_all, folder, ignore=shutil.ignore_patterns("binaries", "fmi2_importer-*"))
    importer = compile_importer("x86_64-linux-gnu.2.17", wheel_all, wheel_all / "sources")
    (tmp_path / "cmake-libm").mkdir()
    build_platform_binary(folder, tmp_path / "cmake-libm", cmake_options={"CMAKE_C_STANDARD_LIBRARIES:STRING": "-lm"})
    table = run([str(importer), str(folder / "binaries" / "linux64" / "Wheel.so"), *scenario(wheel_all)], tmp_path)
    np.testing.assert_array_equal(table, linux64_run)


def test_fmu_is_one_zip_with_every_platform(wheel_all: Path):
    with zipfile.ZipFile(wheel_all.parent / "Wheel.fmu") as archive:
        members = set(archive.namelist())
    for name in platforms.ALL:
        assert f"binaries/{name}/Wheel{platforms.PLATFORMS[name].suffix}" in members
    assert not [m for m in members if m.endswith((".pdb", ".lib"))]


def test_a_failing_target_leaves_the_previous_fmu_as_it_was(wheel_all: Path, tmp_path: Path,
                                                           monkeypatch: pytest.MonkeyPatch):
    """All or nothing: the host compiler fails while win64 builds; the FMU already there stays."""
    zig_or_skip()
    failing = tmp_path / "failing-cc"
    failing.write_text("#!/bin/sh\n[ \"$1\" = --version ] && echo 'failing-cc 1.0' && exit 0\n"
                       "echo 'no way' >&2\nexit 1\n")
    failing.chmod(0o755)
    monkeypatch.setenv("CC", str(failing))
    out = tmp_path / "out"
    out.mkdir()
    (out / "Wheel.fmu").write_bytes(b"the previous FMU")
    with pytest.raises(RuntimeError, match=r"the C compiler failed on \w+\.c for linux64 \(failing-cc 1.0, exit 1\)"):
        build.build_fmu("Wheel", out, platforms=(platforms.HOST, "win64"))
    assert (out / "Wheel.fmu").read_bytes() == b"the previous FMU"
    assert sorted(p.name for p in out.iterdir()) == ["Wheel.fmu"]
