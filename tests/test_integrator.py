"""The FMUs' Co-Simulation integrator (fmubuild/runtime/ode23s.c) on a stiff scalar ODE whose input
jumps at every communication point (tests/ode23s_harness.c), as a wheel's spin under the torque a
controller sets every step: within its tolerance at every communication point, and a
communication step does not as a rule begin with a rejected step and a new Jacobian (it did: the
step size proposed at the end of the last one, past its transient, was tried first)."""

from __future__ import annotations

import ctypes
from pathlib import Path

import pytest
from c_harness import RUNTIME, compiled

HARNESS = Path(__file__).with_name("ode23s_harness.c")
CALLS = 2000
STEP = 1e-3  # s, the paper's communication step
TOLERANCE = 1e-6  # the FMUs' default


@pytest.fixture(scope="module")
def harness(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    return compiled(tmp_path_factory, "ode23s", HARNESS, RUNTIME / "ode23s.c")


def integrate(harness: ctypes.CDLL, rate: float, jump: float) -> dict[str, float]:
    counts = (ctypes.c_long * 4)()
    worst, fewest, most = ctypes.c_double(), ctypes.c_long(), ctypes.c_long()
    status = harness.run(ctypes.c_double(rate), ctypes.c_double(jump), ctypes.c_int(CALLS), ctypes.c_double(STEP),
                         ctypes.c_double(TOLERANCE), counts, ctypes.byref(worst), ctypes.byref(fewest),
                         ctypes.byref(most))
    assert status == 0
    return {"steps": counts[0], "rejected": counts[1], "jacobians": counts[2], "evaluations": counts[3],
            "worst": worst.value, "fewest": fewest.value, "most": most.value}


@pytest.mark.parametrize("rate", [3e3, 3e4])  # 1/s: time constants of a third and a thirtieth of a step
@pytest.mark.parametrize("jump", [1e-4, 1e-3, 1e-2])
def test_input_jumps_at_every_communication_point(harness: ctypes.CDLL, rate: float, jump: float):
    found = integrate(harness, rate, jump)
    # the global error at each communication point, in units of the tolerance (atol + rtol |x|)
    assert found["worst"] < 10, found
    # a transient at each communication point: several steps in each, yet not a rejection and a
    # Jacobian per communication step (before: 0.7-3 rejections and 0.6-1 Jacobians each)
    assert found["most"] > 1, found
    assert found["rejected"] < CALLS / 2, found
    assert found["jacobians"] < CALLS / 2, found


def test_smooth_input_takes_one_step_per_communication_step(harness: ctypes.CDLL):
    """A slow mode under a small jump: one step per communication step, no rejection."""
    found = integrate(harness, 30.0, 1e-4)
    assert found["rejected"] == 0, found
    assert found["fewest"] == found["most"] == 1, found
    assert found["worst"] < 10, found
