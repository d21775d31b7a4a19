import numpy as np
import pytest

from rover_cosim.terramechanics import Soil, Wheel, contact_forces, wheel_state
from rover_cosim.terramechanics.sinkage import GRID_BATCH_SIZE

LOADS = np.geomspace(1.0, 5000.0, 25)  # [N]
SLIPS = np.linspace(-1.0, 1.0, 21)


def test_vertical_force_equals_load_over_the_whole_range():
    state = wheel_state(LOADS[:, None], SLIPS[None, :])
    assert state.sinkage.shape == (25, 21)
    assert np.isfinite(state.sinkage).all()
    assert (state.sinkage > 0).all() and (state.sinkage < Wheel().r).all()
    assert np.max(np.abs(state.Fz / state.load - 1)) < 1e-6
    # independently re-evaluated at the solved sinkage
    again = contact_forces(state.sinkage, state.slip)
    assert np.max(np.abs(again.Fz / state.load - 1)) < 1e-6
    np.testing.assert_allclose(again.Fx, state.Fx, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(again.Tx, state.Tx, rtol=1e-12, atol=1e-9)


def test_large_batches_start_from_a_grid_and_agree_with_small_ones():
    rng = np.random.default_rng(7)
    loads = rng.uniform(1.0, 5000.0, GRID_BATCH_SIZE + 500)
    slips = rng.uniform(-1.0, 1.0, loads.size)
    batch = wheel_state(loads, slips)
    assert np.max(np.abs(batch.Fz / loads - 1)) < 1e-6
    singles = [float(wheel_state(w, k).sinkage) for w, k in zip(loads[:40], slips[:40])]
    np.testing.assert_allclose(batch.sinkage[:40], singles, rtol=1e-8)


def test_constant_slip_batch():
    loads = np.linspace(100.0, 800.0, GRID_BATCH_SIZE)
    state = wheel_state(loads, 1.0)
    assert np.max(np.abs(state.Fz / loads - 1)) < 1e-6
    assert (np.diff(state.sinkage) > 0).all()


def test_state_angles_and_shapes():
    state = wheel_state(np.array([[200.0], [400.0]]), np.array([-0.3, 0.0, 0.3]))
    wheel, soil = Wheel(), Soil()
    assert state.Fx.shape == state.entry_angle.shape == (2, 3)
    np.testing.assert_allclose(state.entry_angle, np.arccos(1 - state.sinkage / wheel.r))
    np.testing.assert_allclose(state.exit_angle, -np.arccos(1 - soil.lam * state.sinkage / wheel.r))
    assert (state.exit_angle < state.max_stress_angle).all()
    assert (state.max_stress_angle < state.entry_angle).all()
    assert (state.sinkage[1] > state.sinkage[0]).all()  # heavier wheel sinks deeper


def test_softer_soil_sinks_deeper():
    firm, soft = wheel_state(424.0, 0.2), wheel_state(424.0, 0.2, soil=Soil(kphi=2e5))
    assert float(soft.sinkage) > float(firm.sinkage)


@pytest.mark.parametrize("load, message", [
    (0.0, r"load=0.0 N: expected a finite value > 0.0 N"),
    (-10.0, r"load=-10.0 N"),
    (float("nan"), r"load=nan N"),
    ([100.0, float("nan")], r"load\[1\]=nan N"),
    (float("inf"), r"load=inf N: expected a finite value > 0.0 N"),
    (1e6, r"load=1000000.0 N at slip=0.2: the wheel \(r=0.355 m\) cannot carry it"),
])
def test_bad_loads_are_named(load, message):
    with pytest.raises(ValueError, match=message):
        wheel_state(load, 0.2)


@pytest.mark.parametrize("kwargs, message", [
    ({"slip": 1.01}, r"slip=1.01: expected a finite value in \[-1.0, 1.0\]"),
    ({"slip": float("nan")}, r"slip=nan"),
    ({"slip": 0.1, "rtol": 0.5}, r"rtol=0.5"),
    ({"slip": 0.1, "nodes": 0}, r"nodes=0"),
])
def test_bad_slip_and_options_are_named(kwargs, message):
    with pytest.raises(ValueError, match=message):
        wheel_state(100.0, **kwargs)


def test_capacity_error_in_a_batch_names_the_heavy_load():
    with pytest.raises(ValueError, match=r"load=90000.0 N"):
        wheel_state(np.array([100.0, 90000.0, 300.0]), 0.1)


def test_capacity_error_in_a_large_batch_names_the_exact_load():
    loads = np.full(GRID_BATCH_SIZE + 10, 300.0)
    loads[123] = 54321.0
    with pytest.raises(ValueError, match=r"load=54321.0 N at slip=0.3"):
        wheel_state(loads, 0.3)


@pytest.mark.parametrize("load, slip", [(50.0, 0.0), (424.0, 0.3), (875.0, 0.9), (275.0, -0.6), (3000.0, -0.2)])
def test_sinkage_matches_an_independent_root_finder_on_the_reference_integrals(load, slip):
    """brentq on the 20 000-point Simpson integrals: a different integrator and root finder."""
    from reference_quadrature import reference_forces
    from scipy.optimize import brentq

    wheel, soil = Wheel(), Soil()
    h_ref = brentq(lambda h: reference_forces(h, slip, wheel, soil)[1] - load, 1e-6, 0.99 * wheel.r,
                   xtol=1e-13, rtol=1e-12)
    state = wheel_state(load, slip)
    assert float(state.sinkage) == pytest.approx(h_ref, rel=1e-6)
    ref = reference_forces(h_ref, slip, wheel, soil)
    assert float(state.Fx) == pytest.approx(ref[0], rel=1e-6, abs=1e-6 * load)
    assert float(state.Tx) == pytest.approx(ref[2], rel=1e-6, abs=1e-6 * load * wheel.r)


def test_a_wheel_state_is_a_table_with_units():
    import numpy as np

    from rover_cosim.terramechanics import Soil, Wheel, wheel_state

    state = wheel_state(np.array([[200.0], [400.0]]), np.array([[0.1, 0.2, 0.3]]), Wheel(), Soil())
    table = state.to_frame()
    assert len(table) == 6 and list(table.columns[:6]) == ["load_N", "slip", "sinkage_m", "Fx_N", "Fz_N", "Tx_Nm"]
    assert table["load_N"].tolist() == [200.0] * 3 + [400.0] * 3 and table["slip"].tolist()[:3] == [0.1, 0.2, 0.3]
    np.testing.assert_array_equal(table["Fx_N"].to_numpy(), np.asarray(state.Fx).ravel())
