"""FMI 3.0 FMUs of the same model code as the FMI 2.0 ones (issue 31, part 3): FMPy validates and
runs them; Co-Simulation gives the FMI 2.0 FMU's results bit for bit; in Model Exchange the
derivatives and outputs at the same points are the FMI 2.0 ones; the directional derivatives are
the same; the engine co-simulates FMI 3.0 Wheel FMUs with the FMI 2.0 RoverBody; bad calls are
refused with a message."""

from __future__ import annotations

import ctypes
import tomllib
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy.fmi2 import FMU2Model
from fmpy.fmi3 import FMU3Model, FMU3Slave
from fmpy.validation import validate_fmu

from rover_cosim.cli import EXAMPLES
from rover_cosim.fmubuild import build
from rover_cosim.orchestrator.master import run
from rover_cosim.orchestrator.system import system_from_dict

MODELS = ("Wheel", "SingleWheel", "RoverBody")
START = {"Wheel": {"W": 424.0, "v_hub": 1.0, "tau": 20.0, "omega": 2.9, "v_lat": 0.05},
         "SingleWheel": {"W": 575.0, "tau": 30.0, "trackAngle": 0.1},
         "RoverBody": {**{f"Fx[{i}]": 25.0 for i in range(1, 7)}, **{f"tau[{i}]": 20.0 for i in range(1, 7)}}}


@pytest.fixture(scope="module")
def fmi3(tmp_path_factory) -> dict[str, Path]:
    """FMI 3.0 FMUs of Wheel, SingleWheel and RoverBody (rover-cosim build-fmus --fmi-version 3)."""
    out = tmp_path_factory.mktemp("fmi3")
    results = build.build_all(MODELS, out, backend="builtin", fmi_version=3)
    return {r.name: r.path for r in results}


@pytest.mark.parametrize("name", MODELS)
def test_fmpy_validates_the_fmi3_fmu_and_it_carries_the_fmi3_layout(fmi3, name):
    assert validate_fmu(str(fmi3[name])) == []
    md = fmpy.read_model_description(fmi3[name])
    assert md.fmiVersion == "3.0" and md.modelExchange is not None and md.coSimulation is not None
    independent = [v for v in md.modelVariables if v.causality == "independent"]
    assert [v.name for v in independent] == ["time"] and independent[0].type == "Float64"
    with zipfile.ZipFile(fmi3[name]) as archive:
        names = archive.namelist()
    assert f"binaries/x86_64-linux/{name}.so" in names and "sources/fmi3_api.c" in names
    assert "sources/fmi2_api.c" not in names


@pytest.mark.parametrize("name", MODELS)
def test_co_simulation_gives_the_fmi2_results_bit_for_bit(fmus, fmi3, name):
    md = fmpy.read_model_description(fmi3[name])
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    three = fmpy.simulate_fmu(str(fmi3[name]), stop_time=0.5, output_interval=1e-3, output=outputs,
                              start_values=START[name], fmi_type="CoSimulation")
    two = fmpy.simulate_fmu(str(fmus[name]), stop_time=0.5, output_interval=1e-3, output=outputs,
                            start_values=START[name], fmi_type="CoSimulation")
    assert len(three) == len(two) == 501
    for output in outputs:
        np.testing.assert_array_equal(three[output], two[output], err_msg=output)
    assert np.ptp(three[outputs[0]]) > 0 or name == "RoverBody"


def _me_instance(path: Path, folder: Path, version: int):
    md = fmpy.read_model_description(path)
    unzipped = fmpy.extract(str(path), unzipdir=str(folder))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    if version == 3:
        fmu = FMU3Model(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.modelExchange.modelIdentifier,
                        instanceName="me3")
        fmu.instantiate()
        fmu.enterInitializationMode(startTime=0.0)
    else:
        fmu = FMU2Model(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.modelExchange.modelIdentifier,
                        instanceName="me2")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    return fmu, refs, md


def test_model_exchange_derivatives_and_outputs_equal_the_fmi2_ones(fmus, fmi3, tmp_path):
    """At the same time, states and inputs, the FMI 3.0 Wheel's derivatives, outputs and
    directional derivatives are the FMI 2.0 Wheel's, bit for bit."""
    start = {k: v for k, v in START["Wheel"].items() if k != "omega"}
    three, refs, md = _me_instance(fmi3["Wheel"], tmp_path / "3", 3)
    two, refs2, _ = _me_instance(fmus["Wheel"], tmp_path / "2", 2)
    three.setFloat64([refs[k] for k in start], list(start.values()))
    two.setReal([refs2[k] for k in start], list(start.values()))
    three.exitInitializationMode()
    two.exitInitializationMode()
    three.enterContinuousTimeMode()
    two.enterContinuousTimeMode()
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    for t, omega in ((0.1, 2.5), (0.2, 2.9), (0.3, 3.4)):
        three.setTime(t)
        two.setTime(t)
        x = (ctypes.c_double * 1)(omega)
        three.setContinuousStates(x, 1)
        two.setContinuousStates(x, 1)
        d3, d2 = (ctypes.c_double * 1)(), (ctypes.c_double * 1)()
        three.getContinuousStateDerivatives(d3, 1)
        two.getDerivatives(d2, 1)
        assert d3[0] == d2[0]
        assert three.getFloat64([refs[o] for o in outputs]) == two.getReal([refs2[o] for o in outputs])
        known = [refs["W"], refs["omega"], refs["v_lat"]]
        unknowns = [refs["Fx"], refs["Fy"], refs["der(omega)"]]
        for k in known:
            assert (three.getDirectionalDerivative(unknowns, [k], [1.0])
                    == two.getDirectionalDerivative(unknowns, [k], [1.0]))
        assert three.getFloat64([refs["time"]]) == [t]
        three.completedIntegratorStep()
        two.completedIntegratorStep()
    for fmu in (three, two):
        fmu.terminate()
        fmu.freeInstance()


def test_the_engine_cosimulates_fmi3_wheels_with_the_fmi2_body(fmus, fmi3, fmu_dir):
    """rover_cosim.toml with the six wheels as FMI 3.0 FMUs and the body as FMI 2.0: the same
    trajectory as the all-FMI 2.0 system, bit for bit (both Co-Simulation, the same model code)."""
    data = tomllib.loads(EXAMPLES["rover_cosim"].read_text())
    data["simulation"]["stop_time"] = 0.3
    reference = run(system_from_dict(data, name="fmi2.toml", base=fmu_dir)).data
    for fmu in data["fmu"]:
        if fmu["path"] == "Wheel.fmu":
            fmu["path"] = str(fmi3["Wheel"])
    mixed_system = system_from_dict(data, name="mixed.toml", base=fmu_dir)
    mixed = run(mixed_system).data
    assert list(mixed.columns) == list(reference.columns) and len(mixed) == len(reference) > 100
    np.testing.assert_array_equal(mixed.to_numpy(), reference.to_numpy())
    assert mixed["body.v"].iloc[-1] > 0


def test_bad_calls_are_refused_with_a_message(fmi3, tmp_path):
    """An FMI 3.0 host's mistakes: a wrong instantiation token, setting the independent variable,
    a state restored into the other interface kind, Scheduled Execution: each an error naming it."""
    md = fmpy.read_model_description(fmi3["Wheel"])
    unzipped = fmpy.extract(str(fmi3["Wheel"]), unzipdir=str(tmp_path / "w"))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    messages: list[str] = []

    def log(env, status, category, message):  # noqa: ANN001 - FMPy's logMessage callback
        messages.append(message.decode() if isinstance(message, bytes) else str(message))

    wrong = FMU3Slave(guid="{not-this-one}", unzipDirectory=unzipped, modelIdentifier="Wheel", instanceName="x")
    with pytest.raises(Exception):  # noqa: B017 - FMPy raises a plain Exception for a NULL instance
        wrong.instantiate(logMessage=log)
    assert any("instantiation token" in m for m in messages)
    slave = FMU3Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier="Wheel", instanceName="cs")
    slave.instantiate(logMessage=log)
    slave.enterInitializationMode(startTime=0.0)
    slave.exitInitializationMode()
    with pytest.raises(fmpy.fmi1.FMICallException):
        slave.setFloat64([refs["time"]], [1.0])
    assert "independent variable" in messages[-1]
    slave.doStep(0.0, 1e-3)
    state = slave.getFMUState()
    serialized = slave.serializeFMUState(state)
    model = FMU3Model(guid=md.guid, unzipDirectory=unzipped, modelIdentifier="Wheel", instanceName="me")
    model.instantiate(logMessage=log)
    with pytest.raises(fmpy.fmi1.FMICallException):
        model.setFMUState(model.deserializeFMUState(serialized))
    assert "Co-Simulation instance" in messages[-1]
    slave.terminate()
    for fmu in (slave, model):
        fmu.freeInstance()
