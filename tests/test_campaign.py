"""A job's independent runs side by side (``Campaign.run_all``) and its figures drawn side by side
(``common.figures.drawn``): the same results as one after the other, bit for bit and in the order
given; the blocks' state after their runs comes back; a system that cannot be sent to a worker runs
here; a failing run fails the job naming it; no worker outlives the call."""

from __future__ import annotations

import multiprocessing

import numpy as np
import pandas as pd
import pytest

from rover_cosim.jobs.campaign import Campaign
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.master import RunError
from rover_cosim.orchestrator.model import System


class CountingTorque:
    """A torque (N.m) that counts its steps and fails at ``fail_at`` [s] if given."""

    def __init__(self, name: str, torque: float, fail_at: float | None = None):
        self.name, self.torque, self.fail_at, self.steps = name, torque, fail_at, 0
        self.inputs: tuple[str, ...] = ("omega",)
        self.outputs: tuple[str, ...] = ("tau",)
        self.units = {"omega": "rad/s", "tau": "N.m"}

    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        return np.array([self.torque])

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        if self.fail_at is not None and t + h > self.fail_at:
            raise ArithmeticError(f"torque block gave up at t = {t + h:g} s")
        self.steps += 1
        return np.array([self.torque])


def wheel(fmus, torque: float, fail_at: float | None = None) -> System:
    return (SystemBuilder(f"one wheel at {torque:g} N.m").simulation(stop_time=0.2, step=1e-3)
            .add_fmu("wheel", fmus["SingleWheel"], parameters={"W": 424.0})
            .add_block("torque", CountingTorque("torque", torque, fail_at))
            .connect("torque.tau", "wheel.tau").connect("wheel.omega", "torque.omega")
            .record("wheel.slip", "wheel.Fx").build())


def test_runs_side_by_side_give_each_runs_results_in_order_with_the_blocks_state(fmus):
    torques = (30.0, 10.0, 20.0)
    alone = Campaign("test", len(torques)).run_all({f"t{k}": wheel(fmus, k) for k in torques}, workers=1)
    campaign = Campaign("test", len(torques))
    progress: list[float] = []
    campaign.stages.progress = progress.append
    together = campaign.run_all({f"t{k}": wheel(fmus, k) for k in torques}, workers=2)
    assert list(together) == list(campaign.walls) == list(campaign.ran) == [f"t{k}" for k in torques]
    for key in together:
        pd.testing.assert_frame_equal(together[key].data, alone[key].data, check_exact=True)
    assert together["t30.0"].data["wheel.slip"].iloc[-1] != together["t10.0"].data["wheel.slip"].iloc[-1]
    # the block that ran is the worker's: its state came back
    blocks = [next(b.block for b in system.blocks) for system in campaign.ran.values()]
    assert all(isinstance(block, CountingTorque) and block.steps == 200 for block in blocks)
    assert sorted(progress)[-1] == 1.0 and len(progress) == len(torques)


def test_a_system_that_cannot_travel_to_a_worker_runs_here_and_the_order_is_kept(fmus):
    systems = {f"t{k}": wheel(fmus, k) for k in (10.0, 20.0, 30.0)}
    local = next(b.block for b in systems["t20.0"].blocks)
    assert isinstance(local, CountingTorque)
    local.hook = lambda: None  # type: ignore[attr-defined]  # a local function: it does not pickle
    campaign = Campaign("test", 3)
    together = campaign.run_all(systems, workers=2)
    assert list(together) == list(campaign.ran) == list(campaign.systems) == list(systems)
    assert campaign.ran["t20.0"] is systems["t20.0"] and local.steps == 200  # it ran here, on this block
    assert campaign.ran["t10.0"] is not systems["t10.0"]  # it ran in a worker
    alone = Campaign("test", 3).run_all({f"t{k}": wheel(fmus, k) for k in (10.0, 20.0, 30.0)}, workers=1)
    for key in systems:
        pd.testing.assert_frame_equal(together[key].data, alone[key].data, check_exact=True)


def test_a_failing_run_among_others_fails_the_job_naming_its_error_and_leaves_no_worker(fmus):
    systems = {"fine": wheel(fmus, 10.0), "failing": wheel(fmus, 20.0, fail_at=0.1), "other": wheel(fmus, 30.0)}
    with pytest.raises(RunError, match=r"torque \(block\): step at t = 0.1 s failed: ArithmeticError: torque "
                                       r"block gave up"):
        Campaign("test", 3).run_all(systems, workers=2)
    assert multiprocessing.active_children() == []


def test_figures_drawn_side_by_side_are_the_figures_drawn_one_after_the_other():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from rover_cosim.common.figures import drawn
    from rover_cosim.identification.figures import png_bytes

    def figure(k: int) -> bytes:
        fig, ax = plt.subplots(figsize=(3, 2))
        ax.plot(np.arange(10), np.arange(10) ** k, label=f"x^{k}")
        ax.set_xlabel("x [1]")
        ax.legend()
        return png_bytes(fig)

    figures = {f"f{k}.png": (lambda k=k: figure(k)) for k in range(3)}
    assert drawn(figures, workers=2) == drawn(figures, workers=1)
    assert list(drawn(figures, workers=2)) == list(figures)
    assert multiprocessing.active_children() == []


def test_the_longest_runs_go_to_the_workers_first_and_the_results_keep_the_systems_order(fmus, monkeypatch):
    from rover_cosim.jobs import campaign as campaign_module

    dispatched: list[str] = []
    real = campaign_module.parallel_map

    def spy(function, arguments, *args, **kwargs):
        dispatched.extend(key for key, _ in arguments)
        return real(function, arguments, *args, **kwargs)

    monkeypatch.setattr(campaign_module, "parallel_map", spy)
    systems = {f"t{k}": wheel(fmus, k) for k in (10.0, 20.0, 30.0, 40.0)}
    campaign = Campaign("test", len(systems))
    together = campaign.run_all(systems, workers=2, longest=("t40.0", "t20.0"))
    assert dispatched == ["t40.0", "t20.0", "t10.0", "t30.0"]
    assert list(together) == list(campaign.ran) == list(campaign.systems) == list(systems)
    with pytest.raises(ValueError, match=r"longest runs \['t50.0'\]: not among the systems"):
        Campaign("test", 1).run_all(systems, workers=1, longest=("t50.0",))


def test_a_campaign_freezes_the_imported_heap_out_of_the_garbage_collector():
    import gc

    before = gc.get_freeze_count()
    made = [object() for _ in range(10)]  # tracked objects made since (lists are tracked)
    Campaign("test", 1)
    assert gc.get_freeze_count() > before and made
    gc.unfreeze()  # back for the other tests of this process
