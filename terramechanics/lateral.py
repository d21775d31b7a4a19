"""Lateral force of the wheel (Ishigami, Miwa, Nagatani, Yoshida, "Terramechanics-based model
for steering maneuver of planetary exploration rovers on loose soil", J. Field Robotics 24(3),
2007): slip angle, lateral shear and the sidewall (bulldozing) resistance.

Conventions: x is the wheel's heading, y its left, z up. The slip angle β [rad] is the angle of
the hub velocity in the wheel frame, positive when the hub slides towards +y while travelling
forwards; Fy is the soil's force on the wheel along +y, so Fy < 0 for β > 0: it opposes the
sliding. Travelling backwards, the wheel is mirrored as for Fx (direction d = sign(v)): β is the
angle seen from the direction of travel, and the forces of the mirrored wheel are turned back.

- Lateral shear displacement (Ishigami Eq. 21): jy(θ) = r (1 - s)(θf - θ) tan β.
- Lateral shear stress (Janosi-Hanamoto): τy = (c + σ tan φ)(1 - exp(-|jy|/ky)) sign(jy), with
  ky = ky0 + ky_beta |β| and kx = kx0 + kx_beta |β| (Ishigami's measured moduli).
- Sidewall: the soil piled against the wheel's side resists like a bulldozing blade of depth
  h(θ) = r (cos θ - cos θf) (Hegedus 1960, "A study of soil bulldozing resistance", as used by
  Ishigami 2007 Eq. 24): R_b = D1 (c h + D2 ρ g h² / 2), D1 = cot Xc + tan(Xc + φ),
  D2 = cot Xc + cot² Xc / cot φ, and its force ∫ R_b (r - h cos θ) dθ over the patch. Ishigami
  applies it in full at any β ≠ 0 (a jump at β = 0). Here it is mobilised like the shear, by
  1 - exp(-|jy(θr)|/ky) with the lateral displacement of the whole patch: Fy_sidewall rises from
  0 in proportion to β and reaches the full resistance within a few ky of sideways travel, so Fy
  is continuous and odd in β.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .kinematics import FloatArray, travel_direction
from .parameters import Soil, Wheel


def slip_angle(r_omega: ArrayLike, v: ArrayLike, v_lateral: ArrayLike, v_eps: float) -> FloatArray:
    """β = atan2(d v_y, max(|v|, v_eps)) [rad] with d the travel direction (sign of v; of ω at
    v = 0): the hub's lateral speed v_y [m/s] against its forward speed v [m/s]; 0 at rest,
    ±π/2 (nearly) for a hub sliding straight sideways."""
    v = np.asarray(v, dtype=float)
    direction = travel_direction(r_omega, v)
    return np.arctan2(direction * np.asarray(v_lateral, dtype=float), np.maximum(np.abs(v), v_eps))


def bulldozing_factors(soil: Soil) -> tuple[float, float]:
    """Hegedus's D1 = cot Xc + tan(Xc + φ) and D2 = cot Xc + cot² Xc / cot φ [-]."""
    cot_xc = 1.0 / math.tan(soil.xc)
    return cot_xc + math.tan(soil.xc + soil.phi), cot_xc + cot_xc**2 * math.tan(soil.phi)


def sidewall_resistance(depth: ArrayLike, soil: Soil) -> FloatArray:
    """R_b = D1 (c h + D2 ρ g h²/2) [N/m] of soil piled to depth h [m] against the wheel's side."""
    d1, d2 = bulldozing_factors(soil)
    h = np.asarray(depth, dtype=float)
    return d1 * (soil.c * h + 0.5 * d2 * soil.rho * soil.gravity * h * h)


def lateral_displacement(theta: ArrayLike, theta_f: ArrayLike, slip: ArrayLike, beta: ArrayLike,
                         wheel: Wheel) -> FloatArray:
    """jy(θ) = r (1 - s)(θf - θ) tan β [m], Ishigami Eq. (21)."""
    return (wheel.r * (1.0 - np.asarray(slip, dtype=float)) * (np.asarray(theta_f, dtype=float) - theta)
            * np.tan(np.asarray(beta, dtype=float)))


def lateral_integrals(theta: FloatArray, dtheta: FloatArray, sigma: FloatArray, theta_f: FloatArray,
                      theta_r: FloatArray, slip: FloatArray, beta: FloatArray, wheel: Wheel,
                      soil: Soil) -> tuple[FloatArray, FloatArray]:
    """(Fy, Fy_sidewall) [N] from the quadrature angles θ and weights dθ (M, pieces, nodes) and σ
    there; the row arrays θf, θr, s, β have shape (M,)."""
    _, ky = soil.shear_moduli(beta)
    rows = (slice(None), None, None)
    jy = lateral_displacement(theta, theta_f[rows], slip[rows], beta[rows], wheel)
    strength = soil.c + sigma * math.tan(soil.phi)
    tau_y = strength * -np.expm1(-np.abs(jy) / ky[rows]) * np.sign(jy)
    shear = wheel.r * wheel.b * np.einsum("ipn,ipn->i", tau_y, dtheta)
    depth = np.maximum(wheel.r * (np.cos(theta) - np.cos(theta_f)[rows]), 0.0)
    pile = np.einsum("ipn,ipn->i", sidewall_resistance(depth, soil) * (wheel.r - depth * np.cos(theta)), dtheta)
    mobilised = -np.expm1(-np.abs(lateral_displacement(theta_r, theta_f, slip, beta, wheel)) / ky)
    sidewall = -np.sign(beta) * mobilised * pile
    return sidewall - shear, sidewall
