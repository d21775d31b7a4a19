"""The longitudinal characteristics the paper states in Sec. 2.2.7 (Fig. 3)."""

import numpy as np
import pytest

from rover_cosim.terramechanics import wheel_state

LOADS = np.arange(100.0, 801.0, 100.0)  # [N]
SLIPS = np.linspace(0.0, 0.9, 91)


@pytest.fixture(scope="module")
def fx():
    return wheel_state(LOADS[:, None], SLIPS[None, :]).Fx  # (load, slip)


def test_fx_rises_with_slip_and_saturates(fx):
    assert (np.diff(fx, axis=1) > 0).all()
    early = (fx[:, 10] - fx[:, 0]) / 0.1   # dFx/dκ over κ in [0, 0.1]
    late = (fx[:, 90] - fx[:, 80]) / 0.1   # over κ in [0.8, 0.9]
    assert (late < 0.25 * early).all()
    # the curve flattens monotonically: its slope keeps falling
    assert (np.diff(np.diff(fx[:, 10:], axis=1), axis=1) < 0).all()


def test_fx_rises_with_load_at_every_slip(fx):
    assert (np.diff(fx[:, 1:], axis=0) > 0).all()


def test_fx_increase_per_100_N_shrinks_with_load_at_high_slip(fx):
    """Sec. 2.2.7: 'the increasing ratio of Fx decreases as the load grows'.

    With Table 2 soil this holds for κ >= 0.7; at low slip the per-100 N increase of Fx grows
    with load in this model (the larger contact patch wins over the larger compaction), which
    the README notes as a difference from the paper's statement.
    """
    high_slip = SLIPS >= 0.7 - 1e-12
    increments = np.diff(fx[:, high_slip], axis=0)
    assert (np.diff(increments, axis=0) < 0).all()


def test_fx_increase_per_100_N_grows_with_load_at_low_slip(fx):
    """The other half of the finding above (README, 'One difference from the paper's text')."""
    low_slip = (SLIPS > 0.0) & (SLIPS <= 0.3 + 1e-12)
    increments = np.diff(fx[:, low_slip], axis=0)
    assert (np.diff(increments, axis=0) > 0).all()
