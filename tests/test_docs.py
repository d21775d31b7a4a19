"""The documentation site builds without a warning (mkdocs --strict: broken links, docstrings that
name parameters a function does not have), and its generated reference pages follow the code:
every rover-cosim command, every shipped soil and wheel, the Modelica package's UsersGuide."""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from rover_cosim.cli import build_parser

REPOSITORY = Path(__file__).resolve().parent.parent


def test_the_docs_site_builds_strictly_with_the_generated_references(tmp_path):
    pytest.importorskip("mkdocs", reason="mkdocs not installed (the docs extra: pip install -e '.[docs]')")
    pytest.importorskip("mkdocstrings", reason="mkdocstrings not installed (the docs extra)")
    site = tmp_path / "site"
    result = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site)],
                            cwd=REPOSITORY, capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr[-3000:]
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
