"""The leg-wheel rover's limbs (issue 47): geometry (``geometry``: six rotary joints per limb after
NASA/JPL's ATHLETE, the paper's Fig. 1) and kinematics (``kinematics``: forward and inverse
kinematics of a limb and of the whole stance, the Jacobian and the joint torques that hold the
hub forces) and statics (``statics``: how the weight spreads over six compliant limbs). numpy
only: the independent cross-check of the Modelica leg-wheel rover and the posture controller's
model. A layer of its own: it imports nothing of ours but ``common``."""

from .geometry import JOINT_NAMES, JOINTS, LIMBS, LimbGeometry, athlete_limbs
from .kinematics import (
    LimbPose,
    Unreachable,
    attitude,
    forward,
    inverse,
    jacobian,
    joint_torques,
    stance_forward,
    stance_inverse,
)
from .statics import holding_torques, hub_compliance, static_heave, static_loads

__all__ = ["JOINTS", "JOINT_NAMES", "LIMBS", "LimbGeometry", "LimbPose", "Unreachable", "athlete_limbs", "attitude",
           "forward", "holding_torques", "hub_compliance", "inverse", "jacobian", "joint_torques", "stance_forward",
           "stance_inverse", "static_heave", "static_loads"]
