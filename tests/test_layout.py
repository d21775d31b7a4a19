"""The package's shape: one import root, layers that import one way only and no import cycles,
a wheel with nothing but rover_cosim at the top level that works when installed, and a project
that lives beside python-control (whose import name is ``control``)."""

from __future__ import annotations

import ast
import os
import shutil
import site
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

REPOSITORY = Path(__file__).resolve().parent.parent
PACKAGE = REPOSITORY / "rover_cosim"

#: What each layer may import besides itself (docs/design/development.md "Architecture"); "top" may import anything.
ALLOWED = {
    "common": set(),
    "terramechanics": {"common"},
    "limbs": {"common"},
    "fmubuild": {"common"},
    "orchestrator": {"common"},
    "identification": {"common", "terramechanics", "orchestrator"},
    "control": {"common", "orchestrator", "identification", "limbs"},
}


def package_modules() -> dict[str, Path]:
    """Every module of rover_cosim by dotted name (the linked layer folders included)."""
    modules: dict[str, Path] = {}
    for root, _dirs, files in os.walk(PACKAGE, followlinks=True):
        for file in files:
            if not file.endswith(".py"):
                continue
            path = Path(root) / file
            parts = list(path.relative_to(REPOSITORY).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            modules[".".join(parts)] = path
    return modules


def imports_of(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """rover_cosim modules imported by ``name`` anywhere in it (function-level imports included)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            for alias in node.names:
                found.add(f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base)
    return {m for m in found if m in modules and m != name}


def layer(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in ALLOWED else "top"


@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    modules = package_modules()
    return {name: imports_of(name, path, modules) for name, path in modules.items()}


def test_the_layer_folders_are_linked_into_the_one_import_root():
    for name in ("terramechanics", "fmubuild", "orchestrator", "identification", "modelica"):
        assert (REPOSITORY / name).is_dir() and (PACKAGE / name).resolve() == (REPOSITORY / name).resolve()
    assert not (REPOSITORY / "control").exists(), "a top-level control/ would shadow python-control in a checkout"


def test_layers_import_one_way_only(graph):
    wrong = [f"{module} ({layer(module)}) imports {target} ({layer(target)})"
             for module, targets in sorted(graph.items()) for target in sorted(targets)
             if layer(module) != "top" and layer(target) != layer(module)
             and (layer(target) == "top" or layer(target) not in ALLOWED[layer(module)])]
    assert not wrong, "imports against the layer order:\n" + "\n".join(wrong)


def test_no_import_cycles(graph):
    def cycle_from(start: str) -> list[str] | None:
        stack = [(start, [start])]
        while stack:
            node, path = stack.pop()
            for target in graph[node]:
                if target == start:
                    return [*path, start]
                if target not in path and len(path) < 50:
                    stack.append((target, [*path, target]))
        return None

    cycles = [" -> ".join(c) for m in sorted(graph) if (c := cycle_from(m))]
    assert not cycles, "import cycles:\n" + "\n".join(cycles)


def test_the_layer_test_sees_the_engine_and_would_catch_a_wrong_import(graph):
    """Guards the test itself: it parses the linked folders and flags an import across layers."""
    assert "rover_cosim.orchestrator.master" in graph and "rover_cosim.orchestrator.model" in graph[
        "rover_cosim.orchestrator.master"]
    assert "rover_cosim.common.units" in graph["rover_cosim.orchestrator.builder"]
    for module in ("builder", "system", "ssp", "algorithms", "executors", "execution", "observers", "unpacking"):
        assert f"rover_cosim.orchestrator.{module}" in graph, module
    assert "control" not in ALLOWED["orchestrator"] and "identification" not in ALLOWED["orchestrator"]


def test_import_rover_cosim_gives_the_version_and_the_reference_wheel():
    import rover_cosim
    import rover_cosim.terramechanics as wheel

    assert rover_cosim.__version__[0].isdigit()
    assert callable(wheel.wheel_state) and callable(wheel.contact_forces)


def run(command: list[str], cwd: Path, env: dict[str, str] | None = None, timeout: float = 600) -> str:
    result = subprocess.run(command, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout, check=False)
    what = f"{' '.join(command)} failed ({result.returncode})"
    assert result.returncode == 0, f"{what}:\n{result.stdout}\n{result.stderr}"
    return result.stdout


#: What the wheel's build does not need from a checkout (build outputs, environments, results).
NOT_BUILT_FROM = shutil.ignore_patterns(".git", ".venv", "results", "build", "dist", "*.egg-info", "__pycache__",
                                        ".pytest_cache", ".mypy_cache", ".ruff_cache", "*.fmu")


@pytest.fixture(scope="module")
def release(tmp_path_factory) -> tuple[Path, Path]:
    """The project's sdist and the wheel built from that sdist (``python -m build``, as a release is
    made), from a copy of the checkout in a scratch folder, so that the build leaves nothing in the
    checkout (offline: build and setuptools from the test extra)."""
    out = tmp_path_factory.mktemp("dist")
    source = tmp_path_factory.mktemp("source") / "rover-cosim"
    shutil.copytree(REPOSITORY, source, symlinks=True, ignore=NOT_BUILT_FROM)
    run([sys.executable, "-m", "build", "--no-isolation", "--outdir", str(out), str(source)], cwd=out)
    (sdist,) = out.glob("rover_cosim-*.tar.gz")
    (built,) = out.glob("rover_cosim-*.whl")
    return sdist, built


@pytest.fixture(scope="module")
def wheel(release) -> Path:
    return release[1]


def test_the_sdist_carries_the_release_files_and_the_sources_the_wheel_is_built_from(release):
    """The source distribution holds the licence, changelog and citation, the Modelica library, the
    C runtime, the shipped soils and the examples (the wheel above was built from it, not from the
    checkout)."""
    import tarfile

    sdist, _ = release
    with tarfile.open(sdist) as archive:
        names = {name.split("/", 1)[1] for name in archive.getnames() if "/" in name}
    for expected in ("LICENSE", "CHANGELOG.md", "CITATION.cff", "README.md", "pyproject.toml",
                     "rover_cosim/modelica/RoverTerramechanics/package.mo",
                     "rover_cosim/fmubuild/runtime/fmi2_api.c", "rover_cosim/terramechanics/library/soils.toml",
                     "rover_cosim/py.typed", "examples/README.md", "examples/own_soil.py", "examples/grc1.toml",
                     "examples/my_study.toml"):
        assert expected in names, expected


def test_building_the_wheel_leaves_nothing_in_the_checkout(wheel):
    assert wheel.is_file()
    assert not (REPOSITORY / "build").exists(), "the wheel's build left build/ in the checkout"


def test_the_wheel_has_only_rover_cosim_at_the_top_level(wheel):
    with zipfile.ZipFile(wheel) as archive:
        names = archive.namelist()
    top = {name.split("/")[0] for name in names}
    assert top == {"rover_cosim", wheel.name.split("-")[0] + "-" + wheel.name.split("-")[1] + ".dist-info"}, top
    for expected in ("rover_cosim/orchestrator/systems/rover_cosim.toml", "rover_cosim/fmubuild/runtime/fmi2_api.c",
                     "rover_cosim/modelica/RoverTerramechanics/package.mo",
                     "rover_cosim/modelica/RoverTerramechanics/package.order", "rover_cosim/terramechanics/forces.py",
                     "rover_cosim/modelica/RoverTerramechanics/FMUs/Wheel.mo",
                     "rover_cosim/modelica/RoverTerramechanics/Interfaces/WheelHub.mo",
                     "rover_cosim/modelica/RoverTerramechanics/UsersGuide/package.order"):
        assert expected in names, expected


def test_python_control_and_rover_cosim_live_side_by_side(tmp_path):
    """python-control keeps its import name; rover_cosim imports and runs beside it."""
    script = ("import control, rover_cosim.control.controller, rover_cosim.cli\n"
              "assert hasattr(control, 'tf') and 'site-packages' in control.__file__, control.__file__\n"
              "print(control.tf([1.0], [1.0, 1.0]).poles())\n"
              "arguments = ['fig3', '--loads', '300', '--slip-step', '0.3', '--out', '.']\n"
              "raise SystemExit(rover_cosim.cli.main(arguments))\n")
    output = run([sys.executable, "-P", "-c", script], cwd=tmp_path)
    assert "[-1" in output and (tmp_path / "fig3_fx_vs_slip.csv").is_file()


@pytest.mark.slow
def test_installed_wheel_works_from_another_folder(wheel, tmp_path):
    """`pip install` of the wheel into a fresh virtualenv outside the repository, then the command
    from another folder: Fig. 3 and an FMU build (the Modelica library is package data).

    The new environment sees this environment's site-packages for the dependencies (numpy, CasADi,
    rumoca, ...) through a .pth file, so the test needs no network; rover_cosim itself comes only
    from the installed wheel."""
    venv = tmp_path / "venv"
    run([sys.executable, "-m", "venv", "--without-pip", str(venv)], cwd=tmp_path)
    python = venv / "bin" / "python"
    purelib = Path(run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                       cwd=tmp_path).strip())
    dependencies = [p for p in site.getsitepackages() + [sysconfig.get_paths()["purelib"]] if Path(p).is_dir()]
    (purelib / "_rover_cosim_test_dependencies.pth").write_text("\n".join(dict.fromkeys(dependencies)) + "\n")
    run([sys.executable, "-m", "pip", "--python", str(python), "install", "--quiet", "--no-deps", str(wheel)],
        cwd=tmp_path)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    where = run([str(python), "-c", "import rover_cosim, rover_cosim.fmubuild.source as s; "
                 "print(rover_cosim.__file__); print(s.MODELICA_ROOT)"], cwd=elsewhere, env=env).split()
    assert all(Path(p).resolve().is_relative_to(venv.resolve()) for p in where), where
    command = str(venv / "bin" / "rover-cosim")
    run([command, "fig3", "--out", "X", "--loads", "300,600", "--slip-step", "0.1"], cwd=elsewhere, env=env)
    assert (elsewhere / "X" / "fig3_fx_vs_slip.csv").is_file() and (elsewhere / "X" / "fig3_fx_vs_slip.png").is_file()
    run([command, "build-fmus", "--out", "Y", "--backend", "builtin", "SingleWheel"], cwd=elsewhere, env=env)
    with zipfile.ZipFile(elsewhere / "Y" / "SingleWheel.fmu") as archive:
        assert "modelDescription.xml" in archive.namelist()
    assert run([command, "--version"], cwd=elsewhere, env=env).startswith("rover-cosim ")


def test_the_wheel_is_release_shaped(wheel):
    """The wheel carries the license text, the typing marker and the metadata a package index shows;
    the repository has a changelog and a citation file (of this software and the paper it reproduces)."""
    with zipfile.ZipFile(wheel) as archive:
        names = archive.namelist()
        metadata = archive.read(next(n for n in names if n.endswith(".dist-info/METADATA"))).decode()
    assert any(n.endswith("licenses/LICENSE") for n in names) and "rover_cosim/py.typed" in names
    assert "License-Expression: Apache-2.0" in metadata and "Classifier: Typing :: Typed" in metadata
    root = Path(__file__).resolve().parents[1]
    assert "Apache License" in (root / "LICENSE").read_text() and "## Unreleased" in (root / "CHANGELOG.md").read_text()
    citation = (root / "CITATION.cff").read_text()
    assert "cff-version: 1.2.0" in citation and "Yoshikawa" in citation and "year: 2017" in citation
