"""The lateral force in the FMUs and in rumoca's simulation of the same Modelica, against the
numpy reference at the recorded states (issue 14, point 2), and the co-simulation wheel's new
input, optional so that existing systems run unchanged."""

from __future__ import annotations

import json
import math
import zipfile

import fmpy
import numpy as np
import pytest

from rover_cosim.fmubuild import source
from rover_cosim.terramechanics import wheel_forces

OUTPUTS = ["v", "omega", "Fx", "Fy", "Tx", "slip", "sinkage"]


def run_test_bed(fmus, load: float, degrees: float, tau: float = 30.0, stop: float = 2.0) -> np.ndarray:
    return fmpy.simulate_fmu(fmus["SingleWheel"], stop_time=stop, output_interval=0.01, output=OUTPUTS,
                             start_values={"W": load, "slipAngle": math.radians(degrees), "tau": tau,
                                           "solver.tolerance": 1e-8})


def reference(load: float, degrees: float, omega: np.ndarray, v: np.ndarray):
    beta = math.radians(degrees)
    return wheel_forces(load, omega, v * math.cos(beta), v_lateral=v * math.sin(beta))


@pytest.mark.parametrize("load", [275.0, 575.0, 875.0])
@pytest.mark.parametrize("degrees", [5.0, 12.5, 25.0])
def test_single_wheel_fy_agrees_with_the_reference_wheel(fmus, load: float, degrees: float):
    """Every recorded Fy and Fx equals terramechanics.wheel_forces at the same state within 0.5 %
    of its largest value (measured: below 1e-6)."""
    result = run_test_bed(fmus, load, degrees)
    expected = reference(load, degrees, result["omega"], result["v"])
    for name in ("Fy", "Fx", "Tx"):
        scale = np.abs(getattr(expected, name)).max()
        assert np.abs(result[name] - getattr(expected, name)).max() <= 0.005 * scale, name
    assert (result["Fy"][1:] < 0).all()


def test_single_wheel_fy_is_odd_and_zero_without_slip_angle(fmus):
    left, right = run_test_bed(fmus, 424.0, 10.0), run_test_bed(fmus, 424.0, -10.0)
    straight = run_test_bed(fmus, 424.0, 0.0)
    np.testing.assert_array_equal(right["Fy"], -left["Fy"])
    np.testing.assert_array_equal(right["v"], left["v"])
    assert (straight["Fy"] == 0).all()


@pytest.mark.parametrize("degrees", [7.5, 20.0])
def test_rumoca_simulation_of_the_modelica_gives_the_same_fy(degrees: float):
    name = f"{source.PACKAGE}.Examples.SingleWheelStep"
    df = source.simulate(name, params={"W": 575.0, "tauStep": 30.0, "slipAngle": math.radians(degrees)},
                         stop=1.0, interval=0.01)
    expected = reference(575.0, degrees, df["testBed.omega"].to_numpy(), df["testBed.v"].to_numpy())
    scale = np.abs(expected.Fy).max()
    assert np.abs(df["testBed.Fy"].to_numpy() - expected.Fy).max() <= 0.005 * scale


def test_wheel_fmu_takes_the_lateral_speed_and_gives_fy_and_the_slip_angle(fmus):
    md = fmpy.read_model_description(fmus["Wheel"])
    variables = {v.name: v for v in md.modelVariables}
    assert variables["v_lat"].causality == "input" and float(variables["v_lat"].start) == 0.0
    assert variables["Fy"].causality == "output" and variables["slipAngle"].causality == "output"
    with zipfile.ZipFile(fmus["Wheel"]) as archive:
        assert "v_lat" in json.loads(archive.read("documentation/build.json"))["optional_inputs"]
    result = fmpy.simulate_fmu(fmus["Wheel"], stop_time=0.5, output=["Fy", "slipAngle", "omega"],
                               start_values={"W": 424.0, "v_hub": 1.0, "v_lat": 0.1, "omega": 1.0 / 0.355})
    expected = wheel_forces(424.0, result["omega"], 1.0, v_lateral=0.1)
    np.testing.assert_allclose(result["slipAngle"], math.atan(0.1), rtol=1e-12)
    np.testing.assert_allclose(result["Fy"], expected.Fy, rtol=1e-4)


@pytest.mark.parametrize("phi_deg", [30.0, 37.2, 44.0])
def test_the_fmus_destructive_angle_follows_phi_unless_given(fmus, phi_deg: float):
    """soil.xc left at its default (0) is 45° - φ/2 of the φ the user sets, as in
    terramechanics.Soil: a plain FMPy user changing soil.phi alone gets the sidewall force of
    that soil (before, X_c stayed 26.4°); an explicit soil.xc is used as given."""
    from rover_cosim.terramechanics import Soil

    phi = math.radians(phi_deg)
    derived = fmpy.simulate_fmu(fmus["Wheel"], stop_time=0.2, output=["Fy", "omega"],
                                start_values={"W": 424.0, "v_hub": 1.0, "v_lat": 0.1, "soil.phi": phi,
                                              "omega": 1.0 / 0.355})
    expected = wheel_forces(424.0, derived["omega"], 1.0, v_lateral=0.1, soil=Soil(phi=phi))
    np.testing.assert_allclose(derived["Fy"], expected.Fy, rtol=1e-6)  # measured 1e-8: the sinkage solve
    given = fmpy.simulate_fmu(fmus["Wheel"], stop_time=0.2, output=["Fy", "omega"],
                              start_values={"W": 424.0, "v_hub": 1.0, "v_lat": 0.1, "soil.phi": phi,
                                            "soil.xc": math.radians(20.0), "omega": 1.0 / 0.355})
    expected = wheel_forces(424.0, given["omega"], 1.0, v_lateral=0.1, soil=Soil(phi=phi, xc=math.radians(20.0)))
    np.testing.assert_allclose(given["Fy"], expected.Fy, rtol=1e-6)
    assert abs(given["Fy"][-1] - derived["Fy"][-1]) > 1e-3 * abs(derived["Fy"][-1])
