"""The steerable rover (SteerableRover / SteerableRoverBody FMUs): the straight-line Rover with
the steering at zero, the physics of a turn (yaw, roll, load transfer, mirror symmetry, rest),
rumoca's simulation of the same Modelica, and the shipped co-simulation wiring."""

from __future__ import annotations

import numpy as np
from fmpy import simulate_fmu

from rover_cosim.fmubuild import source
from rover_cosim.orchestrator.examples import example
from rover_cosim.orchestrator.master import run
from rover_cosim.orchestrator.system import load_system
from rover_cosim.terramechanics import Wheel

WHEELS = range(1, 7)
TURN = {1: 0.05, 2: 0.0, 3: -0.05, 4: 0.05, 5: 0.0, 6: -0.05}  # front left, rear right


def simulate(fmu, torque: float, steer: dict[int, float] | None, stop: float, start_speed: float = 0.0,
             outputs: tuple[str, ...] = ("v", "x")) -> np.ndarray:
    """CS run at 1 ms with constant inputs; starts rolling at ``start_speed``."""
    names = [f"tau[{i}]" for i in WHEELS] + ([f"steer[{i}]" for i in WHEELS] if steer is not None else [])
    values = [torque] * 6 + ([steer[i] for i in WHEELS] if steer is not None else [])
    signal = np.array([(0.0, *values), (stop, *values)], dtype=[("time", float)] + [(n, float) for n in names])
    start = {}
    if start_speed:
        start = {"v": start_speed, **{f"omega[{i}]": start_speed / Wheel().r for i in WHEELS}}
    return simulate_fmu(str(fmu), stop_time=stop, step_size=1e-3, output_interval=0.01, input=signal,
                        output=list(outputs), fmi_type="CoSimulation", start_values=start)


def test_zero_steering_reproduces_the_straight_rover(fmus):
    """Same torque, steering zero: velocity and wheel loads of SteerableRover equal Rover's
    (floor 0.5 %; measured to rounding), and the rover stays on its line."""
    outputs = ("v", "x", "pitch", *[f"Fz[{i}]" for i in WHEELS])
    straight = simulate(fmus["Rover"], 20.0, None, 6.0, outputs=outputs)
    steered = simulate(fmus["SteerableRover"], 20.0, dict.fromkeys(WHEELS, 0.0), 6.0,
                       outputs=(*outputs, "y", "yaw", "roll"))
    assert np.abs(steered["v"] - straight["v"]).max() <= 0.005 * np.abs(straight["v"]).max()
    for i in WHEELS:
        assert np.abs(steered[f"Fz[{i}]"] - straight[f"Fz[{i}]"]).max() <= 0.005 * 424.0
    assert np.abs(steered["y"]).max() < 1e-12 and np.abs(steered["yaw"]).max() < 1e-12


def test_a_left_turn_yaws_rolls_out_and_loads_the_outer_wheels_and_mirrors(fmus):
    outputs = ("x", "y", "yaw", "roll", "yawRate", *[f"Fz[{i}]" for i in WHEELS], *[f"Fy[{i}]" for i in WHEELS])
    left = simulate(fmus["SteerableRover"], 20.0, TURN, 10.0, 0.5, outputs)
    right = simulate(fmus["SteerableRover"], 20.0, {i: -a for i, a in TURN.items()}, 10.0, 0.5, outputs)
    end = -1
    assert left["yaw"][end] > 0.2 and left["y"][end] > 1.0 and left["yawRate"][end] > 0
    assert left["roll"][end] > 0                     # to the outside: the left side goes up
    assert left["Fz[4]"][end] > left["Fz[1]"][end]   # right (outer) front wheel carries more
    assert left["Fz[6]"][end] > left["Fz[3]"][end]
    for name in ("y", "yaw", "roll", "yawRate"):
        np.testing.assert_allclose(right[name], -left[name], atol=1e-9 * max(1.0, np.abs(left[name]).max()))
    np.testing.assert_allclose(right["x"], left["x"], rtol=1e-9)
    for i, j in ((1, 4), (2, 5), (3, 6)):
        np.testing.assert_allclose(right[f"Fz[{i}]"], left[f"Fz[{j}]"], rtol=1e-8)
        np.testing.assert_allclose(right[f"Fy[{i}]"], -left[f"Fy[{j}]"], atol=1e-6)


def test_at_rest_with_steered_wheels_it_stays_at_rest(fmus):
    run_ = simulate(fmus["SteerableRover"], 0.0, TURN, 20.0, outputs=("v", "vy", "x", "y", "yaw"))
    for name in ("v", "vy", "x", "y", "yaw"):
        assert np.abs(run_[name]).max() < 1e-3, name


def test_fmu_matches_rumocas_simulation_of_the_same_modelica(fmus):
    """Examples.SteerableRoverTurn in rumoca against SteerableRover.fmu with the same inputs:
    pose within 1 mm and 1 mrad, loads within 0.1 N over 10 s."""
    theirs = source.simulate("RoverTerramechanics.Examples.SteerableRoverTurn")
    ours = simulate(fmus["SteerableRover"], 20.0, TURN, 10.0, 0.5, ("x", "y", "yaw", "Fz[1]", "Fz[4]"))
    times = theirs.index.to_numpy()
    for name, atol in (("x", 1e-3), ("y", 1e-3), ("yaw", 1e-3), ("Fz[1]", 0.1), ("Fz[4]", 0.1)):
        np.testing.assert_allclose(np.interp(times, ours["time"], ours[name]), theirs[f"rover.{name}"], atol=atol,
                                   err_msg=name)


def test_shipped_cosim_system_runs_the_lateral_interface(fmu_dir):
    """steerable_rover_cosim.toml: every wheel gets v_lat and gives Fy; the open-loop turn runs."""
    system = load_system(example("steerable_rover_cosim"), fmu_dir=fmu_dir)
    ports = {(c.source.instance, c.source.variable, c.target.instance, c.target.variable) for c in system.connections}
    for i in WHEELS:
        assert ("body", f"v_lat[{i}]", f"wheel{i}", "v_lat") in ports
        assert (f"wheel{i}", "Fy", "body", f"Fy[{i}]") in ports
    outcome = run(system)
    assert outcome.data["body.yaw"].iloc[-1] > 0.2 and outcome.data["body.roll"].iloc[-1] > 0

