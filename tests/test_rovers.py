"""The rover library (terramechanics/library/rovers.toml, terramechanics.Rover, --rover, --set
rover.*, `rover-cosim rovers`) and the identification plan that scales with the rover and wheel
(identification.plan): the paper's choice keeps the paper's plan, every shipped rover gets loads
around its own static wheel load and torques that the numpy reference wheel puts in the fits'
slip window; a rover that cannot be driven is refused before any sweep."""

from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import asdict

import numpy as np
import pytest

from rover_cosim.common.paper import LOADS, ROVER_MASS, STATIC_WHEEL_LOAD
from rover_cosim.identification.fits import FIT_TORQUE_MAX, SLIP_FIT_RANGE
from rover_cosim.identification.plan import IdentificationPlan, NotDrivable, plan_for, read_plan, static_load
from rover_cosim.identification.sweep import PAPER_TORQUES
from rover_cosim.identification.validate import VALIDATION_LOADS, VALIDATION_TORQUES
from rover_cosim.terramechanics import wheel_state
from rover_cosim.terramechanics.library import choose, describe, names, rover_parameters, vary
from rover_cosim.terramechanics.parameters import Rover

SHIPPED = names("rover")


def test_the_library_ships_the_issues_rovers_each_with_a_source():
    assert {"paper", "mer", "msl", "viper"} <= set(SHIPPED)
    for name in SHIPPED:
        choice = choose(rover=name)
        assert choice.rover_entry.get("source") and choice.rover_entry.get("title"), name
        assert choice.wheel_name == choice.rover_entry["wheel"], name  # the rover's own wheel
    assert choose(rover="viper").rover.wheels == 4 and choose(rover="msl").rover.wheels == 6


def test_the_paper_rover_is_the_modelica_default_and_the_papers_numbers():
    paper = choose().rover
    assert paper == Rover() and paper.mass == ROVER_MASS and paper.wheels == 6
    assert paper.static_wheel_load(1.62) == STATIC_WHEEL_LOAD  # bit for bit: the ablation's load


def test_loads_at_rest_sum_to_the_weight():
    for name in SHIPPED:
        choice = choose(rover=name, soil="lunar_nominal")
        load = static_load(choice)
        assert load * choice.rover.wheels == pytest.approx(choice.rover.mass * choice.soil.gravity, rel=1e-12)


def test_rover_parameters_name_the_modelica_record():
    values = rover_parameters(choose(rover="viper").rover, 1.62)
    assert values["rover.M"] == 430.0 and values["rover.g"] == 1.62
    assert values["rover.xLimb[1]"] == -values["rover.xLimb[2]"] and "rover.xLimb[3]" not in values
    assert {"rover.Iyy", "rover.Ixx", "rover.Izz", "rover.hCoG", "rover.yLimb", "rover.kLimb",
            "rover.dLimb"} <= set(values)


def test_set_and_vary_change_a_rover_and_the_record_says_so():
    choice = choose(rover="viper", assignments=["rover.mass=500", "rover.x_limb=1.0,-1.0"])
    assert choice.rover.mass == 500.0 and choice.rover.x_limb == (1.0, -1.0)
    assert choice.overrides == ("rover.mass=500", "rover.x_limb=1.0,-1.0")
    heavier = vary(choice, rover={"mass": 600.0})
    assert heavier.rover.mass == 600.0 and heavier.overrides[-1] == "rover.mass=600.0"
    record = describe(heavier)["rover"]
    assert record["name"] == "viper" and record["wheels"] == 4 and record["values"]["x_limb"] == [1.0, -1.0]


def test_a_rover_file_of_the_users(tmp_path):
    path = tmp_path / "two_axle.toml"
    path.write_text('title = "a light two-axle test rover"\nwheel = "mer"\nmass = 60.0\nx_limb = [0.3, -0.3]\n'
                    "y_limb = 0.25\n")
    choice = choose(rover=str(path))
    assert choice.rover_name == "two_axle" and choice.rover.wheels == 4 and choice.wheel_name == "mer"
    assert choice.rover.Iyy == Rover().Iyy  # what the file leaves out: the paper's
    assert choose(rover=str(path), wheel="msl").wheel_name == "msl"  # --wheel wins over the rover's


@pytest.mark.parametrize(("assignment", "message"), [
    ("rover.mass=-1", r"mass=-1.0 is not physical: expected mass > 0 kg"),
    ("rover.x_limb=-1,1", r"x_limb=\[-1.0, 1.0\] is not physical: expected positions from front to rear"),
    ("rover.x_limb=1,x", r"'1,x' is not a number \(x_limb: comma-separated numbers"),
    ("rover.wings=2", r"unknown key\(s\) \['wings'\]"),
    ("rover.y_limb=0", r"y_limb=0.0 is not physical: expected y_limb > 0 m"),
])
def test_bad_rover_values_are_named(assignment, message):
    with pytest.raises(ValueError, match=message):
        choose(assignments=[assignment])


def test_a_bad_rover_file_is_named(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('x_limb = "front"\n')
    with pytest.raises(ValueError, match=r"x_limb = 'front': expected a list of hub positions"):
        choose(rover=str(path))
    path.write_text('wheel = "square"\n')
    with pytest.raises(ValueError, match=r"rover 'bad': its wheel: wheel 'square': expected one of"):
        choose(rover=str(path))


def test_the_rovers_command_lists_and_shows_them():
    listed = subprocess.run([sys.executable, "-P", "-m", "rover_cosim", "rovers"], capture_output=True, text=True,
                            check=True).stdout
    assert all(f"  {name} " in listed for name in SHIPPED)
    shown = subprocess.run([sys.executable, "-P", "-m", "rover_cosim", "rovers", "viper"], capture_output=True,
                           text=True, check=True).stdout
    assert "x_limb   0.6418, -0.6418 m" in shown and "wheels   4" in shown and "174.2 N on the Moon" in shown
    unknown = subprocess.run([sys.executable, "-P", "-m", "rover_cosim", "rovers", "nope"], capture_output=True,
                             text=True, check=False)
    assert unknown.returncode == 2 and "no shipped rover of that name" in unknown.stderr
    assert "Traceback" not in unknown.stderr


# --- the identification plan ------------------------------------------------------------------------

def test_the_paper_keeps_the_papers_plan_value_for_value():
    plan = plan_for(choose())
    assert plan.is_paper and plan == IdentificationPlan()
    assert (plan.loads, plan.torques, plan.fit_torque_max) == (LOADS, PAPER_TORQUES, FIT_TORQUE_MAX)
    assert (plan.validation_loads, plan.validation_torques) == (VALIDATION_LOADS, VALIDATION_TORQUES)


@pytest.mark.parametrize("rover", SHIPPED)
def test_a_scaled_plan_brackets_the_static_load_and_puts_three_torques_in_the_window(rover):
    """Per load, at least three torque levels up to the fits' largest settle (by the reference
    wheel: Tx(W, slip) = torque) with their slip in the fits' window: what a degree-2 fit needs."""
    choice = choose(rover=rover, soil="lunar_nominal")
    plan = plan_for(choice)
    load = static_load(choice)
    assert min(plan.loads) < load < max(plan.loads)
    assert min(plan.validation_loads) < load < max(plan.validation_loads)
    for w in plan.loads:
        ends = wheel_state(np.full(2, w), np.array(SLIP_FIT_RANGE), choice.wheel, choice.soil).Tx
        inside = [t for t in plan.torques if ends[0] <= t <= min(ends[1], plan.fit_torque_max)]
        assert len(inside) >= 3, (rover, w, plan.torques, ends)
    assert "scaled" in plan.basis and f"{load:.1f} N" in plan.basis


def test_the_mer_wheel_on_the_papers_rover_gets_torques_for_its_light_loads():
    """The issue's case: `make run SOIL=lunar_nominal WHEEL=mer` had one point at 100 N."""
    choice = choose(soil="lunar_nominal", wheel="mer")
    plan = plan_for(choice)
    for w in plan.loads:
        ends = wheel_state(np.full(2, w), np.array(SLIP_FIT_RANGE), choice.wheel, choice.soil).Tx
        assert sum(ends[0] <= t <= min(ends[1], plan.fit_torque_max) for t in plan.torques) >= 3, w


def test_a_rover_that_cannot_be_driven_is_refused_before_the_sweep():
    sinking = choose(rover="mer", soil="lunar_nominal", assignments=["rover.mass=20000"])
    with pytest.raises(NotDrivable, match=r"static wheel load .* cannot carry it: it sinks to its radius"):
        plan_for(sinking)


def test_a_plan_file_round_trips_and_bad_ones_are_named(tmp_path):
    path = tmp_path / "plan.toml"
    path.write_text("loads = [50.0, 100.0, 150.0]\ntorques = [1.0, 2.0, 4.0]\nfit_torque_max = 2.0\n")
    plan = read_plan(path)
    assert plan.loads == (50.0, 100.0, 150.0) and plan.fit_torque_max == 2.0
    assert plan.validation_loads == VALIDATION_LOADS and str(path) in plan.basis  # the paper's where left out
    assert not plan.is_paper and plan.to_dict()["loads"] == [50.0, 100.0, 150.0]
    for text, message in (("loads = [100.0, -5.0]\n", r"each > 0 N"), ("torque = [1.0]\n", r"unknown key\(s\)"),
                          ("loads = [100.0]\n", r"at least two loads"), ("loads = 100\n", r"expected a list"),
                          ("loads = [1.0, 1.0]\n", r"distinct")):
        path.write_text(text)
        with pytest.raises(ValueError, match=message):
            read_plan(path)
    with pytest.raises(ValueError, match=r"no such file"):
        read_plan(tmp_path / "none.toml")


def test_the_scaled_torques_follow_the_wheels_torque_on_the_soil():
    """Scaling by Tx at 20 % slip under the static load: the plan's torques give the new wheel
    the slips the paper's give its own (the middle of the paper's levels, 20 N·m at 424 N)."""
    paper = choose()
    for rover in ("mer", "msl", "viper"):
        choice = choose(rover=rover, soil="lunar_nominal")
        plan = plan_for(choice)
        ratio = plan.torques[PAPER_TORQUES.index(20.0)] / 20.0
        reference = wheel_state(np.array([static_load(choice)]), np.array([0.2]), choice.wheel, choice.soil).Tx[0] / \
            wheel_state(np.array([STATIC_WHEEL_LOAD]), np.array([0.2]), paper.wheel, paper.soil).Tx[0]
        assert math.isclose(ratio, reference, rel_tol=5e-3), rover
    assert asdict(plan_for(paper))["loads"] == LOADS
