"""Numbers quoted from the paper (Yoshikawa et al.), in SI units, in one place.

The soil and wheel of Table 2 are ``rover_cosim.terramechanics.Soil`` / ``Wheel`` defaults (and
the Modelica records); what is here are the scenario and the results the reproduction is compared
against.
"""

from __future__ import annotations

#: Rover mass [kg] and lunar gravity [m/s^2] (Sec. 4).
ROVER_MASS = 1570.0
LUNAR_GRAVITY = 1.62
#: Number of wheels (limbs) of the ATHLETE-like rover.
WHEELS = 6
#: Static load per wheel on the Moon [N]: M g / 6, about 424 N.
STATIC_WHEEL_LOAD = ROVER_MASS * LUNAR_GRAVITY / WHEELS
#: Target velocity of the closed loop [m/s] (x_t = 1.0 t).
TARGET_VELOCITY = 1.0
#: Natural frequency of the Eq. (17) filter [rad/s].
FILTER_WN = 342.0

#: Wheel loads of Fig. 3 and of the look-up tables [N]: 100 ... 800 N, 100 N apart (Sec. 2.2.7).
LOADS = tuple(float(w) for w in range(100, 801, 100))
#: Table 1: Fit [%] of the identified model at the validation loads [N].
TABLE_1_FIT = {275.0: 82.1, 575.0: 96.8, 875.0: 96.2}
#: Table 3: RMS(Fx - Fx_des) [N] of limbs 1-3.
TABLE_3_RMS = {1: 0.7, 2: 0.4, 3: 0.5}
