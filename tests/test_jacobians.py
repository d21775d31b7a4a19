"""The FMUs' directional derivatives along a trajectory, against central finite differences
(issue 31, part 4).

Each FMU runs a scenario in Co-Simulation (1 ms steps, inputs that change, a slip angle that is
zero for the first half and not after); at every 100th step fmi2GetDirectionalDerivative of every
output and derivative with respect to every input (Co-Simulation) and every input and state (Model
Exchange, at the same point: the Co-Simulation instance's states set into a Model Exchange
instance, whose wheels' warm-start memory is then set by fmi2CompletedIntegratorStep) is compared
with central differences of fmi2GetReal. Before, the wheels' derivatives were lost once the
warm start was set (dFz/dW = 0 instead of 1) and the lateral force had no derivative at zero slip
angle (zero cornering stiffness).

Error of a column (the derivatives with respect to one known): max |AD - FD| / max |FD|, at most
1e-6. FD is the best, entry by entry, of three steps (1e-3, 1e-5 and 1e-7 of max(1, |value|)):
the largest keeps the sinkage solve's tolerance (Fz = W to 1e-10) from showing as noise of
1e-10 W / h in dFz, the smallest is below the O(h) error of the |slip angle| kink at zero slip
angle, where the central difference of Fy is a + b h. A wrong derivative (the zeros of before)
matches none of them.
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Callable
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy.fmi2 import FMU2Model, FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.fmi2 import defaultCallbacks as default_callbacks

STEP = 1e-3
STEPS = 500
TOLERANCE = 1e-6

Inputs = Callable[[float], dict[str, float]]


def _wheel(t: float) -> dict[str, float]:
    return {"tau": 20.0 + 10.0 * math.sin(8 * t), "W": 424.0 + 60.0 * math.sin(5 * t), "v_hub": 1.0,
            "v_lat": 0.0 if t < 0.25 else 0.05, "soilShare": _share(t), "rutDepth": _rut(t)}


def _rut(t: float) -> float:
    """A wheel rolling along a rut of varying depth [m] (inside (0, r), where the rut's column is
    defined by central differences: 0 is the input's bound)."""
    return 0.012 + 0.006 * math.sin(4 * t)


def _share(t: float) -> float:
    """A wheel rolling across a soil boundary (inside (0, 1), where the share's column is defined
    by central differences)."""
    return 0.5 + 0.4 * math.sin(3 * t)


#: The second soil of the runs with a soil share: softer and weaker than the first (the paper's).
SOIL_B = {"soilB.kphi": 4e5, "soilB.c": 300.0, "soilB.phi": 0.55, "soilB.n": 1.1}


def _single_wheel(t: float) -> dict[str, float]:
    return {"tau": 30.0 + 20.0 * math.sin(6 * t), "trackAngle": 0.0 if t < 0.25 else 0.1, "rutDepth": _rut(t)}


def _rover(t: float) -> dict[str, float]:
    return {f"tau[{i}]": 20.0 + 5.0 * i * math.sin(4 * t) for i in range(1, 7)}


def _steerable(t: float) -> dict[str, float]:
    steer = 0.0 if t < 0.25 else 0.08
    return {**_rover(t), **{f"steer[{i}]": steer * (1 if i in (1, 4) else -1 if i in (3, 6) else 0)
                            for i in range(1, 7)},
            **{f"soilShare[{i}]": _share(t + 0.1 * i) for i in range(1, 7)}}


def _body(t: float) -> dict[str, float]:
    return {**{f"Fx[{i}]": 30.0 + 5.0 * i * math.sin(3 * t) for i in range(1, 7)},
            **{f"tau[{i}]": 20.0 for i in range(1, 7)}}


def _steerable_body(t: float) -> dict[str, float]:
    return {**_body(t), **{f"Fy[{i}]": 2.0 * i * math.sin(2 * t) for i in range(1, 7)},
            **{f"steer[{i}]": 0.05 * math.sin(t) for i in range(1, 7)}}


SCENARIOS: dict[str, tuple[dict[str, float], Inputs]] = {
    # the wheel with every effect of issue 48 on: grousers, slip-sinkage (and the rut of _wheel)
    "Wheel": ({"omega": 1.0 / 0.355, **SOIL_B, "wheel.grouserHeight": 0.01, "wheel.grouserCount": 24.0,
               "soil.nSlip": 0.3, "soilB.nSlip": 0.3}, _wheel),
    "SingleWheel": ({"W": 575.0}, _single_wheel),
    "Rover": ({}, _rover),
    "RoverBody": ({}, _body),
    "SteerableRover": (SOIL_B, _steerable),
    "SteerableRoverBody": ({}, _steerable_body),
}


class Instance:
    """One FMU instance (CS or ME) with its variables by name."""

    def __init__(self, path: Path, folder: str, kind: str, starts: dict[str, float], name: str):
        md = fmpy.read_model_description(path)
        self.refs = {v.name: v.valueReference for v in md.modelVariables}
        self.inputs = [v.name for v in md.modelVariables if v.causality == "input"]
        self.lower = {v.name: float(v.min) for v in md.modelVariables if v.causality == "input" and v.min is not None}
        self.states = [d.variable.derivative.name for d in md.derivatives]
        self.unknowns = [o.variable.name for o in md.outputs] + [d.variable.name for d in md.derivatives]
        cls = FMU2Slave if kind == "CS" else FMU2Model
        self.fmu = cls(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                       instanceName=name)
        self.kind = kind
        # A logger of its own, alive as long as the instance: FMPy's default callbacks go through one
        # process-wide proxy that another FMPy user may have pointed at a logger since freed (a crash).
        self.messages: list[str] = []
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, category, text:
                                                       self.messages.append(text.decode()))
        self.callbacks.allocateMemory = default_callbacks.allocateMemory
        self.callbacks.freeMemory = default_callbacks.freeMemory
        self.fmu.instantiate(callbacks=self.callbacks)
        self.fmu.setupExperiment(startTime=0.0)
        self.set(starts)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        if kind == "ME":
            self.fmu.enterContinuousTimeMode()

    def set(self, values: dict[str, float]) -> None:
        if values:
            self.fmu.setReal([self.refs[k] for k in values], list(values.values()))

    def get(self, names: list[str]) -> np.ndarray:
        return np.array(self.fmu.getReal([self.refs[k] for k in names]))

    def set_states(self, values: np.ndarray) -> None:
        self.fmu.setContinuousStates((ctypes.c_double * len(values))(*values), len(values))


def _finite_differences(instance: Instance, known: str, derivative: np.ndarray) -> np.ndarray:
    """Central differences of the unknowns with respect to ``known``, the best of three steps
    entry by entry (see the module docstring); the instance is left as it was."""
    state = instance.fmu.getFMUstate()
    is_state = instance.kind == "ME" and known in instance.states
    centre = instance.get(instance.states) if is_state else None
    x0 = float(instance.get([known])[0])
    estimates = []
    for relative in (1e-3, 1e-5, 1e-7):
        h = relative * max(1.0, abs(x0))
        sides = []
        for sign in (1.0, -1.0):
            instance.fmu.setFMUstate(state)
            if is_state:
                assert centre is not None
                moved = centre.copy()
                moved[instance.states.index(known)] += sign * h
                instance.set_states(moved)
            else:
                instance.set({known: x0 + sign * h})
            sides.append(instance.get(instance.unknowns))
        estimates.append((sides[0] - sides[1]) / (2 * h))
    instance.fmu.setFMUstate(state)
    instance.fmu.freeFMUstate(state)
    stacked = np.array(estimates)
    best = np.argmin(np.abs(stacked - derivative), axis=0)
    return stacked[best, np.arange(len(derivative))]


def _column_errors(instance: Instance, knowns: list[str]) -> dict[str, tuple[float, str]]:
    """For each known: the column's error and the unknown where it is largest."""
    refs = [instance.refs[u] for u in instance.unknowns]
    errors = {}
    for known in knowns:
        # an input at its lower bound (a rover's rut depth of 0) has no central difference; the rut's
        # column is checked inside its range on the Wheel
        if known in instance.lower and float(instance.get([known])[0]) <= instance.lower[known]:
            continue
        derivative = np.array(instance.fmu.getDirectionalDerivative(refs, [instance.refs[known]], [1.0]))
        numeric = _finite_differences(instance, known, derivative)
        scale = max(float(np.max(np.abs(numeric))), 1e-12)
        worst = int(np.argmax(np.abs(derivative - numeric)))
        errors[known] = (float(abs(derivative[worst] - numeric[worst])) / scale,
                         f"d{instance.unknowns[worst]}/d{known}: AD {derivative[worst]:.10g}, FD {numeric[worst]:.10g}")
    return errors


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_directional_derivatives_along_a_trajectory(fmus, tmp_path, name):
    starts, inputs = SCENARIOS[name]
    folder = fmpy.extract(str(fmus[name]), unzipdir=str(tmp_path / name))
    cs = Instance(fmus[name], folder, "CS", {**starts, **inputs(0.0)}, "cs")
    me = Instance(fmus[name], folder, "ME", {**starts, **inputs(0.0)}, "me")
    failures = []
    checked = 0
    for k in range(STEPS):
        t = k * STEP
        cs.set(inputs(t))
        cs.fmu.doStep(t, STEP)
        if (k + 1) % 100:
            continue
        for error, where in _column_errors(cs, cs.inputs).values():
            checked += 1
            if not error <= TOLERANCE:
                failures.append(f"CS t={t + STEP:.3f} {where} (column error {error:.2e})")
        me.fmu.setTime(t + STEP)
        me.set_states(cs.get(cs.states))
        me.set(inputs(t))
        me.fmu.completedIntegratorStep()  # the wheels' warm start at this point
        for error, where in _column_errors(me, me.inputs + me.states).values():
            checked += 1
            if not error <= TOLERANCE:
                failures.append(f"ME t={t + STEP:.3f} {where} (column error {error:.2e})")
    bounded = sum(1 for k in cs.inputs if k in cs.lower and float(cs.get([k])[0]) <= cs.lower[k])
    assert checked >= (STEPS // 100) * (2 * (len(cs.inputs) - bounded) + len(me.states))
    assert not failures, "\n".join(failures[:20])
    for instance in (cs, me):
        instance.fmu.terminate()
        instance.fmu.freeInstance()


def test_directional_derivatives_refuse_unknowns_that_are_no_output_state_or_derivative(fmus, tmp_path):
    """A memory of the runtime (the sinkage solve's warm start), a local variable or an input asked
    for as an unknown is an error (it read past the output buffer and returned fmi2OK before)."""
    md = fmpy.read_model_description(fmus["SingleWheel"])
    folder = fmpy.extract(str(fmus["SingleWheel"]), unzipdir=str(tmp_path / "sw"))
    instance = Instance(fmus["SingleWheel"], folder, "CS", {"W": 575.0, "tau": 30.0}, "cs")
    instance.fmu.doStep(0.0, STEP)
    locals_ = [v.name for v in md.modelVariables if v.causality == "local" and not v.name.startswith("der(")]
    memory = next(n for n in locals_ if n.endswith("logSinkageStart"))
    for unknown in (memory, "rigidWheel.slip", "tau"):
        assert unknown in instance.refs
        with pytest.raises(fmpy.fmi1.FMICallException):
            instance.fmu.getDirectionalDerivative([instance.refs[unknown]], [instance.refs["tau"]], [1.0])
        message = instance.messages[-1]
        assert unknown in message and "expected a state, a derivative or an output" in message
    fine = instance.fmu.getDirectionalDerivative([instance.refs["Fx"]], [instance.refs["tau"]], [1.0])
    assert math.isfinite(fine[0])
    instance.fmu.terminate()
    instance.fmu.freeInstance()
