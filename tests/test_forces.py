import numpy as np
import pytest
from reference_quadrature import POINTS, reference_forces

from rover_cosim.terramechanics import DEFAULT_NODES, Soil, Wheel, contact_forces

WHEEL = Wheel()
SINKAGES = (1e-4, 0.005, 0.03, 0.1, 0.2, 0.3, 0.35)  # [m]
SLIPS = (-1.0, -0.5, -0.1, 0.0, 0.2, 0.5, 0.9, 1.0)
SOILS = {"table 2": Soil(), "n=0.8": Soil(n=0.8), "n=1.3": Soil(n=1.3), "lam=1": Soil(lam=1.0, a1=0.3)}


def _relative_error(got, ref):
    """Largest component error relative to the size of the load vector (Fx, Fz, Tx/r)."""
    scale = np.array([1.0, 1.0, 1.0 / WHEEL.r])
    return np.max(np.abs((np.asarray(got[:3]) - ref) * scale)) / np.max(np.abs(ref * scale))


@pytest.mark.parametrize("soil_name", SOILS)
def test_quadrature_matches_20000_point_reference(soil_name):
    soil = SOILS[soil_name]
    worst = 0.0
    for h in SINKAGES:
        for kappa in SLIPS:
            ref = reference_forces(h, kappa, WHEEL, soil)
            worst = max(worst, _relative_error(contact_forces(h, kappa, WHEEL, soil), ref))
    assert POINTS == 20_000
    assert worst < 1e-6, f"default {DEFAULT_NODES}-node quadrature error {worst:.2e}"


def test_quadrature_matches_reference_at_random_states():
    rng = np.random.default_rng(20261123)
    states = zip(rng.uniform(1e-4, WHEEL.r, 60), rng.uniform(-1.0, 1.0, 60))
    worst = max(_relative_error(contact_forces(h, k), reference_forces(h, k, WHEEL, Soil())) for h, k in states)
    assert worst < 1e-6


def test_quadrature_converges_with_nodes():
    cases = [(h, k) for h in (0.03, 0.2, 0.3) for k in (-0.8, 0.3)]
    refs = [reference_forces(h, k, WHEEL, Soil()) for h, k in cases]
    errors = [max(_relative_error(contact_forces(h, k, nodes=n), ref) for (h, k), ref in zip(cases, refs))
              for n in (4, 8, 12, 16)]
    assert errors[0] > errors[1] > errors[2] > errors[3]
    assert errors[3] < 1e-9


def test_vectorized_over_broadcast_arrays():
    h = np.array([[0.01], [0.02], [0.05]])
    kappa = np.array([-0.5, 0.0, 0.5, 1.0])
    forces = contact_forces(h, kappa)
    assert forces.Fx.shape == forces.Fz.shape == forces.Tx.shape == (3, 4)
    for i in range(3):
        for j in range(4):
            single = contact_forces(float(h[i, 0]), float(kappa[j]))
            assert forces.Fx[i, j] == pytest.approx(float(single.Fx), rel=1e-13, abs=1e-9)
            assert forces.Fz[i, j] == pytest.approx(float(single.Fz), rel=1e-13)


def test_physical_signs():
    forces = contact_forces(0.03, np.array([-0.5, 0.5]))
    assert forces.Fx[0] < 0 < forces.Fx[1]   # braking pulls back, driving pushes
    assert forces.Tx[0] < 0 < forces.Tx[1]
    assert (forces.Fz > 0).all()
    none = contact_forces(0.0, 0.3)
    assert (float(none.Fx), float(none.Fz), float(none.Tx)) == (0.0, 0.0, 0.0)


def test_deeper_wheel_carries_more():
    fz = contact_forces(np.linspace(0.001, 0.3, 50), 0.3).Fz
    assert (np.diff(fz) > 0).all()


@pytest.mark.parametrize("kwargs, message", [
    ({"sinkage": -0.01, "slip": 0.1}, r"sinkage=-0.01 m: expected a finite value in \[0.0, 0.355\]"),
    ({"sinkage": 0.4, "slip": 0.1}, r"sinkage=0.4 m"),
    ({"sinkage": [0.01, float("nan")], "slip": 0.1}, r"sinkage\[1\]=nan"),
    ({"sinkage": 0.01, "slip": 1.5}, r"slip=1.5: expected a finite value in \[-1.0, 1.0\]"),
    ({"sinkage": 0.01, "slip": "fast"}, r"slip='fast': expected real numbers"),
    ({"sinkage": 0.01, "slip": 0.1, "nodes": 1}, r"nodes=1"),
])
def test_bad_input_is_named(kwargs, message):
    with pytest.raises(ValueError, match=message):
        contact_forces(**kwargs)
