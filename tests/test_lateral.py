"""The lateral force of the numpy reference wheel (Ishigami et al. 2007): quadrature against an
independent 20 000-point reference, nothing changes at slip angle 0, Fy odd in the slip angle,
rising and saturating, opposing the hub's sliding, and the trends Ishigami reports."""

from __future__ import annotations

import math

import numpy as np
import pytest
from reference_quadrature import reference_lateral

from rover_cosim.terramechanics import (
    Soil,
    Wheel,
    bulldozing_factors,
    contact_forces,
    slip_angle,
    wheel_forces,
    wheel_state,
)

WHEEL, SOIL = Wheel(), Soil()
ANGLES = np.radians([2.0, 5.0, 10.0, 20.0, 30.0])


@pytest.mark.parametrize("beta_deg", [2.0, 10.0, 30.0, -15.0])
def test_lateral_quadrature_matches_20000_point_reference(beta_deg: float):
    beta = math.radians(beta_deg)
    worst = 0.0
    for h in (0.005, 0.03, 0.1):
        for kappa in (-0.5, 0.0, 0.2, 0.9):
            fx, fy, side = reference_lateral(h, kappa, beta, WHEEL, SOIL)
            got = contact_forces(h, kappa, slip_angle=beta)
            scale = max(abs(fy), abs(fx), 1.0)
            errors = (got.Fy - fy, got.Fy_sidewall - side, got.Fx - fx)
            worst = max(worst, *(float(abs(e)) / scale for e in errors))
    assert worst < 1e-5, worst


def test_slip_angle_zero_changes_nothing_bit_for_bit():
    loads, slips = np.array([100.0, 424.0, 800.0])[:, None], np.linspace(-1, 1, 9)
    plain, zero = wheel_state(loads, slips), wheel_state(loads, slips, slip_angle=0.0)
    for name in ("sinkage", "Fx", "Fz", "Tx", "entry_angle", "exit_angle", "max_stress_angle"):
        np.testing.assert_array_equal(getattr(zero, name), getattr(plain, name), err_msg=name)
    assert (zero.Fy == 0).all() and (zero.Fy_sidewall == 0).all()
    a, b = contact_forces(0.03, slips), contact_forces(0.03, slips, slip_angle=np.zeros(9))
    for name in ("Fx", "Fz", "Tx"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def test_fy_is_odd_in_the_slip_angle_and_opposes_the_sliding():
    left = wheel_state(424.0, 0.1, slip_angle=ANGLES)
    right = wheel_state(424.0, 0.1, slip_angle=-ANGLES)
    np.testing.assert_allclose(right.Fy, -left.Fy, rtol=1e-12)
    np.testing.assert_allclose(right.Fx, left.Fx, rtol=1e-12)
    assert (left.Fy < 0).all() and (left.Fy_sidewall < 0).all()


def test_fy_rises_with_the_slip_angle_and_saturates():
    betas = np.radians(np.arange(0.0, 45.1, 5.0))
    fy = -wheel_state(424.0, 0.1, slip_angle=betas).Fy
    steps = np.diff(fy)
    assert (steps > 0).all()
    assert steps[-1] < 0.25 * steps[0]


def test_ishigami_trends_against_slip_and_load():
    """Ishigami et al. 2007 (Figs. 8-10): the side force falls as the slip ratio grows and rises
    with the load; the drawbar pull falls as the slip angle grows."""
    beta = math.radians(10.0)
    by_slip = -wheel_state(424.0, np.array([0.0, 0.1, 0.3, 0.5]), slip_angle=beta).Fy
    assert (np.diff(by_slip) < 0).all()
    by_load = -wheel_state(np.array([100.0, 300.0, 500.0, 800.0]), 0.1, slip_angle=beta).Fy
    assert (np.diff(by_load) > 0).all()
    fx = wheel_state(424.0, 0.2, slip_angle=ANGLES).Fx
    assert (np.diff(fx) < 0).all()


def test_sidewall_is_continuous_at_zero_and_a_minority_of_fy():
    small = wheel_state(424.0, 0.1, slip_angle=np.array([1e-6, 1e-4])).Fy_sidewall
    assert abs(small[1] / small[0] - 100.0) < 1.0  # proportional to beta near 0
    state = wheel_state(np.array([100.0, 800.0]), 0.1, slip_angle=math.radians(20.0))
    share = state.Fy_sidewall / state.Fy
    assert (share > 0).all() and (share < 0.2).all() and share[1] > share[0]


def test_bulldozing_factors_for_ishigamis_soil():
    d1, d2 = bulldozing_factors(SOIL)
    xc, phi = SOIL.xc, SOIL.phi
    assert d1 == pytest.approx(1 / math.tan(xc) + math.tan(xc + phi))
    assert d2 == pytest.approx(1 / math.tan(xc) + 1 / math.tan(xc) ** 2 / (1 / math.tan(phi)))
    assert math.degrees(xc) == pytest.approx(45.0 - math.degrees(phi) / 2, abs=1e-9)


def test_slip_angle_of_the_hub_velocity_at_rest_reverse_and_sideways():
    beta = slip_angle([1.0, -1.0, 0.0, 0.0], [1.0, -1.0, 0.0, 0.0], [0.1, -0.1, 0.0, 0.5], 1e-3)
    np.testing.assert_allclose(beta[:3], [math.atan(0.1), math.atan(0.1), 0.0])
    assert beta[3] > math.radians(89.0)


def test_wheel_forces_with_sideways_speed_mirror_and_dissipate():
    rng = np.random.default_rng(4)
    load = rng.uniform(100, 900, 300)
    v = rng.choice([-1, 1], 300) * 10 ** rng.uniform(-5, 0.2, 300)
    omega = v * rng.uniform(0.5, 1.5, 300) / WHEEL.r
    v_y = v * rng.uniform(-0.6, 0.6, 300)
    ahead = wheel_forces(load, omega, v, v_lateral=v_y)
    back = wheel_forces(load, -omega, -v, v_lateral=-v_y)
    np.testing.assert_array_equal(back.Fy, -ahead.Fy)
    np.testing.assert_array_equal(back.Fx, -ahead.Fx)
    assert (ahead.Fy * v_y <= 0).all()
    power = ahead.Fx * v - ahead.Tx * omega + ahead.Fy * v_y
    assert power.max() <= 1e-9


@pytest.mark.parametrize("field,value", [("ky", 0.0), ("ky_beta", -0.01), ("kx_beta", -1.0), ("rho", -1.0),
                                         ("gravity", -1.62), ("xc", 0.0), ("xc", math.pi / 2)])
def test_lateral_soil_parameters_are_checked(field: str, value: float):
    with pytest.raises(ValueError, match=field):
        Soil(**{field: value})


def test_slip_angle_out_of_range_is_refused():
    with pytest.raises(ValueError, match="slip_angle"):
        wheel_state(424.0, 0.1, slip_angle=math.pi / 2)
