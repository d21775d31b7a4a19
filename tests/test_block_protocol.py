"""The Python block protocol: ``start(t0, u0, h)`` tells a block the run's communication step (a
controller discretises its filter at it, so the step is given once, by the system); a block
written for the earlier ``start(t0, u0)`` still runs."""

from __future__ import annotations

import numpy as np
import pytest

from rover_cosim.orchestrator.blocks import Constant, takes_step
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.master import run


class _Told:
    """Records the step it was told; integrates its input (so a wrong step shows in its output)."""

    inputs: tuple[str, ...] = ("u",)
    outputs: tuple[str, ...] = ("y",)
    units: dict[str, str] = {}

    def __init__(self, name: str):
        self.name, self.y = name, 0.0
        self.told: float | str | None = None

    def start(self, t0: float, u0: np.ndarray, h: float) -> np.ndarray:
        self.told = h
        return np.array([self.y])

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        self.y += h * float(u[0])
        return np.array([self.y])


class _Earlier(_Told):
    """A block of the earlier protocol: start(t0, u0)."""

    def start(self, t0: float, u0: np.ndarray) -> np.ndarray:  # type: ignore[override]
        self.told = "not told"
        return np.array([self.y])


@pytest.mark.parametrize("step", [1e-3, 2.5e-3])
def test_a_block_is_told_the_systems_step_and_an_earlier_block_still_runs(step):
    told, earlier = _Told("told"), _Earlier("earlier")
    builder = SystemBuilder("blocks").simulation(stop_time=0.1, step=step)
    builder.add_block("one", Constant("one", 1.0)).add_block("told", told)
    builder.add_block("earlier", earlier)  # type: ignore[arg-type]
    builder.connect("one.y", "told.u").connect("one.y", "earlier.u")
    result = run(builder.build())
    assert told.told == step and earlier.told == "not told"
    assert result.data["told.y"].iloc[-1] == pytest.approx(0.1)
    assert result.data["earlier.y"].iloc[-1] == pytest.approx(0.1)
    assert takes_step(told) and not takes_step(earlier)


def test_the_controller_takes_its_step_from_the_start_not_its_constructor(identified):
    """The paper's controller made with the default 1 ms, started at 4 ms: its filter is
    discretised at 4 ms (the same outputs as one made with step=4e-3), and a 4 ms step is no longer
    refused as longer than its own."""
    from rover_cosim.control.controller import InverseModelController
    from rover_cosim.identification.model_set import ModelSet

    models = ModelSet.read(identified.files[0].parent / "model.json")
    told, made = InverseModelController("a", models), InverseModelController("b", models, step=4e-3)
    u = np.array([0.0, 0.2, *[424.0] * 6])
    assert np.array_equal(told.start(0.0, u, 4e-3), made.start(0.0, u))
    for k in range(1, 50):
        assert np.array_equal(told.step(k * 4e-3, 4e-3, u), made.step(k * 4e-3, 4e-3, u))
    with pytest.raises(ValueError, match="step = 0.0 s: expected a finite step > 0"):
        told.start(0.0, u, 0.0)
