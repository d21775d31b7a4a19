"""Wheel kinematics: slip ratio (Eq. 4) and contact-patch angles (Eqs. 1-3).

Angles are measured from the downward vertical through the axle, positive towards the
direction of travel: the entry angle is positive, the exit angle negative.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .parameters import Soil, Wheel

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
IndexArray = NDArray[np.intp]


def slip_ratio(r_omega: ArrayLike, v: ArrayLike, v_eps: float = 0.0) -> FloatArray:
    """Longitudinal slip ratio κ [-], paper Eq. (4), vectorized over broadcastable arrays.

    Args:
        r_omega: wheel circumferential speed r·ω [m/s].
        v: wheel hub forward speed v_x [m/s].
        v_eps: optional regularising speed [m/s] >= 0 added to the denominator's floor; 0
            (default) gives Eq. (4) exactly.

    For forward travel (r·ω >= 0, v >= 0) this is Eq. (4): (rω - v)/(rω) when rω > v
    (driving, 0 < κ <= 1) and (rω - v)/v when rω < v (skidding, -1 <= κ < 0). Both branches
    are the single expression (rω - v)/max(|rω|, |v|), which is finite at ω = 0 (κ = -1 for
    v > 0) and at v = 0 (κ = 1 for ω > 0); at rω = v = 0 the wheel is at rest and κ = 0.
    For reverse or mixed-sign motion, outside the paper's scope, the same expression is used
    and clipped to [-1, 1].
    """
    if not (np.isfinite(v_eps) and v_eps >= 0):
        raise ValueError(f"v_eps={v_eps!r}: expected a finite speed >= 0 m/s")
    r_omega = np.asarray(r_omega, dtype=float)
    v = np.asarray(v, dtype=float)
    difference = r_omega - v
    denominator = np.maximum(np.maximum(np.abs(r_omega), np.abs(v)), v_eps)
    at_rest = denominator == 0.0
    kappa = difference / np.where(at_rest, 1.0, denominator)
    return np.clip(np.where(at_rest, 0.0, kappa), -1.0, 1.0)


def travel_direction(r_omega: ArrayLike, v: ArrayLike) -> FloatArray:
    """+1 where the hub travels forwards (v > 0), -1 backwards; at v = 0 the sign of ω (+1 at rest)."""
    v = np.asarray(v, dtype=float)
    r_omega = np.asarray(r_omega, dtype=float)
    return np.where(v > 0, 1.0, np.where(v < 0, -1.0, np.where(r_omega < 0, -1.0, 1.0)))


def entry_angle(sinkage: ArrayLike, wheel: Wheel) -> FloatArray:
    """Entry angle θf = acos(1 - h/r) [rad], Eq. (1); sinkage h [m] in [0, r]."""
    return np.arccos(1.0 - np.asarray(sinkage, dtype=float) / wheel.r)


def exit_angle(sinkage: ArrayLike, wheel: Wheel, soil: Soil) -> FloatArray:
    """Exit angle θr = -acos(1 - λh/r) [rad], Eq. (2), negative behind the axle."""
    return -np.arccos(1.0 - soil.lam * np.asarray(sinkage, dtype=float) / wheel.r)


def max_stress_angle(theta_f: ArrayLike, slip: ArrayLike, soil: Soil) -> FloatArray:
    """Angle of maximum normal stress θm = (a0 + a1 κ) θf [rad], Eq. (3)."""
    return (soil.a0 + soil.a1 * np.asarray(slip, dtype=float)) * np.asarray(theta_f, dtype=float)
