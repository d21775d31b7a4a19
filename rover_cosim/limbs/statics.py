"""How the leg-wheel rover's weight spreads over its six wheels: each limb a compliant chain (its
joints position servos of stiffness ``k`` [N·m/rad] about their set-points), the body a rigid
plate on the six hubs. Six limbs carry the body with more contacts than it needs, so the loads
follow from the limbs' compliance (the reason the paper's rover can shift its load with its
posture).

- :func:`hub_compliance`: the hub's Cartesian compliance C = J_p K^-1 J_p^T [m/N] of a limb;
  its vertical compliance ``C_zz`` is the limb's spring under a load where the wheel rolls
  freely along the ground (horizontal forces small against the load, the model of the rovers'
  vertical limbs).
- :func:`static_loads`: the wheel loads [N] of a stance at rest on level ground, with the centre
  of gravity at a point of the body: heave, roll and pitch of the body on the six vertical
  springs 1/C_zz in equilibrium with the weight; they sum to M g and balance its moments.
- :func:`static_heave`: how far the body sinks on its limbs at rest [m] (the same solution's heave):
  the hubs' set-points sit that much below where the loaded hubs come to rest.
- :func:`holding_torques`: the joint torques [N·m] that hold those loads (virtual work, J^T F).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .geometry import JOINTS, LimbGeometry
from .kinematics import forward, jacobian, joint_torques

FloatArray = NDArray[np.float64]


def hub_compliance(geometry: LimbGeometry, q: ArrayLike, joint_stiffness: ArrayLike) -> FloatArray:
    """The hub's compliance (3 x 3) [m/N] for joints ``q`` [rad] of stiffness ``joint_stiffness``
    [N·m/rad] (one value or six): C = J_p K^-1 J_p^T."""
    stiffness = np.broadcast_to(np.asarray(joint_stiffness, float), (JOINTS,))
    if not np.all(stiffness > 0) or not np.all(np.isfinite(stiffness)):
        raise ValueError(f"joint_stiffness = {joint_stiffness!r}: expected values > 0 N·m/rad")
    linear = jacobian(geometry, q)[:3]
    return linear @ np.diag(1.0 / stiffness) @ linear.T


def static_loads(limbs: Sequence[LimbGeometry], joints: ArrayLike, joint_stiffness: ArrayLike, mass: float,
                 gravity: float, centre: ArrayLike = (0.0, 0.0)) -> FloatArray:
    """The wheel loads [N] (one per limb) of the body at rest on level ground on the stance
    ``joints`` (a row of six per limb) with the weight ``mass`` [kg] x ``gravity`` [m/s²] acting at
    ``centre`` (x, y) [m] of the body frame: heave, roll and pitch in equilibrium on the limbs'
    vertical springs. A limb that would pull (a negative load) is an error naming it: the stance
    cannot carry the weight there."""
    loads, _ = _equilibrium(limbs, joints, joint_stiffness, mass, gravity, centre)
    if np.any(loads < 0):
        lifted = [i + 1 for i in np.flatnonzero(loads < 0)]
        raise ValueError(f"limbs {lifted} would pull on the ground (loads {np.round(loads, 1).tolist()} N): the "
                         "stance cannot carry the weight at that centre of gravity")
    return loads


def static_heave(limbs: Sequence[LimbGeometry], joints: ArrayLike, joint_stiffness: ArrayLike, mass: float,
                 gravity: float, centre: ArrayLike = (0.0, 0.0)) -> float:
    """How far [m] the centre of gravity sinks at rest on the stance of :func:`static_loads` (same
    arguments): the limbs' common compression at the centre."""
    static_loads(limbs, joints, joint_stiffness, mass, gravity, centre)  # the same checks and errors
    return float(_equilibrium(limbs, joints, joint_stiffness, mass, gravity, centre)[1][0])


def _equilibrium(limbs: Sequence[LimbGeometry], joints: ArrayLike, joint_stiffness: ArrayLike, mass: float,
                 gravity: float, centre: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """The loads [N] and the body's motion (heave [m], roll, pitch [rad]) at rest (see static_loads)."""
    if not (mass > 0 and gravity > 0):
        raise ValueError(f"mass = {mass!r} kg, gravity = {gravity!r} m/s²: expected both > 0")
    angles = np.asarray(joints, float).reshape(len(limbs), JOINTS)
    springs = np.array([1.0 / hub_compliance(limb, q, joint_stiffness)[2, 2] for limb, q in zip(limbs, angles)])
    hubs = np.array([forward(limb, q).hub for limb, q in zip(limbs, angles)])
    x, y = hubs[:, 0] - float(np.asarray(centre)[0]), hubs[:, 1] - float(np.asarray(centre)[1])
    # sinking by s_i = dz + y_i roll - x_i pitch loads hub i by k_i s_i: sum = M g, moments about the centre = 0
    basis = np.column_stack([np.ones_like(x), y, -x])          # s = basis @ (dz, roll, pitch)
    system = basis.T @ np.diag(springs) @ basis                # sum of k s, of y k s, of -x k s
    weight = mass * gravity
    motion = np.linalg.solve(system, np.array([weight, 0.0, 0.0]))
    return springs * (basis @ motion), motion


def holding_torques(limbs: Sequence[LimbGeometry], joints: ArrayLike, loads: ArrayLike) -> FloatArray:
    """The joint torques [N·m] (a row of six per limb) that hold vertical wheel loads ``loads`` [N]
    pushing up on the hubs: -J^T (0, 0, W)."""
    angles = np.asarray(joints, float).reshape(len(limbs), JOINTS)
    weights = np.asarray(loads, float).reshape(len(limbs))
    return np.array([joint_torques(limb, q, [0.0, 0.0, float(w)]) for limb, q, w in zip(limbs, angles, weights)])
