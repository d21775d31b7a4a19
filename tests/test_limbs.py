"""The leg-wheel rover's limb kinematics (rover_cosim.limbs, issue 47 item 3): the inverse
kinematics puts the hub where it was asked to within 1e-9 m with the ankle link vertical and the
wheel rolling along its heading, on a level and a tilted body; the Jacobian is the forward
kinematics' derivative; the joint torques that hold a hub force do the same virtual work; the
stance mirrors left and right; a target out of reach is named."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rover_cosim.limbs import (
    JOINTS,
    LimbGeometry,
    Unreachable,
    athlete_limbs,
    attitude,
    forward,
    inverse,
    jacobian,
    joint_torques,
    stance_forward,
    stance_inverse,
)

LIMBS = athlete_limbs()
#: The paper's posture: hubs at x = 1.5, 0, -1.5 m, y = +-1.5 m, 1.0 m below the centre of gravity.
PAPER_HUBS = np.array([[x, y, -1.0] for y in (1.5, -1.5) for x in (1.5, 0.0, -1.5)])


def _targets(limb: LimbGeometry, rng: np.random.Generator, count: int, out_max: float = 1.6) -> list[np.ndarray]:
    """Reachable hub targets around the limb's mount: out 0.6 m to ``out_max``, 0.7-1.4 m below it."""
    targets = []
    for _ in range(count):
        angle = limb.mount_yaw + rng.uniform(-0.8, 0.8)
        out, down = rng.uniform(0.6, out_max), rng.uniform(0.7, 1.4)
        targets.append(np.array(limb.mount) + np.array([out * math.cos(angle), out * math.sin(angle), -down]))
    return targets


@pytest.mark.parametrize("limb", range(6))
def test_inverse_then_forward_reaches_the_hub_on_a_level_body(limb):
    rng = np.random.default_rng(47 + limb)
    geometry = LIMBS[limb]
    for target in _targets(geometry, rng, 40):
        heading = rng.uniform(-1.0, 1.0)
        pose = forward(geometry, inverse(geometry, target, heading))
        assert np.max(np.abs(pose.hub - target)) < 1e-9
        assert pose.link @ np.array([0.0, 0.0, -1.0]) == pytest.approx(1.0, abs=1e-12)   # the link hangs down
        assert abs(pose.axle[2]) < 1e-12                                               # the axle is level
        np.testing.assert_allclose(pose.heading(), [math.cos(heading), math.sin(heading), 0.0], atol=1e-12)


def test_inverse_then_forward_reaches_the_hub_on_a_tilted_body():
    rng = np.random.default_rng(471)
    for limb in LIMBS:
        for target in _targets(limb, rng, 10, out_max=1.2):  # within reach of a hanging ankle tilted 0.25 rad
            roll, pitch = rng.uniform(-0.25, 0.25, 2)
            up = attitude(roll, pitch, 0.0).T @ np.array([0.0, 0.0, 1.0])
            heading = rng.uniform(-0.5, 0.5)
            pose = forward(limb, inverse(limb, target, heading, up))
            assert np.max(np.abs(pose.hub - target)) < 1e-9
            assert abs(pose.axle @ up) < 1e-9                          # the axle level in the world
            assert abs(pose.heading(up) @ np.cross(up, _heading_direction(up, heading))) < 1e-9  # along the heading
            if abs(pose.axes[5] @ pose.axes[1]) < 0.85:                # the wrist well away from its singularity
                assert pose.link @ up == pytest.approx(-1.0, abs=1e-9)  # the link vertical in the world


def _heading_direction(up: np.ndarray, heading: float) -> np.ndarray:
    """The direction ``heading`` [rad] from the body's x axis projected on the plane normal to ``up``."""
    x_on_plane = np.array([1.0, 0.0, 0.0]) - up[0] * up
    x_on_plane /= np.linalg.norm(x_on_plane)
    return math.cos(heading) * x_on_plane + math.sin(heading) * np.cross(up, x_on_plane)


def test_a_middle_limb_near_its_wrist_singularity_stands_its_wheel_upright_under_a_tilted_body():
    """The middle limb steered 90 deg: its roll axis along the pitch axes, it cannot tilt its link
    out of its plane. Under roll and pitch it still reaches the hub, heads its wheel along the
    heading and keeps it upright (camber 0); over a sweep of small steps (a posture controller's)
    no joint jumps."""
    limb = LIMBS[1]
    hub = PAPER_HUBS[1] + np.array([0.0, 0.0, -0.2])  # the body raised to 1.2 m, as the posture controller does
    q = inverse(limb, hub, 0.0)
    for k in range(1, 41):
        roll, pitch = -0.35 * k / 40, 0.02 * k / 40
        up = attitude(roll, pitch, 0.0).T @ np.array([0.0, 0.0, 1.0])
        rotation = attitude(roll, pitch, 0.0)
        target = rotation.T @ (hub + np.array([0.0, -0.1 * k / 40, 0.0]))
        moved = inverse(limb, target, 0.0, up, q)
        assert np.max(np.abs(moved - q)) < 0.05, f"step {k}: a joint jumped by {np.max(np.abs(moved - q)):.3g} rad"
        q = moved
        pose = forward(limb, q)
        assert np.max(np.abs(pose.hub - target)) < 1e-9 and abs(pose.axle @ up) < 1e-9
        assert abs(pose.axle @ _heading_direction(up, 0.0)) < 1e-9


def test_the_jacobian_is_the_forward_kinematics_derivative():
    rng = np.random.default_rng(472)
    for limb in LIMBS:
        q = inverse(limb, _targets(limb, rng, 1)[0], 0.3) + rng.normal(0, 0.1, JOINTS)
        step = 1e-6
        numeric = np.column_stack([(forward(limb, q + step * e).hub - forward(limb, q - step * e).hub) / (2 * step)
                                   for e in np.eye(JOINTS)])
        np.testing.assert_allclose(jacobian(limb, q)[:3], numeric, atol=1e-8)
        axes = jacobian(limb, q)[3:]
        np.testing.assert_allclose(np.linalg.norm(axes, axis=0), 1.0, atol=1e-12)


def test_joint_torques_do_the_virtual_work_of_the_hub_force():
    """tau . dq = -F . dp for a small joint motion: the joints hold what the ground pushes."""
    rng = np.random.default_rng(473)
    for limb in LIMBS:
        q = inverse(limb, _targets(limb, rng, 1)[0], 0.0)
        force = np.array([rng.normal(0, 30), rng.normal(0, 30), 424.0])
        torques = joint_torques(limb, q, force)
        dq = rng.normal(0, 1e-7, JOINTS)
        dp = forward(limb, q + dq).hub - forward(limb, q).hub
        assert torques @ dq == pytest.approx(-force @ dp, rel=1e-5, abs=1e-12)


def test_the_paper_posture_is_reached_and_mirrored_left_to_right():
    joints = stance_inverse(LIMBS, PAPER_HUBS, np.zeros(6))
    np.testing.assert_allclose(stance_forward(LIMBS, joints, np.zeros(6)), PAPER_HUBS, atol=1e-9)
    left, right = joints[:3], joints[3:]
    np.testing.assert_allclose(right[:, [1, 2, 3, 5]], left[:, [1, 2, 3, 5]], atol=1e-12)  # pitches equal
    np.testing.assert_allclose(right[:, [0, 4]], -left[:, [0, 4]], atol=1e-12)              # yaws mirrored
    np.testing.assert_allclose(joints[0, 1:4], joints[2, 1:4], atol=1e-12)                  # front as rear


def test_a_stance_under_a_tilted_and_moved_body_round_trips():
    rng = np.random.default_rng(474)
    pose = np.array([2.0, -1.0, 0.3, 0.12, -0.08, 0.6])
    rotation = attitude(*pose[3:])
    hubs = np.array([pose[:3] + rotation @ hub for hub in PAPER_HUBS]) + rng.normal(0, 0.05, (6, 3))
    joints = stance_inverse(LIMBS, hubs, pose, headings=rng.uniform(-0.3, 0.3, 6))
    np.testing.assert_allclose(stance_forward(LIMBS, joints, pose), hubs, atol=1e-9)


def test_a_target_out_of_reach_and_bad_geometry_are_named():
    limb = LIMBS[0]
    with pytest.raises(Unreachable, match=r"the limb reaches 0 to 2 m \(off by"):
        inverse(limb, np.array(limb.mount) + np.array([3.0, 3.0, -1.0]))
    with pytest.raises(ValueError, match=r"thigh=-1.0: expected a length > 0 m"):
        LimbGeometry((0.0, 0.0, 0.0), 0.0, thigh=-1.0)
    with pytest.raises(ValueError, match=r"expected 6 finite joint angles"):
        forward(limb, [0.0] * 5)


def test_the_modelica_limb_forward_kinematics_is_the_numpy_one():
    """Components.Limb (through Examples.LimbKinematics with this limb and these angles as
    modifiers, run by rumoca) against rover_cosim.limbs.forward: hub, link and axle to 1e-9 for
    every limb of the frame."""
    import rumoca

    from rover_cosim.fmubuild import catalog

    def values(numbers) -> str:  # noqa: ANN001 - a sequence of floats
        return "{" + ", ".join(repr(float(v)) for v in numbers) + "}"

    rng = np.random.default_rng(475)
    for number, limb in enumerate(LIMBS, start=1):
        q = inverse(limb, _targets(limb, rng, 1)[0], rng.uniform(-0.5, 0.5)) + rng.normal(0, 0.2, JOINTS)
        text = (f"model Check extends RoverTerramechanics.Examples.LimbKinematics(q = {values(q)}, limb(mount = "
                f"{values(limb.mount)}, mountYaw = {limb.mount_yaw!r}, thigh = {limb.thigh!r}, shank = {limb.shank!r}, "
                f"ankle = {limb.ankle!r}, hubOffset = {limb.hub_offset!r})); end Check;")
        session = rumoca.Session(roots=[str(catalog.MODELICA_ROOT)])
        row = session.loads(text, model="Check", filename="Check.mo").simulate(t=(0.0, 0.01), dt=0.01).to_dataframe()
        row = row.iloc[-1]
        pose = forward(limb, q)
        for name, expected in (("hub", pose.hub), ("link", pose.link), ("axle", pose.axle)):
            got = np.array([row[f"kinematics.{name}[{k}]"] for k in (1, 2, 3)])
            np.testing.assert_allclose(got, expected, atol=1e-9, err_msg=f"limb {number}: {name}")
        got = np.array([[row[f"kinematics.jacobian[{i},{k}]"] for k in range(1, 7)] for i in (1, 2, 3)])
        np.testing.assert_allclose(got, jacobian(limb, q)[:3], atol=1e-9, err_msg=f"limb {number}: jacobian")
        got = np.array([[row[f"kinematics.axes[{i},{k}]"] for k in range(1, 7)] for i in (1, 2, 3)])
        np.testing.assert_allclose(got, jacobian(limb, q)[3:], atol=1e-9, err_msg=f"limb {number}: axes")


# --- statics: the weight over six compliant limbs -------------------------------------------------

def test_loads_at_rest_sum_to_the_weight_and_balance_its_moments():
    from rover_cosim.limbs import static_loads

    joints = stance_inverse(LIMBS, PAPER_HUBS, np.zeros(6))
    loads = static_loads(LIMBS, joints, 2.0e4, 1570.0, 1.62)
    assert loads.sum() == pytest.approx(1570.0 * 1.62, rel=1e-12)
    assert PAPER_HUBS[:, 0] @ loads == pytest.approx(0.0, abs=1e-9)
    assert PAPER_HUBS[:, 1] @ loads == pytest.approx(0.0, abs=1e-9)
    np.testing.assert_allclose(loads[:3], loads[3:], rtol=1e-9)    # left as right
    assert loads[0] == pytest.approx(loads[2], rel=1e-9)             # front as rear
    forward_shift = static_loads(LIMBS, joints, 2.0e4, 1570.0, 1.62, centre=(0.3, 0.0))
    assert forward_shift[0] > loads[0] and forward_shift[2] < loads[2]  # the load follows the centre of gravity


def test_identical_limbs_share_the_weight_equally():
    """Six limbs of one geometry around the body, each reaching out alike: one sixth each."""
    from rover_cosim.limbs import static_loads

    hubs = np.array([np.array(limb.mount) + 1.2 * np.array([np.cos(limb.mount_yaw), np.sin(limb.mount_yaw), 0.0])
                     + np.array([0.0, 0.0, -1.1]) for limb in LIMBS])
    joints = stance_inverse(LIMBS, hubs, np.zeros(6), headings=0.0)
    np.testing.assert_allclose(static_loads(LIMBS, joints, 3.0e4, 900.0, 3.71), 900.0 * 3.71 / 6, rtol=1e-9)


def test_the_holding_torques_are_the_jacobians_transpose_and_a_pulling_stance_is_named():
    from rover_cosim.limbs import holding_torques, static_loads

    joints = stance_inverse(LIMBS, PAPER_HUBS, np.zeros(6))
    loads = static_loads(LIMBS, joints, 2.0e4, 1570.0, 1.62)
    torques = holding_torques(LIMBS, joints, loads)
    for limb, q, w, tau in zip(LIMBS, joints, loads, torques):
        np.testing.assert_allclose(tau, -jacobian(limb, q)[:3].T @ np.array([0.0, 0.0, w]), atol=1e-9)
        assert abs(tau[0]) < 1e-9 and abs(tau[4]) < 1e-9    # a vertical load turns no yaw or steer joint
    with pytest.raises(ValueError, match=r"limbs \[.*\] would pull on the ground"):
        static_loads(LIMBS, joints, 2.0e4, 1570.0, 1.62, centre=(3.0, 0.0))


def test_the_modelica_leg_wheel_body_settles_on_the_loads_of_the_numpy_statics():
    """Components.LegWheelChassis in the paper's posture (Examples.LegWheelStance, rumoca): after
    5 s on its damped limbs the loads sum to the weight and equal rover_cosim.limbs.static_loads,
    the body level; the posture's joint angles in the example are those stance_inverse gives."""
    from rover_cosim.fmubuild import source
    from rover_cosim.limbs import holding_torques, static_loads

    joints = stance_inverse(LIMBS, PAPER_HUBS, np.zeros(6))
    text = source.class_file("RoverTerramechanics.Examples.LegWheelStance").read_text()
    for name, column in (("hipYaw", 0), ("hipPitch", 1), ("kneePitch", 2), ("anklePitch", 3), ("ankleSteer", 4)):
        declared = text.split(f"parameter Real {name}[6](each unit=\"rad\") = {{")[1].split("}")[0]
        np.testing.assert_allclose([float(v) for v in declared.split(",")], joints[:, column], atol=1e-12)
    last = source.simulate("RoverTerramechanics.Examples.LegWheelStance").iloc[-1]
    loads = np.array([last[f"body.W[{i}]"] for i in range(1, 7)])
    assert loads.sum() == pytest.approx(1570.0 * 1.62, rel=1e-6)
    np.testing.assert_allclose(loads, static_loads(LIMBS, joints, 2.0e4, 1570.0, 1.62), rtol=1e-5)
    assert abs(last["body.pitch"]) < 1e-9 and abs(last["body.roll"]) < 1e-9
    names = ("hipYaw", "hipPitch", "kneePitch", "anklePitch", "ankleSteer", "ankleRoll")
    angles = np.array([[last[f"body.{name}Angle[{i}]"] for name in names] for i in range(1, 7)])
    torques = np.array([[last[f"body.{name}Torque[{i}]"] for name in names] for i in range(1, 7)])
    # the servos hold the loads (virtual work, numpy) and deflect by torque / stiffness
    np.testing.assert_allclose(torques, holding_torques(LIMBS, joints, loads), atol=1e-6)
    np.testing.assert_allclose(angles, joints - torques / 2.0e4, atol=1e-12)
    # the hubs the model reports are numpy's forward kinematics of the angles it reports
    for number, (limb, q) in enumerate(zip(LIMBS, angles), start=1):
        got = [last[f"body.hub{axis}[{number}]"] for axis in "XYZ"]
        np.testing.assert_allclose(got, forward(limb, q).hub, atol=1e-9, err_msg=f"limb {number}")
    # ... which sit on the ground (the normal spring's deflection) to the second order of the deflection
    assert np.max(np.abs(np.array([last[f"body.hubZ[{i}]"] for i in range(1, 7)]) + last["body.z"])) < 2e-3


def test_inverse_leaves_its_start_as_it_was():
    """Newton works on its own copy: the joints a caller passes as the start (a controller's last
    posture) are not changed."""
    limb = LIMBS[0]
    start = inverse(limb, PAPER_HUBS[0], 0.0)
    kept = start.copy()
    up = attitude(0.2, 0.05, 0.0).T @ np.array([0.0, 0.0, 1.0])
    moved = inverse(limb, PAPER_HUBS[0] + np.array([0.0, 0.05, 0.02]), 0.0, up, start)
    np.testing.assert_array_equal(start, kept)
    assert np.max(np.abs(moved - start)) > 1e-3
