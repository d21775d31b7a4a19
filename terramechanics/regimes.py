"""The wheel in every motion regime: driving, braking, free rolling, reverse and standstill.

The paper's model (Eqs. 1-13) describes a wheel rolling forwards, with the soil entering the
contact patch at the front. Applied as it stands at rest it gives Fx(κ = 0) = +5.9 N and
Tx = 9.8 N·m at 424 N (an unpowered wheel at rest would start turning backwards), and in reverse
it keeps the entry at the front, so the soil would feed energy into the vehicle. Here the steady
forces are made a drop-in component by two additions, functions of the same state (load W, spin
ω, hub speed v) as the Modelica function ``Functions.wheelForces``:

1. Direction of travel. The steady forces are those of the paper for the mirrored wheel,
   ``d * F(W, d κ)`` with ``d = sign(v)`` (the sign of ω when v = 0): the entry side of the patch
   follows the hub's travel and driving backwards mirrors driving forwards exactly.
2. Standstill. Below the transition speed ``v_hold`` the steady forces blend into a static
   regime, the soil holding the rim like regularised static friction up to the Mohr-Coulomb
   strength of the patch (Wong, Theory of Ground Vehicles, maximum thrust A c + W tan φ):

       F_static = F_max tanh((r ω - v) / v_stick),   F_max = c b L + W tan φ,
       Fx = β F_steady + (1 - β) F_static,   Tx = β T_steady + (1 - β) r F_static,
       β = u (2 - u),  u = min(|v| / v_hold, 1)      (β = 1 above v_hold: the paper's forces)

   with L = r (θf - θr) the patch's arc length. This is Karnopp's idea of a stick band (Karnopp
   1985, "Computer simulation of stick-slip friction in mechanical dynamic systems", ASME J. Dyn.
   Syst. Meas. Control 107) in the smooth, event-free form of low-speed tyre models that fade the
   rolling forces out below a threshold speed (Bernard and Clover 1995, SAE 950311; Pacejka,
   Tire and Vehicle Dynamics, 3rd ed. 2012, low-speed transient models). Both regimes only take
   energy out: the steady forces dissipate at every slip (tests/test_regimes.py measures it) and
   the static shear opposes the slip velocity, so a wheel at rest stays at rest, a free-rolling
   wheel slows down to rest without turning back, and a holding torque keeps it on a slope.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .checks import checked_array
from .kinematics import FloatArray, slip_ratio, travel_direction
from .lateral import slip_angle
from .parameters import Soil, Wheel
from .sinkage import wheel_state


@dataclass(frozen=True)
class Regimes:
    """Speeds that shape the wheel's low-speed behaviour, all in m/s and > 0.

    Attributes:
        v_eps: regularising speed of the slip ratio, Eq. (4) (floor of its denominator).
        v_hold: transition speed: below it the steady forces blend into the static regime.
        v_stick: slip speed at which the static shear reaches tanh(1) = 76 % of its limit; a
            holding wheel creeps at a fraction of it.
    Defaults are those of the Modelica models (parameters ``vEps``, ``vHold``, ``vStick``).
    """

    v_eps: float = 1e-3
    v_hold: float = 1e-3
    v_stick: float = 1e-4

    def __post_init__(self) -> None:
        for name in ("v_eps", "v_hold", "v_stick"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, numbers.Real) or not (
                    math.isfinite(float(value)) and float(value) > 0):
                raise ValueError(f"{name}={value!r}: expected a finite speed > 0 m/s")


class WheelForces(NamedTuple):
    """The wheel's contact in any motion regime; arrays of the broadcast input shape."""

    slip: FloatArray  #: slip ratio κ [-], Eq. (4): odd in (ω, v)
    sinkage: FloatArray  #: sinkage h [m] with Fz = W
    Fx: FloatArray  #: longitudinal force of the soil on the wheel [N]
    Fz: FloatArray  #: vertical force [N], equal to the load
    Tx: FloatArray  #: resistance torque of the soil about the axle [N·m]
    entry_angle: FloatArray  #: signed entry angle [rad]: positive ahead of the axle, negative behind when reversing
    Fy: FloatArray  #: lateral force of the soil on the wheel [N], along the wheel's left
    slip_angle: FloatArray  #: slip angle β [rad] (terramechanics.lateral.slip_angle)


def steady_weight(v: ArrayLike, v_hold: float) -> FloatArray:
    """β = u (2 - u), u = min(|v|/v_hold, 1) [-]: 0 at rest, 1 from v_hold on, C¹ in between."""
    u = np.minimum(np.abs(np.asarray(v, dtype=float)) / v_hold, 1.0)
    return u * (2.0 - u)


def patch_length(sinkage: ArrayLike, wheel: Wheel, soil: Soil) -> FloatArray:
    """Arc length of the contact patch L = r (θf - θr) [m], Eqs. (1)-(2)."""
    h = np.asarray(sinkage, dtype=float)
    return wheel.r * (np.arccos(1.0 - h / wheel.r) + np.arccos(1.0 - soil.lam * h / wheel.r))


def shear_strength(load: ArrayLike, sinkage: ArrayLike, wheel: Wheel, soil: Soil) -> FloatArray:
    """Mohr-Coulomb strength of the patch F_max = c b L + W tan φ [N] (Wong's maximum thrust)."""
    return soil.c * wheel.b * patch_length(sinkage, wheel, soil) + np.asarray(load, dtype=float) * math.tan(soil.phi)


def static_shear(slip_velocity: ArrayLike, strength: ArrayLike, v_stick: float) -> FloatArray:
    """F_max tanh((r ω - v)/v_stick) [N]: the soil's hold on the rim at slip velocity r ω - v [m/s]."""
    return np.asarray(strength, dtype=float) * np.tanh(np.asarray(slip_velocity, dtype=float) / v_stick)


def wheel_forces(load: ArrayLike, omega: ArrayLike, v: ArrayLike, wheel: Wheel = Wheel(), soil: Soil = Soil(),
                 regimes: Regimes = Regimes(), v_lateral: ArrayLike = 0.0, rut_depth: ArrayLike = 0.0) -> WheelForces:
    """Contact of a wheel with spin ω [rad/s], hub speed v [m/s] along its heading and v_lateral
    [m/s] to its left, under load W [N] (> 0), in any regime; vectorized over broadcastable
    arguments. See the module docstring; the lateral force is terramechanics.lateral's, mirrored
    and blended into the static regime like Fx (static lateral hold -F_max tanh(v_y/v_stick)).
    ``rut_depth`` [m]: the rut the wheel rolls in (``wheel_state``); the sinkage is the total."""
    w = checked_array("load", load, 0.0, math.inf, "N", low_open=True)
    omega = checked_array("omega", omega, -math.inf, math.inf, "rad/s")
    v = checked_array("v", v, -math.inf, math.inf, "m/s")
    v_y = checked_array("v_lateral", v_lateral, -math.inf, math.inf, "m/s")
    w, omega, v, v_y = np.broadcast_arrays(w, omega, v, v_y)
    r_omega = wheel.r * omega
    slip = slip_ratio(r_omega, v, regimes.v_eps)
    direction = travel_direction(r_omega, v)
    angle = slip_angle(r_omega, v, v_y, regimes.v_eps)
    steady = wheel_state(w, direction * slip, wheel, soil, slip_angle=angle, rut_depth=rut_depth)
    strength = shear_strength(w, steady.sinkage - steady.rut_depth, wheel, soil)
    hold = static_shear(r_omega - v, strength, regimes.v_stick)
    beta = steady_weight(v, regimes.v_hold)
    fx = beta * direction * steady.Fx + (1.0 - beta) * hold
    tx = beta * direction * steady.Tx + (1.0 - beta) * wheel.r * hold
    fy = beta * direction * steady.Fy - (1.0 - beta) * static_shear(v_y, strength, regimes.v_stick)
    return WheelForces(slip, steady.sinkage, fx, steady.Fz, tx, direction * steady.entry_angle, fy, angle)
