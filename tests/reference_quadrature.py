"""Independent reference for Eqs. (11)-(13): composite Simpson on 20 000 points per piece.

It uses the public stress functions of Eqs. (5)-(10) directly (both σ branches, the
shear displacement as written), not the fused, node-sharing kernel of terramechanics.forces.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import simpson

from rover_cosim.terramechanics import (
    Soil,
    Wheel,
    entry_angle,
    exit_angle,
    lateral_displacement,
    max_stress_angle,
    normal_stress,
    shear_displacement,
    shear_stress,
    sidewall_resistance,
)

POINTS = 20_000


def reference_forces(sinkage: float, slip: float, wheel: Wheel, soil: Soil,
                     points: int = POINTS) -> np.ndarray:
    """(Fx, Fz, Tx) for one sinkage [m] and slip [-], pieces [θr, θm] and [θm, θf]."""
    theta_f = entry_angle(sinkage, wheel)
    theta_r = exit_angle(sinkage, wheel, soil)
    theta_m = max_stress_angle(theta_f, slip, soil)
    total = np.zeros(3)
    for start, end in ((theta_r, theta_m), (theta_m, theta_f)):
        theta = np.linspace(start, end, points)
        sigma = normal_stress(theta, theta_f, theta_r, theta_m, wheel, soil)
        tau = shear_stress(sigma, shear_displacement(theta, theta_f, slip, wheel), soil)
        total += [
            wheel.r * wheel.b * simpson(tau * np.cos(theta) - sigma * np.sin(theta), x=theta),
            wheel.r * wheel.b * simpson(tau * np.sin(theta) + sigma * np.cos(theta), x=theta),
            wheel.r**2 * wheel.b * simpson(tau, x=theta),
        ]
    return total


def reference_lateral(sinkage: float, slip: float, slip_angle: float, wheel: Wheel, soil: Soil,
                      points: int = POINTS) -> tuple[float, float, float]:
    """(Fx, Fy, Fy_sidewall) at a slip angle [rad], written out from Ishigami et al. 2007 with the
    public functions: kx, ky grow with |β|, τy from jy, the sidewall mobilised by jy(θr)."""
    theta_f = entry_angle(sinkage, wheel)
    theta_r = exit_angle(sinkage, wheel, soil)
    theta_m = max_stress_angle(theta_f, slip, soil)
    kx = soil.kx + soil.kx_beta * abs(slip_angle)
    ky = soil.ky + soil.ky_beta * abs(slip_angle)
    fx = shear = pile = 0.0
    for start, end in ((theta_r, theta_m), (theta_m, theta_f)):
        theta = np.linspace(start, end, points)
        sigma = normal_stress(theta, theta_f, theta_r, theta_m, wheel, soil)
        tau_x = shear_stress(sigma, shear_displacement(theta, theta_f, slip, wheel), soil, kx)
        jy = lateral_displacement(theta, theta_f, slip, slip_angle, wheel)
        tau_y = (soil.c + sigma * np.tan(soil.phi)) * (1 - np.exp(-np.abs(jy) / ky)) * np.sign(jy)
        depth = wheel.r * (np.cos(theta) - np.cos(theta_f))
        fx += wheel.r * wheel.b * simpson(tau_x * np.cos(theta) - sigma * np.sin(theta), x=theta)
        shear += wheel.r * wheel.b * simpson(tau_y, x=theta)
        pile += simpson(sidewall_resistance(depth, soil) * (wheel.r - depth * np.cos(theta)), x=theta)
    mobilised = 1 - np.exp(-abs(float(lateral_displacement(theta_r, theta_f, slip, slip_angle, wheel))) / ky)
    sidewall = -np.sign(slip_angle) * mobilised * pile
    return fx, sidewall - shear, sidewall
