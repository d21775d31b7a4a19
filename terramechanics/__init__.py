"""``rover_cosim.terramechanics``, the pure-numpy reference wheel: Wong-Reece/Ishigami
terramechanics as in Yoshikawa et al.

Public API: ``Wheel``, ``Soil`` (parameters, Table 2 defaults), ``slip_ratio`` (Eq. 4),
``contact_forces`` (Eqs. 1-13), ``wheel_state`` (sinkage solving Fz = W) and ``wheel_forces``
(the wheel in every motion regime: reverse, braking, free rolling, standstill; ``Regimes``);
the lateral force Fy at a slip angle (Ishigami et al. 2007) in ``contact_forces``,
``wheel_state`` (``slip_angle=``) and ``wheel_forces`` (``v_lateral=``); the ground plane under the steerable
rover, ``PlaneTerrain`` (slope, downhill direction: gravity's components in the heading frame).
"""

from rover_cosim.common.identity import require_root

require_root(__name__)

from .forces import DEFAULT_NODES, ContactForces, contact_forces
from .kinematics import entry_angle, exit_angle, max_stress_angle, slip_ratio, travel_direction
from .lateral import bulldozing_factors, lateral_displacement, sidewall_resistance, slip_angle
from .parameters import Soil, Wheel
from .regimes import Regimes, WheelForces, shear_strength, steady_weight, wheel_forces
from .sinkage import WheelState, bekker_sinkage, wheel_state
from .stress import normal_stress, shear_displacement, shear_stress
from .terrain import PlaneTerrain

__all__ = [
    "DEFAULT_NODES", "ContactForces", "bulldozing_factors", "lateral_displacement", "sidewall_resistance",
    "slip_angle", "Regimes", "Soil", "Wheel", "WheelForces", "WheelState", "bekker_sinkage",
    "contact_forces", "entry_angle", "exit_angle", "max_stress_angle", "normal_stress",
    "shear_displacement", "shear_strength", "shear_stress", "slip_ratio", "steady_weight", "travel_direction",
    "wheel_forces", "wheel_state", "PlaneTerrain",
]
