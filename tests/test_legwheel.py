"""The leg-wheel rover (issue 47): the posture controller against the numpy kinematics, the FMUs'
physics (rest stays at rest and carries the weight, the joint torques are J^T F, the hubs are the
forward kinematics of the reported joint angles, reverse mirrors forward, energy is not created,
monolithic and co-simulated agree) and the scenarios' job and command on short runs."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path
from typing import Any

import fmpy
import numpy as np
import pandas as pd
import pytest
from cs_slave import Slave

from rover_cosim.control.posture import JOINT_INPUTS, Posture, PostureController, StepOver, posture_joints
from rover_cosim.limbs import athlete_limbs, attitude, forward, holding_torques, static_loads

LIMBS = athlete_limbs()
PAPER = [(1.5, 1.5), (0.0, 1.5), (-1.5, 1.5), (1.5, -1.5), (0.0, -1.5), (-1.5, -1.5)]  # the paper's footprint [m]
MASS, G = 1570.0, 1.62


def joints_of(mapping: dict[str, float]) -> np.ndarray:
    """The 6 x 6 joints (a row per limb) of the FMUs' set-point names."""
    return np.array([[mapping[f"{name}[{i}]"] for name in JOINT_INPUTS] for i in range(1, 7)])


# --- the posture controller ---------------------------------------------------------------------

def test_the_paper_posture_is_the_fmus_default_and_puts_the_hubs_where_the_paper_has_them(fmus):
    """The block's set-points of the paper's posture equal the leg-wheel FMUs' input start values
    (the Modelica declaration and the Python controller agree), and their forward kinematics puts the
    hubs at x = 1.5, 0, -1.5 m, y = +-1.5 m, 1.0 m below the centre of gravity, wheels straight."""
    expected = posture_joints()
    for name in ("LegWheelRover", "LegWheelRoverBody"):
        starts = {v.name: float(v.start) for v in fmpy.read_model_description(str(fmus[name])).modelVariables
                  if v.causality == "input" and v.name.split("[")[0] in JOINT_INPUTS}
        assert starts.keys() == expected.keys()
        np.testing.assert_allclose([starts[k] for k in expected], list(expected.values()), atol=1e-12)
    hubs = np.array([forward(limb, q).hub for limb, q in zip(LIMBS, joints_of(expected))])
    np.testing.assert_allclose(hubs, [[x, y, -1.0] for y in (1.5, -1.5) for x in (1.5, 0.0, -1.5)], atol=1e-12)


def test_the_posture_block_steers_each_wheel_by_its_ankle_steer_joint():
    """A steering input of d turns the wheel's heading by d (forward kinematics of the output)."""
    block = PostureController("posture")
    steer = np.array([0.1, -0.2, 0.05, 0.3, -0.1, 0.0])
    u = np.concatenate([[1.0, 0.0, 0.0, 0.0], np.full(6, 424.0), steer])
    outputs = dict(zip(block.outputs, block.start(0.0, u, 1e-3)))
    for i, (limb, q) in enumerate(zip(LIMBS, joints_of(outputs))):
        heading = forward(limb, q).heading()
        assert math.atan2(heading[1], heading[0]) == pytest.approx(steer[i], abs=1e-12)


def test_the_posture_block_levels_the_body_across_a_slope_and_shares_the_load():
    """On a 20 deg side slope (the valley to the right), fed a body that follows its commands and
    loads that favour the downhill limbs, the block rolls the body to -20 deg at its rate limit,
    raises the downhill hubs' extension less than the uphill ones' where those carry more (lift),
    moves the centre of gravity uphill, and keeps every wheel straight ahead and upright."""
    slope = math.radians(20.0)
    block = PostureController("posture", control=True, slope=slope, downhill=-math.pi / 2, height=1.2)
    loads = np.array([300.0, 280.0, 300.0, 560.0, 600.0, 560.0])
    u = np.concatenate([[1.0, 0.0, 0.0, 0.0], loads, np.zeros(6)])
    block.start(0.0, u, 1e-3)
    for k in range(1, 121):  # 12 s; the body at its commanded height and roll, the loads held
        u[0], u[1] = block.loops.height, block.loops.roll
        block.step((k - 1) * 0.1, 0.1, u)
    report = block.report()
    assert report["roll_cmd_rad"] == pytest.approx(-slope, abs=1e-6)     # levelled
    assert report["shift_m"][1] > 0.1                                      # the centre of gravity uphill
    lift = np.array(report["lift_m"])
    assert lift[3:].mean() > lift[:3].mean() and abs(lift.sum()) < 1e-12  # the loaded hubs raised, mean 0
    np.testing.assert_allclose(np.array(report["footprint_m"]), PAPER, atol=1e-12)  # front and rear balanced
    rotation = attitude(block.loops.roll, 0.0, 0.0)
    for limb, q in zip(LIMBS, block.loops.joints):
        pose = forward(limb, q)
        axle = rotation @ pose.axle
        assert abs(axle[2]) < 1e-9 and abs(axle[0]) < 1e-9             # upright, rolling along x


def test_the_posture_block_pitches_the_body_level_up_a_slope_keeping_the_middle_hubs_under_their_hips():
    """Climbing a 10 deg slope (uphill ahead), fed a body that follows its commands, the block
    pitches the body to -10 deg against the ground at its rate limit, carries the centre of gravity
    uphill by height tan(10 deg) so that the weight's line passes through the middle hubs, keeps
    the middle limbs' hubs where they were in the body frame (their singular wrist cannot tilt the
    link along the body: no hip yaw, the steer at 90 deg) and every wheel upright, rolling along x
    up the slope; going down the same slope mirrors it."""
    slope = math.radians(10.0)
    for downhill, sign in ((math.pi, 1.0), (0.0, -1.0)):  # climbing; descending
        block = PostureController("posture", control=True, slope=slope, downhill=downhill, height=1.2)
        u = np.concatenate([[1.2, 0.0, 0.0, 0.0], np.full(6, 424.0), np.zeros(6)])
        block.start(0.0, u, 1e-3)
        rates = []
        for k in range(1, 81):  # 8 s; the body at its commanded pitch
            before = block.loops.pitch
            u[2] = block.loops.pitch
            block.step((k - 1) * 0.1, 0.1, u)
            rates.append(abs(block.loops.pitch - before) / 0.1)
        report = block.report()
        assert report["pitch_cmd_rad"] == pytest.approx(-sign * slope, abs=1e-6)    # levelled
        assert max(rates) <= math.radians(3.0) + 1e-12                             # at its rate limit
        assert report["shift_m"][0] == pytest.approx(-report["height_cmd_m"] * math.tan(report["pitch_cmd_rad"]),
                                                     rel=1e-12)
        assert abs(report["roll_cmd_rad"]) < 1e-12
        paper = joints_of(posture_joints())
        rotation = attitude(0.0, block.loops.pitch, 0.0)
        for i, (limb, q) in enumerate(zip(LIMBS, block.loops.joints)):
            pose = forward(limb, q)
            axle = rotation @ pose.axle
            assert abs(axle[2]) < 1e-9 and abs(axle[0]) < 1e-9                   # upright, rolling along x
            if i in (1, 4):  # the middle limbs: the hub under the hip as before, hip yaw 0, steer 90 deg
                assert pose.hub[0] == pytest.approx(forward(limb, paper[i]).hub[0], abs=1e-9)
                assert q[0] == pytest.approx(0.0, abs=1e-9) and abs(q[4]) == pytest.approx(math.pi / 2, abs=1e-9)
        ground = np.array([rotation @ forward(limb, q).hub for limb, q in zip(LIMBS, block.loops.joints)]).T
        # in the ground's frame (x along the slope): the footprint kept, the hubs on the ground plane
        np.testing.assert_allclose(ground[2], ground[2].mean(), atol=1e-9)
        np.testing.assert_allclose(ground[0, [0, 1, 2]] - ground[0, [3, 4, 5]], 0.0, atol=1e-9)
        np.testing.assert_allclose(np.diff(ground[0, :3]), [-1.5, -1.5], atol=1e-9)


def test_a_posture_out_of_the_limbs_reach_is_held_not_commanded():
    """Up a 35 deg slope the level posture (pitched -35 deg, the centre of gravity carried uphill) is out of
    the rear limbs' reach: the block does not fail; it holds the last posture the limbs reach, says
    when, and its set-points stay those of that posture (forward kinematics: the hubs on the ground)."""
    slope = math.radians(35.0)
    block = PostureController("posture", control=True, slope=slope, downhill=math.pi, height=1.2)
    u = np.concatenate([[1.0, 0.0, 0.0, 0.0], np.full(6, 424.0), np.zeros(6)])
    block.start(0.0, u, 1e-3)
    for k in range(1, 201):  # 20 s; the body at its commanded height and pitch
        u[0], u[2] = block.loops.height, block.loops.pitch
        block.step((k - 1) * 0.1, 0.1, u)
    report = block.report()
    assert report["held_unreachable_s"], "expected the level posture to be out of reach"
    assert -slope < report["pitch_cmd_rad"] < -math.radians(15.0)   # as far as the limbs go
    held = block.loops.joints
    assert np.all(np.isfinite(held))
    rotation = attitude(0.0, block.loops.pitch, 0.0)
    hubs = np.array([rotation @ forward(limb, q).hub for limb, q in zip(LIMBS, held)])
    np.testing.assert_allclose(hubs[:, 2], hubs[:, 2].mean(), atol=1e-9)  # still on the ground plane


def test_the_posture_block_moves_its_corner_hubs_towards_the_loads_centre_along_the_heading():
    """Loads heavier at the rear (as on a climb, where the contacts lie uphill of the hubs): the front
    and rear hubs move back together at the shift's rate limit, the middle hubs stay under their
    hips; a balanced load moves nothing."""
    for loads, moves in (((380.0, 420.0, 460.0) * 2, True), ((420.0,) * 6, False)):
        block = PostureController("posture", control=True)
        u = np.concatenate([[1.0, 0.0, 0.0, 0.0], loads, np.zeros(6)])
        block.start(0.0, u, 1e-3)
        for k in range(1, 11):  # 1 s
            u[0] = block.loops.height
            block.step((k - 1) * 0.1, 0.1, u)
        foot = np.array(block.report()["footprint_m"])
        moved = foot[:, 0] - np.array(PAPER)[:, 0]
        np.testing.assert_allclose(moved[[1, 4]], 0.0, atol=1e-15)          # the middle hubs stay
        np.testing.assert_allclose(foot[:, 1], np.array(PAPER)[:, 1], atol=1e-15)
        if moves:
            assert np.all(moved[[0, 2, 3, 5]] < 0) and np.ptp(moved[[0, 2, 3, 5]]) < 1e-15
            assert moved[0] >= -0.15 * 1.0 - 1e-12                               # the rate limit, 0.15 m/s
        else:
            np.testing.assert_allclose(moved, 0.0, atol=1e-12)


def test_the_posture_blocks_rates_are_the_slopes_of_its_set_points_over_each_step():
    """Every step, the rate outputs (``hipYawRate[i]`` ...) times the step are the set-points' change
    over it (the steering's own changes aside), across the updates that start a new ramp too; a
    block without control holds its posture: every rate 0."""
    for control in (True, False):
        block = PostureController("posture", control=control, step_over=StepOver() if control else None)
        n, h = 6, 1e-3
        names = [f"{joint}[{i}]" for joint in JOINT_INPUTS for i in range(1, n + 1)]
        rates = [f"{joint}Rate[{i}]" for joint in JOINT_INPUTS for i in range(1, n + 1)]
        sinkage = np.array([0.11, 0.02, 0.02, 0.02, 0.02, 0.02])  # limb 1 steps out
        u = np.concatenate([[1.0, 0.0, 0.0, 0.0], [380.0, 420.0, 460.0] * 2, np.zeros(6), sinkage, np.ones(6)])
        u = u[:len(block.inputs)]
        before = dict(zip(block.outputs, block.start(0.0, u, h)))
        largest = 0.0
        for k in range(600):  # 0.6 s: six updates
            after = dict(zip(block.outputs, block.step(k * h, h, u)))
            change = np.array([after[name] - before[name] for name in names])
            slope = np.array([after[name] for name in rates])
            np.testing.assert_allclose(slope * h, change, atol=1e-12)
            largest = max(largest, float(np.abs(slope).max()))
            before = after
        assert (largest > 0.01) == control, largest  # with control the hubs move: the lift, the balance


def test_the_posture_block_steps_a_sunk_wheel_out_and_holds_its_motor_meanwhile():
    """With ``step_over``: a wheel past the trigger sinkage has its hub lifted, carried ``reach``
    ahead and set down (the forward kinematics of the outputs), its torque output 0 while it is
    in the air, the others' torques passed through; each limb steps once."""
    plan = StepOver(trigger_sinkage=0.06, lift=0.25, reach=1.0, lift_time=0.5, swing_time=1.0, lower_time=0.5)
    block = PostureController("posture", control=True, step_over=plan)
    sinkage = np.array([0.11, 0.024, 0.024, 0.024, 0.024, 0.024])
    torques = np.arange(1.0, 7.0)
    u = np.concatenate([[1.0, 0.0, 0.0, 0.0], np.full(6, 420.0), np.zeros(6), sinkage, torques])
    block.start(0.0, u, 1e-3)
    outputs: dict[float, dict[str, float]] = {}
    for k in range(1, 41):  # 4 s at the block's 0.1 s
        y = block.step((k - 1) * 0.1, 0.1, u)
        outputs[round(k * 0.1, 1)] = dict(zip(block.outputs, y))
        if k == 3:
            u[4 + 12] = 0.0  # out of the patch: the wheel no longer sinks (a second trigger would be ignored)
    hub = {t: forward(LIMBS[0], joints_of(o)[0]).hub for t, o in outputs.items()}
    start = forward(LIMBS[0], joints_of(posture_joints())[0]).hub
    assert hub[1.0][2] - start[2] == pytest.approx(0.25, abs=1e-6)            # lifted (the set-points lag a period)
    assert outputs[1.0]["tau[1]"] == 0.0 and outputs[1.0]["tau[2]"] == 2.0    # its motor held, the others' passed
    assert hub[3.0][0] - start[0] == pytest.approx(1.0, abs=1e-6)             # carried 1 m ahead ...
    assert hub[3.0][2] - start[2] == pytest.approx(0.0, abs=1e-3)             # ... and set down
    assert outputs[3.0]["tau[1]"] == 1.0
    steps = block.report()["steps"]
    assert [s["limb"] for s in steps] == [1] and steps[0]["ended_s"] - steps[0]["began_s"] == pytest.approx(2.0)


def test_the_limb_soil_block_puts_each_hub_where_the_rover_says_it_is():
    from rover_cosim.jobs.ground import LimbSoilBlock
    from rover_cosim.terramechanics import Soil
    from rover_cosim.terramechanics.terrain import soil_patch

    soil_map = soil_patch((2.5, 1.5), 0.5, Soil(), Soil(c=200.0))
    block = LimbSoilBlock("soil", soil_map)
    hub_x = np.array([1.5, 0.0, -1.5, 1.5, 0.0, -1.5])
    hub_y = np.array([1.5, 1.5, 1.5, -1.5, -1.5, -1.5])
    shares = block.start(0.0, np.concatenate([[0.0, 0.0, 0.0], hub_x, hub_y]))
    assert shares.tolist() == [0.0] * 6
    hub_x[0] = 2.5  # limb 1 stepped 1 m ahead: into the patch
    assert block.step(0.0, 1e-3, np.concatenate([[0.0, 0.0, 0.0], hub_x, hub_y])).tolist() == [1.0] + [0.0] * 5
    turned = block.step(0.0, 1e-3, np.concatenate([[1.0, 0.0, 0.5 * math.pi], hub_x, hub_y]))  # the body turned left
    assert turned[0] == 0.0


@pytest.mark.parametrize("run_", ["step", "roll"])
def test_the_posture_and_limb_soil_twins_step_the_soft_patch_natively_bit_for_bit(fmus, identified, results_root,
                                                                                  run_):
    """The soft patch, 1.2 s (12 updates of the slow loops; with step-over the front-left limb
    lifts from 0.1 s, up 0.25 m from 0.6 s): the posture block's and the limb soil block's C twins step natively (the
    posture twin calls back into the block's update every 0.1 s) and the run gives the Python-stepped
    run's trajectories to the bit, and the same posture report."""
    import dataclasses

    from rover_cosim.jobs import legwheel
    from rover_cosim.orchestrator import native
    from rover_cosim.orchestrator.master import run

    if native.unavailable_reason() is not None:
        pytest.skip(str(native.unavailable_reason()))
    model = results_root / "identification" / "model.json"
    fmu_dir = fmus["LegWheelRover"].parent
    tables, reports = {}, {}
    for stepped_natively in (False, True):
        system = dataclasses.replace(legwheel.patch_system(fmu_dir, model, run_), stop_time=1.2,
                                     native=stepped_natively)
        if stepped_natively:
            blocks: dict[str, Any] = {entry.name: entry.block for entry in system.blocks}
            assert blocks["posture"].native() is not None and blocks["soil"].native() is not None
        tables[stepped_natively] = run(system).data
        reports[stepped_natively] = legwheel._posture_report(system)
    pd.testing.assert_frame_equal(tables[True], tables[False], check_exact=True)
    assert reports[True] == reports[False]
    assert reports[True]["updates"] == 12
    assert (reports[True]["lift_m"][0] > 0.2) == (run_ == "step")  # the front-left hub up in the air


def test_a_failing_posture_update_in_the_c_twin_fails_the_run_naming_the_block_and_the_error(
        fmus, identified, results_root, monkeypatch):
    import dataclasses

    from rover_cosim.jobs import legwheel
    from rover_cosim.orchestrator import native
    from rover_cosim.orchestrator.master import RunError, run

    if native.unavailable_reason() is not None:
        pytest.skip(str(native.unavailable_reason()))

    def broken(self, t, u):
        raise ArithmeticError("the loads are gone")

    monkeypatch.setattr(PostureController, "_update", broken)
    model = results_root / "identification" / "model.json"
    system = dataclasses.replace(legwheel.slope_system(fmus["LegWheelRover"].parent, model, "posture"), stop_time=0.5)
    with pytest.raises(RunError, match=r"posture \(block\).*the posture update at t = 0.1 s failed: "
                                       r"ArithmeticError: the loads are gone"):
        run(system)


def test_posture_ramps_enter_the_integrators_dfdt_one_step_per_communication_step(fmus, identified, results_root):
    """The side slope with posture control: its set-points ramp over every step (and the steering
    on them), a braking wheel's spin the stiffest mode. With d xdot / d u times the ramps' slopes in
    the Co-Simulation integrator's dfdt it takes one internal step per communication step once
    settled (it took three: the Rosenbrock stages then missed how the right-hand side moves with
    the inputs)."""
    import dataclasses

    from rover_cosim.jobs import legwheel
    from rover_cosim.orchestrator.master import run
    from rover_cosim.orchestrator.model import Port

    model = results_root / "identification" / "model.json"
    system = legwheel.slope_system(fmus["LegWheelRover"].parent, model, "posture")
    system = dataclasses.replace(system, stop_time=2.0, record=[*system.record, Port.parse("rover.statistics.steps")])
    data = run(system).data
    steps = data["rover.statistics.steps"].to_numpy()
    settled = np.searchsorted(data["time"].to_numpy(), 0.5)
    communication = len(data) - 1 - settled
    assert steps[-1] - steps[settled] <= 1.1 * communication, (steps[-1] - steps[settled], communication)


def test_posture_settings_out_of_range_are_refused_with_their_value():
    with pytest.raises(ValueError, match=r"slope = 2.0 rad: expected \[0, pi/2\)"):
        PostureController("p", slope=2.0)
    with pytest.raises(ValueError, match=r"period = 0.0: expected a finite value > 0"):
        PostureController("p", period=0.0)
    with pytest.raises(ValueError, match=r"footprint of 2 hubs for 6 limbs"):
        PostureController("p", footprint=((1.0, 1.0), (1.0, -1.0)))


# --- the FMUs' physics --------------------------------------------------------------------------

def _names(prefix: str, name: str) -> list[str]:
    return [f"{prefix}{name}[{i}]" for i in range(1, 7)]


def _rest(fmu: Path, stop: float = 3.0, **start: float) -> np.ndarray:
    from rover_cosim.jobs.legwheel import settled_height
    from rover_cosim.terramechanics.library import choose

    outputs = ["x", "v", "z", "pitch", "roll", *_names("", "Fz"), *_names("", "hubX"), *_names("", "hubY"),
               *_names("", "hubZ"), *[n for j in JOINT_INPUTS for n in _names("", f"{j}Angle")],
               *[n for j in JOINT_INPUTS for n in _names("", f"{j}Torque")]]
    return fmpy.simulate_fmu(str(fmu), stop_time=stop, output_interval=0.01, output=outputs,
                             start_values={"height0": settled_height(choose()), **start})


def test_at_rest_the_leg_wheel_rover_stays_put_carries_its_weight_and_holds_it_by_j_transpose_f(fmus):
    """LegWheelRover started at rest on its limbs in the paper's posture: it does not move, its
    loads sum to M g and equal the numpy statics, the joint torques are -J^T (0, 0, W) of the numpy
    Jacobian (virtual work) to 1e-6 N·m, and the hubs are numpy's forward kinematics of the joint
    angles it reports to 1e-9 m."""
    result = _rest(fmus["LegWheelRover"])
    last = result[-1]
    assert np.abs(result["x"]).max() < 1e-6 and np.abs(result["v"]).max() < 1e-6   # a micron, a micron per second
    loads = np.array([last[n] for n in _names("", "Fz")])
    assert loads.sum() == pytest.approx(MASS * G, rel=1e-6)
    set_points = joints_of(posture_joints())
    np.testing.assert_allclose(loads, static_loads(LIMBS, set_points, 2.0e4, MASS, G), rtol=1e-5)
    torques = np.array([[last[f"{name}Torque[{i}]"] for name in JOINT_INPUTS] for i in range(1, 7)])
    np.testing.assert_allclose(torques, holding_torques(LIMBS, set_points, loads), atol=1e-6)
    angles = np.array([[last[f"{name}Angle[{i}]"] for name in JOINT_INPUTS] for i in range(1, 7)])
    for i, (limb, q) in enumerate(zip(LIMBS, angles), start=1):
        np.testing.assert_allclose([last[f"hub{a}[{i}]"] for a in "XYZ"], forward(limb, q).hub, atol=1e-9)


def test_the_set_points_rates_move_the_hubs_against_the_body_at_j_qdot(fmus, tmp_path):
    """LegWheelRoverBody with its body rolled and pitched against the ground: the set-points' rates
    add R J q_set' (numpy's Jacobian and attitude) to each hub's velocity, along the wheel's heading
    (v_hub) and across it (v_lat) to 1e-12 m/s, and along the ground's normal load the limb through
    the servos' damping: dW = -k_n d_joint / k_joint n.(R J q_set')."""
    from rover_cosim.jobs.legwheel import settled_height
    from rover_cosim.limbs import jacobian
    from rover_cosim.terramechanics.library import choose

    roll, pitch = 0.01, -0.005  # every wheel loaded, none to its limb's yield load
    slave = Slave(fmus["LegWheelRoverBody"], tmp_path, start={"roll": roll, "pitch": pitch,
                                                              "height0": settled_height(choose())})
    refs = slave.refs
    parameters = {v.name: float(v.start) for v in slave.description.modelVariables if v.name.startswith("legs.")}
    stiffness, damping = parameters["legs.kJoint"], parameters["legs.dJoint"]
    joints = joints_of(posture_joints())
    rates = np.random.default_rng(1).uniform(-0.02, 0.02, (6, 6))
    names = [f"{joint}Rate[{i}]" for i in range(1, 7) for joint in JOINT_INPUTS]
    outputs = [f"{name}[{i}]" for name in ("v_hub", "v_lat", "W", "steer") for i in range(1, 7)]

    def read(values: np.ndarray) -> dict[str, float]:
        slave.slave.setReal([refs[n] for n in names], list(values.reshape(-1)))
        return dict(zip(outputs, slave.slave.getReal([refs[n] for n in outputs])))

    moving, still = read(rates), read(np.zeros((6, 6)))
    slave.close()
    rotation = attitude(roll, pitch, 0.0)
    normal = rotation[2]  # the ground's normal in the body frame
    loaded = 0
    for i, (limb, q) in enumerate(zip(LIMBS, joints), start=1):
        linear = jacobian(limb, q)[:3]
        velocity = rotation @ (linear @ rates[i - 1])
        steer = still[f"steer[{i}]"]
        along = velocity[0] * math.cos(steer) + velocity[1] * math.sin(steer)
        across = velocity[1] * math.cos(steer) - velocity[0] * math.sin(steer)
        assert moving[f"v_hub[{i}]"] - still[f"v_hub[{i}]"] == pytest.approx(along, abs=1e-12)
        assert moving[f"v_lat[{i}]"] - still[f"v_lat[{i}]"] == pytest.approx(across, abs=1e-12)
        if moving[f"W[{i}]"] > 0 and still[f"W[{i}]"] > 0:  # in the ground both ways, below the yield load
            spring = stiffness / float(np.sum((normal @ linear) ** 2))
            assert moving[f"W[{i}]"] - still[f"W[{i}]"] == pytest.approx(
                -spring * damping / stiffness * velocity[2], rel=1e-9)
            loaded += 1
    assert loaded >= 4


def test_a_limb_that_swings_its_hub_back_makes_its_free_wheel_roll_and_the_body_stay(fmus, tmp_path):
    """LegWheelRover at rest, no motor torque: the front-left limb carries its hub straight back
    at 0.2 m/s (its set-points ramped at q' = J^-1 (-0.2, 0, 0, 0, 0, 0), the rates given) for 0.5 s.
    The wheel rolls back under its hub (r omega near -0.2 m/s, less its slip), the other wheels stay
    still and the body stays put (free wheels pass no push to it); a hub moved without its rates is
    not seen by its wheel (it would not spin)."""
    from rover_cosim.jobs.legwheel import settled_height
    from rover_cosim.limbs import jacobian
    from rover_cosim.terramechanics.library import choose

    joints = joints_of(posture_joints())
    rate = np.linalg.solve(jacobian(LIMBS[0], joints[0]), [-0.2, 0.0, 0.0, 0.0, 0.0, 0.0])
    spins = {}
    for given in (True, False):
        slave = Slave(fmus["LegWheelRover"], tmp_path / str(given), start={"height0": settled_height(choose())})
        refs = slave.refs
        set_points = [refs[f"{joint}[1]"] for joint in JOINT_INPUTS]
        rate_inputs = [refs[f"{joint}Rate[1]"] for joint in JOINT_INPUTS]
        step = 1e-3
        for k in range(500):
            slave.slave.setReal(set_points, list(joints[0] + rate * k * step))
            slave.slave.setReal(rate_inputs, list(rate if given else np.zeros(6)))
            slave.slave.doStep(k * step, step)
        radius = 0.355
        spins[given] = np.array(slave.slave.getReal([refs[f"omega[{i}]"] for i in range(1, 7)])) * radius
        x = slave.slave.getReal([refs["x"]])[0]
        slave.close()
        assert abs(x) < 1e-3
    assert -0.2 < spins[True][0] < -0.17                    # rolls back with its hub, a little slip
    assert np.abs(spins[True][1:]).max() < 1e-3
    assert np.abs(spins[False]).max() < 1e-3                # without the rates: the wheel sees nothing


def _drive(fmu: Path, torque: float, stop: float = 2.0, **start: float) -> np.ndarray:
    from rover_cosim.jobs.legwheel import settled_height
    from rover_cosim.terramechanics.library import choose

    inputs = {f"tau[{i}]": torque for i in range(1, 7)}
    return fmpy.simulate_fmu(str(fmu), stop_time=stop, output_interval=0.01,
                             start_values={"height0": settled_height(choose()), **inputs, **start},
                             output=["x", "v", "pitch", *_names("", "Fz"), *_names("", "omega"),
                                     *_names("", "hipPitchTorque")])


def test_reverse_mirrors_forward_on_the_leg_wheel_rover(fmus):
    """Torques -T give the trajectory of +T mirrored front to back (the posture is front-back
    symmetric): x, v and pitch change sign; the front and rear limbs swap their loads, their hip
    torques and (with the sign changed) their wheels' spins; the middle limbs keep theirs."""
    ahead, back = _drive(fmus["LegWheelRover"], 40.0), _drive(fmus["LegWheelRover"], -40.0)
    assert ahead["v"][-1] > 0.05
    for name in ("x", "v", "pitch", "omega[2]"):
        np.testing.assert_allclose(back[name], -ahead[name], rtol=1e-6, atol=1e-9, err_msg=name)
    for front, rear in ((1, 3), (4, 6), (3, 1)):
        for name, sign in (("Fz", 1.0), ("hipPitchTorque", 1.0), ("omega", -1.0)):
            np.testing.assert_allclose(back[f"{name}[{front}]"], sign * ahead[f"{name}[{rear}]"], rtol=1e-6,
                                       atol=1e-9, err_msg=f"{name}[{front}]")
    np.testing.assert_allclose(back["Fz[2]"], ahead["Fz[2]"], rtol=1e-6)


def test_energy_is_not_created_rolling_out_without_torque(fmus):
    """Started at 0.5 m/s with its wheels rolling and no motor torque on level ground, the rover's
    kinetic energy (body and wheels) never grows: the soil and the joint servos only take energy."""
    fmu = fmus["LegWheelRover"]
    radius = 0.355
    result = fmpy.simulate_fmu(str(fmu), stop_time=3.0, output_interval=0.01, output=["v", "vy", *_names("", "omega")],
                               start_values={"height0": _rest(fmu, 0.01)["z"][0], "v": 0.5,
                                             **{f"omega[{i}]": 0.5 / radius for i in range(1, 7)}})
    spins = np.column_stack([result[f"omega[{i}]"] for i in range(1, 7)])
    energy = 0.5 * MASS * (result["v"] ** 2 + result["vy"] ** 2) + 0.5 * 0.5 * (spins ** 2).sum(axis=1)
    assert energy[-1] < energy[0]
    assert np.all(np.diff(energy) <= 1e-9 * energy[0]), f"grows by {np.diff(energy).max():.3g} J"


def test_the_monolithic_and_co_simulated_leg_wheel_rovers_agree(fmus, identified, results_root):
    """The paper's straight run, 4 s, on LegWheelRover.fmu and on LegWheelRoverBody + 6 Wheel:
    speed within 1 % of 1 m/s, loads within 2 % of the static load, the path within 2 mm (the wheels
    take the hub speeds as ramps: held at their end values the co-simulated rover gained 8 mm in
    4 s and 33 mm in 20 s; ramped 0.5 mm and 0.9 mm)."""
    from rover_cosim.jobs import legwheel
    from rover_cosim.orchestrator.master import run

    model = results_root / "identification" / "model.json"
    fmu_dir = fmus["LegWheelRover"].parent
    mono = legwheel.straight_table(run(legwheel.straight_system(fmu_dir, model, stop=4.0)).data)
    cosim = legwheel.straight_table(run(legwheel.straight_cosim_system(fmu_dir, model, stop=4.0)).data, cosim=True)
    agreement = legwheel._straight_agreement(mono, cosim)
    assert mono["v"].iloc[-1] > 0.3
    assert agreement["speed_max_difference_percent"] < 1.0
    assert agreement["load_max_difference_percent"] < 2.0
    assert abs(agreement["final_x_difference_m"]) < 2e-3


# --- the job and the command --------------------------------------------------------------------

def test_the_leg_wheel_scenarios_write_their_files_and_posture_control_spreads_the_load_less(
        fmus, identified, results_root, tmp_path):
    """``run_legwheel`` on short runs (2 s straight, 0.9 m of the 20 deg slope): every file, a record
    naming the FMUs and the posture's report; with posture control the uphill-downhill spread of
    the loads is smaller than with the paper's posture (already while the body levels)."""
    from rover_cosim.jobs.legwheel import run_legwheel

    result = run_legwheel(fmus["LegWheelRover"].parent, results_root / "identification" / "model.json", tmp_path,
                          stop=2.0, length=0.9, patch_stop=3.0)
    names = {p.name for p in result.files}
    assert {"legwheel_straight.csv", "legwheel_rms.csv", "legwheel_metrics.csv", "legwheel_stance.png",
            "legwheel_limbs_slope.png", "legwheel.json", "legwheel_slope_fixed.csv",
            "legwheel_slope_posture.csv"} <= names
    assert set(result.record["fmus"]) >= {"LegWheelRover", "LegWheelRoverBody", "Wheel", "Rover"}
    assert result.record["posture"]["posture"]["control"] and result.record["posture"]["posture"]["updates"] > 0
    metrics = result.metrics.set_index(["scenario", "run"])
    assert metrics.loc[("slope", "posture"), "load_spread"] < metrics.loc[("slope", "fixed"), "load_spread"]
    # the climb: the body pitches towards level (3 deg/s) and the front-rear load spread shrinks already
    assert metrics.loc[("climb", "posture"), "load_spread"] < metrics.loc[("climb", "fixed"), "load_spread"]
    assert metrics.loc[("climb", "posture"), "pitch_end_deg"] < -5.0
    assert abs(metrics.loc[("climb", "fixed"), "pitch_end_deg"]) < 1.0
    assert {"legwheel_climb_fixed.csv", "legwheel_climb_posture.csv", "legwheel_limbs_climb.png"} <= names
    # the soft patch: the sunk front-left wheel stepped out; in the air it carries no load and makes
    # no force; set down on firm soil it sinks as the others do
    assert [s["limb"] for s in result.record["posture"]["patch_step"]["steps"]] == [1]
    step = result.tables["patch_step"]
    began, ended = (result.record["posture"]["patch_step"]["steps"][0][k] for k in ("began_s", "ended_s"))
    air = step[(step["time"] > began + 0.6) & (step["time"] < ended - 0.6)]
    assert len(air) > 100 and air["Fz_1"].max() < 0.01 and air["Fx_1"].abs().max() < 0.05  # of 426 N on the ground
    assert step["soilShare_1"].iloc[-1] == 0.0 and step["sinkage_1"].iloc[-1] < 0.04
    assert result.tables["patch_roll"]["sinkage_1"].iloc[-1] > 0.09
    assert not result.record["posture"]["patch_roll"]["steps"]
    assert "legwheel_patch_step.csv" in names and "legwheel_limbs_patch.png" in names
    rms = pd.read_csv(tmp_path / "legwheel_rms.csv")
    assert list(rms.columns) == ["limb", "rms_legwheel_N", "rms_legwheel_cosim_N", "rms_spring_damper_N",
                                 "rms_paper_N"]


def test_simulate_only_legwheel_refuses_another_rover_with_its_name(tmp_path, fmus, identified, results_root):
    completed = subprocess.run([sys.executable, "-P", "-m", "rover_cosim", "simulate", "--only", "legwheel", "--rover",
                                "mer", "--allow-model-mismatch", "--quiet", "--out", str(tmp_path / "out"),
                                "--fmu-dir", str(fmus["LegWheelRover"].parent), "--model",
                                str(results_root / "identification" / "model.json")],
                               capture_output=True, text=True, timeout=600)
    assert completed.returncode != 0
    assert "rover 'mer': the leg-wheel scenarios are the paper's rover's" in completed.stderr
    assert "Traceback" not in completed.stderr
    assert not (tmp_path / "out" / "legwheel.json").exists()


def test_a_rover_too_heavy_for_its_joints_is_refused_before_any_run_with_the_numbers(fmus):
    """The job's joint limit and stiffness are the FMU's defaults; a rover whose limbs cannot hold
    it at rest (the FMU would yield and fall through) is refused naming its mass, the torque it
    needs and the limit; the paper's rover passes."""
    from rover_cosim.jobs.legwheel import K_JOINT, TAU_JOINT_MAX, check_carryable
    from rover_cosim.terramechanics.library import choose

    starts = {v.name: float(v.start) for v in fmpy.read_model_description(str(fmus["LegWheelRover"])).modelVariables
              if v.name in ("legs.tauJointMax", "legs.kJoint")}
    assert starts == {"legs.tauJointMax": TAU_JOINT_MAX, "legs.kJoint": K_JOINT}
    check_carryable(choose())
    with pytest.raises(ValueError, match=r"rover mass = 20000 kg under 1.62 m/s²: its limbs would need \d+ N·m at a "
                                         r"joint .* hold 2000 N·m .*up to about \d+ kg"):
        check_carryable(choose(assignments=["rover.mass=20000"]))


def test_the_stance_figure_draws_both_stances():
    from rover_cosim.jobs import legwheel_figures

    side, climb = math.radians(20.0), math.radians(10.0)
    png = legwheel_figures.stance({
        "paper's posture": (posture_joints(), 0.0, 0.0, (side, 0.0)),
        "levelled": (posture_joints(Posture(1.2, (0.0, 0.3), -0.3)), -0.3, 0.0, (side, 0.0)),
        "climb": (posture_joints(Posture(1.2, (1.2 * math.tan(climb), 0.0), 0.0, -climb)), 0.0, -climb, (0.0, climb))})
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 20_000



class _Recorder:
    """A block that reads a hub position and sets a joint: what it saw at its start is kept."""

    inputs: tuple[str, ...] = ("hub",)
    outputs: tuple[str, ...] = ("q",)
    units: dict[str, str] = {}

    def __init__(self, value: float):
        self.name, self.value = "holder", value
        self.seen: float | None = None

    def start(self, t0: float, u0: np.ndarray, h: float) -> np.ndarray:
        self.seen = float(u0[0])
        return np.array([self.value])

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        return np.array([self.value])


def test_an_fmu_input_fed_by_a_block_holds_its_start_value_until_the_block_starts(fmus):
    """The engine's initialization: LegWheelRoverBody's hip yaw set-point of limb 1 comes from a
    block started after the FMUs; until then the input keeps its declared start (the paper's
    posture), so the hub the block reads at its start is the posture's (x = 1.5 m), not that of a
    hip yaw of 0; after the start the block's value holds."""
    from rover_cosim.orchestrator.builder import SystemBuilder
    from rover_cosim.orchestrator.master import run

    posture = posture_joints()
    block = _Recorder(posture["hipYaw[1]"] + 0.1)
    builder = SystemBuilder("start values").simulation(stop_time=0.01, step=1e-3, allow_algebraic_loops=True)
    unloaded = {f"{name}[{i}]": 0.0 for name in ("Fx", "Fy", "tau") for i in range(1, 7)}
    builder.add_fmu("body", fmus["LegWheelRoverBody"], start=unloaded).add_block("holder", block)
    builder.connect("body.hubX[1]", "holder.hub").connect("holder.q", "body.hipYaw[1]")
    data = run(builder.build()).data
    assert block.seen == pytest.approx(forward(LIMBS[0], joints_of(posture)[0]).hub[0], abs=1e-3)
    turned = joints_of(posture)[0] + np.array([0.1, 0, 0, 0, 0, 0])
    assert data["body.hubX[1]"].iloc[-1] == pytest.approx(forward(LIMBS[0], turned).hub[0], abs=1e-3)
