"""The FMUs in every motion regime (issue 13): SingleWheel, Rover and RoverBody + 6 Wheel at rest,
free rolling, reverse, braking and on slopes, cross-checked against the numpy reference test bed;
the parameter checks of the FMUs (run in a child process, so a crash would be seen); the
DefaultExperiment and the start values of the states."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import textwrap
import tomllib

import fmpy
import numpy as np
import pytest
from fmpy import fmi2

from rover_cosim.identification.reference_plant import StartState, run_reference_test_bed
from rover_cosim.identification.testbed import TorqueProfile
from rover_cosim.orchestrator.examples import example
from rover_cosim.orchestrator.master import run
from rover_cosim.orchestrator.system import system_from_dict
from rover_cosim.terramechanics import Soil, Wheel, shear_strength

R = Wheel().r
G = 1.62
OUTPUTS = ["x", "v", "omega", "Fx", "Tx", "slip", "sinkage", "entryAngle"]


def torque(value: float, name: str = "tau") -> np.ndarray:
    return np.array([(0.0, value)], dtype=[("time", float), (name, float)])


def single_wheel(fmus, stop: float, tau: float = 0.0, **start: float) -> np.ndarray:
    return fmpy.simulate_fmu(fmus["SingleWheel"], stop_time=stop, output_interval=min(0.01, stop / 100),
                             start_values=start, input=torque(tau), output=OUTPUTS)


def kinetic_energy(run: np.ndarray, load: float) -> np.ndarray:
    return 0.5 * load / G * run["v"] ** 2 + 0.5 * Wheel().J * run["omega"] ** 2


@pytest.mark.parametrize("load", [100.0, 300.0, 500.0, 700.0, 900.0])
def test_single_wheel_at_rest_stays_at_rest(fmus, load: float):
    result = single_wheel(fmus, 60.0, W=load)
    assert np.abs(result["v"]).max() < 1e-3 and abs(result["x"][-1]) < 1e-3


@pytest.mark.parametrize("load", [100.0, 424.0, 900.0])
def test_rover_at_rest_stays_at_rest(fmus, load: float):
    result = fmpy.simulate_fmu(fmus["Rover"], stop_time=60.0, start_values={"rover.M": 6 * load / G},
                               output=["x", "v", "pitch"])
    assert np.abs(result["v"]).max() < 1e-3 and abs(result["x"][-1]) < 1e-3


def test_cosimulated_rover_at_rest_stays_at_rest(fmu_dir, fmus):
    data = tomllib.loads(example("rover_cosim").read_text())
    data["simulation"].update(stop_time=60.0, step=0.01)
    for block in data["block"]:
        block.update(begin=0.0, end=0.0)  # the torque source gives zero throughout
    result = run(system_from_dict(data, name="rest.toml", base=fmu_dir)).data
    assert result["body.v"].abs().max() < 1e-3 and abs(result["body.x"].iloc[-1]) < 1e-3


@pytest.mark.parametrize("load", [100.0, 424.0, 900.0])
def test_free_rolling_slows_to_rest_never_turning_back(fmus, load: float):
    result = single_wheel(fmus, 60.0, W=load, v=1.0, omega=1.0 / R)
    # The speed never turns negative; the spin may settle through zero at numerical noise level
    # (|r omega| below 1e-6 mm/s).
    assert result["v"].min() >= 0.0 and result["omega"].min() >= -1e-6
    assert result["v"][-1] < 1e-3
    energy = kinetic_energy(result, load)
    assert np.diff(energy).max() <= 1e-9 * energy[0]


@pytest.mark.parametrize("load,tau", [(100.0, 10.0), (424.0, 30.0), (900.0, 60.0)])
def test_reverse_mirrors_forward(fmus, load: float, tau: float):
    ahead, back = single_wheel(fmus, 5.0, tau, W=load), single_wheel(fmus, 5.0, -tau, W=load)
    for name in ("v", "omega", "Fx", "Tx", "slip"):
        scale = np.abs(ahead[name]).max()
        assert np.abs(back[name] + ahead[name]).max() <= 1e-6 * scale, name
    moving = np.abs(ahead["v"]) > 1e-3
    assert (np.sign(ahead["entryAngle"][moving]) == np.sign(ahead["v"][moving])).all()
    assert (np.sign(back["entryAngle"][moving]) == np.sign(back["v"][moving])).all()


def test_braking_skids_decelerates_and_keeps_the_shear_bounded(fmus):
    load = 424.0
    result = single_wheel(fmus, 2.0, -30.0, W=load, v=1.0, omega=1.0 / R)
    moving = (result["time"] > 0.05) & (result["v"] > 0.01)
    assert moving.sum() > 100
    assert (result["slip"][moving] < 0).all() and (np.diff(result["v"][moving]) < 0).all()
    strength = shear_strength(load, result["sinkage"], Wheel(), Soil())
    assert (np.abs(result["Fx"]) <= strength * (1 + 1e-6)).all()


def test_single_wheel_matches_the_reference_test_bed_when_braking(fmus):
    """Same formulation as functions of the same state: Simpson (FMU) against Gauss-Legendre
    (numpy) quadrature leaves about 1e-4 of the forces."""
    result = single_wheel(fmus, 1.0, -30.0, v=1.0, omega=1.0 / R)
    reference = run_reference_test_bed(424.0, TorqueProfile.step(-30.0), 1.0, 0.01,
                                       start=StartState(v=1.0, omega=1.0 / R))
    for name in ("v", "omega", "Fx", "Tx", "slip"):
        scale = np.abs(reference[name]).max()
        assert np.abs(result[name] - reference[name].to_numpy()).max() <= 2e-3 * scale, name


@pytest.mark.parametrize("degrees", [5.0, 10.0, 20.0])
def test_on_a_slope_the_wheel_rolls_back_or_is_held(fmus, degrees: float):
    slope, load = math.radians(degrees), 424.0
    rolls = single_wheel(fmus, 5.0, slope=slope)
    assert rolls["v"][-1] < -0.1 and rolls["x"][-1] < -0.1
    held = single_wheel(fmus, 60.0, load * math.sin(slope) * R, slope=slope)
    assert np.abs(held["x"]).max() < 1e-3 and np.abs(held["v"]).max() < 1e-3


def test_a_slope_steeper_than_the_wheel_can_climb_slides_back(fmus):
    """At 45 degrees the most the soil gives the driven wheel is less than W sin(slope)."""
    result = single_wheel(fmus, 5.0, 120.0, slope=math.radians(45.0))
    assert result["v"][-1] < -0.5 and result["omega"][-1] > 0


def test_rover_on_a_slope_rolls_back_without_torque(fmus):
    result = fmpy.simulate_fmu(fmus["Rover"], stop_time=5.0, start_values={"slope": math.radians(10.0)},
                               output=["x", "v"])
    assert result["v"][-1] < -0.1


# --- model descriptions: DefaultExperiment and start values of the states --------------------------

@pytest.mark.parametrize("name", ["SingleWheel", "Rover", "RoverBody", "Wheel"])
def test_default_experiment_and_state_starts(fmus, name: str):
    md = fmpy.read_model_description(fmus[name])
    assert md.defaultExperiment is not None and float(md.defaultExperiment.stopTime) > 0
    states = [d.variable.derivative for d in md.derivatives]
    assert states and all(s.initial == "exact" for s in states), [s.name for s in states if s.initial != "exact"]


def test_a_run_can_start_in_motion(fmus):
    result = fmpy.simulate_fmu(fmus["Rover"], stop_time=0.5, output=["v", "omega[1]"],
                               start_values={"v": 1.0, **{f"omega[{i}]": 1.0 / R for i in range(1, 7)}})
    assert result["v"][0] == 1.0 and 0.9 < result["v"][-1] < 1.0


# --- parameter checks, in a child process ----------------------------------------------------------

CHECK = textwrap.dedent("""
    import json, sys
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    path, cases = sys.argv[1], json.loads(sys.argv[2])
    md = read_model_description(path)
    folder = extract(path)
    refs = {v.name: v.valueReference for v in md.modelVariables}
    answers = []
    for values in cases:
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName="check", fmiCallLogger=None)
        fmu.instantiate(loggingOn=False)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setReal([refs[k] for k in values], list(values.values()))
        try:
            fmu.exitInitializationMode()
            status = "ok"
        except Exception as error:
            status = "error"
        answers.append(status)
        fmu.freeInstance()
    print(json.dumps(answers))
""")

BAD_PARAMETERS = {
    "SingleWheel": [({"W": 1e7}, "W"), ({"W": -1.0}, "W"), ({"W": 0.0}, "W"), ({"soil.n": 0.0}, "soil.n"),
                    ({"soil.n": -1.0}, "soil.n"), ({"soil.kx": -0.01}, "soil.kx"), ({"soil.kx": 0.0}, "soil.kx"),
                    ({"soil.phi": math.pi / 2}, "soil.phi"), ({"soil.phi": 2.0}, "soil.phi"),
                    ({"wheel.J": -0.5}, "wheel.J"), ({"soil.a1": 0.5}, "soil.a1"), ({"soil.lam": 1.5}, "soil.lam"),
                    ({"slope": 2.0}, "slope"), ({"vHold": 0.0}, "vHold")],
    "Wheel": [({"soil.kphi": 0.0}, "soil.kphi"), ({"wheel.r": -0.3}, "wheel.r"), ({"soil.c": -1.0}, "soil.c")],
    "Rover": [({"rover.M": 0.0}, "rover.M"), ({"rover.M": -1570.0}, "rover.M"), ({"wheel.J": 0.0}, "wheel.J"),
              ({"rover.kLimb": 0.0}, "rover.kLimb")],
    "RoverBody": [({"rover.Iyy": -1.0}, "rover.Iyy"), ({"rover.g": 0.0}, "rover.g")],
    "SteerableRover": [({"rover.Izz": -1.0}, "rover.Izz"), ({"rover.Ixx": 0.0}, "rover.Ixx"),
                       ({"rover.yLimb": 0.0}, "rover.yLimb"), ({"wheel.J": 0.0}, "wheel.J")],
    "SteerableRoverBody": [({"rover.Izz": 0.0}, "rover.Izz"), ({"rover.M": -1.0}, "rover.M")],
}


def child_check(path, cases: list[dict]) -> list[str]:
    done = subprocess.run([sys.executable, "-c", CHECK, str(path), json.dumps(cases)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, f"the child process died ({done.returncode}): {done.stderr[-2000:]}"
    return json.loads(done.stdout.strip().splitlines()[-1])


def logged_messages(path, values: dict) -> str:
    """exitInitializationMode's logger text, gathered in this process (the child showed it does not crash)."""
    messages: list[str] = []

    def logger(component, instance, status, category, message):
        messages.append(message.decode())

    callbacks = fmi2.fmi2CallbackFunctions()
    callbacks.logger = fmi2.fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = fmi2.defaultCallbacks.allocateMemory
    callbacks.freeMemory = fmi2.defaultCallbacks.freeMemory
    md = fmpy.read_model_description(path)
    refs = {v.name: v.valueReference for v in md.modelVariables}
    fmu = fmi2.FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(path),
                         modelIdentifier=md.coSimulation.modelIdentifier, instanceName="check")
    fmu.instantiate(callbacks=callbacks, loggingOn=False)
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setReal([refs[k] for k in values], list(values.values()))
    with pytest.raises(fmpy.fmi1.FMICallException):
        fmu.exitInitializationMode()
    fmu.freeInstance()
    return "\n".join(messages)


@pytest.mark.parametrize("name", sorted(BAD_PARAMETERS))
def test_impossible_parameters_are_an_error_never_a_crash(fmus, name: str):
    cases = [values for values, _ in BAD_PARAMETERS[name]]
    assert child_check(fmus[name], cases) == ["error"] * len(cases)
    assert child_check(fmus[name], [{}]) == ["ok"]


@pytest.mark.parametrize("values,named", BAD_PARAMETERS["SingleWheel"] + BAD_PARAMETERS["Rover"][:1])
def test_the_error_names_the_parameter_its_value_and_the_range(fmus, values: dict, named: str):
    model = "Rover" if named.startswith("rover.") else "SingleWheel"
    text = logged_messages(fmus[model], values)
    value = next(iter(values.values()))
    assert named in text and f"{value:.10g}" in text, text
    assert any(word in text for word in ("must", "cannot")), text


@pytest.mark.parametrize("field,value", [("n", 0.0), ("kx", -0.01), ("phi", math.pi / 2), ("a1", 0.5),
                                         ("lam", 1.5), ("kphi", 0.0), ("c", -1.0)])
def test_fmu_ranges_are_the_numpy_references(field: str, value: float):
    """The same values the FMUs refuse, terramechanics.Soil refuses."""
    with pytest.raises(ValueError, match=field):
        Soil(**{field: value})
