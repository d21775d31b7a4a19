"""The typed system model: built in code through SystemBuilder with the parser's precise errors,
written to TOML and read back (and through SSP) to the same system, changed copies
(replace_settings, with_parameters), observers that watch and stop a run, the model file as a
typed object, and the layer packages' one identity."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from rover_cosim.cli import EXAMPLES
from rover_cosim.identification.model_set import SCHEMA_VERSION, ModelFileError, ModelSet
from rover_cosim.jobs.plants import add_rover
from rover_cosim.orchestrator import Observer, StopWhen, SystemBuilder, run
from rover_cosim.orchestrator.blocks import Constant, TanhStep
from rover_cosim.orchestrator.builder import replace_settings, with_parameters
from rover_cosim.orchestrator.model import System, SystemFileError
from rover_cosim.orchestrator.ssp import export_ssp, load_ssp
from rover_cosim.orchestrator.system import load_system, system_to_toml

REPOSITORY = Path(__file__).resolve().parent.parent


def shape(system: System) -> tuple[Any, ...]:
    """Everything a system says, comparable (FMU files by their resolved path)."""
    return ([(f.name, f.path.resolve(), f.parameters, f.start) for f in system.fmus],
            [(b.name, b.kind, b.keys) for b in system.blocks],
            [(str(c.source), str(c.target)) for c in system.connections], [str(p) for p in system.record],
            system.order, system.step, system.stop_time, system.start_time, system.algorithm, system.iteration,
            system.threads_setting, system.native, system.allow_algebraic_loops)


def rover_in_code(fmu_dir: Path, stop_time: float = 6.0) -> System:
    """The shipped rover_cosim.toml, built in code: RoverBody + 6 Wheel on the open-loop torque."""
    builder = SystemBuilder("rover in code").simulation(stop_time=stop_time, step=1e-3, algorithm="gauss-seidel")
    builder.add_fmu("body", fmu_dir / "RoverBody.fmu")
    for i in range(1, 7):
        builder.add_fmu(f"wheel{i}", fmu_dir / "Wheel.fmu")
    builder.add_block("torque", TanhStep("torque", begin=40.0, end=9.0, time=3.0, width=0.3, unit="N.m"))
    for i in range(1, 7):
        builder.connect(f"body.W[{i}]", f"wheel{i}.W").connect(f"body.v_hub[{i}]", f"wheel{i}.v_hub")
        builder.connect(f"wheel{i}.Fx", f"body.Fx[{i}]").connect("torque.y", f"wheel{i}.tau")
        builder.connect("torque.y", f"body.tau[{i}]")
    return builder.simulation(order=["torque", "body", *[f"wheel{i}" for i in range(1, 7)]]).build()


def test_a_system_built_in_code_is_the_shipped_file_and_runs_to_its_results(fmu_dir, fmus):
    shipped = replace_settings(load_system(EXAMPLES["rover_cosim"], fmu_dir=fmu_dir), stop_time=0.3)
    ours = rover_in_code(fmu_dir, stop_time=0.3)
    assert [f.name for f in ours.fmus] == [f.name for f in shipped.fmus]
    assert sorted(shape(ours)[2]) == sorted(shape(shipped)[2])  # the same connections
    assert shape(ours)[4:] == shape(shipped)[4:]                # order, settings
    theirs = run(shipped).data                                   # the file records a few outputs; ours all
    pd.testing.assert_frame_equal(run(ours).data[theirs.columns], theirs, check_exact=True)


def test_the_hub_wiring_helper_wires_the_rover_as_the_file_does(fmu_dir, fmus):
    builder = SystemBuilder("hubs").simulation(stop_time=0.1, step=1e-3)
    wheels = add_rover(builder, fmu_dir / "RoverBody.fmu", fmu_dir / "Wheel.fmu", 6, None)
    builder.add_block("torque", Constant("torque", 20.0, unit="N.m"))
    for i, wheel in enumerate(wheels, 1):
        builder.connect("torque.y", f"{wheel}.tau").connect("torque.y", f"body.tau[{i}]")
    system = builder.build()
    hubs = {(str(c.source), str(c.target)) for c in system.connections if c.source.instance != "torque"}
    shipped = load_system(EXAMPLES["rover_cosim"], fmu_dir=fmu_dir)
    assert hubs == {(str(c.source), str(c.target)) for c in shipped.connections if c.source.instance != "torque"}


def _open(fmu_dir: Path) -> SystemBuilder:
    builder = SystemBuilder("mine").simulation(stop_time=1.0, step=1e-3)
    builder.add_fmu("body", fmu_dir / "RoverBody.fmu").add_fmu("wheel", fmu_dir / "Wheel.fmu")
    return builder.add_block("torque", Constant("torque", 20.0, unit="N.m"))


BAD_CALLS = {
    "unknown variable": (lambda b: b.connect("body.Wx[1]", "wheel.W"),
                         "mine: connect('body.Wx[1]', 'wheel.W'): body (RoverBody.fmu) has no variable 'Wx[1]'"),
    "unknown instance": (lambda b: b.connect("bdy.W[1]", "wheel.W"), "no instance 'bdy'; expected one of body"),
    "unit mismatch": (lambda b: b.connect("body.v_hub[1]", "wheel.W"),
                      "unit mismatch: body.v_hub[1] is in m/s, wheel.W in N"),
    "causality": (lambda b: b.connect("wheel.W", "body.Fx[1]"), "wheel.W is not an output (causality input)"),
    "connected twice": (lambda b: b.connect("body.W[1]", "wheel.W").connect("body.W[2]", "wheel.W"),
                        "input wheel.W is connected twice (also by connection 1)"),
    "not a parameter": (lambda b: b.set_parameters("wheel", {"tau": 1.0}), "wheel.tau is not a parameter"),
    "not a port": (lambda b: b.connect("bodyW", "wheel.W"), "'bodyW': expected \"instance.variable\""),
    "name twice": (lambda b: b.add_fmu("wheel", "x.fmu"), "add_fmu('wheel'): name 'wheel' is used twice"),
    "step too long": (lambda b: b.simulation(step=2.0), "step: 2.0 s is longer than the run"),
    "undriven input": (lambda b: b.build(), "is neither connected nor given a value"),
    "not a block": (lambda b: b.add_block("gain", 2.0), "add_block('gain'): 2.0 is not a block"),
}


@pytest.mark.parametrize("case", sorted(BAD_CALLS))
def test_the_builder_refuses_what_the_parser_refuses_naming_the_call(fmu_dir, fmus, case):
    call, expected = BAD_CALLS[case]
    with pytest.raises(SystemFileError) as error:
        call(_open(fmu_dir))
    assert str(error.value).startswith("mine: ") and expected in str(error.value), str(error.value)


def test_an_algebraic_loop_is_refused_for_explicit_masters_and_kept_for_the_iterative_one():
    def looped(algorithm: str) -> System:
        builder = SystemBuilder("loop").simulation(stop_time=0.01, step=1e-3, algorithm=algorithm)
        builder.add_block("a", _Gain()).add_block("b", _Gain())
        return builder.connect("a.y", "b.u").connect("b.y", "a.u").build()

    with pytest.raises(SystemFileError, match=r"loop: connections: algebraic loop .*a\.y -> b\.u -> b\.y -> a\.u"):
        looped("jacobi")
    loop = looped("iterative").algebraic_loop
    assert loop is not None and {str(p) for p in loop} == {"a.u", "a.y", "b.u", "b.y"}


class _Gain:
    """y = u / 2 (a feedthrough block without units)."""

    inputs, outputs = ("u",), ("y",)
    units: dict[str, str] = {}

    def start(self, t0: float, u0: np.ndarray) -> np.ndarray:
        return u0 / 2.0

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        return u / 2.0


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_toml_to_model_to_toml_gives_the_same_system(fmu_dir, fmus, tmp_path, name):
    system = load_system(EXAMPLES[name], fmu_dir=fmu_dir)
    written = tmp_path / f"{name}.toml"
    written.write_text(system_to_toml(system, tmp_path))
    again = load_system(written)
    assert shape(again)[1:] == shape(system)[1:] and shape(again)[0] == shape(system)[0]
    written.write_text(system_to_toml(again, tmp_path))   # and a second time: a fixed point
    assert system_to_toml(load_system(written), tmp_path) == written.read_text()


def test_a_block_object_cannot_be_written_to_a_file_and_says_so(fmu_dir, fmus):
    builder = SystemBuilder("code").simulation(stop_time=0.1, step=1e-3)
    builder.add_fmu("wheel", fmu_dir / "SingleWheel.fmu", start={"tau": 10.0}).add_block("gain", _Gain())
    system = builder.connect("wheel.Fx", "gain.u").build()
    with pytest.raises(SystemFileError, match="block 'gain' \\(_Gain\\) was built in code from an object"):
        system_to_toml(system)


def test_ssp_to_model_gives_the_same_system(fmu_dir, fmus, tmp_path):
    system = with_parameters(load_system(EXAMPLES["rover_cosim"], fmu_dir=fmu_dir), {"rover.M": 1600.0})
    again = load_ssp(export_ssp(system, tmp_path / "rover.ssp").path, tmp_path / "unpacked")
    assert [(f.name, f.path.name, f.parameters, f.start) for f in again.fmus] == \
        [(f.name, f.path.name, f.parameters, f.start) for f in system.fmus]
    assert sorted(shape(again)[2]) == sorted(shape(system)[2]) and shape(again)[1] == shape(system)[1]
    assert shape(again)[3:9] == shape(system)[3:9]


def test_changed_copies_are_checked_and_leave_the_original_alone(fmu_dir, fmus):
    system = load_system(EXAMPLES["rover_cosim"], fmu_dir=fmu_dir)
    faster = replace_settings(system, step=2e-3, threads=1)
    assert (faster.step, faster.threads) == (2e-3, 1) and system.step == 1e-3
    with pytest.raises(SystemFileError, match="threads: 0: expected a whole number from 1 to 256"):
        replace_settings(system, threads=0)
    heavier = with_parameters(system, {"rover.M": 1600.0, "soil.c": 500.0})
    assert heavier.fmu("body").parameters == {"rover.M": 1600.0}        # the body has no soil
    assert heavier.fmu("wheel3").parameters == {"soil.c": 500.0}        # a wheel has no rover.M
    assert system.fmu("body").parameters == {}


class _Peak(Observer):
    """Collects the largest normal force of wheel 1 (a metric) and the body's load on it (a port
    the shipped file does not record), and counts the points it saw."""

    ports = ("wheel1.Fz", "body.W[1]")

    def __init__(self) -> None:
        self.peak, self.load, self.points, self.finished = -np.inf, -np.inf, 0, False

    def observe(self, t: float, values: np.ndarray) -> None:
        self.peak, self.load = max(self.peak, float(values[0])), max(self.load, float(values[1]))
        self.points += 1

    def finish(self, result: Any) -> None:
        self.finished = True


def fmu_only_rover(fmu_dir: Path) -> System:
    """RoverBody + 6 Wheel at a constant 20 N·m, Jacobi: stepped from C throughout."""
    builder = SystemBuilder("constant torque").simulation(stop_time=0.3, step=1e-3, algorithm="jacobi", threads=2)
    for wheel in add_rover(builder, fmu_dir / "RoverBody.fmu", fmu_dir / "Wheel.fmu", 6, None):
        builder.set_start(wheel, {"tau": 20.0})
    return builder.set_start("body", {f"tau[{i}]": 20.0 for i in range(1, 7)}).build()


@pytest.mark.parametrize("plant", ["with a Python block", "stepped from C throughout"])
def test_observers_collect_a_metric_and_stop_a_run_without_changing_it(fmu_dir, fmus, plant):
    if plant == "with a Python block":
        system = replace_settings(load_system(EXAMPLES["rover_cosim"], fmu_dir=fmu_dir), stop_time=0.3)
    else:
        system = fmu_only_rover(fmu_dir)
    plain = run(system)
    peak = _Peak()
    watched = run(system, observers=[peak])  # an observer of every step: the run steps one by one
    pd.testing.assert_frame_equal(plain.data, watched.data, check_exact=True)   # watching changes nothing
    assert peak.finished and peak.points == len(plain.data) and peak.peak == plain.data["wheel1.Fz"].max()
    assert abs(peak.load - peak.peak) < 1e-6 * peak.peak  # the wheel carries the load it is given
    x = plain.data["body.x"].to_numpy()
    limit = float(x[150])
    assert limit > x[0]
    stopped = run(system, observers=[StopWhen("body.x", lambda value: value >= limit)])
    reached = int(np.argmax(x >= limit))
    assert stopped.stopped is not None and stopped.stopped.startswith("body.x = ")
    assert len(stopped.data) == reached + 1 and stopped.steps == reached
    pd.testing.assert_frame_equal(stopped.data, plain.data.iloc[:reached + 1], check_exact=True)


def test_an_observer_of_an_unknown_port_is_refused(fmu_dir, fmus):
    system = replace_settings(load_system(EXAMPLES["rover_cosim"], fmu_dir=fmu_dir), stop_time=0.01)
    with pytest.raises(ValueError, match="observer StopWhen: port 'body.vv'"):
        run(system, observers=[StopWhen("body.vv", lambda v: v > 1)])


def test_the_model_file_is_a_typed_object_with_a_schema_version(identified, tmp_path):
    path = identified.files[0].parent / "model.json"
    models = ModelSet.read(path)
    assert models.recommended == "quadratic" and set(models.longitudinal) == {"quadratic", "linear"}
    assert models.lateral is not None and models.details["fmu"]["sha256"]
    again = ModelSet.from_json(models.to_json())
    assert again.to_json() == models.to_json() == path.read_bytes()
    np.testing.assert_array_equal(again.model().gain, models.model("quadratic").gain)
    newer = path.read_text().replace(f'"schema_version": {SCHEMA_VERSION}', f'"schema_version": {SCHEMA_VERSION + 1}')
    with pytest.raises(ModelFileError, match=f"schema_version {SCHEMA_VERSION + 1}: this rover-cosim reads"):
        ModelSet.from_json(newer, "newer.json")
    with pytest.raises(ModelFileError, match="not found"):
        ModelSet.read(tmp_path / "none.json")
    with pytest.raises(ModelFileError, match="model 'cubic' not in it"):
        models.model("cubic")


@pytest.mark.parametrize("package", ["orchestrator", "terramechanics", "identification", "fmubuild"])
def test_the_layer_folders_refuse_their_top_level_name(package):
    done = subprocess.run([sys.executable, "-c", f"import {package}"], cwd=REPOSITORY, capture_output=True,
                          text=True, check=False)
    assert done.returncode != 0 and f"import rover_cosim.{package}, not {package}" in done.stderr, done.stderr


def test_the_guides_example_builds_and_runs_the_co_simulated_rover(fmus, monkeypatch, capsys):
    """The co-simulation guide's ~15 lines, executed as written (FMUs in fmus/ of the checkout)."""
    text = (REPOSITORY / "docs" / "guide" / "cosimulation.md").read_text()
    begin = text.index("from rover_cosim.jobs.plants import add_rover")
    example = text[begin:text.index("```", begin)]
    assert len(example.strip().splitlines()) <= 15
    monkeypatch.chdir(REPOSITORY)
    namespace: dict[str, Any] = {}
    exec(compile(example, "cosimulation.md", "exec"), namespace)  # noqa: S102 - our own documentation
    result = namespace["result"]
    assert result.stopped.startswith("body.x = ") and result.data["body.v"].iloc[-1] > 0
    assert result.data["body.x"].iloc[-2] < 1.0 <= result.data["body.x"].iloc[-1]
    assert "wheel1.slip" in capsys.readouterr().out


def test_an_angle_may_be_given_in_degrees_as_set_takes_it(fmu_dir, fmus):
    import math

    system = (SystemBuilder("deg").simulation(stop_time=0.1, step=0.01)
              .add_fmu("w", fmu_dir / "SingleWheel.fmu", parameters={"soil.phi_deg": 35.0},
                       start={"tau": 10.0, "W": 400.0}).build())
    assert system.fmus[0].parameters["soil.phi"] == math.radians(35.0)
    with pytest.raises(SystemFileError, match="expected a number of degrees"):
        SystemBuilder("bad").add_fmu("w", fmu_dir / "SingleWheel.fmu", parameters={"soil.phi_deg": "35"})


def test_an_fmus_description_is_read_once_per_version_of_its_file(fmus, tmp_path, monkeypatch):
    """Systems built on one FMU share its reading (a job builds many); a file replaced is read again."""
    import shutil

    import fmpy

    from rover_cosim.orchestrator import builder

    reads: list[str] = []
    original = fmpy.read_model_description

    def counted(filename: str, *args: Any, **kwargs: Any) -> Any:
        reads.append(filename)
        return original(filename, *args, **kwargs)

    monkeypatch.setattr(builder.fmpy, "read_model_description", counted)
    fmu = tmp_path / "Wheel.fmu"
    shutil.copy(fmus["Wheel"], fmu)
    first = builder.read_fmu(fmu, "a")[0]
    assert builder.read_fmu(fmu, "b")[0] is first and len(reads) == 1
    replaced = tmp_path / "other.fmu"
    shutil.copy(fmus["RoverBody"], replaced)
    replaced.replace(fmu)  # another FMU under the same name
    again = builder.read_fmu(fmu, "c")[0]
    assert len(reads) == 2 and again.modelName != first.modelName
