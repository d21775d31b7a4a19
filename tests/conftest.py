"""Shared fixtures: the FMUs of `make fmus`, built once per test session, and the pipeline's
results (identification, then the closed loop), each computed once per test session; the test
FMU of our own with a variable of every FMI 2.0 type (tests/fmus/typed.c)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rover_cosim.fmubuild import build
from rover_cosim.jobs.identify import IdentificationResult, run_identification
from rover_cosim.jobs.simulate import SimulationResult, run_simulation

REPOSITORY = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="session")
def typed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Typed.fmu (tests/typed_fmu.py), built once per session; skipped where it cannot be built."""
    from typed_fmu import build_typed_fmu

    built = build_typed_fmu(tmp_path_factory.mktemp("typed"))
    if isinstance(built, str):
        pytest.skip(f"the test FMU cannot be built here: {built}")
    return built


@pytest.fixture(scope="session")
def fmus() -> dict[str, Path]:
    """The FMUs by model name, built into fmus/ as `make fmus` does (skipped when up to date)."""
    results = build.build_all(build.FMU_MODELS, REPOSITORY / "fmus", backend="builtin")
    return {r.name: r.path for r in results}


@pytest.fixture(scope="session")
def fmu_dir(fmus: dict[str, Path]) -> Path:
    """The folder holding the built FMUs."""
    return next(iter(fmus.values())).parent


@pytest.fixture(scope="session")
def results_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A results folder shared by the pipeline fixtures, like results/ after `make run`."""
    return tmp_path_factory.mktemp("results")


@pytest.fixture(scope="session")
def identified(fmus: dict[str, Path], results_root: Path) -> IdentificationResult:
    """`make identify` on SingleWheel.fmu into <results>/identification (once per session)."""
    return run_identification(fmus["SingleWheel"], results_root / "identification", workers=2)


@pytest.fixture(scope="session")
def simulated(fmu_dir: Path, identified: IdentificationResult, results_root: Path) -> SimulationResult:
    """`make simulate` with the identified model into <results>/simulation (once per session)."""
    return run_simulation(fmu_dir, results_root / "identification" / "model.json", results_root / "simulation")
