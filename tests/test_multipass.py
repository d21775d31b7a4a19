"""The rut participant (issue 48, multi-pass): RutMap's memory, RutBlock on Rover.fmu, and the
straight-run ablation of every wheel effect (``simulate --only effects``)."""

from __future__ import annotations

import numpy as np
import pytest

from rover_cosim.jobs.ruts import RutBlock
from rover_cosim.terramechanics.multipass import RutMap


def test_a_wheel_meets_the_rut_another_left_and_never_its_own():
    ruts = RutMap(2, cell=0.02)
    ruts.stamp(np.array([1.0, 0.0]), np.array([0.0, 0.0]), np.array([0.024, 0.0]), half_width=0.09)
    assert ruts.depths(np.array([1.0, 1.0]), np.array([0.0, 0.05])).tolist() == [0.0, 0.024]
    assert ruts.depths(np.array([5.0, 5.0]), np.zeros(2)).tolist() == [0.0, 0.0]  # virgin soil elsewhere
    assert ruts.depths(np.array([1.0, 1.0]), np.array([0.0, 0.2]))[1] == 0.0  # beside the track
    ruts.stamp(np.array([1.0, 1.0]), np.zeros(2), np.array([0.01, 0.03]), half_width=0.09)
    assert ruts.depths(np.array([1.0, 1.0]), np.zeros(2)).tolist() == [0.03, 0.024]  # the deepest stays
    with pytest.raises(ValueError, match="wheels"):
        RutMap(0)


def test_the_block_gives_the_rear_wheels_the_front_wheels_rut_one_step_late():
    block = RutBlock("ruts", (1.5, 0.0, -1.5), 1.5, 0.175)
    assert block.feedthrough is False and block.inputs[0] == "x" and len(block.outputs) == 6
    sinkage = np.array([0.024, 0.025, 0.026, 0.024, 0.025, 0.026])
    assert np.all(block.start(0.0, np.array([0.0, *sinkage]), 1e-3) == 0.0)
    for x in np.arange(0.0, 1.6, 0.001):  # the front wheels roll over the middle ones' place
        out = block.step(float(x), 1e-3, np.array([float(x), *sinkage]))
    np.testing.assert_allclose(out[[1, 4]], 0.024)  # middle wheels in the front ones' rut
    np.testing.assert_allclose(out[[2, 5]], 0.025)  # rear wheels in the middle ones'
    np.testing.assert_allclose(out[[0, 3]], 0.0)  # the front wheels on virgin soil
    state = block.get_state()
    block.set_state({})
    assert np.all(block.step(1.6, 1e-3, np.array([1.6, *sinkage]))[[1, 4]] == 0.0)
    block.set_state(state)
    assert np.all(block.step(1.6, 1e-3, np.array([1.6, *sinkage]))[[1, 4]] > 0.0)


def test_the_effects_ablation_runs_and_the_rear_wheels_sink_deeper_in_the_ruts(fmus, identified, results_root,
                                                                               tmp_path):
    import pandas as pd

    from rover_cosim.jobs.effects import VARIANTS, run_effects

    result = run_effects(fmus["Rover"].parent, results_root / "identification" / "model.json", tmp_path)
    ablation = pd.read_csv(tmp_path / "effects_ablation.csv")
    assert list(ablation["variant"].unique()) == list(VARIANTS)
    sinkage = result.sinkage.set_index("wheel")
    # the paper's smooth wheel: the straight run's Table 3 figures (below 1 N), wheels 4-6 mirror 1-3
    smooth = ablation[ablation["variant"] == "smooth"].set_index("wheel")
    assert (smooth["rms_N"] < 1.0).all()
    np.testing.assert_allclose(smooth.loc[[4, 5, 6], "rms_N"].to_numpy(), smooth.loc[[1, 2, 3], "rms_N"].to_numpy())
    # multi-pass: each wheel deeper than the one ahead, by less each time; the front one on virgin soil
    ruts = sinkage["sinkage_multi_pass_m"]
    assert ruts[1] == pytest.approx(sinkage.loc[1, "sinkage_smooth_m"], rel=0.02)
    assert ruts[3] > ruts[2] > ruts[1] and ruts[3] - ruts[2] < ruts[2] - ruts[1]
    # slip-sinkage sinks every wheel at least as deep; grousers change the pull, hence the model's error
    assert (sinkage["sinkage_slip_sinkage_m"] >= sinkage["sinkage_smooth_m"]).all()
    grousers = ablation[ablation["variant"] == "grousers"].set_index("wheel")
    assert (grousers["rms_N"] > smooth["rms_N"]).all()
    assert {p.name for p in result.files} == {"effects_ablation.csv", "effects_sinkage.csv", "effects_trends.png",
                                              "effects.json"}
    assert result.record["parameters"]["variants"]["grousers"]["wheel"]["grouser_count"] == 24.0
