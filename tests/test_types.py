"""Every FMI 2.0 variable type through the engine, on a test FMU of our own (tests/fmus/typed.c):
typed parameters and start values (TOML numbers, booleans, strings), value references resolved
per type (they are shared across types in this FMU), type checks of connections at load, typed
recorded columns, a feedthrough chain across types, the Python path for FMUs that exchange other
types than Real (the native stepper sets and gets Reals only), and the clean end of a run when
an FMU ends the simulation (fmi2Discard with fmi2Terminated), from Python and from C."""

from __future__ import annotations

import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from typed_fmu import build_typed_fmu

from rover_cosim.cli import main
from rover_cosim.orchestrator import SystemBuilder, run
from rover_cosim.orchestrator.builder import with_isolation
from rover_cosim.orchestrator.execution import make_execution
from rover_cosim.orchestrator.master import participants_of
from rover_cosim.orchestrator.model import SystemFileError
from rover_cosim.orchestrator.system import system_from_dict, system_to_toml
from rover_cosim.orchestrator.wiring import wire


def _built(folder: Path, **variant: Any) -> Path:
    built = build_typed_fmu(folder, **variant)
    if isinstance(built, str):
        pytest.skip(f"the test FMU cannot be built here: {built}")
    return built


@pytest.fixture(scope="module")
def typed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The test FMU (no FMU state, variable communication steps)."""
    return _built(tmp_path_factory.mktemp("typed"))


@pytest.fixture(scope="module")
def stateful(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The test FMU saying it can get and set its state (for the iterative master)."""
    return _built(tmp_path_factory.mktemp("stateful"), name="TypedState", states=True)


def one(typed: Path, **fmu: Any) -> dict[str, Any]:
    return {"simulation": {"stop_time": 1.0, "step": 0.1, "algorithm": "jacobi"},
            "fmu": [{"name": "a", "path": str(typed), **fmu}]}


def test_shared_value_references_are_resolved_per_type(typed):
    data = run(system_from_dict(one(typed), name="t", base=typed.parent)).data
    np.testing.assert_allclose(data["a.x"], data["time"], rtol=0, atol=1e-12)   # Real 0
    assert data["a.counter"].tolist() == list(range(11))                       # Integer 0, not Real 0
    assert data["a.even"].tolist() == [k % 2 == 0 for k in range(11)]            # Boolean 0
    assert data["a.mode"].tolist() == [1 + k % 3 for k in range(11)]             # Enumeration (Integer 4)
    assert str(data["a.counter"].dtype) == "int64" and str(data["a.even"].dtype) == "bool"
    assert "a.label" not in data  # a String output would not be recorded by default (none here)


def test_typed_parameters_and_start_values_from_a_file(typed, tmp_path):
    data = one(typed, parameters={"gain": 3, "label": "hello", "stopAfter": 0}, start={"u": 2.0, "k": 5, "b": True})
    system = system_from_dict(data, name="t", base=typed.parent)
    assert system.fmus[0].parameters == {"gain": 3.0, "label": "hello", "stopAfter": 0}
    assert system.fmus[0].start == {"u": 2.0, "k": 5, "b": True}
    recorded = run(system).data
    assert (recorded["a.y"] == 6.0).all() and recorded["a.k2"].tolist() == [5 + k for k in range(11)]
    assert not recorded["a.notb"].any()
    written = tmp_path / "typed.toml"
    written.write_text(system_to_toml(system, tmp_path))
    assert 'label = "hello"' in written.read_text() and "b = true" in written.read_text()


BAD_VALUES: dict[str, tuple[dict[str, Any], str]] = {
    "a number for a Boolean": ({"start": {"b": 1}}, "start b: 1: expected true or false (Boolean)"),
    "a fraction for an Integer": ({"start": {"k": 2.5}}, "start k: 2.5: expected a whole number (Integer)"),
    "a number for a String": ({"parameters": {"label": 3}}, "parameters label: 3: expected text (String)"),
    "a boolean for a Real": ({"parameters": {"gain": True}}, "parameters gain: True: expected a number (Real)"),
}


@pytest.mark.parametrize("case", sorted(BAD_VALUES))
def test_a_value_of_the_wrong_type_names_the_variable_and_its_type(typed, case):
    fmu, expected = BAD_VALUES[case]
    with pytest.raises(SystemFileError, match=expected.replace("(", r"\(").replace(")", r"\)")):
        system_from_dict(one(typed, **fmu), name="t", base=typed.parent)


def chain(typed: Path, algorithm: str = "gauss-seidel") -> SystemBuilder:
    """a -> b across every type but String: Real y -> u, Integer k2 -> k, Boolean notb -> b."""
    builder = SystemBuilder("chain").simulation(stop_time=1.0, step=0.1, algorithm=algorithm)
    builder.add_fmu("a", typed, start={"u": 1.5, "k": 7, "b": False}).add_fmu("b", typed)
    return builder.connect("a.y", "b.u").connect("a.k2", "b.k").connect("a.notb", "b.b")


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi", "iterative"])
def test_feedthrough_to_feedthrough_across_types(typed, stateful, algorithm):
    """Iterative: on the FMU with states; its discrete inputs take the values at the end of the
    step (never averaged), so it gives Gauss-Seidel's results."""
    data = run(chain(stateful if algorithm == "iterative" else typed, algorithm).build()).data
    assert (data["b.y"] == 2.0 * 2.0 * 1.5).all()                       # Real through two gains of 2
    assert not data["b.notb"].any()                                        # not (not False)
    a_k2 = data["a.k2"].to_numpy()
    assert a_k2.tolist() == (7 + data["a.counter"]).tolist()   # (the iterative master's first step is in pieces)
    # Gauss-Seidel and iterative: b sees a's k2 of the same instant; Jacobi: of the step before.
    seen = a_k2 if algorithm != "jacobi" else np.concatenate([[a_k2[0]], a_k2[:-1]])
    assert data["b.k2"].tolist() == (seen + data["b.counter"]).tolist()


def test_the_iterative_master_refuses_an_fmu_without_states_by_name(typed):
    with pytest.raises(SystemFileError, match=r"a \(Typed.fmu\) cannot save and restore its state "
                                              r"\(canGetAndSetFMUstate is false\)"):
        chain(typed, "iterative").build()


def test_an_integer_output_may_drive_an_enumeration_and_back_but_not_a_real(typed):
    builder = SystemBuilder("mix").simulation(stop_time=0.3, step=0.1)
    builder.add_fmu("a", typed).add_fmu("b", typed)
    builder.connect("a.mode", "b.k")   # Enumeration -> Integer: allowed
    with pytest.raises(SystemFileError, match=r"type mismatch: a\.counter is Integer, b\.u is Real"):
        builder.connect("a.counter", "b.u")
    with pytest.raises(SystemFileError, match=r"type mismatch: a\.y is Real, b\.b is Boolean"):
        builder.connect("a.y", "b.b")
    data = run(builder.build()).data
    assert data["b.k2"].tolist() == [m + c for m, c in zip(data["a.mode"], range(4))]


def test_an_fmu_exchanging_other_types_steps_in_python_and_a_real_only_one_natively(typed):
    """In this process (isolation "none": a test FMU is not one this project generated, so "auto"
    would run it in a child process, which the native stepper cannot step)."""
    mixed = with_isolation(chain(typed, "jacobi").build(), "none")
    reals = SystemBuilder("reals").simulation(stop_time=1.0, step=0.1, algorithm="jacobi")
    reals.add_fmu("a", typed, start={"u": 1.0}, isolation="none").add_fmu("b", typed, isolation="none")
    reals.connect("a.y", "b.u")
    real_only = reals.record("a.x", "b.y").build()
    for system, natively in ((mixed, set()), (real_only, {0, 1})):
        wiring = wire(system)
        with participants_of(system, wiring) as participants:
            execution = make_execution(system, participants, wiring)
            assert set(execution.natively) == natively
            execution.close()


@pytest.mark.parametrize("which", ["from Python (typed outputs)", "from C (Real outputs only)"])
def test_an_fmu_that_ends_the_simulation_ends_the_run_cleanly(typed, which):
    builder = SystemBuilder("stops").simulation(stop_time=1.0, step=0.1, algorithm="jacobi")
    builder.add_fmu("a", typed, parameters={"stopAfter": 4})
    if which.startswith("from C"):
        builder.record("a.x")
    result = run(builder.build())
    assert result.stopped is not None and "a (Typed.fmu) ended the simulation at t = 0.4 s" in result.stopped
    assert "stopAfter = 4 steps reached" in result.stopped
    # One FMU: the last row at the time it got to (fmi2LastSuccessfulTime), as FMPy records it.
    assert len(result.data) == 5 and result.steps == 4
    np.testing.assert_allclose(result.data["time"], [0.0, 0.1, 0.2, 0.3, 0.4])
    if which.startswith("from Python"):
        assert result.data["a.counter"].tolist() == [0, 1, 2, 3, 4]


def test_with_other_participants_the_run_ends_where_they_all_agree(typed):
    builder = chain(typed, "gauss-seidel")
    builder.set_parameters("a", {"stopAfter": 4})
    result = run(builder.build())
    assert "a (Typed.fmu) ended the simulation at t = 0.4 s" in (result.stopped or "")
    assert len(result.data) == 4 and result.data["time"].iloc[-1] == pytest.approx(0.3)


def test_rover_cosim_run_exits_0_with_every_row_when_an_fmu_ends_the_simulation(typed, tmp_path, capsys):
    system = tmp_path / "stops.toml"
    system.write_text(f'[simulation]\nstop_time = 1.0\nstep = 0.1\n\n[[fmu]]\nname = "a"\npath = "{typed}"\n'
                      "parameters = { stopAfter = 3 }\n")
    assert main(["run", str(system), "-o", str(tmp_path / "stops.csv"), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "stopped: a (Typed.fmu) ended the simulation at t = 0.3 s" in out
    data = pd.read_csv(tmp_path / "stops.csv")
    assert data["a.counter"].tolist() == [0, 1, 2, 3]


def test_a_system_without_stop_time_or_step_takes_the_fmus_default_experiment(typed, tmp_path):
    system = system_from_dict({"fmu": [{"name": "a", "path": str(typed)}]}, name="t", base=typed.parent)
    assert (system.stop_time, system.step) == (1.0, 0.1)
    assert system.settings_from == {"stop_time": "DefaultExperiment stopTime of a (Typed.fmu)",
                                    "step": "DefaultExperiment stepSize of a (Typed.fmu)"}
    assert len(run(system).data) == 11


def test_an_fmu_without_a_binary_for_this_platform_is_named_with_the_ones_it_has(tmp_path):
    foreign = _built(tmp_path, name="Elsewhere", platform="win64")
    with zipfile.ZipFile(foreign, "a") as archive:  # an empty folder of this platform and another model's binary
        archive.writestr("binaries/linux64/", b"")
        archive.writestr("binaries/darwin64/Other.dylib", b"")
    with pytest.raises(SystemFileError, match=r"Elsewhere.fmu has no binary for this platform "
                                              r"\(binaries/linux64/Typed.so\); the platform folders holding a binary "
                                              r"of Typed: win64$"):
        system_from_dict(one(foreign), name="t", base=tmp_path)


def test_a_fixed_step_fmu_gets_no_shorter_last_step(tmp_path):
    fixed = _built(tmp_path, name="Fixed", fixed_step=True)
    with pytest.raises(SystemFileError, match="takes one fixed communication step"):
        system_from_dict({"simulation": {"stop_time": 0.95, "step": 0.1}, "fmu": [{"name": "a", "path": str(fixed)}]},
                         name="t", base=tmp_path)
    assert len(run(system_from_dict(one(fixed), name="t", base=tmp_path)).data) == 11


def test_rover_cosim_run_runs_one_fmu_file_with_its_default_experiment(typed, tmp_path, capsys):
    out = tmp_path / "alone.csv"
    assert main(["run", str(typed), "-o", str(out), "--quiet"]) == 0
    data = pd.read_csv(out)
    assert len(data) == 11 and data["model.counter"].tolist() == list(range(11))
    assert main(["run", str(typed), "-o", str(out), "--stop-time", "0.5", "--quiet"]) == 0
    assert len(pd.read_csv(out)) == 6
    assert main(["run", str(typed), "-o", str(out), "--step", "0", "--quiet"]) == 2
    assert "step: 0.0: expected a communication step > 0 s" in capsys.readouterr().err


def test_results_have_short_reprs(typed):
    result = run(SystemBuilder("r").simulation(stop_time=1.0, step=0.1).add_fmu("a", typed).build())
    text = repr(result)
    assert text.startswith("RunResult(11 rows x ") and "10 steps" in text and len(text) < 200


def test_the_largest_64_bit_integers_saturate_instead_of_wrapping():
    """The value vector holds floats: 2^63 - 1 and 2^64 - 1 become 2^63 and 2^64 there. Set into an
    Int64/UInt64 input or recorded, they are the type's largest value again (the Reference-FMUs'
    Feedthrough with its input file: before, -2^63 and 0 where FMPy gives 2^63 - 1 and 2^64 - 1)."""
    from rover_cosim.orchestrator.fmi_access import c_values
    from rover_cosim.orchestrator.recorder import typed

    assert c_values(3, "Int64", [float(2**63 - 1), -float(2**63), 7.0]) == [2**63 - 1, -2**63, 7]
    assert c_values(3, "UInt64", [float(2**64 - 1), -1.0]) == [2**64 - 1, 0]
    assert c_values(2, "Integer", [float(2**31), 3.0]) == [2**31 - 1, 3]
    assert typed(np.array([float(2**63 - 1), -float(2**63), 5.0]), "Int64").tolist() == [2**63 - 1, -2**63, 5]
    assert typed(np.array([float(2**64 - 1), 1.0]), "UInt64").tolist() == [2**64 - 1, 1]
