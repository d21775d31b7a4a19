"""Grousers, slip-sinkage and multi-pass ruts in Wheel.fmu against the numpy reference (issue 48):
the FMU's contact at chosen states (load, spin, hub speed, slip angle, rut) equals
terramechanics.wheel_state with the FMU's quadrature (the Gauss-Legendre nodes a piece of the Modelica
RigidWheel's nNodes) to 1e-6."""

from __future__ import annotations

import ctypes
import math
import shutil

import fmpy
import numpy as np
import pytest
from fmpy.fmi2 import FMU2Model
from modelica_defaults import FMU_NODES

from rover_cosim.terramechanics import Soil, Wheel, wheel_state
from rover_cosim.terramechanics.library import fmu_parameters

EFFECTS = {
    "smooth": (Wheel(), Soil(), 0.0),
    "grousers": (Wheel(grouser_height=0.015, grouser_count=24), Soil(), 0.0),
    "few grousers": (Wheel(grouser_height=0.02, grouser_count=5), Soil(), 0.0),
    "slip-sinkage": (Wheel(), Soil(n_slip=0.6), 0.0),
    "multi-pass": (Wheel(), Soil(), 0.02),
    "all three": (Wheel(grouser_height=0.01, grouser_count=18), Soil(n_slip=0.4), 0.03),
}
LOADS = [60.0, 424.0, 1200.0]
SLIPS = [0.02, 0.15, 0.4, 0.8]
SLIP_ANGLES = [0.0, 0.2]


@pytest.fixture(scope="module")
def wheel_model(fmus, tmp_path_factory):
    """Wheel.fmu's Model Exchange interface, unpacked once."""
    path = fmus["Wheel"]
    description = fmpy.read_model_description(path)
    folder = tmp_path_factory.mktemp("wheel_fmu")
    fmpy.extract(path, str(folder))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    yield description, str(folder), refs
    shutil.rmtree(folder, ignore_errors=True)


def contact_at_states(model, wheel: Wheel, soil: Soil, rut: float) -> dict[str, np.ndarray]:
    """The FMU's outputs at every (load, slip, slip angle) of the grid, hub speed 1 m/s forwards."""
    description, folder, refs = model
    fmu = FMU2Model(guid=description.guid, unzipDirectory=folder,
                    modelIdentifier=description.modelExchange.modelIdentifier, instanceName="effects")
    fmu.instantiate()
    out: dict[str, list[float]] = {name: [] for name in ("sinkage", "Fx", "Fz", "Tx", "Fy")}
    try:
        parameters = fmu_parameters(soil, wheel)
        fmu.setReal([refs[k] for k in parameters], list(parameters.values()))
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.enterContinuousTimeMode()
        for load in LOADS:
            for slip in SLIPS:
                for beta in SLIP_ANGLES:
                    omega = 1.0 / (wheel.r * (1.0 - slip))
                    fmu.setReal([refs["W"], refs["v_hub"], refs["v_lat"], refs["rutDepth"], refs["tau"]],
                                [load, 1.0, math.tan(beta), rut, 0.0])
                    fmu.setContinuousStates((ctypes.c_double * 1)(omega), 1)
                    values = fmu.getReal([refs[name] for name in out])
                    for name, value in zip(out, values):
                        out[name].append(value)
    finally:
        fmu.terminate()
        fmu.freeInstance()
    return {name: np.array(values) for name, values in out.items()}


@pytest.mark.parametrize("effect", EFFECTS)
def test_the_wheel_fmu_gives_the_reference_contact_with_each_effect(wheel_model, effect: str):
    wheel, soil, rut = EFFECTS[effect]
    description = wheel_model[0]
    assert description.numberOfContinuousStates == 1
    got = contact_at_states(wheel_model, wheel, soil, rut)
    loads, slips, betas = (a.ravel() for a in np.meshgrid(LOADS, SLIPS, SLIP_ANGLES, indexing="ij"))
    # the FMU's slip ratio and slip angle at these states: Eq. (4) with its regularising speed, atan(v_lat/v)
    expected = wheel_state(loads, slips, wheel, soil, nodes=FMU_NODES, slip_angle=betas, rut_depth=rut)
    for name in ("sinkage", "Fx", "Fz", "Tx", "Fy"):
        reference = getattr(expected, name)
        scale = np.maximum(np.abs(reference), 1e-3 * loads)
        error = np.abs(got[name] - reference) / scale
        assert error.max() <= 1e-6, (name, float(error.max()))


def test_a_rut_makes_the_wheel_fmu_sink_deeper_in_total_but_less_below_the_rut(wheel_model):
    fresh = contact_at_states(wheel_model, Wheel(), Soil(), 0.0)
    rutted = contact_at_states(wheel_model, Wheel(), Soil(), 0.02)
    assert np.all(rutted["sinkage"] > 0.02)
    assert np.all(rutted["sinkage"] - 0.02 < fresh["sinkage"])


@pytest.mark.parametrize("rut", [0.0, 0.02])
def test_the_closed_form_of_n_1_joins_the_power_law_on_either_side(wheel_model, rut: float):
    """Soil n = 1 without slip-sinkage takes the normal stress's closed form (no exp/log); n a hair
    either side takes the power law: the contact moves by about that hair, not by a step. With
    slip-sinkage (n_slip > 0) n = 1 takes the power law (the exponent then varies with the slip)."""
    wheel = Wheel()
    at_one = contact_at_states(wheel_model, wheel, Soil(n=1.0), rut)
    for n in (1.0 - 1e-9, 1.0 + 1e-9):
        near = contact_at_states(wheel_model, wheel, Soil(n=n), rut)
        for name in ("sinkage", "Fx", "Tx"):
            scale = np.abs(at_one[name]).max()
            assert np.abs(near[name] - at_one[name]).max() <= 1e-7 * scale, (n, name)
    sinking = contact_at_states(wheel_model, wheel, Soil(n=1.0, n_slip=1e-12), rut)
    for name in ("sinkage", "Fx", "Tx"):
        assert np.abs(sinking[name] - at_one[name]).max() <= 1e-9 * np.abs(at_one[name]).max(), name


def test_the_fmus_take_the_new_parameters_and_the_rovers_a_rut_input(fmus):
    for name in ("Wheel", "SingleWheel", "Rover", "SteerableRover", "LegWheelRover"):
        variables = {v.name: v for v in fmpy.read_model_description(fmus[name]).modelVariables}
        for parameter in ("wheel.grouserHeight", "wheel.grouserCount", "soil.nSlip"):
            assert variables[parameter].causality == "parameter", (name, parameter)
            assert float(variables[parameter].start) == 0.0
        ruts = [v for v in variables if v.startswith("rutDepth")]
        assert ruts and all(variables[v].causality == "input" and float(variables[v].start) == 0.0 for v in ruts)
