"""Rover FMUs for any number of wheels (issue 46): the Modelica rover's wheel count is a structural
parameter (RoverParameters.nAxles), an FMU built on demand for a rover's count
(fmubuild.build.build_fmu(axles=...), jobs.plants.rover_fmu), cached by digest; a four-wheel rover
stands with its weight on its wheels, and runs monolithic and co-simulated alike."""

from __future__ import annotations

import numpy as np
import pytest

from rover_cosim.fmubuild import build, source
from rover_cosim.jobs import simulate
from rover_cosim.jobs.plants import add_rover, hubs, rover_fmu
from rover_cosim.orchestrator.builder import SystemBuilder, replace_settings
from rover_cosim.orchestrator.master import run
from rover_cosim.terramechanics.library import choose

pytestmark = pytest.mark.fmu


def test_a_variant_is_asked_for_a_rover_model_and_a_count_it_can_take():
    with pytest.raises(ValueError, match=r"model 'Wheel': the number of wheels is a parameter of Rover"):
        source.variant_source("Wheel", 2)
    with pytest.raises(ValueError, match=r"axles = 0: expected 1 to 16 wheels per side"):
        source.variant_source("Rover", 0)
    text = source.variant_source("RoverBody", 2)
    assert "extends RoverTerramechanics.FMUs.RoverBody(rover(nAxles=2, xLimb={1.5, -1.5}))" in text


def test_the_papers_six_wheels_use_the_package_fmus(fmu_dir):
    assert rover_fmu(fmu_dir, "Rover", choose()) == fmu_dir / "Rover.fmu"
    assert rover_fmu(fmu_dir, "RoverBody", choose(rover="msl")) == fmu_dir / "RoverBody.fmu"  # six wheels too


def test_a_four_wheel_body_is_built_once_and_carries_the_weight(fmu_dir):
    choice = choose(rover="viper", soil="lunar_nominal")
    body = rover_fmu(fmu_dir, "RoverBody", choice)
    assert body == fmu_dir / "wheels4" / "RoverBody.fmu" and len(hubs(body)) == 4
    again = build.build_fmu("RoverBody", body.parent, axles=2)
    assert not again.rebuilt  # cached by digest
    builder = SystemBuilder("viper body at rest").simulation(stop_time=3.0, step=1e-3)
    add_rover(builder, body, fmu_dir / "Wheel.fmu", 4, choice, body_start={f"tau[{i}]": 0.0 for i in range(1, 5)},
              wheel_start={"tau": 0.0})
    data = run(builder.build()).data
    loads = np.array([data[f"body.W[{i}]"].iloc[-1] for i in range(1, 5)])
    weight = choice.rover.mass * choice.soil.gravity
    assert loads.sum() == pytest.approx(weight, rel=1e-6)  # loads at rest sum to the weight
    assert np.allclose(loads, weight / 4, rtol=1e-6)       # symmetric hubs: equal loads
    assert abs(data["body.x"].iloc[-1]) < 1e-6                # rest stays at rest


def test_a_four_wheel_rover_runs_monolithic_and_cosimulated_alike(fmu_dir, identified, results_root):
    choice = choose(rover="viper", soil="lunar_nominal", wheel="paper")
    model = results_root / "identification" / "model.json"
    mono = run(replace_settings(simulate.monolithic_system(fmu_dir, model, choice), stop_time=6.0)).data
    cosim = run(replace_settings(simulate.cosim_system(fmu_dir, model, choice), stop_time=6.0)).data
    a, b = simulate.trajectories(mono, "monolithic"), simulate.trajectories(cosim, "cosim")
    assert [c for c in a.columns if c.startswith("Fz_")] == ["Fz_1", "Fz_2", "Fz_3", "Fz_4"]
    assert a["Fz_1"].iloc[0] == pytest.approx(choice.rover.mass * choice.soil.gravity / 4, rel=1e-6)
    assert np.max(np.abs(a["v"] - b["v"])) < 0.01
    assert max(np.max(np.abs(a[f"Fz_{i}"] - b[f"Fz_{i}"])) for i in range(1, 5)) < 2.0
    assert a["v"].iloc[-1] > 0.5  # it drives: the controller asks M a of its four wheels
    accelerating = a["time"] < 3.0
    assert a["Fz_1"][accelerating].min() < choice.rover.mass * choice.soil.gravity / 4 < a["Fz_2"][accelerating].max()
