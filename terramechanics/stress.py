"""Stress distributions under the wheel: normal stress (Eqs. 5-6) and shear stress (Eqs. 7-10).

All functions are pure and vectorized: every argument broadcasts against the others.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from .kinematics import FloatArray
from .parameters import Soil, Wheel


def pressure_from_cosines(cos_theta: ArrayLike, cos_theta_f: ArrayLike, wheel: Wheel, soil: Soil,
                          exponent: ArrayLike | None = None, rut: ArrayLike | None = None) -> FloatArray:
    """Eq. (5) written with cosines: r^n (kc/b + kφ) (z_r/r + cos θ - cos θf)^n [Pa], the difference
    of cosines floored at 0.

    ``exponent`` (broadcastable; None: soil.n) is the sinkage exponent where it depends on the slip
    (``Soil.sinkage_exponent``). ``rut`` (broadcastable; None: 0) is the depth z_r [m] of the rut
    a previous wheel left: the soil under its floor carried the pressure of that depth and goes on
    from there (multi-pass, :mod:`terramechanics.multipass`); θf is then measured from the floor.
    """
    difference = np.asarray(cos_theta, dtype=float) - cos_theta_f
    depth = np.maximum(difference, 0.0, out=np.empty(difference.shape))
    if rut is not None:
        depth += np.asarray(rut, dtype=float) / wheel.r
    if exponent is None:
        if soil.n != 1.0:
            depth = np.power(depth, soil.n, out=depth)
        depth *= soil.bekker_modulus(wheel.b) * wheel.r**soil.n
        return depth
    n = np.asarray(exponent, dtype=float)
    depth = np.power(depth, n, out=depth)
    depth *= soil.bekker_modulus(wheel.b) * wheel.r**n
    return depth


def normal_stress_front(theta: ArrayLike, theta_f: ArrayLike, wheel: Wheel, soil: Soil,
                        exponent: ArrayLike | None = None, rut: ArrayLike | None = None) -> FloatArray:
    """σf(θ) = r^n (kc/b + kφ) (cos θ - cos θf)^n [Pa], Eq. (5), for θm <= θ <= θf (``exponent``
    and ``rut`` as in pressure_from_cosines)."""
    return pressure_from_cosines(np.cos(theta), np.cos(theta_f), wheel, soil, exponent, rut)


def normal_stress_rear(
    theta: ArrayLike, theta_f: ArrayLike, theta_r: ArrayLike, theta_m: ArrayLike,
    wheel: Wheel, soil: Soil, exponent: ArrayLike | None = None, rut: ArrayLike | None = None,
) -> FloatArray:
    """σr(θ) [Pa], Eq. (6), for θr <= θ <= θm (requires θm > θr).

    The rear branch is the front branch evaluated at the equivalent front angle
    θf - (θ - θr)/(θm - θr)·(θf - θm), so σ is continuous at θm and zero at θr.
    """
    theta = np.asarray(theta, dtype=float)
    theta_f = np.asarray(theta_f, dtype=float)
    theta_r = np.asarray(theta_r, dtype=float)
    theta_m = np.asarray(theta_m, dtype=float)
    equivalent = theta_f - (theta - theta_r) / (theta_m - theta_r) * (theta_f - theta_m)
    return normal_stress_front(equivalent, theta_f, wheel, soil, exponent, rut)


def normal_stress(
    theta: ArrayLike, theta_f: ArrayLike, theta_r: ArrayLike, theta_m: ArrayLike,
    wheel: Wheel, soil: Soil, exponent: ArrayLike | None = None, rut: ArrayLike | None = None,
) -> FloatArray:
    """σ(θ) [Pa] over the whole contact patch θr <= θ <= θf: Eq. (5) at and above θm, Eq. (6) below
    (``exponent`` and ``rut`` as in pressure_from_cosines)."""
    theta = np.asarray(theta, dtype=float)
    front = normal_stress_front(theta, theta_f, wheel, soil, exponent, rut)
    rear = normal_stress_rear(theta, theta_f, theta_r, theta_m, wheel, soil, exponent, rut)
    return np.where(theta >= theta_m, front, rear)


def shear_displacement(theta: ArrayLike, theta_f: ArrayLike, slip: ArrayLike, wheel: Wheel,
                       radius: ArrayLike | None = None) -> FloatArray:
    """Soil shear displacement jx(θ) = r[θf - θ - (1 - κ)(sin θf - sin θ)] [m], Eq. (10); ``radius``
    [m] (broadcastable; None: r) replaces r, the grousers' shear radius (:mod:`terramechanics.grousers`)."""
    theta = np.asarray(theta, dtype=float)
    theta_f = np.asarray(theta_f, dtype=float)
    r = wheel.r if radius is None else np.asarray(radius, dtype=float)
    return r * (theta_f - theta - (1.0 - np.asarray(slip, dtype=float)) * (np.sin(theta_f) - np.sin(theta)))


def shear_stress(sigma: ArrayLike, j: ArrayLike, soil: Soil, kx: ArrayLike | None = None) -> FloatArray:
    """τx = (c + σ tan φ)(1 - exp(-jx/kx)) [Pa], Eqs. (7)-(9), from σ [Pa] and jx [m].

    Eq. (9) is used as written for jx >= 0. Where the soil is sheared backwards (jx < 0,
    which happens while skidding, κ < 0) the Janosi-Hanamoto law is applied with the sign of
    the displacement, τx = -τmax (1 - exp(jx/kx)), so that |τx| never exceeds the Mohr-Coulomb
    strength τmax of Eq. (8); Eq. (9) read literally would grow like exp(|jx|/kx) there.
    ``kx`` [m] (broadcastable) replaces soil.kx, for a wheel with a slip angle.
    """
    tau_max = soil.c + np.asarray(sigma, dtype=float) * np.tan(soil.phi)
    j = np.asarray(j, dtype=float)
    factor = np.abs(j, out=np.empty(j.shape))
    if kx is None:
        factor *= -1.0 / soil.kx
    else:
        factor *= -1.0 / np.asarray(kx, dtype=float)
    np.expm1(factor, out=factor)
    np.negative(factor, out=factor)
    np.copysign(factor, j, out=factor)
    factor *= tau_max
    return factor
