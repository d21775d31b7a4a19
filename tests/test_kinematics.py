import math

import numpy as np
import pytest

from rover_cosim.terramechanics import (
    Soil,
    Wheel,
    entry_angle,
    exit_angle,
    max_stress_angle,
    slip_ratio,
)


@pytest.mark.parametrize("r_omega, v, expected", [
    (1.0, 0.8, 0.2),      # driving: (rω - v)/(rω)
    (2.0, 0.5, 0.75),
    (0.8, 1.0, -0.2),     # skidding: (rω - v)/v
    (0.5, 2.0, -0.75),
    (1.0, 0.0, 1.0),      # v = 0: spinning in place
    (0.0, 1.0, -1.0),     # ω = 0: locked wheel
    (0.0, 0.0, 0.0),      # at rest
    (1.3, 1.3, 0.0),      # pure rolling
])
def test_slip_ratio_eq4(r_omega, v, expected):
    assert slip_ratio(r_omega, v) == pytest.approx(expected, abs=1e-15)


def test_slip_ratio_is_vectorized_and_finite():
    r_omega = np.array([[0.0], [0.5], [1.0]])
    v = np.array([0.0, 0.5, 1.0, 2.0])
    kappa = slip_ratio(r_omega, v)
    assert kappa.shape == (3, 4)
    assert np.isfinite(kappa).all()
    assert kappa[2, 3] == pytest.approx(-0.5)
    assert kappa[1, 0] == 1.0


def test_slip_ratio_regularisation_and_bad_input():
    assert slip_ratio(1e-6, 0.0, v_eps=1e-3) == pytest.approx(1e-3)
    with pytest.raises(ValueError, match="v_eps=-1"):
        slip_ratio(1.0, 0.5, v_eps=-1.0)


def test_contact_angles_eqs_1_to_3():
    wheel, soil = Wheel(), Soil()
    h = wheel.r * (1 - math.cos(0.5))
    assert entry_angle(h, wheel) == pytest.approx(0.5)
    assert entry_angle(wheel.r, wheel) == pytest.approx(math.pi / 2)
    assert entry_angle(0.0, wheel) == 0.0
    # Eq. (2): lam*h/r = 1 - cos(0.3) gives theta_r = -0.3 (behind the axle)
    h_r = wheel.r * (1 - math.cos(0.3)) / soil.lam
    assert exit_angle(h_r, wheel, soil) == pytest.approx(-0.3)
    # Eq. (3): (a0 + a1 kappa) theta_f
    assert max_stress_angle(0.5, 0.2, soil) == pytest.approx((0.4 + 0.15 * 0.2) * 0.5)
    assert max_stress_angle(np.array([0.5, 1.0]), -1.0, soil) == pytest.approx([0.125, 0.25])
