"""The documentation site builds without a warning (mkdocs --strict: broken links, docstrings that
name parameters a function does not have), and its generated pages follow the code and the results:
every rover-cosim command, every shipped soil and wheel, every system-file key and block type, every
FMU variable, the benchmark files, the pipeline's validation tables and the Modelica
package's UsersGuide."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
from fmpy import read_model_description

import rover_cosim
from rover_cosim.cli import build_parser
from rover_cosim.common.outputs import run_record
from rover_cosim.orchestrator.blocks import BLOCK_TYPES
from rover_cosim.orchestrator.system import SECTION_KEYS

REPOSITORY = Path(__file__).resolve().parent.parent


def test_the_docs_site_builds_strictly_with_the_generated_references(tmp_path, fmu_dir, simulated, results_root):
    pytest.importorskip("mkdocs", reason="mkdocs not installed (the docs extra: pip install -e '.[docs]')")
    pytest.importorskip("mkdocstrings", reason="mkdocstrings not installed (the docs extra)")
    results = tmp_path / "results"  # the pipeline's results (linked) and one benchmark file
    results.mkdir()
    for name in ("identification", "simulation"):
        (results / name).symlink_to(results_root / name)
    (results / "bench").mkdir()
    bench = {**run_record("make bench", {"repeats": 3}), "results": {"closed_loop": {"wall_s": 0.6789, "rtf": 29.4}}}
    (results / "bench" / "closed_loop.json").write_text(json.dumps(bench))
    site = tmp_path / "site"
    environment = {**os.environ, "ROVER_COSIM_DOCS_FMUS": str(fmu_dir), "ROVER_COSIM_DOCS_RESULTS": str(results)}
    result = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
                            cwd=REPOSITORY, capture_output=True, text=True, check=False, env=environment)
    assert result.returncode == 0, result.stderr[-3000:]
    page = (site / "reference" / "system-files" / "index.html").read_text()
    for section, keys in SECTION_KEYS.items():
        assert all(f"<code>{key}</code>" in page for key in keys), section
    assert all(f'type = "{kind}"' in page.replace("&quot;", '"') for kind in BLOCK_TYPES)
    page = (site / "reference" / "fmu-variables" / "index.html").read_text()
    for fmu in sorted(fmu_dir.glob("*.fmu")):
        names = [v.name for v in read_model_description(str(fmu)).modelVariables if v.causality in ("input", "output")]
        assert "<h2 id=" in page and all(f"<code>{n}</code>" in page for n in names), fmu.name
    page = (site / "results" / "benchmarks" / "index.html").read_text()
    assert "closed_loop.wall_s" in page and "0.6789" in page and str(bench["git_commit"])[:12] in page
    page = (site / "results" / "validation" / "index.html").read_text()
    assert "Table 1" in page and "data:image" not in page  # the report's tables, without its figures
    cli = (site / "reference" / "cli" / "index.html").read_text()
    commands = next(a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction")
    assert isinstance(commands.choices, dict)
    for name in commands.choices:
        assert f"rover-cosim {name}" in cli, name
    soils = (site / "reference" / "soils" / "index.html").read_text()
    library = REPOSITORY / "terramechanics" / "library"
    for kind in ("soils", "wheels"):
        for name in tomllib.loads((library / f"{kind}.toml").read_text()):
            assert f">{name}<" in soils, name
    api = (site / "reference" / "python" / "index.html").read_text()
    assert "wheel_state" in api and "sinkage" in api  # rendered from the docstrings
    assert not (site / "hooks.py").exists()
    modelica = (site / "guide" / "modelica" / "index.html").read_text()  # with the package's UsersGuide
    guide = REPOSITORY / "modelica" / "RoverTerramechanics" / "UsersGuide"
    for section in (guide / "package.order").read_text().split():
        assert f'id="{section.lower()}"' in modelica, section
    assert "<h4>Wheel</h4>" in modelica and "modelica://" not in modelica


def test_the_readme_python_quick_start_runs_and_prints_physical_values():
    text = (REPOSITORY / "README.md").read_text()
    block = text.split("```python\n", 1)[1].split("```", 1)[0]
    result = subprocess.run([sys.executable, "-P", "-c", block], capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr[-2000:]
    numbers = [float(word) for word in result.stdout.replace(",", " ").split() if word.replace(".", "").isdigit()]
    pull, torque, sinkage_mm = numbers
    assert 0 < pull < 424 and 0 < torque < 424 * 0.355 and 1 < sinkage_mm < 355


#: File names the "To change …" and "To add …" tables of the design pages may name.
_NAMED_FILE = re.compile(r"`([\w./-]+\.(?:py|mo|c|h|toml|json|order|md))`")


def _repository_files() -> list[Path]:
    """The repository's files, not descending into the folders of tools and results (the virtual
    environment alone has tens of thousands)."""
    skipped = {".git", ".venv", "results", "site", "fmus", "node_modules", ".pytest_cache", ".mypy_cache", ".cache"}
    files: list[Path] = []
    for folder, subfolders, names in os.walk(REPOSITORY):
        subfolders[:] = [d for d in subfolders if d not in skipped]
        files.extend(Path(folder) / name for name in names)
    return files


def test_every_file_the_change_tables_name_exists():
    """The design pages' "To change …, touch these files" and "To add …" tables name files by their
    path from the repository, from the Modelica package or by their name alone (a C twin beside its
    block); each must be there, so that a renamed or removed file cannot leave a table pointing
    nowhere."""
    files = _repository_files()
    names = {path.name for path in files}
    tails = {path.relative_to(REPOSITORY).as_posix() for path in files}
    pages = sorted((REPOSITORY / "docs" / "design").glob("*.md"))
    missing, named = [], 0
    for page in pages:
        text = page.read_text()
        for part in re.split(r"^## ", text, flags=re.MULTILINE):
            if not part.startswith(("To change", "To add")):
                continue
            for rows in re.findall(r"^\|.*\|$", part, flags=re.MULTILINE):
                for name in _NAMED_FILE.findall(rows):
                    named += 1
                    if "/" not in name:
                        found = name in names
                    else:
                        found = any(tail == name or tail.endswith("/" + name) for tail in tails)
                    if not found and not name.startswith("../"):
                        missing.append(f"{page.name}: {name}")
    assert named > 40, f"only {named} files named: the tables were not found"
    assert not missing, missing


def test_the_design_pages_say_how_to_add_a_command_a_scenario_an_fmu_and_a_soil_field():
    text = (REPOSITORY / "docs" / "design" / "development.md").read_text()
    table = text.split("## To add", 1)[1].split("\n## ", 1)[0]
    for row in ("| a command", "| a terrain scenario", "| an FMU", "| a soil field"):
        assert row in table, row


def test_the_engine_api_example_of_the_cosimulation_guide_runs(fmu_dir, fmus, tmp_path):
    """docs/guide/cosimulation.md, "The engine from Python": its two files (a block module and a
    script) written out and the script run beside them, the FMUs in fmus/: it builds, runs, exports
    the system to SSP and gets the same rows back."""
    part = (REPOSITORY / "docs" / "guide" / "cosimulation.md").read_text().split("## The engine from Python", 1)[1]
    module, script = re.findall(r"```python\n(.*?)```", part, re.DOTALL)[:2]
    (tmp_path / "my_blocks.py").write_text(module)
    (tmp_path / "brake.py").write_text(script)
    (tmp_path / "fmus").symlink_to(fmu_dir, target_is_directory=True)
    done = subprocess.run([sys.executable, "-P", "brake.py"], cwd=tmp_path, capture_output=True, text=True,
                          check=False, env={**os.environ, "PYTHONPATH": str(Path(rover_cosim.__file__).parents[1])})
    assert done.returncode == 0, done.stderr[-2000:]
    assert "brake.ssp: the same 501 rows" in done.stdout and (tmp_path / "brake.ssp").is_file()
