"""The FMUs of `make fmus` (built-in backend): FMI 2.0 conformance as FMPy checks it, ME and CS
runs, agreement with the numpy reference wheel and with rumoca's simulation of the same Modelica,
an independent importer (libcosimpy), and the runtime's contract (errors through the logger,
FMU state, reset, directional derivatives, instances in threads)."""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
import threading
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy.fmi2 import (
    FMU2Model,
    FMU2Slave,
    defaultCallbacks,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.validation import validate_fmu

from rover_cosim.fmubuild import build, catalog, source
from rover_cosim.fmubuild.expressions import UnsupportedConstruct
from rover_cosim.terramechanics import Wheel, slip_ratio, wheel_forces, wheel_state

STEP_LOADS = (275.0, 575.0, 875.0)


def variables(path: Path) -> dict[str, fmpy.model_description.ScalarVariable]:
    return {v.name: v for v in fmpy.read_model_description(str(path)).modelVariables}


def assert_close(name: str, got: np.ndarray, ref: np.ndarray, rtol: float, atol: float) -> None:
    error = np.abs(got - ref)
    bound = rtol * np.abs(ref) + atol
    worst = int(np.argmax(error - bound))
    assert np.all(error <= bound), f"{name}: {got[worst]!r} vs reference {ref[worst]!r} at row {worst}"


# --- conformance --------------------------------------------------------------------------------

@pytest.mark.parametrize("name", build.FMU_MODELS)
def test_fmpy_validation_reports_no_problem(fmus, name: str):
    assert validate_fmu(str(fmus[name])) == []


@pytest.mark.parametrize("name", build.FMU_MODELS)
def test_fmu_is_me_and_cs_with_sources_units_and_solver_parameters(fmus, name: str):
    md = fmpy.read_model_description(str(fmus[name]))
    assert md.modelExchange is not None and md.coSimulation is not None
    assert md.coSimulation.providesDirectionalDerivative and md.coSimulation.canGetAndSetFMUstate
    with zipfile.ZipFile(fmus[name]) as archive:
        members = set(archive.namelist())
        root = ET.fromstring(archive.read("modelDescription.xml"))
    for kind in ("ModelExchange", "CoSimulation"):
        listed = [f.get("name") for f in root.findall(f"{kind}/SourceFiles/File")]
        assert "fmi2_api.c" in listed and all(f"sources/{f}" in members for f in listed)
    assert {"sources/fmi2_api.c", "sources/core.h", "sources/instance.c", "sources/model_casadi.c",
            "sources/model.h"} <= members
    assert f"binaries/{build.platform_folder()}/{name}{build.shared_library_suffix()}" in members
    reals = [v for v in md.modelVariables if v.type == "Real"]
    assert all(v.unit is not None for v in reals), [v.name for v in reals if v.unit is None]
    names = {v.name: v for v in md.modelVariables}
    assert names["solver.tolerance"].causality == "parameter" and names["solver.maxStep"].unit == "s"
    assert len(md.derivatives) == sum(v.derivative is not None for v in md.modelVariables) > 0


@pytest.mark.parametrize("name", ["SingleWheel", "Wheel", "Rover"])
def test_fmu_metadata_carries_ranges_display_units_and_its_documentation(fmus, name: str):
    """min/max of every soil and wheel parameter from the one range table, angles shown in deg
    (declared in UnitDefinitions), documentation/index.html listing the variables with units."""
    from rover_cosim.terramechanics.library import MODELICA_NAMES
    from rover_cosim.terramechanics.parameters import RANGES

    md = fmpy.read_model_description(str(fmus[name]))
    names = {v.name: v for v in md.modelVariables}
    prefix = next(p for p in ("soil.", "rover.soil.", "wheel1.soil.") if f"{p}c" in names)
    for field, (low, high) in RANGES.items():
        kind = "wheel." if field in ("r", "b", "J", "grouser_height", "grouser_count") else "soil."
        variable = names[prefix.replace("soil.", kind) + MODELICA_NAMES.get(field, field)]
        declared = tuple(None if b is None else float(b) for b in (variable.min, variable.max))  # FMPy keeps text
        assert declared == (low, high), variable.name
    phi = names[f"{prefix}phi"]
    assert phi.displayUnit == "deg" and phi.unit == "rad"
    rad = next(u for u in md.unitDefinitions if u.name == "rad")
    assert any(d.name == "deg" and abs(d.factor - 57.29577951308232) < 1e-12 for d in rad.displayUnits)
    with zipfile.ZipFile(fmus[name]) as archive:
        page = archive.read("documentation/index.html").decode()
    assert f"<h1>{name}</h1>" in page and f"{prefix}phi" in page and "rad (shown in deg)" in page


def test_model_description_interfaces_match_the_users_guide(fmus):
    """The interfaces the UsersGuide (UsersGuide.Models) promises (spot checks per FMU)."""
    single = variables(fmus["SingleWheel"])
    assert single["tau"].causality == "input" and single["tau"].unit == "N.m"
    assert single["W"].causality == "parameter" and single["W"].unit == "N"
    outputs = {n for n, v in single.items() if v.causality == "output"}
    assert {"Fx", "Fz", "Tx", "slip", "sinkage", "omega", "v"} <= outputs
    wheel = variables(fmus["Wheel"])
    assert {n for n, v in wheel.items() if v.causality == "input"} == {"tau", "W", "v_hub", "v_lat", "soilShare",
                                                                       "rutDepth"}
    body = variables(fmus["RoverBody"])
    assert {f"Fx[{i}]" for i in range(1, 7)} <= {n for n, v in body.items() if v.causality == "input"}
    assert {f"W[{i}]" for i in range(1, 7)} <= {n for n, v in body.items() if v.causality == "output"}
    rover = variables(fmus["Rover"])
    assert ({f"tau[{i}]" for i in range(1, 7)} | {f"rutDepth[{i}]" for i in range(1, 7)}
            == {n for n, v in rover.items() if v.causality == "input"})


@pytest.mark.parametrize("name", build.FMU_MODELS)
def test_fmpy_simulates_each_fmu_as_cs_and_as_me_with_the_same_result(fmus, name: str):
    torques, forces = {f"tau[{i}]": 40.0 for i in range(1, 7)}, {f"Fx[{i}]": 20.0 for i in range(1, 7)}
    inputs = {"SingleWheel": {"tau": 40.0}, "Wheel": {"tau": 40.0, "W": 424.0, "v_hub": 0.2},
              "RoverBody": {f"Fx[{i}]": 20.0 for i in range(1, 7)},
              "Rover": {f"tau[{i}]": 40.0 for i in range(1, 7)},
              "SteerableRover": {**{f"tau[{i}]": 40.0 for i in range(1, 7)}, "steer[1]": 0.05, "steer[4]": 0.05},
              "SteerableRoverBody": {**{f"Fx[{i}]": 20.0 for i in range(1, 7)}, "Fy[1]": 15.0, "steer[3]": -0.05},
              "LegWheelRover": {**torques, "ankleSteer[1]": 1.25, "kneePitch[2]": 2.5},
              "LegWheelRoverBody": {**forces, "Fy[1]": 15.0, "hipPitch[3]": -0.4}}[name]
    runs = {kind: fmpy.simulate_fmu(str(fmus[name]), fmi_type=kind, stop_time=0.3,
                                    output_interval=0.01, start_values=inputs, relative_tolerance=1e-8)
            for kind in ("CoSimulation", "ModelExchange")}
    cs, me = runs["CoSimulation"], runs["ModelExchange"]
    assert len(cs) == len(me) >= 30
    for column in cs.dtype.names[1:]:
        assert np.all(np.isfinite(cs[column])), column
        scale = max(1.0, float(np.abs(me[column]).max()))
        np.testing.assert_allclose(cs[column], me[column], rtol=0, atol=1e-4 * scale, err_msg=column)


# --- physics against the references -------------------------------------------------------------

def single_wheel_step(path: Path, load: float, torque: float, stop: float = 2.0) -> np.ndarray:
    """CS at a 1 ms communication step (FMPy's output_interval), torque constant from t = 0."""
    return fmpy.simulate_fmu(str(path), stop_time=stop, output_interval=1e-3,
                             start_values={"W": load, "tau": torque})


@pytest.mark.parametrize("load", STEP_LOADS)
def test_single_wheel_fmu_step_agrees_with_the_reference_wheel(fmus, load: float):
    """Torque step from rest (60 N·m): every recorded (sinkage, Fx, Fz, Tx) equals
    terramechanics.wheel_forces at the same load, spin and speed within 0.5 % (absolute floors of
    0.1 µm and 1 mN for values passing through zero); the slip is Eq. (4) of the recorded speeds."""
    result = single_wheel_step(fmus["SingleWheel"], load, 60.0)
    slip = result["slip"]
    assert slip.max() > 0.02  # the step really drives the wheel
    state = wheel_forces(np.full(slip.shape, load), result["omega"], result["v"])
    assert_close("sinkage", result["sinkage"], state.sinkage, 0.005, 1e-7)
    assert_close("Fx", result["Fx"], state.Fx, 0.005, 1e-3)
    assert_close("Fz", result["Fz"], state.Fz, 0.005, 1e-3)
    assert_close("Tx", result["Tx"], state.Tx, 0.005, 1e-3)
    np.testing.assert_allclose(slip, slip_ratio(Wheel().r * result["omega"], result["v"], 1e-3), rtol=0, atol=1e-12)


@pytest.mark.parametrize("load", STEP_LOADS)
def test_single_wheel_fmu_trajectories_agree_with_rumoca(fmus, load: float):
    """The FMU (CS, 1 ms, integrator tolerance 1e-8) against rumoca's simulation of
    Examples.SingleWheelStep (its annotation's tolerance 1e-8) with the same load and torque,
    at rumoca's output times."""
    torque = 60.0
    reference = source.simulate(f"{source.PACKAGE}.Examples.SingleWheelStep", params={"W": load, "tauStep": torque},
                                stop=2.0, interval=0.01)
    result = fmpy.simulate_fmu(str(fmus["SingleWheel"]), stop_time=2.0, output_interval=0.01,
                               start_values={"W": load, "tau": torque, "solver.tolerance": 1e-8})
    times = reference.index.to_numpy()
    for column, atol in (("slip", 1e-4), ("v", 1e-5), ("omega", 1e-4), ("Fx", 0.05), ("sinkage", 1e-6)):
        got = np.interp(times, result["time"], result[column])
        ref = reference[f"testBed.{column}"].to_numpy()
        assert_close(column, got, ref, 1e-3, atol)


@pytest.mark.parametrize("values", [{"tau": 20.0, "v_hub": 0.0}, {"tau": 2.0, "v_hub": 0.0},
                                    {"tau": -20.0, "v_hub": 0.5}], ids=["held-hub", "creep", "braking"])
def test_cs_integrator_copes_with_stiff_wheel_spin_at_low_speed(fmus, values: dict[str, float]):
    """A wheel whose hub is held (v = 0) sits in the regularised slip region, where
    d(slip)/d(omega) = r/vEps = 355 s: stiff. The Co-Simulation integrator keeps to about one
    step per 1 ms communication step (an explicit method would need hundreds) and agrees with
    FMPy's CVODE on the Model Exchange interface at 1e-10."""
    start = {"W": 424.0, **values}
    messages: list[bytes] = []
    cs = fmpy.simulate_fmu(str(fmus["Wheel"]), stop_time=1.0, output_interval=1e-3, start_values=start,
                           debug_logging=True, logger=lambda *args: messages.append(args[-1]))
    me = fmpy.simulate_fmu(str(fmus["Wheel"]), fmi_type="ModelExchange", stop_time=1.0, output_interval=1e-3,
                           start_values=start, relative_tolerance=1e-10)
    for column, atol in (("omega", 1e-4), ("slip", 1e-4), ("Fx", 0.05)):
        assert_close(column, cs[column], me[column], 1e-4, atol)
    statistics = [m.decode() for m in messages if b"integrator:" in m]
    assert len(statistics) == 1, messages
    steps = int(statistics[0].split("integrator: ")[1].split(" steps")[0])
    assert 1000 <= steps < 3000, statistics[0]


def open_loop_torque(t: np.ndarray) -> np.ndarray:
    """Examples.openLoopTorque with its defaults: 40 N·m, blended (tanh, 0.3 s) to 9 N·m at 3 s."""
    return 9.0 + (40.0 - 9.0) * 0.5 * (1.0 - np.tanh((t - 3.0) / 0.3))


def test_rover_fmu_follows_rumocas_open_loop_rover(fmus):
    """Rover.fmu (CS at a 1 ms communication step) driven by openLoopTorque against rumoca's
    simulation of Examples.RoverOpenLoop over its 6 s experiment. The inputs are held over each
    step (FMPy sets them at the step's start), so the signal is sampled at mid-step: the hold
    then errs to second order only (sampled at the step's start, v would be off by ~2e-4 m/s)."""
    reference = source.simulate(f"{source.PACKAGE}.Examples.RoverOpenLoop")
    step = 1e-3
    times = np.arange(0.0, 6.0 + step, step)
    signal = np.zeros(times.size, dtype=[("time", float)] + [(f"tau[{i}]", float) for i in range(1, 7)])
    signal["time"] = times
    for i in range(1, 7):
        signal[f"tau[{i}]"] = open_loop_torque(times + step / 2)
    # FMPy's Co-Simulation communication step is its output_interval.
    result = fmpy.simulate_fmu(str(fmus["Rover"]), stop_time=6.0, output_interval=step, input=signal,
                               start_values={"solver.tolerance": 1e-8})
    at = reference.index.to_numpy()
    for column, atol in (("v", 1e-6), ("x", 1e-5), ("Fz[1]", 2e-3), ("Fz[3]", 2e-3), ("pitch", 1e-7),
                         ("slip[2]", 2e-5), ("omega[1]", 1e-5)):
        got = np.interp(at, result["time"], result[column])
        assert_close(column, got, reference[f"rover.{column}"].to_numpy(), 0.0, atol)
    assert result["v"].max() > 0.9


def test_libcosimpy_runs_single_wheel_and_reports_what_fmpy_reports(fmus):
    """Open Simulation Platform's libcosim (an independent FMI importer) steps SingleWheel.fmu at
    1 ms and ends with the same outputs as FMPy."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    path = str(fmus["SingleWheel"])
    refs = {name: v.valueReference for name, v in variables(fmus["SingleWheel"]).items()}
    execution = CosimExecution.from_step_size(int(1e6))  # ns
    index = execution.add_local_slave(CosimLocalSlave(fmu_path=path, instance_name="wheel"))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    execution.real_initial_value(index, refs["W"], 575.0)
    execution.real_initial_value(index, refs["tau"], 60.0)
    assert execution.simulate_until(int(0.5e9))
    names = ["v", "omega", "slip", "sinkage", "Fx", "Fz", "Tx"]
    cosim = dict(zip(names, observer.last_real_values(index, [refs[n] for n in names])))
    result = single_wheel_step(fmus["SingleWheel"], 575.0, 60.0, stop=0.5)
    for name in names:
        assert cosim[name] == pytest.approx(float(result[name][-1]), rel=1e-9, abs=1e-12), name
    assert cosim["v"] > 0.1


# --- the runtime's contract ---------------------------------------------------------------------

class Messages:
    """A logger that records what the FMU reports."""

    def __init__(self) -> None:
        self.lines: list[tuple[int, str]] = []
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(self)
        self.callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self.callbacks.freeMemory = defaultCallbacks.freeMemory

    def __call__(self, env, instance, status, category, message) -> None:
        self.lines.append((status, message.decode()))

    def errors(self) -> list[str]:
        return [m for s, m in self.lines if s >= 3]


def unpacked(fmus, name: str, tmp_path: Path) -> tuple[str, fmpy.model_description.ModelDescription]:
    """The FMU extracted under tmp_path (once: later instances load the same binary)."""
    folder = tmp_path / name
    if not folder.exists():
        fmpy.extract(str(fmus[name]), str(folder))
    return str(folder), fmpy.read_model_description(str(fmus[name]))


def slave(fmus, name: str, tmp_path: Path, messages: Messages, instance: str = "a") -> tuple[FMU2Slave, dict[str, int]]:
    folder, md = unpacked(fmus, name, tmp_path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=name, instanceName=instance)
    fmu.instantiate(callbacks=messages.callbacks)
    return fmu, {v.name: v.valueReference for v in md.modelVariables}


def test_errors_come_through_the_logger_as_fmi2error_not_crashes(fmus, tmp_path):
    messages = Messages()
    fmu, vr = slave(fmus, "SingleWheel", tmp_path, messages)
    with pytest.raises(Exception, match="status 3"):
        fmu.setReal([vr["W"]], [float("nan")])
    assert any("W = nan" in m and "finite" in m for m in messages.errors())
    with pytest.raises(Exception, match="status 3"):
        fmu.setReal([9999], [1.0])
    assert any("9999" in m for m in messages.errors())
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    with pytest.raises(Exception, match="status 3"):
        fmu.setReal([vr["W"]], [500.0])  # fixed parameter after initialization
    assert any("fixed parameter" in m for m in messages.errors())
    with pytest.raises(Exception, match="status 3"):
        fmu.doStep(0.0, -1e-3)
    assert any("communication step size" in m for m in messages.errors())
    with pytest.raises(Exception, match="status 3"):
        fmu.setReal([vr["solver.tolerance"]], [2.0])
    fmu.doStep(0.0, 1e-3)  # still usable after rejected calls
    fmu.terminate()
    fmu.freeInstance()


def test_wrong_guid_is_refused_with_a_message(fmus, tmp_path):
    folder, _ = unpacked(fmus, "Wheel", tmp_path)
    messages = Messages()
    fmu = FMU2Slave(guid="{not-the-guid}", unzipDirectory=folder, modelIdentifier="Wheel", instanceName="w")
    with pytest.raises(Exception, match="Failed to instantiate"):
        fmu.instantiate(callbacks=messages.callbacks)
    assert any("GUID" in m for m in messages.errors())


def run_steps(fmu: FMU2Slave, vr: dict[str, int], t0: float, steps: int, names: list[str]) -> np.ndarray:
    rows = []
    for k in range(steps):
        fmu.doStep(t0 + k * 1e-3, 1e-3)
        rows.append(fmu.getReal([vr[n] for n in names]))
    return np.array(rows)


def started(fmus, name: str, tmp_path: Path, values: dict[str, float], instance: str = "a"):
    messages = Messages()
    fmu, vr = slave(fmus, name, tmp_path, messages, instance)
    fmu.setupExperiment(startTime=0.0)
    fmu.setReal([vr[k] for k in values], list(values.values()))
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu, vr


def test_fmu_state_get_set_and_serialize_reproduce_the_trajectory(fmus, tmp_path):
    fmu, vr = started(fmus, "SingleWheel", tmp_path, {"W": 575.0, "tau": 60.0})
    names = ["v", "omega", "slip", "Fx"]
    run_steps(fmu, vr, 0.0, 100, names)
    state = fmu.getFMUstate()
    first = run_steps(fmu, vr, 0.1, 100, names)
    fmu.setFMUstate(state)
    again = run_steps(fmu, vr, 0.1, 100, names)
    np.testing.assert_array_equal(first, again)
    serialized = fmu.serializeFMUstate(state)
    fmu.freeFMUstate(state)
    restored = fmu.deSerializeFMUstate(serialized)
    fmu.setFMUstate(restored)
    np.testing.assert_array_equal(run_steps(fmu, vr, 0.1, 100, names), first)
    fmu.freeFMUstate(restored)
    fmu.terminate()
    fmu.freeInstance()


STATISTICS = ["statistics.evaluations", "statistics.reusedEvaluations", "statistics.jacobians", "statistics.steps",
              "statistics.rejectedSteps"]


def test_outputs_after_a_step_reuse_its_last_evaluation_and_match_a_fresh_one(fmus, tmp_path):
    """The runtime keeps the model's last evaluation with its exact (t, x, u): the outputs right
    after a step are those of the step's last stage (no new evaluation), a new input value makes
    the next step evaluate again, and the values equal those of a fresh instance restored to the
    same state (which has nothing to reuse)."""
    fmu, vr = started(fmus, "Wheel", tmp_path, {"W": 575.0, "tau": 40.0, "v_hub": 0.3})
    stats = [vr[n] for n in STATISTICS]
    outputs = [vr[n] for n in ("Fx", "sinkage", "slip", "Tx")]
    fmu.doStep(0.0, 1e-3)
    before = fmu.getReal(stats)
    first = fmu.getReal(outputs)
    fmu.getReal(outputs)
    assert fmu.getReal(stats) == before  # nothing evaluated for the outputs
    fmu.doStep(1e-3, 1e-3)
    stepped = fmu.getReal(stats)
    # The stages of at least one step, and the outputs at its end answered by the last one.
    assert stepped[3] >= before[3] + 1 and stepped[0] >= before[0] + 2 and stepped[1] == before[1] + 1
    state = fmu.getFMUstate()
    second = fmu.getReal(outputs)
    other, _ = started(fmus, "Wheel", tmp_path, {"W": 575.0, "tau": 40.0, "v_hub": 0.3}, instance="b")
    other.setFMUstate(state)
    assert other.getReal(stats) == stepped  # the statistics come with the state
    assert other.getReal(outputs) == second  # bit for bit: a fresh evaluation at the same point
    assert other.getReal([vr["statistics.evaluations"]])[0] == stepped[0] + 1  # (none to reuse there)
    assert first != second
    with pytest.raises(Exception, match="status 3"):
        fmu.setReal([vr["statistics.steps"]], [0.0])
    fmu.freeFMUstate(state)
    for instance in (fmu, other):
        instance.terminate()
        instance.freeInstance()


MEMORIES = ["logSinkageStart", "slopeStart"]


def test_warm_started_sinkage_solve_gives_the_cold_result_with_fewer_evaluations(fmus, tmp_path):
    """Warm start: the runtime holds each wheel's last sinkage solve (log h and slope, the memories
    of RigidWheel) from the end of the previous step and starts the next solve there. A fresh
    instance at the same state and inputs (cold start, Bekker's sinkage) gives the same forces to
    the solve's tolerance with more force evaluations; the memories are read-only and come back
    with the FMU state, and reset forgets them."""
    values = {"W": 575.0, "tau": 40.0, "v_hub": 0.3}
    fmu, vr = started(fmus, "Wheel", tmp_path, values)
    assert fmu.getReal([vr[m] for m in MEMORIES]) == [0.0, 0.0]  # cold before the first step
    outputs = [vr[n] for n in ("Fx", "Fz", "Tx", "sinkage", "slip", "entryAngle")]
    warm_counts = []
    for k in range(300):
        t = k * 1e-3
        fmu.setReal([vr["tau"], vr["v_hub"]], [40.0 + 10.0 * np.sin(20.0 * t), 0.3 + 0.2 * t])
        fmu.doStep(t, 1e-3)
        warm_counts.append(fmu.getReal([vr["contactEvaluations"]])[0])
    log_h, slope = fmu.getReal([vr[m] for m in MEMORIES])
    assert slope > 0 and log_h == np.log(fmu.getReal([vr["sinkage"]])[0])
    warm = np.array(fmu.getReal(outputs))
    at_end = dict(zip(("tau", "W", "v_hub", "omega"), fmu.getReal([vr[n] for n in ("tau", "W", "v_hub", "omega")])))
    cold_fmu, _ = started(fmus, "Wheel", tmp_path, at_end, instance="cold")
    cold = np.array(cold_fmu.getReal(outputs))
    cold_count = cold_fmu.getReal([vr["contactEvaluations"]])[0]
    np.testing.assert_allclose(warm, cold, rtol=1e-8, atol=1e-12)
    assert np.mean(warm_counts[50:]) <= cold_count - 1, (np.mean(warm_counts[50:]), cold_count)
    with pytest.raises(Exception, match="status 3"):
        fmu.setReal([vr["slopeStart"]], [1.0])
    state = fmu.getFMUstate()
    cold_fmu.setFMUstate(state)
    assert cold_fmu.getReal([vr[m] for m in MEMORIES]) == [log_h, slope]
    fmu.freeFMUstate(state)
    fmu.reset()
    assert fmu.getReal([vr[m] for m in MEMORIES]) == [0.0, 0.0]
    fmu.freeInstance()
    cold_fmu.terminate()
    cold_fmu.freeInstance()


def test_reset_returns_to_the_start(fmus, tmp_path):
    fmu, vr = started(fmus, "SingleWheel", tmp_path, {"W": 275.0, "tau": 30.0})
    first = run_steps(fmu, vr, 0.0, 50, ["v", "slip"])
    fmu.reset()
    fmu.setupExperiment(startTime=0.0)
    fmu.setReal([vr["W"], vr["tau"]], [275.0, 30.0])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    np.testing.assert_array_equal(run_steps(fmu, vr, 0.0, 50, ["v", "slip"]), first)
    fmu.terminate()
    fmu.freeInstance()


def test_directional_derivatives_match_finite_differences(fmus, tmp_path):
    """d(outputs, derivatives)/d(states, inputs) of Wheel.fmu from fmi2GetDirectionalDerivative
    against central differences of fmi2GetReal (Model Exchange)."""
    folder, md = unpacked(fmus, "Wheel", tmp_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Model(guid=md.guid, unzipDirectory=folder, modelIdentifier="Wheel", instanceName="me")
    messages = Messages()  # kept alive while the FMU may call its logger
    fmu.instantiate(callbacks=messages.callbacks)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.enterContinuousTimeMode()
    base = {"tau": 30.0, "W": 424.0, "v_hub": 0.3}
    fmu.setReal([vr[k] for k in base], list(base.values()))
    fmu.setContinuousStates((ctypes.c_double * 1)(2.0), 1)
    unknowns = ["der(omega)", "Fx", "Tx", "slip", "sinkage"]
    for known, step in (("omega", 1e-5), ("W", 1e-3), ("v_hub", 1e-6), ("tau", 1e-4)):
        analytic = fmu.getDirectionalDerivative([vr[u] for u in unknowns], [vr[known]], [1.0])

        def at(value: float, known: str = known) -> np.ndarray:
            if known == "omega":
                fmu.setContinuousStates((ctypes.c_double * 1)(value), 1)
            else:
                fmu.setReal([vr[known]], [value])
            return np.array(fmu.getReal([vr[u] for u in unknowns]))

        centre = 2.0 if known == "omega" else base[known]
        numeric = (at(centre + step) - at(centre - step)) / (2 * step)
        at(centre)
        np.testing.assert_allclose(analytic, numeric, rtol=1e-4, atol=1e-6, err_msg=known)
    fmu.terminate()
    fmu.freeInstance()


def test_instances_in_parallel_threads_do_not_share_state(fmus, tmp_path):
    """Two instances of one binary stepped concurrently in two threads give what each gives alone."""
    loads = (275.0, 875.0)
    alone = []
    for i, load in enumerate(loads):
        fmu, vr = started(fmus, "SingleWheel", tmp_path / f"seq{i}", {"W": load, "tau": 60.0})
        alone.append(run_steps(fmu, vr, 0.0, 300, ["v", "slip", "sinkage"]))
        fmu.freeInstance()
    together: dict[int, np.ndarray] = {}
    pairs = [started(fmus, "SingleWheel", tmp_path / "par", {"W": load, "tau": 60.0}, instance=f"i{i}")
             for i, load in enumerate(loads)]

    def work(i: int) -> None:
        fmu, refs = pairs[i]
        together[i] = run_steps(fmu, refs, 0.0, 300, ["v", "slip", "sinkage"])

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for i in range(2):
        np.testing.assert_array_equal(together[i], alone[i])
    assert not np.allclose(alone[0], alone[1])


def test_fmu_sources_rebuild_the_binary(fmus, tmp_path):
    """The C sources inside the FMU compile on their own into a binary that runs (RoverBody)."""
    folder, _ = unpacked(fmus, "RoverBody", tmp_path)
    sources = Path(folder) / "sources"
    library = Path(folder) / "binaries" / build.platform_folder() / "RoverBody.so"
    library.unlink()
    subprocess.run([build.compiler(), "-O1", "-fPIC", "-shared", "-I", str(sources),
                    *map(str, sorted(sources.glob("*.c"))), "-o", str(library), "-lm"], check=True)
    result = fmpy.simulate_fmu(folder, stop_time=0.2, output_interval=1e-3,
                               start_values={f"Fx[{i}]": 20.0 for i in range(1, 7)})
    reference = fmpy.simulate_fmu(str(fmus["RoverBody"]), stop_time=0.2, output_interval=1e-3,
                                  start_values={f"Fx[{i}]": 20.0 for i in range(1, 7)})
    np.testing.assert_allclose(result["v"], reference["v"], rtol=1e-12, atol=1e-15)
    assert result["v"][-1] > 0


# --- the build ----------------------------------------------------------------------------------

def test_unchanged_sources_are_not_rebuilt(fmu_dir, fmus):
    before = {name: path.stat().st_mtime_ns for name, path in fmus.items()}
    results = build.build_all(build.FMU_MODELS, fmu_dir, backend="builtin", jobs=1)
    assert [r.rebuilt for r in results] == [False] * len(build.FMU_MODELS)
    assert {r.name: r.path.stat().st_mtime_ns for r in results} == before


BAD_PACKAGE = """package Bad
end Bad;
"""
BAD_FMUS = """within Bad;
package FMUs
end FMUs;
"""
BAD_MODEL = """within Bad.FMUs;
model SingleWheel "a model with an event"
  input Real tau(unit="N.m");
  Real omega(start=0, unit="rad/s");
equation
  der(omega) = tau;
  when omega > 1 then
    terminate("spun up");
  end when;
end SingleWheel;
"""


def test_unsupported_construct_is_rejected_and_leaves_the_output_folder_untouched(tmp_path, monkeypatch):
    root = tmp_path / "modelica"
    (root / "Bad" / "FMUs").mkdir(parents=True)
    (root / "Bad" / "package.mo").write_text(BAD_PACKAGE)
    (root / "Bad" / "package.order").write_text("FMUs\n")
    (root / "Bad" / "FMUs" / "package.mo").write_text(BAD_FMUS)
    (root / "Bad" / "FMUs" / "SingleWheel.mo").write_text(BAD_MODEL)
    (root / "Bad" / "FMUs" / "package.order").write_text("SingleWheel\n")
    monkeypatch.setattr(catalog, "MODELICA_ROOT", root)  # the package's location and name live there
    monkeypatch.setattr(catalog, "PACKAGE", "Bad")
    out = tmp_path / "fmus"
    out.mkdir()
    (out / "SingleWheel.fmu").write_bytes(b"previous build")
    with pytest.raises(UnsupportedConstruct) as error:
        build.build_fmu("SingleWheel", out, force=True)
    message = str(error.value)
    assert "when" in message and "SingleWheel.mo:" in message and "omc" in message
    assert sorted(p.name for p in out.iterdir()) == ["SingleWheel.fmu"]
    assert (out / "SingleWheel.fmu").read_bytes() == b"previous build"


def test_build_cli_reports_up_to_date_fmus(fmu_dir, fmus, capsys):
    from rover_cosim.cli import main

    assert main(["build-fmus", "--out", str(fmu_dir), "--backend", "builtin", "--jobs", "1", "Wheel"]) == 0
    assert "Wheel.fmu is up to date" in capsys.readouterr().out
    assert main(["build-fmus", "--out", str(fmu_dir), "NoSuchModel"]) == 2  # bad input: nothing built
    assert "NoSuchModel" in capsys.readouterr().err


@pytest.mark.parametrize("jobs", [1, 2])
def test_a_build_reports_each_stage_as_it_ends(tmp_path, jobs):
    """build-fmus shows progress per compile step (issue 29): every FMU's stages reach the step
    callback, in order per FMU, from this process (--jobs 1) and from the pool's workers (--jobs 2),
    before its BuildResult; the CLI draws them as a bar on a terminal."""
    seen: list[tuple[str, str]] = []
    results = build.build_all(["RoverBody", "SteerableRoverBody"], tmp_path, jobs=jobs, backend="builtin",
                              step=lambda model, stage: seen.append((model, stage)))
    folder = build.host_folder()
    for model in ("RoverBody", "SteerableRoverBody"):
        assert [s for m, s in seen if m == model] == ["translate", "generate", f"compile {folder}", "package"]
    assert len(seen) == 2 * build.steps_of(["host"]) and all(r.rebuilt for r in results)
    again: list[tuple[str, str]] = []
    build.build_all(["RoverBody"], tmp_path, jobs=jobs, backend="builtin", step=lambda m, s: again.append((m, s)))
    assert again == []  # up to date: nothing to wait for


def test_build_cli_draws_a_progress_bar_on_a_terminal(tmp_path, monkeypatch, capsys):
    import io

    from rover_cosim.cli import main

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    terminal = Terminal()
    monkeypatch.setattr("sys.stderr", terminal)
    from rover_cosim.progress import ProgressBar

    defaults = {**(ProgressBar.__init__.__kwdefaults__ or {}), "delay": 0.0}  # drawn at once
    monkeypatch.setattr(ProgressBar.__init__, "__kwdefaults__", defaults)
    assert main(["build-fmus", "--out", str(tmp_path), "--backend", "builtin", "--jobs", "1", "RoverBody"]) == 0
    assert "build-fmus [" in terminal.getvalue() and "100.0%" in terminal.getvalue()
    assert "built " in capsys.readouterr().out
    quiet = Terminal()
    monkeypatch.setattr("sys.stderr", quiet)
    assert main(["build-fmus", "--out", str(tmp_path), "--force", "-q", "--jobs", "1", "RoverBody"]) == 0
    assert quiet.getvalue() == ""


def test_backend_choice_and_the_omc_script(monkeypatch):
    from rover_cosim.fmubuild.omc import script

    monkeypatch.setenv("PATH", "/nonexistent")
    assert build.resolve_backend("auto") == "builtin"
    with pytest.raises(RuntimeError, match="omc.*not on PATH"):
        build.resolve_backend("omc")
    with pytest.raises(ValueError, match="backend='cmake'"):
        build.resolve_backend("cmake")
    text = script("Rover")
    assert 'buildModelFMU(RoverTerramechanics.FMUs.Rover, version="2.0", fmuType="me_cs"' in text
    assert 'fileNamePrefix="Rover"' in text  # the FMU keeps its name and model identifier
    assert "--fmiFlags=s:cvode" in text and source.package_file().as_posix() in text


FAKE_OMC = """#!/bin/sh
# Stands in for OpenModelica: checks the script it is given and "exports" a prepared FMU.
if [ "$1" = "--version" ]; then echo "OpenModelica 0.0-stand-in"; exit 0; fi
grep -q 'buildModelFMU(RoverTerramechanics.FMUs.Wheel, version="2.0", fmuType="me_cs"' "$1" || exit 3
cp "$PREPARED_FMU" Wheel.fmu
"""


def test_omc_backend_plumbing_with_a_stand_in_omc(fmus, tmp_path, monkeypatch):
    """build_fmu_omc runs omc on its script in a scratch folder, records its inputs in the FMU and
    moves it into place; a second call is skipped. (OpenModelica itself: the hosted workflow.)"""
    from rover_cosim.fmubuild.omc import build_fmu_omc

    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / "omc").write_text(FAKE_OMC)
    (bin_dir / "omc").chmod(0o755)
    monkeypatch.setenv("PATH", f"{bin_dir}:{os.environ['PATH']}")
    monkeypatch.setenv("PREPARED_FMU", str(fmus["Wheel"]))
    out = tmp_path / "fmus"
    first = build_fmu_omc("Wheel", out)
    assert first.rebuilt and validate_fmu(str(first.path)) == []
    with zipfile.ZipFile(first.path) as archive:
        assert "omc" in archive.read(build.BUILD_RECORD).decode()
    assert not build_fmu_omc("Wheel", out).rebuilt
    assert sorted(p.name for p in out.iterdir()) == ["Wheel.fmu"]


@pytest.mark.skipif(shutil.which("omc") is None, reason="omc not on PATH")
def test_omc_backend_builds_a_single_wheel_fmu_that_agrees_with_the_reference(tmp_path):
    from rover_cosim.fmubuild.omc import build_fmu_omc

    result = build_fmu_omc("SingleWheel", tmp_path)
    assert validate_fmu(str(result.path)) == []
    out = single_wheel_step(result.path, 575.0, 60.0)
    state = wheel_state(np.full(out["slip"].shape, 575.0), out["slip"])
    assert_close("Fx", out["Fx"], state.Fx, 0.005, 1e-3)
