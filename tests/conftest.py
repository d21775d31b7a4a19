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


#: Fixtures that build or run FMUs (and the pipeline on them): a test that uses one, directly or
#: through another fixture, belongs to the full tier only.
FMU_FIXTURES = {"fmus", "fmu_dir", "identified", "simulated", "typed"}

#: Fixtures that run the pipeline (identification, then the closed loop): ``-m pipeline`` selects
#: the tests of the pipeline's results, ``-m "fmu and not pipeline"`` the FMU tests without them.
PIPELINE_FIXTURES = {"identified", "simulated"}

#: Modules that build FMUs, translate the Modelica library or run whole commands of their own (C test
#: FMUs, zig cross-builds, rumoca, killed processes) without those fixtures.
FULL_TIER_MODULES = {"test_platforms", "test_killed_commands", "test_fmi_kinds", "test_ssp_foreign",
                     "test_inputs_outputs", "test_fmi3", "test_layout", "test_fmus", "test_modelica_rumoca",
                     "test_translate"}


def pytest_configure(config: pytest.Config) -> None:
    """A suite started in the background of a non-interactive shell (``make test &``, nohup) has
    SIGINT ignored, and the commands the tests start inherit that: the tests that interrupt them
    with SIGINT would see it ignored. Python's own handler here makes the children start with the
    default disposition, as they do from a terminal."""
    import signal

    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark the tests of the full tier ``fmu`` (they build or run FMUs), so that ``make test-fast``
    (``-m "not fmu and not slow"``) runs the rest in seconds; ``make test`` runs every test."""
    for item in items:
        module = getattr(getattr(item, "module", None), "__name__", "")
        fixtures = set(getattr(item, "fixturenames", ()))
        if FMU_FIXTURES & fixtures or module in FULL_TIER_MODULES:
            item.add_marker(pytest.mark.fmu)
        if PIPELINE_FIXTURES & fixtures:
            item.add_marker(pytest.mark.pipeline)
