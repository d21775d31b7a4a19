"""Grousers: the shear of a wheel with grousers (lugs) on loose soil.

Model (the choice and its assumptions):

- Shear at the grouser tips. The soil trapped between grousers moves with the wheel, so the soil
  is sheared on a cylinder through the tips, of radius r_s = r + e h_g (Ding, Gao, Deng et al.,
  J. Terramechanics 48, 2011: the "shearing radius" r_s = r + λ_s h of a grousered wheel). It
  replaces r in the shear displacement, Eq. (10), j = r_s[θf - θ - (1 - κ)(sin θf - sin θ)], and
  in the shear terms of Eqs. (11)-(13) (the shear acts at r_s: lever r_s for the torque).
- Shear on the sides of the trapped soil. Between two grousers the soil block is also sheared on
  its two side faces of height h_g, a width factor g = 1 + 2 e h_g / b on the shear stress (the
  grouser correction of a track's thrust, (A c + W tan φ)(1 + 2 h/b), Wong, Theory of Ground
  Vehicles, Sec. 2.4, after Reece; as recalled there, not re-checked against the book here).
- Engagement e = min(1, N_g (θf - θr) / 2π): the mean number of grousers in the contact patch,
  at most 1. With one grouser or more always in the patch the effect is full; a wheel with few
  grousers or a shallow patch gets part of it. This is our assumption (Ding's λ_s is a fitted
  constant per wheel; the count must enter somewhere): it makes drawbar pull rise with the count
  until a grouser is always engaged, and with the height without limit within the model's
  range (grouser_height <= r/2).
- The normal stress stays on the rim (Eqs. 5-6, the rim carries the load; the grousers cut into
  the soil), the lateral force and the static regime keep the rim's radius.

A smooth wheel (height or count 0) has e h_g = 0, r_s = r and g = 1 exactly: every result is the
smooth wheel's, bit for bit. Energy: with r_s > r the shear's torque grows by r_s/r more than its
thrust, so the wheel never delivers more power than its motor puts in.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .kinematics import FloatArray
from .parameters import Wheel


def grouser_engagement(theta_f: ArrayLike, theta_r: ArrayLike, wheel: Wheel) -> FloatArray:
    """e = min(1, N_g (θf - θr)/2π) [1]: the mean number of grousers in the patch, at most one."""
    span = np.asarray(theta_f, dtype=float) - np.asarray(theta_r, dtype=float)
    return np.minimum(1.0, wheel.grouser_count * span / (2.0 * math.pi))


def shear_radius(engagement: ArrayLike, wheel: Wheel) -> FloatArray:
    """r_s = r + e h_g [m]: the radius at which the soil is sheared (Ding et al. 2011)."""
    return wheel.r + np.asarray(engagement, dtype=float) * wheel.grouser_height


def side_shear_factor(engagement: ArrayLike, wheel: Wheel) -> FloatArray:
    """g = 1 + 2 e h_g / b [1]: the sides of the soil blocks between grousers also shear."""
    return 1.0 + 2.0 * np.asarray(engagement, dtype=float) * wheel.grouser_height / wheel.b
