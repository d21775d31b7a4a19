"""The iterative master (each step repeated with the participants rolled back until the coupled
values converge) and the FMUs' input interpolation it uses (fmi2SetRealInputDerivatives)."""

from __future__ import annotations

import tomllib

import fmpy
import numpy as np
import pytest
from fmpy import fmi2
from fmpy.fmi2 import FMU2Slave

from rover_cosim.cli import EXAMPLES
from rover_cosim.jobs.cosim_study import coupling_errors
from rover_cosim.orchestrator.master import RunError, run
from rover_cosim.orchestrator.system import SystemFileError, system_from_dict


def example(name: str, **simulation: object) -> dict:
    data = tomllib.loads(EXAMPLES[name].read_text())
    data["simulation"].update(simulation)
    return data


class Counter:
    """A stateful user block without get_state/set_state (the master deep-copies it): y = the
    number of steps taken, u ignored."""

    def __init__(self, name: str):
        self.name, self.inputs, self.outputs, self.units = name, ("u",), ("y",), {"u": "rad/s", "y": "N.m"}
        self.count = 0

    def start(self, t0, u0):
        return np.array([0.0])

    def step(self, t, h, u):
        self.count += 1
        return np.array([1e-3 * self.count])


def test_blocks_are_rolled_back_with_the_fmus(fmu_dir, fmus):
    """A block that counts its steps ends with the number of communication steps, not of passes."""
    data = example("single_wheel_step", stop_time=0.2, algorithm="iterative")
    data["block"] = [{"name": "count", "type": "python", "factory": "test_iterative:Counter"}]
    data["connection"] = [{"from": "testbed.omega", "to": "count.u"}, {"from": "count.y", "to": "testbed.tau"}]
    result = run(system_from_dict(data, name="count.toml", base=fmu_dir)).data
    steps = round(0.2 / 1e-3)
    # The first step is taken in 10 pieces (the start); every later step counts once.
    assert result["count.y"].iloc[-1] == pytest.approx(1e-3 * (steps - 1 + 10))


def test_the_iterative_master_matches_the_monolithic_rover_far_better(fmu_dir, fmus):
    """At 10 ms the co-simulated rover under the iterative master is at least 10 times closer to
    the monolithic Rover.fmu than under Gauss-Seidel, in velocity and in wheel loads."""
    table = coupling_errors(fmu_dir, steps=(0.01,)).set_index("algorithm")
    gs, it = table.loc["gauss-seidel"], table.loc["iterative"]
    assert it["max_abs_v_error_m_s"] * 10 <= gs["max_abs_v_error_m_s"], table.to_dict()
    assert it["max_abs_Fz_error_N"] * 10 <= gs["max_abs_Fz_error_N"], table.to_dict()


def test_non_convergence_names_the_step_and_the_signals(fmu_dir, fmus):
    data = example("rover_cosim", stop_time=0.05, algorithm="iterative", max_iterations=1)
    with pytest.raises(RunError, match=r"did not converge in 1 passes.*still moving: .*(wheel\d\.Fx|body\.)"):
        run(system_from_dict(data, name="rover.toml", base=fmu_dir))


@pytest.mark.parametrize(("settings", "message"), [
    ({"algorithm": "gauss-seidel", "tolerance": 1e-6}, "only apply to algorithm = \"iterative\""),
    ({"algorithm": "iterative", "tolerance": 0.0}, "tolerance: 0.0: expected > 0"),
    ({"algorithm": "iterative", "relaxation": 1.5}, "relaxation: 1.5"),
    ({"algorithm": "iterative", "max_iterations": 0}, "max_iterations: 0"),
])
def test_iteration_settings_are_checked(fmu_dir, fmus, settings, message):
    with pytest.raises(SystemFileError, match=message):
        system_from_dict(example("rover_cosim", **settings), name="bad.toml", base=fmu_dir)


def test_fmu_interpolates_inputs_over_a_step(fmus):
    """RoverBody with Fx[i] = 10 N rising at 100 N/s over a 0.1 s step: the body gains exactly the
    impulse of the ramp, and the input holds its value at the step's end afterwards."""
    path = str(fmus["RoverBody"])
    md = fmpy.read_model_description(path)
    assert md.coSimulation.canInterpolateInputs
    refs = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="ramp")
    # Own callbacks: FMPy's default ones log through a proxy that keeps the logger of the last
    # simulate_fmu call, which is gone by now (an FMPy pitfall, not the FMU's).
    messages: list[str] = []
    callbacks = fmi2.fmi2CallbackFunctions()
    callbacks.logger = fmi2.fmi2CallbackLoggerTYPE(lambda env, name, status, category, text:
                                                   messages.append(text.decode()))
    callbacks.allocateMemory = fmi2.defaultCallbacks.allocateMemory
    callbacks.freeMemory = fmi2.defaultCallbacks.freeMemory
    fmu.instantiate(callbacks=callbacks)
    fmu.setupExperiment(startTime=0.0)
    forces = [refs[f"Fx[{i}]"] for i in range(1, 7)]
    fmu.setReal([refs["solver.tolerance"]], [1e-10])
    fmu.enterInitializationMode()
    fmu.setReal(forces, [10.0] * 6)
    fmu.exitInitializationMode()
    fmu.setRealInputDerivatives(forces, [1] * 6, [100.0] * 6)
    fmu.doStep(0.0, 0.1)
    v = fmu.getReal([refs["v"]])[0]
    assert v == pytest.approx(6 * (10.0 * 0.1 + 100.0 * 0.1**2 / 2) / 1570.0, rel=1e-6)
    assert fmu.getReal(forces[:1]) == [pytest.approx(20.0)]
    fmu.doStep(0.1, 0.1)   # no derivatives set again: held at 20 N
    assert fmu.getReal([refs["v"]])[0] - v == pytest.approx(6 * 20.0 * 0.1 / 1570.0, rel=1e-6)
    with pytest.raises(fmpy.fmi1.FMICallException):
        fmu.setRealInputDerivatives(forces[:1], [2], [1.0])   # only first derivatives
    with pytest.raises(fmpy.fmi1.FMICallException):
        fmu.setRealInputDerivatives([refs["v"]], [1], [1.0])  # not an input
    assert any("only order 1" in m for m in messages) and any("not an input" in m for m in messages)
    fmu.terminate()
    fmu.freeInstance()
