"""The numpy reference wheel in every motion regime (terramechanics.regimes) and the reference
test bed over time: rest stays rest, energy is never created, reverse mirrors forward, braking
skids, slopes act through the weight. The FMU side of the same properties: test_fmu_regimes.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rover_cosim.identification.reference_plant import StartState, run_reference_test_bed
from rover_cosim.identification.testbed import TorqueProfile
from rover_cosim.terramechanics import (
    Regimes,
    Soil,
    Wheel,
    shear_strength,
    steady_weight,
    travel_direction,
    wheel_forces,
    wheel_state,
)

WHEEL, SOIL, REGIMES = Wheel(), Soil(), Regimes()
LOADS = (100.0, 424.0, 900.0)
G = 1.62


def states(seed: int = 0, n: int = 400) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random (load, omega, v): speeds from standstill (1e-6 m/s) to 2 m/s, both signs."""
    rng = np.random.default_rng(seed)
    load = rng.uniform(50.0, 1000.0, n)
    v = rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(-6, 0.3, n)
    r_omega = v * (1.0 + rng.uniform(-1.5, 1.5, n))
    return load, r_omega / WHEEL.r, v


def test_at_rest_the_soil_exerts_no_force_or_torque():
    forces = wheel_forces(np.array(LOADS), 0.0, 0.0)
    np.testing.assert_array_equal(forces.Fx, 0.0)
    np.testing.assert_array_equal(forces.Tx, 0.0)
    np.testing.assert_allclose(forces.Fz, LOADS, rtol=1e-9)


def test_reverse_mirrors_forward_exactly():
    load, omega, v = states()
    ahead, back = wheel_forces(load, omega, v), wheel_forces(load, -omega, -v)
    for name in ("Fx", "Tx", "slip", "entry_angle"):
        np.testing.assert_array_equal(getattr(back, name), -getattr(ahead, name), err_msg=name)
    np.testing.assert_array_equal(back.sinkage, ahead.sinkage)


def test_entry_side_follows_the_direction_of_travel():
    load, omega, v = states(1)
    forces = wheel_forces(load, omega, v)
    assert (np.sign(forces.entry_angle) == np.sign(v)).all()
    np.testing.assert_array_equal(travel_direction([1.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]), [1, -1, 1, 1])


def test_rolling_wheel_gets_exactly_the_papers_forces():
    """Above vHold the regime changes nothing: Eqs. (1)-(13) at the slip of Eq. (4)."""
    load = np.repeat(np.array(LOADS), 4)
    v = np.tile([0.05, 0.3, 1.0, 2.0], 3)
    slip = np.tile([-0.3, 0.0, 0.1, 0.6], 3)
    r_omega = np.where(slip >= 0, v / (1 - slip), v * (1 + slip))
    forces = wheel_forces(load, r_omega / WHEEL.r, v)
    paper = wheel_state(load, forces.slip)
    np.testing.assert_allclose(forces.slip, slip, atol=1e-12)
    np.testing.assert_array_equal(forces.Fx, paper.Fx)
    np.testing.assert_array_equal(forces.Tx, paper.Tx)


def test_soil_forces_never_create_energy():
    """Power of the contact on wheel and carrier, Fx v - Tx omega <= 0, in every regime."""
    load, omega, v = states(2, 2000)
    forces = wheel_forces(load, omega, v)
    power = forces.Fx * v - forces.Tx * omega
    assert power.max() <= 1e-12 * np.abs(forces.Tx * omega).max(), power.max()


def test_shear_stays_within_the_mohr_coulomb_strength_of_the_patch():
    load, omega, v = states(3, 2000)
    forces = wheel_forces(load, omega, v)
    strength = shear_strength(load, forces.sinkage, WHEEL, SOIL)
    assert (np.abs(forces.Fx) <= strength * (1 + 1e-9)).all()
    assert (np.abs(forces.Tx) <= WHEEL.r * strength * (1 + 1e-9)).all()


def test_an_anchored_wheel_holds_more_than_a_rolling_wheel_pulls():
    """Push-roll's margin in this contact (the leg-wheel design page): a braked wheel that the limbs
    hold still is held by the soil up to the patch's Mohr-Coulomb strength, and dragged back it takes
    the mirrored skid's force, more than a rolling wheel pulls at any slip, which compaction costs."""
    load = np.array(LOADS)
    rolling = np.array([wheel_forces(load, 0.3 / (1 - slip) / WHEEL.r, 0.3).Fx  # at 0.3 m/s
                        for slip in (0.5, 0.9, 0.999)]).max(axis=0)
    dragged = wheel_forces(load, 0.0, -0.01).Fx   # braked, pushed back at 1 cm/s: the mirrored skid
    holding = wheel_forces(load, 0.0, -REGIMES.v_stick)  # braked, creeping: the static regime
    strength = shear_strength(load, holding.sinkage, WHEEL, SOIL)
    assert (rolling > 0).all() and (dragged > rolling).all()
    assert (strength > rolling).all() and (holding.Fx > 0).all() and (holding.Fx <= strength).all()


def test_steady_weight_blends_from_rest_to_rolling():
    w = steady_weight([0.0, 0.25e-3, 1e-3, 1.0, -1.0], 1e-3)
    np.testing.assert_allclose(w, [0.0, 0.4375, 1.0, 1.0, 1.0])


@pytest.mark.parametrize("field", ["v_eps", "v_hold", "v_stick"])
@pytest.mark.parametrize("value", [0.0, -1e-3, math.inf, math.nan])
def test_regime_speeds_must_be_positive(field: str, value: float):
    with pytest.raises(ValueError, match=f"{field}="):
        Regimes(**{field: value})


def test_wheel_forces_names_a_bad_state():
    with pytest.raises(ValueError, match="load"):
        wheel_forces(0.0, 1.0, 1.0)
    with pytest.raises(ValueError, match="omega"):
        wheel_forces(424.0, math.nan, 1.0)


# --- the reference test bed over time ---------------------------------------------------------------

def kinetic_energy(run, load: float) -> np.ndarray:
    return 0.5 * load / G * run["v"].to_numpy() ** 2 + 0.5 * WHEEL.J * run["omega"].to_numpy() ** 2


@pytest.mark.parametrize("load", [100.0, 900.0])
def test_reference_test_bed_at_rest_stays_at_rest(load: float):
    run = run_reference_test_bed(load, TorqueProfile.step(0.0), 60.0, 1.0)
    assert run["v"].abs().max() < 1e-3 and run["x"].abs().max() < 1e-3


def test_reference_free_rolling_slows_to_rest_without_turning_back():
    load = 424.0
    start = StartState(v=1.0, omega=1.0 / WHEEL.r)
    # stops at 12.55 s; rtol 1e-5 (the reference's 1e-7 costs the stiff approach to rest 1.6x as
    # much): the same stop, energy never rises by more than 1e-23 J a sample, v never below -1e-12
    run = run_reference_test_bed(load, TorqueProfile.step(0.0), 14.0, 0.05, start=start, rtol=1e-5)
    v = run["v"].to_numpy()
    assert v[-1] < 1e-3 and v.min() >= -1e-9
    assert np.diff(kinetic_energy(run, load)).max() <= 1e-9


def test_reference_reverse_mirrors_forward_over_time():
    # rtol 1e-5: the mirror is exact at any tolerance (measured 0.0 at 1e-5 and at the default 1e-7)
    ahead = run_reference_test_bed(424.0, TorqueProfile.step(30.0), 1.0, 0.01, rtol=1e-5)
    back = run_reference_test_bed(424.0, TorqueProfile.step(-30.0), 1.0, 0.01, rtol=1e-5)
    for name in ("v", "omega", "Fx", "Tx", "slip"):
        scale = ahead[name].abs().max()
        assert np.abs(back[name] + ahead[name]).max() <= 1e-6 * scale, name


def test_reference_braking_skids_and_slows_down():
    run = run_reference_test_bed(424.0, TorqueProfile.step(-30.0), 1.0, 0.01,
                                 start=StartState(v=1.0, omega=1.0 / WHEEL.r))
    moving = run[run["time"] > 0.05]
    assert (moving["slip"] < 0).all() and (np.diff(moving["v"]) < 0).all()


def test_reference_slope_slides_back_or_holds():
    load, slope = 424.0, math.radians(10.0)
    # at rtol 1e-4 (the stiff stick regime costs Radau 9x as much at the reference's 1e-7): both
    # properties are a millimetre's or a tenth of a metre per second's, and the final speed of the
    # slide is 1e-4's the same as 1e-7's to six digits
    slides = run_reference_test_bed(load, TorqueProfile.step(0.0), 2.0, 0.1, slope=slope, rtol=1e-4)
    assert slides["v"].iloc[-1] < -0.1
    hold = load * math.sin(slope) * WHEEL.r
    # held for 0.5 s: a creep of 2 mm/s would show
    held = run_reference_test_bed(load, TorqueProfile.step(hold), 0.5, 0.1, slope=slope, rtol=1e-4)
    assert held["x"].abs().max() < 1e-3


def test_the_reference_test_bed_refuses_what_it_cannot_run_with_the_value():
    step = TorqueProfile.step(0.0)
    with pytest.raises(ValueError, match=r"load = 0.0 N: expected > 0"):
        run_reference_test_bed(0.0, step, 0.1, 0.05)
    with pytest.raises(ValueError, match=r"slope = 2.0 rad: expected -pi/2 < slope < pi/2"):
        run_reference_test_bed(424.0, step, 0.1, 0.05, slope=2.0)
    with pytest.raises(ValueError, match=r"rtol = 0.0: expected 0 < rtol < 1"):
        run_reference_test_bed(424.0, step, 0.1, 0.05, rtol=0.0)
