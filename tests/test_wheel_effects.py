"""Grousers, slip-sinkage and multi-pass ruts in the numpy reference wheel (issue 48): off, each is
the smooth wheel on virgin soil bit for bit; on, each shows the trend its source claims and keeps
the physics (rest, mirror, no energy created, sinkage never negative)."""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np
import pytest

from rover_cosim.terramechanics import Soil, Wheel, contact_forces, wheel_forces, wheel_state
from rover_cosim.terramechanics.grousers import grouser_engagement, shear_radius, side_shear_factor

LOAD = 424.0  # N, a wheel of the paper's rover at rest
SLIPS = np.linspace(-0.6, 0.9, 16)
GROUSERED = Wheel(grouser_height=0.015, grouser_count=24)
SLIP_SINKAGE = Soil(n_slip=0.6)



class Effect(NamedTuple):
    wheel: Wheel
    soil: Soil
    rut: float  #: rut depth [m]


EFFECTS = {
    "grousers": Effect(GROUSERED, Soil(), 0.0),
    "slip-sinkage": Effect(Wheel(), SLIP_SINKAGE, 0.0),
    "multi-pass": Effect(Wheel(), Soil(), 0.03),
    "all three": Effect(GROUSERED, SLIP_SINKAGE, 0.03),
}


def _fields(state):
    return [np.asarray(getattr(state, name)) for name in ("sinkage", "Fx", "Fz", "Tx", "Fy")]


@pytest.mark.parametrize("off", [Wheel(grouser_height=0.02, grouser_count=0), Wheel(grouser_height=0.0,
                                                                                    grouser_count=30)])
def test_a_wheel_without_grousers_is_the_smooth_wheel_bit_for_bit(off):
    loads, slips = np.meshgrid([50.0, 424.0, 1500.0], SLIPS)
    smooth = wheel_state(loads, slips, Wheel(), Soil(), slip_angle=0.1)
    other = wheel_state(loads, slips, off, Soil(), slip_angle=0.1)
    for a, b in zip(_fields(smooth), _fields(other)):
        assert np.array_equal(a, b)


def test_no_rut_and_no_slip_sinkage_are_virgin_soil_bit_for_bit():
    loads, slips = np.meshgrid([50.0, 424.0, 1500.0], SLIPS)
    plain = wheel_state(loads, slips, Wheel(), Soil())
    for state in (wheel_state(loads, slips, Wheel(), Soil(n_slip=0.0), rut_depth=0.0),
                  wheel_state(loads, slips, Wheel(), Soil(), rut_depth=np.zeros_like(loads))):
        for a, b in zip(_fields(plain), _fields(state)):
            assert np.array_equal(a, b)


def test_the_grouser_model_is_its_three_formulas():
    theta_f, theta_r = np.array([0.2, 0.5]), np.array([-0.1, -0.3])
    engagement = grouser_engagement(theta_f, theta_r, GROUSERED)
    np.testing.assert_allclose(engagement, np.minimum(1.0, 24 * (theta_f - theta_r) / (2 * np.pi)))
    np.testing.assert_allclose(shear_radius(engagement, GROUSERED), 0.355 + engagement * 0.015)
    np.testing.assert_allclose(side_shear_factor(engagement, GROUSERED), 1 + 2 * engagement * 0.015 / 0.175)


def test_drawbar_pull_at_20_percent_slip_rises_with_grouser_height_and_with_count_until_one_is_always_engaged():
    heights = [0.0, 0.005, 0.01, 0.02, 0.04]
    pulls = [float(wheel_state(LOAD, 0.2, Wheel(grouser_height=h, grouser_count=24)).Fx) for h in heights]
    assert all(b > a for a, b in zip(pulls, pulls[1:])), pulls
    state = wheel_state(LOAD, 0.2, Wheel())
    span = float(state.entry_angle - state.exit_angle)
    saturating = int(np.ceil(2 * np.pi / span))  # from this count on a grouser is always in the patch
    counts = [1, 2, saturating // 2, saturating, 2 * saturating, 8 * saturating]
    by_count = [float(wheel_state(LOAD, 0.2, Wheel(grouser_height=0.01, grouser_count=n)).Fx) for n in counts]
    assert all(b > a for a, b in zip(by_count[:4], by_count[1:4])), by_count
    assert by_count[3] == pytest.approx(by_count[4], rel=0.02) and by_count[4] == pytest.approx(by_count[5], rel=1e-3)


def test_sinkage_grows_with_slip_more_with_slip_sinkage_and_is_unchanged_at_zero_slip():
    slips = np.array([0.0, 0.1, 0.2, 0.4, 0.6])
    plain = wheel_state(LOAD, slips, Wheel(), Soil()).sinkage
    sinking = wheel_state(LOAD, slips, Wheel(), SLIP_SINKAGE).sinkage
    assert sinking[0] == plain[0]
    assert np.all(np.diff(sinking) > 0)
    growth, plain_growth = sinking / sinking[0], plain / plain[0]
    assert np.all(growth[1:] > plain_growth[1:])
    assert growth[-1] > 1.5  # Ding et al. 2011 measured sinkage growing 2-4 fold from 0 to 60 % slip


def test_a_second_pass_in_the_first_ones_rut_sinks_less_than_the_first_and_a_third_less_again():
    first = wheel_state(LOAD, 0.2, Wheel(), Soil())
    second = wheel_state(LOAD, 0.2, Wheel(), Soil(), rut_depth=first.sinkage)
    third = wheel_state(LOAD, 0.2, Wheel(), Soil(), rut_depth=second.sinkage)
    added_second = float(second.sinkage - first.sinkage)
    added_third = float(third.sinkage - second.sinkage)
    assert 0 < added_second < float(first.sinkage)
    assert 0 < added_third < added_second
    assert float(second.Fz) == pytest.approx(LOAD, rel=1e-9)
    # the patch of a wheel in a rut is shorter: it rests on soil that already carries the load
    assert float(second.entry_angle) < float(first.entry_angle)


@pytest.mark.parametrize("effect", EFFECTS)
def test_each_effect_converges_with_the_quadrature_nodes(effect):
    case = EFFECTS[effect]
    h, slips = np.meshgrid([0.005, 0.03, 0.12], SLIPS)
    coarse = contact_forces(h, slips, case.wheel, case.soil, slip_angle=0.05, rut_depth=case.rut)
    fine = contact_forces(h, slips, case.wheel, case.soil, 400, slip_angle=0.05, rut_depth=case.rut)
    for name in ("Fz", "Fx", "Tx"):
        scale = np.abs(fine.Fz)
        error = np.abs(getattr(coarse, name) - getattr(fine, name)) / scale
        assert error.max() < 2e-4, (name, error.max())


@pytest.mark.parametrize("effect", EFFECTS)
def test_each_effect_keeps_rest_at_rest_mirrors_reverse_and_creates_no_energy(effect):
    case = EFFECTS[effect]
    wheel, soil, rut = case
    rest = wheel_forces(LOAD, 0.0, 0.0, wheel, soil, rut_depth=rut)
    assert float(rest.Fx) == 0.0 and float(rest.Tx) == 0.0
    omega = np.linspace(-3.0, 3.0, 13)[:, None]
    v = np.linspace(-1.0, 1.0, 9)[None, :]
    ahead = wheel_forces(LOAD, omega, v, wheel, soil, rut_depth=rut)
    back = wheel_forces(LOAD, -omega, -v, wheel, soil, rut_depth=rut)
    np.testing.assert_allclose(back.Fx, -ahead.Fx, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(back.Tx, -ahead.Tx, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(back.sinkage, ahead.sinkage, rtol=1e-9)
    # the power the motor puts in, Tx ω, is never less than what reaches the hub, Fx v
    dissipated = ahead.Tx * omega - ahead.Fx * v
    assert dissipated.min() >= -1e-9 * np.abs(ahead.Tx * omega).max()
    assert np.all(ahead.sinkage >= rut)


def test_a_grousered_wheel_sinks_like_the_smooth_one_at_zero_slip_and_pulls_more_when_driven():
    smooth = wheel_state(LOAD, SLIPS, Wheel(), Soil())
    grousered = wheel_state(LOAD, SLIPS, GROUSERED, Soil())
    driving = SLIPS > 0.05
    assert np.all(grousered.Fx[driving] > smooth.Fx[driving])
    assert np.all(grousered.sinkage > 0)


def test_bad_effect_parameters_name_the_value():
    with pytest.raises(ValueError, match="grouser_count"):
        Wheel(grouser_height=0.01, grouser_count=2.5)
    with pytest.raises(ValueError, match="grouser_height"):
        Wheel(grouser_height=0.3)
    with pytest.raises(ValueError, match="n_slip"):
        Soil(n_slip=-0.1)
    with pytest.raises(ValueError, match="rut_depth"):
        wheel_state(LOAD, 0.1, rut_depth=-0.01)
    assert replace(GROUSERED, grouser_count=0).grousered is False


def test_slip_sinkage_reaches_the_band_a_source_measured_and_the_smooth_law_does_not():
    """Ding et al. 2010 measured lugged wheels sinking 3-7 times their static sinkage at 60 % slip: the
    smooth law stays near 1, the n_slip band that spans 3-7 holds the ablation's default n_slip and
    gives the band's ends back."""
    from rover_cosim.jobs.effects import DEFAULT_N_SLIP, SLIP_SINKAGE_REPORTED, n_slip_band, sinkage_ratio

    slip, low, high, _ = SLIP_SINKAGE_REPORTED
    wheel, soil, load = Wheel(), Soil(), 424.0
    assert sinkage_ratio(wheel, soil, load, 0.0, slip) < 1.2 < low
    first, last = n_slip_band(wheel, soil, load)
    assert 0 < first < DEFAULT_N_SLIP < last
    assert sinkage_ratio(wheel, soil, load, first, slip) == pytest.approx(low, rel=1e-6)
    assert sinkage_ratio(wheel, soil, load, last, slip) == pytest.approx(high, rel=1e-6)
