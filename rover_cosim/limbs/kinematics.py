"""Forward and inverse kinematics of a limb of the leg-wheel rover (``geometry``), and of its whole
stance: pure numpy, independent of the Modelica model it cross-checks.

Conventions: the body frame has x forward, y left, z up, origin at the centre of gravity; a
limb's joint vector is ``q = (q1 .. q6)`` [rad] in the order of ``geometry.JOINT_NAMES``. The
driving posture hangs the ankle link along the world's vertical (down) with the wheel's axle
horizontal; the wheel rolls along ``axle x up`` (its heading).

- :func:`forward`: the joint frames and the hub (position, link and axle directions), the frame turned
  joint by joint about one of its axes.
- :func:`jacobian`: d(hub position)/dq and the joints' axes (geometric Jacobian, 6 x 6).
- :func:`inverse`: the joints that put the hub at a point with the ankle link vertical and the
  wheel rolling along a heading: closed form on a level body (the hip yaw from the plane of the
  limb, hip and knee pitch by the law of cosines, the ankle pitch that hangs the link, the steer
  that turns the axle), Newton on the six conditions for a tilted one.
- :func:`stance_forward`, :func:`stance_inverse`: the six limbs under a body pose (x, y, z, roll,
  pitch, yaw; roll about x, then pitch about y, then yaw about z, intrinsic z-y-x).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .geometry import JOINTS, LimbGeometry


def cross(a: ArrayLike, b: ArrayLike) -> NDArray[np.float64]:
    """a x b of 3-vectors along the last axis (broadcast), with numpy.cross's arithmetic
    (a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0: the same bits) without its overhead, which was
    half the posture controller's inverse kinematics."""
    u, v = np.asarray(a, float), np.asarray(b, float)
    return np.stack([u[..., 1] * v[..., 2] - u[..., 2] * v[..., 1], u[..., 2] * v[..., 0] - u[..., 0] * v[..., 2],
                     u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]], axis=-1)

FloatArray = NDArray[np.float64]
#: Newton's tolerance on the conditions of :func:`inverse` [m, and 1 for the directions].
TOLERANCE = 1e-13
NEWTON_STEPS = 30
#: |cos| of the angle between the ankle roll axis and the pitch axes above which :func:`inverse`
#: treats the wrist as singular (within 15 deg of it; see there).
WRIST_SINGULAR = math.cos(math.radians(15.0))


class Unreachable(ValueError):
    """The hub target is out of the limb's reach (the message says by how much)."""


def rot_x(angle: float) -> FloatArray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(angle: float) -> FloatArray:
    """Rotation about y; a positive angle tips the x axis down (towards -z)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(angle: float) -> FloatArray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def attitude(roll: float, pitch: float, yaw: float) -> FloatArray:
    """The body's rotation into the world: R = Rz(yaw) Ry(-pitch) Rx(roll), so that a positive pitch
    lifts the nose (as the rovers' ``pitch``) and a positive roll lifts the left side."""
    return rot_z(yaw) @ rot_y(-pitch) @ rot_x(roll)


@dataclass(frozen=True)
class LimbPose:
    """A limb's frames for joints ``q`` in the body frame (SI): ``origins[k]``, ``axes[k]`` of joint
    k (k = 0..5), the hub's position, the ankle link's direction (from the ankle towards the hub) and
    the wheel's axle (unit vectors)."""

    origins: FloatArray   # (6, 3) [m]
    axes: FloatArray      # (6, 3) [1]
    hub: FloatArray       # (3,) [m]
    link: FloatArray      # (3,) [1]
    axle: FloatArray      # (3,) [1]

    def heading(self, up: ArrayLike = (0.0, 0.0, 1.0)) -> FloatArray:
        """The unit direction the wheel rolls along: axle x up, normalised [1]."""
        direction = cross(self.axle, np.asarray(up, float))
        return direction / np.linalg.norm(direction)


def _checked(q: ArrayLike) -> FloatArray:
    joints = np.asarray(q, dtype=float)
    if joints.shape != (JOINTS,) or not np.all(np.isfinite(joints)):
        raise ValueError(f"q = {q!r}: expected {JOINTS} finite joint angles [rad]")
    return joints


Vector = tuple[float, float, float]


def _frames(geometry: LimbGeometry, q: Sequence[float]) -> tuple[list[Vector], list[Vector], Vector, Vector, Vector]:
    """The joints' origins and axes [m, 1], the hub, the link and the axle of :func:`forward`, in
    floats: the frame's columns turned joint by joint (a 3 x 3 product with a rotation about one
    axis changes two columns), a tenth of the cost of the matrices in numpy, which was the posture
    controller's inverse kinematics."""
    q1, q2, q3, q4, q5, q6 = q
    c, s = math.cos(geometry.mount_yaw), math.sin(geometry.mount_yaw)
    x_axis, y_axis, z_axis = (c, s, 0.0), (-s, c, 0.0), (0.0, 0.0, 1.0)  # the columns of rot_z(mount yaw)
    position = (float(geometry.mount[0]), float(geometry.mount[1]), float(geometry.mount[2]))
    origins: list[Vector] = []
    axes: list[Vector] = []
    for axis, angle, length in ((2, q1, 0.0), (1, q2, geometry.thigh), (1, q3, geometry.shank),
                                (1, q4, geometry.ankle), (0, q5, 0.0), (2, q6, geometry.hub_offset)):
        origins.append(position)
        axes.append((x_axis, y_axis, z_axis)[axis])
        c, s = math.cos(angle), math.sin(angle)
        if axis == 2:    # rot_z: x' = c x + s y, y' = -s x + c y
            x_axis, y_axis = _combine(c, x_axis, s, y_axis), _combine(-s, x_axis, c, y_axis)
        elif axis == 1:  # rot_y: x' = c x - s z, z' = s x + c z
            x_axis, z_axis = _combine(c, x_axis, -s, z_axis), _combine(s, x_axis, c, z_axis)
        else:            # rot_x: y' = c y + s z, z' = -s y + c z
            y_axis, z_axis = _combine(c, y_axis, s, z_axis), _combine(-s, y_axis, c, z_axis)
        position = (position[0] + length * x_axis[0], position[1] + length * x_axis[1],
                    position[2] + length * x_axis[2])
    return origins, axes, position, x_axis, y_axis


def _combine(a: float, u: Vector, b: float, v: Vector) -> Vector:
    return a * u[0] + b * v[0], a * u[1] + b * v[1], a * u[2] + b * v[2]


def _cross(a: Vector, b: Vector) -> Vector:
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def forward(geometry: LimbGeometry, q: ArrayLike) -> LimbPose:
    """The limb's frames and hub for the joint angles ``q`` [rad] (body frame, SI)."""
    origins, axes, hub, link, axle = _frames(geometry, [float(v) for v in _checked(q)])
    return LimbPose(np.array(origins), np.array(axes), np.array(hub), np.array(link), np.array(axle))


def jacobian(geometry: LimbGeometry, q: ArrayLike) -> FloatArray:
    """The geometric Jacobian (6 x 6): rows 0-2 d(hub)/dq [m/rad], rows 3-5 the joints' axes (the
    hub frame's angular velocity per joint rate); column k for joint k."""
    pose = forward(geometry, q)
    linear = cross(pose.axes, pose.hub - pose.origins)
    return np.vstack([linear.T, pose.axes.T])


def joint_torques(geometry: LimbGeometry, q: ArrayLike, force: ArrayLike,
                  moment: ArrayLike = (0.0, 0.0, 0.0)) -> FloatArray:
    """The joint torques [N·m] that hold a force [N] (and moment [N·m]) applied by the ground to the
    hub, by virtual work: tau = -J^T (F, M) (the joints push back on what the ground pushes)."""
    wrench = np.concatenate([np.asarray(force, float), np.asarray(moment, float)])
    return -jacobian(geometry, q).T @ wrench


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2 * math.pi) - math.pi


def _level_inverse(geometry: LimbGeometry, hub: FloatArray, heading: float) -> FloatArray:
    """The closed form on a level body: the ankle link straight down, the wheel rolling along
    ``heading`` [rad] (body frame), knee up."""
    ankle = hub + np.array([0.0, 0.0, geometry.drop])
    mount = np.array(geometry.mount)
    dx, dy = ankle[0] - mount[0], ankle[1] - mount[1]
    reach, depth = math.hypot(dx, dy), mount[2] - ankle[2]
    q1 = _wrap(math.atan2(dy, dx) - geometry.mount_yaw) if reach > 1e-12 else 0.0
    l1, l2 = geometry.thigh, geometry.shank
    distance = math.hypot(reach, depth)
    cosine = (distance ** 2 - l1 ** 2 - l2 ** 2) / (2 * l1 * l2)
    if not -1.0 <= cosine <= 1.0:
        limit = l1 + l2 if cosine > 1 else abs(l1 - l2)
        raise Unreachable(f"hub at {hub.tolist()} m: the ankle is {distance:.4g} m from the hip pitch joint, the "
                          f"limb reaches {abs(l1 - l2):.4g} to {l1 + l2:.4g} m (off by {abs(distance - limit):.3g} m)")
    q3 = math.acos(cosine)  # knee up: the shank bends down from the thigh
    q2 = math.atan2(depth, reach) - math.atan2(l2 * math.sin(q3), l1 + l2 * math.cos(q3))
    q4 = math.pi / 2 - q2 - q3
    partial = forward(geometry, [q1, q2, q3, q4, 0.0, 0.0])
    frame_y = cross(partial.link, partial.axle)  # the ankle frame's z axis: link x axle
    wanted = cross([0.0, 0.0, 1.0], [math.cos(heading), math.sin(heading), 0.0])  # the axle: up x heading
    q5 = math.atan2(float(wanted @ frame_y), float(wanted @ partial.axle))
    return np.array([q1, q2, q3, q4, q5, 0.0])


def inverse(geometry: LimbGeometry, hub: ArrayLike, heading: float = 0.0,
            up: ArrayLike = (0.0, 0.0, 1.0), start: ArrayLike | None = None) -> FloatArray:
    """The joints [rad] that put the hub at ``hub`` [m] (body frame) with the ankle link hanging
    along -``up`` (the world's up in body coordinates; (0, 0, 1) on a level body) and the wheel
    rolling along ``heading`` [rad] (in the plane normal to ``up``, from the body's x axis
    projected on it). Knee up, camber 0. A limb whose wrist is near its singularity (steered within
    15 deg of 90 deg: the roll axis along the pitch axes, the middle limbs of the paper's posture)
    cannot tilt its link out of its plane: on a tilted body it keeps its ankle roll and stands the
    wheel upright (hub, heading, camber 0), its link as the rest leaves it. Unreachable for a
    target out of reach.
    ``start``: where Newton starts on a tilted body (e.g. the joints of a nearby pose, which a
    controller that moves the posture step by step has; default: the level closed form's)."""
    target = np.asarray(hub, float)
    vertical = np.asarray(up, float)
    if target.shape != (3,) or not np.all(np.isfinite(target)):
        raise ValueError(f"hub = {hub!r}: expected (x, y, z) [m], finite")
    if vertical.shape != (3,) or not np.linalg.norm(vertical) > 0:
        raise ValueError(f"up = {up!r}: expected a direction (x, y, z)")
    vertical = vertical / np.linalg.norm(vertical)
    x_on_plane = np.array([1.0, 0.0, 0.0]) - vertical[0] * vertical
    if np.linalg.norm(x_on_plane) < 1e-9:
        raise ValueError(f"up = {up!r}: the body's x axis is vertical; no heading can be measured from it")
    x_on_plane /= np.linalg.norm(x_on_plane)
    y_on_plane = cross(vertical, x_on_plane)
    forward_dir = math.cos(heading) * x_on_plane + math.sin(heading) * y_on_plane
    across = cross(vertical, forward_dir)
    level = float(np.linalg.norm(vertical - np.array([0.0, 0.0, 1.0])))
    if level < 1e-15:
        return _level_inverse(geometry, target, heading)
    q = (_checked(start).copy() if start is not None
         else _level_inverse(geometry, _level_target(geometry, target, vertical), heading))
    pose = forward(geometry, q)
    # A wrist steered near 90 deg has its roll axis along the pitch axes: it cannot tilt its link out
    # of the limb's plane, so the link cannot be held vertical under any tilt; such a limb keeps its
    # ankle roll and stands its wheel upright instead (hub, heading, camber 0 on the other five).
    singular = abs(float(pose.axes[5] @ pose.axes[1])) > WRIST_SINGULAR
    rows, joints = ((0, 1, 2, 5, 6), slice(0, 5)) if singular else ((0, 1, 2, 3, 4, 5), slice(0, 6))
    for _ in range(NEWTON_STEPS):
        residual, slopes = _conditions_and_slopes(geometry, q, target, forward_dir, across, vertical)
        if np.max(np.abs(residual[list(rows)])) < TOLERANCE:
            return q
        q[joints] = q[joints] - np.linalg.lstsq(slopes[list(rows), joints], residual[list(rows)], rcond=None)[0]
    residual, _ = _conditions_and_slopes(geometry, q, target, forward_dir, across, vertical)
    if np.max(np.abs(residual[list(rows)])) > 1e-9:
        ankle = float(np.linalg.norm(target + geometry.drop * vertical - np.array(geometry.mount)))
        raise Unreachable(f"hub at {target.tolist()} m with up {vertical.tolist()}: no joint angles found "
                          f"(largest condition {np.max(np.abs(residual)):.3g}; the hanging ankle would be "
                          f"{ankle:.4g} m from the hip, the limb reaches {geometry.thigh + geometry.shank:.4g} m)")
    return q


def _conditions_and_slopes(geometry: LimbGeometry, q: FloatArray, hub: FloatArray, forward_dir: FloatArray,
                           across: FloatArray, up: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The conditions of :func:`inverse`: the hub at the target (3), the link along -up (2), the
    axle normal to the heading (1), the axle level (1, camber 0); and their derivatives by the
    joints (7 x 6): the hub's by the geometric Jacobian, a direction d's by a_k x d (every joint
    turns the hub frame)."""
    origins, axes, position, link, axle = _frames(geometry, q.tolist())
    heading, side, vertical = forward_dir.tolist(), across.tolist(), up.tolist()
    slopes = np.empty((7, JOINTS))
    for k, (origin, axis) in enumerate(zip(origins, axes)):
        lever = (position[0] - origin[0], position[1] - origin[1], position[2] - origin[2])
        link_turn, axle_turn = _cross(axis, link), _cross(axis, axle)
        slopes[:, k] = (*_cross(axis, lever), _dot(link_turn, heading), _dot(link_turn, side),
                        _dot(axle_turn, heading), _dot(axle_turn, vertical))
    target = hub.tolist()
    residual = np.array([position[0] - target[0], position[1] - target[1], position[2] - target[2],
                         _dot(link, heading), _dot(link, side), _dot(axle, heading), _dot(axle, vertical)])
    return residual, slopes


def _level_target(geometry: LimbGeometry, hub: FloatArray, up: FloatArray) -> FloatArray:
    """A start for Newton on a tilted body: the hub moved so that the level closed form hangs its
    ankle where the tilted one would."""
    return hub + geometry.drop * (up - np.array([0.0, 0.0, 1.0]))


def stance_forward(limbs: Sequence[LimbGeometry], joints: ArrayLike, pose: ArrayLike) -> FloatArray:
    """The hubs in the world [m], one row per limb, for ``joints`` (one row of six per limb) and the
    body ``pose`` (x, y, z [m], roll, pitch, yaw [rad])."""
    angles = np.asarray(joints, float).reshape(len(limbs), JOINTS)
    x, y, z, roll, pitch, yaw = (float(v) for v in np.asarray(pose, float))
    rotation = attitude(roll, pitch, yaw)
    return np.array([rotation @ forward(limb, q).hub + np.array([x, y, z]) for limb, q in zip(limbs, angles)])


def stance_inverse(limbs: Sequence[LimbGeometry], hubs: ArrayLike, pose: ArrayLike,
                   headings: ArrayLike | float = 0.0, start: ArrayLike | None = None) -> FloatArray:
    """The joints (a row of six per limb) that put each hub at ``hubs`` [m] (world) under the body
    ``pose`` (x, y, z [m], roll, pitch, yaw [rad]), each ankle link vertical in the world and each
    wheel rolling along ``headings`` [rad] (from the body's heading, in the ground plane);
    ``start``: the joints Newton starts from on a tilted body (a row per limb; see :func:`inverse`)."""
    targets = np.asarray(hubs, float).reshape(len(limbs), 3)
    x, y, z, roll, pitch, yaw = (float(v) for v in np.asarray(pose, float))
    rotation = attitude(roll, pitch, yaw)
    up = rotation.T @ np.array([0.0, 0.0, 1.0])
    turns = np.broadcast_to(np.asarray(headings, float), (len(limbs),))
    starts = [None] * len(limbs) if start is None else list(np.asarray(start, float).reshape(len(limbs), JOINTS))
    return np.array([inverse(limb, rotation.T @ (target - np.array([x, y, z])), float(turn), up, first)
                     for limb, target, turn, first in zip(limbs, targets, turns, starts)])
