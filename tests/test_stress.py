import math

import numpy as np
import pytest

from rover_cosim.terramechanics import Soil, Wheel, normal_stress, shear_displacement, shear_stress
from rover_cosim.terramechanics.stress import normal_stress_front, normal_stress_rear

WHEEL, SOIL = Wheel(), Soil()
K = 1.37e3 / 0.175 + 8.14e5  # kc/b + kphi [N/m^3], by hand from Table 2


def test_front_normal_stress_eq5():
    # theta = 0, theta_f = 0.5, n = 1: sigma = r * K * (1 - cos 0.5)
    expected = 0.355 * K * (1 - math.cos(0.5))
    assert normal_stress_front(0.0, 0.5, WHEEL, SOIL) == pytest.approx(expected, rel=1e-12)
    assert normal_stress_front(0.5, 0.5, WHEEL, SOIL) == 0.0
    soil = Soil(n=0.5)
    assert normal_stress_front(0.0, 0.5, WHEEL, soil) == pytest.approx(
        0.355**0.5 * K * (1 - math.cos(0.5)) ** 0.5, rel=1e-12)


def test_rear_normal_stress_eq6():
    theta_f, theta_r, theta_m = 0.5, -0.4, 0.2
    assert normal_stress_rear(theta_r, theta_f, theta_r, theta_m, WHEEL, SOIL) == pytest.approx(0.0, abs=1e-9)
    # continuous at theta_m
    assert normal_stress_rear(theta_m, theta_f, theta_r, theta_m, WHEEL, SOIL) == pytest.approx(
        normal_stress_front(theta_m, theta_f, WHEEL, SOIL), rel=1e-12)
    # half way from theta_r to theta_m: equivalent angle theta_f - (theta_f - theta_m)/2 = 0.35
    mid = 0.5 * (theta_r + theta_m)
    assert normal_stress_rear(mid, theta_f, theta_r, theta_m, WHEEL, SOIL) == pytest.approx(
        0.355 * K * (math.cos(0.35) - math.cos(0.5)), rel=1e-12)


def test_normal_stress_picks_the_branch_and_peaks_at_theta_m():
    theta_f, theta_r, theta_m = 0.5, -0.4, 0.2
    theta = np.linspace(theta_r, theta_f, 2001)
    sigma = normal_stress(theta, theta_f, theta_r, theta_m, WHEEL, SOIL)
    assert theta[np.argmax(sigma)] == pytest.approx(theta_m, abs=1e-3)
    assert (sigma >= 0).all()


def test_shear_displacement_eq10():
    assert shear_displacement(0.5, 0.5, 0.3, WHEEL) == 0.0
    assert shear_displacement(0.1, 0.5, 1.0, WHEEL) == pytest.approx(0.355 * 0.4)
    assert shear_displacement(0.0, 0.5, 0.0, WHEEL) == pytest.approx(0.355 * (0.5 - math.sin(0.5)))
    assert shear_displacement(-0.2, 0.5, 0.25, WHEEL) == pytest.approx(
        0.355 * (0.7 - 0.75 * (math.sin(0.5) + math.sin(0.2))))


def test_shear_stress_eqs_7_to_9():
    tau_max = 800.0 + 1e4 * math.tan(math.radians(37.2))
    assert shear_stress(1e4, 0.036, SOIL) == pytest.approx(tau_max * (1 - math.exp(-1)))
    assert shear_stress(1e4, 10.0, SOIL) == pytest.approx(tau_max)
    assert shear_stress(1e4, 0.0, SOIL) == 0.0
    # backward shear is bounded by the same strength (sign-symmetric Janosi-Hanamoto)
    assert shear_stress(1e4, -0.036, SOIL) == pytest.approx(-tau_max * (1 - math.exp(-1)))
    assert shear_stress(1e4, -10.0, SOIL) == pytest.approx(-tau_max)
