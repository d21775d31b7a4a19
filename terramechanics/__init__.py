"""``rover_cosim.terramechanics``, the pure-numpy reference wheel: Wong-Reece/Ishigami
terramechanics as in Yoshikawa et al.

Public API: ``Wheel``, ``Soil`` (parameters, Table 2 defaults), ``slip_ratio`` (Eq. 4),
``contact_forces`` (Eqs. 1-13) and ``wheel_state`` (sinkage solving Fz = W).
"""

from .forces import DEFAULT_NODES, ContactForces, contact_forces
from .kinematics import entry_angle, exit_angle, max_stress_angle, slip_ratio
from .parameters import Soil, Wheel
from .sinkage import WheelState, bekker_sinkage, wheel_state
from .stress import normal_stress, shear_displacement, shear_stress

__all__ = [
    "DEFAULT_NODES", "ContactForces", "Soil", "Wheel", "WheelState", "bekker_sinkage",
    "contact_forces", "entry_angle", "exit_angle", "max_stress_angle", "normal_stress",
    "shear_displacement", "shear_stress", "slip_ratio", "wheel_state",
]
