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
    # a new run starts on virgin soil (the block of a system run twice forgets the first run's ruts)
    assert np.all(block.start(0.0, np.array([1.6, *sinkage]), 1e-3) == 0.0) and len(block.map.get_state()) > 0


@pytest.mark.parametrize(("planar", "x_limb"), [(False, (1.5, 0.0, -1.5)), (True, (1.5, 0.0, -1.5)),
                                               (True, (0.6, -0.6)), (False, (0.0,))])
def test_the_rut_blocks_c_twin_gives_its_outputs_bit_for_bit(planar, x_limb):
    """From a map the Python block already marked, random walks of the rover with random sinkages (some
    zero, some NaN: not marked) over more cells than the twin's first table holds: the same rut
    depths at every step; a pose on no cell (NaN) is an error in both, the twin's naming the wheel."""
    from test_native_blocks import Twin

    rng = np.random.default_rng(48)
    block = RutBlock("ruts", x_limb, 0.4, 0.175, planar=planar)
    wheels = block.wheels

    def inputs(k: int) -> np.ndarray:
        pose = [0.004 * k, 0.3 * np.sin(0.002 * k), 0.002 * k] if planar else [0.004 * k]
        sinkage = rng.uniform(-0.005, 0.05, wheels)
        sinkage[rng.uniform(size=wheels) < 0.05] = np.nan
        return np.array([*pose, *sinkage])

    block.start(0.0, inputs(0))
    for k in range(1, 200):
        block.step(0.0, 1e-3, inputs(k))
    twin = Twin(block, "rut")  # type: ignore[arg-type]
    for k in range(200, 3200):
        u = inputs(k)
        assert np.array_equal(block.step(0.0, 1e-3, u), twin.step(0.0, 1e-3, u)), f"step {k}"
    assert len(block.map.get_state()) > 1024  # the twin's table grew
    bad = inputs(0)
    bad[0] = np.nan
    with pytest.raises(ValueError):
        block.step(0.0, 1e-3, bad)
    with pytest.raises(ValueError, match="wheel 1's hub at .* is on no cell"):
        twin.step(0.0, 1e-3, bad)
    twin.made.close()


def test_a_run_with_ruts_steps_natively_and_gives_the_python_runs_numbers_bit_for_bit(fmus, identified,
                                                                                      results_root, monkeypatch):
    """``simulate --ruts``'s monolithic run: with the rut block's C twin every participant steps
    natively, and the trajectories are those of the run stepped in Python, to the bit (6 s: 1.6 m on, the
    middle wheels in the front ones' rut). The same system runs twice: the second starts on virgin soil."""
    import pandas as pd

    from rover_cosim.jobs.simulate import monolithic_system
    from rover_cosim.orchestrator import master
    from rover_cosim.orchestrator.builder import replace_settings

    stepped_natively: list[bool] = []
    made = master.make_execution

    def execution(*args: object) -> object:
        made_now = made(*args)  # type: ignore[arg-type]
        stepped_natively.append(made_now.all_native)
        return made_now

    monkeypatch.setattr(master, "make_execution", execution)
    system = monolithic_system(fmus["Rover"].parent, results_root / "identification" / "model.json", ruts=True)
    runs = {native: master.run(replace_settings(system, stop_time=6.0, native=native)) for native in (False, True)}
    assert stepped_natively == [False, True]
    assert runs[True].data["ruts.rutDepth[2]"].iloc[-1] > 0.02  # the middle wheels in the front ones' rut
    pd.testing.assert_frame_equal(runs[False].data, runs[True].data, check_exact=True)


def test_the_effects_ablation_runs_and_the_rear_wheels_sink_deeper_in_the_ruts(fmus, identified, results_root,
                                                                               tmp_path):
    import pandas as pd

    from rover_cosim.identification.model_set import ModelSet
    from rover_cosim.jobs.effects import GIVEN_MODEL, OWN_MODEL, VARIANTS, run_effects

    result = run_effects(fmus["Rover"].parent, results_root / "identification" / "model.json", tmp_path,
                         straight=3.0)  # the turn's straights shortened from 10 m
    ablation = pd.read_csv(tmp_path / "effects_ablation.csv")
    assert list(ablation["variant"].unique()) == list(VARIANTS)
    by_model = {label: ablation[ablation["model"] == label] for label in (GIVEN_MODEL, OWN_MODEL)}
    reidentified = ["grousers", "slip_sinkage"]  # the paper's model is the smooth wheel's: its own elsewhere
    assert list(by_model[OWN_MODEL]["variant"].unique()) == reidentified
    sinkage = result.sinkage.set_index("wheel")
    # the paper's smooth wheel: the straight run's Table 3 figures (below 1 N), wheels 4-6 mirror 1-3
    smooth = by_model[GIVEN_MODEL][by_model[GIVEN_MODEL]["variant"] == "smooth"].set_index("wheel")
    assert (smooth["rms_N"] < 1.0).all()
    np.testing.assert_allclose(smooth.loc[[4, 5, 6], "rms_N"].to_numpy(), smooth.loc[[1, 2, 3], "rms_N"].to_numpy())
    # multi-pass: each wheel deeper than the one ahead, by less each time; the front one on virgin soil
    ruts = sinkage["sinkage_multi_pass_m"]
    assert ruts[1] == pytest.approx(sinkage.loc[1, "sinkage_smooth_m"], rel=0.02)
    assert ruts[3] > ruts[2] > ruts[1] and ruts[3] - ruts[2] < ruts[2] - ruts[1]
    # slip-sinkage sinks every wheel at least as deep; grousers change the pull, hence the model's error
    assert (sinkage["sinkage_slip_sinkage_m"] >= sinkage["sinkage_smooth_m"]).all()
    for variant in reidentified:
        unaware = by_model[GIVEN_MODEL][by_model[GIVEN_MODEL]["variant"] == variant].set_index("wheel")
        aware = by_model[OWN_MODEL][by_model[OWN_MODEL]["variant"] == variant].set_index("wheel")
        assert (unaware["rms_N"] > smooth["rms_N"]).all(), variant
        # the model identified with the effect controls better than the smooth wheel's
        assert (aware["rms_N"] < unaware["rms_N"]).all(), variant
    # Table 1: the smooth row is `identify`'s Table 1 (the same sweep, fits and staircase); with an effect
    # on, the smooth wheel's model fits worse than the one identified with it
    fits = result.table1.set_index(["variant", "load_N"])
    paper = pd.read_csv(results_root / "identification" / "fit_table.csv").set_index("load_N")["fit_percent"]
    np.testing.assert_allclose(fits.loc["smooth", f"fit_percent_{GIVEN_MODEL}"].to_numpy(), paper.to_numpy(),
                               atol=1e-3)
    for variant in reidentified:
        assert (fits.loc[variant, f"fit_percent_{OWN_MODEL}"] > fits.loc[variant, f"fit_percent_{GIVEN_MODEL}"]).all()
    assert {p.name for p in result.files} == {"effects_ablation.csv", "effects_sinkage.csv", "effects_trends.png",
                                              "effects.json", "effects_table1.csv", "effects_model_grousers.json",
                                              "effects_model_slip_sinkage.json", "effects_path_sinkage.csv"}
    # the turn: on the straight the middle and rear wheels run in ruts and sink deeper, the front ones not;
    # on the arc the middle wheels leave the front wheels' tracks in part: a shallower rut under them
    turn = result.path_sinkage.set_index(["phase", "wheel"])
    straight = turn.loc["straight"]
    assert straight.loc[1, "rut_depth_m"] == 0.0 and (straight.loc[[2, 5], "rut_depth_m"] > 0.01).all()
    assert (straight.loc[[2, 5], "sinkage_ruts_m"] > straight.loc[[2, 5], "sinkage_virgin_m"] + 2e-3).all()
    assert (turn.loc["arc"].loc[[2, 5], "rut_depth_m"] < 0.5 * straight.loc[[2, 5], "rut_depth_m"]).all()
    reread = ModelSet.read(tmp_path / "effects_model_grousers.json")
    assert reread.details["wheel"]["values"]["grouser_count"] == 24.0
    assert result.record["parameters"]["variants"]["grousers"]["wheel"]["grouser_count"] == 24.0


def test_the_straight_run_with_ruts_agrees_on_both_plants(fmus, identified, results_root):
    """``simulate --ruts``: Rover.fmu and RoverBody + 6 Wheel, each with the rut block on its wheels'
    rutDepth inputs, give the same ruts and sinkage (two implementations of the same plant)."""
    import dataclasses

    from rover_cosim.jobs.simulate import cosim_system, monolithic_system
    from rover_cosim.orchestrator.master import run

    model = results_root / "identification" / "model.json"
    sinkage = {}
    for plant, build, wheel in (("monolithic", monolithic_system, "rover.sinkage[{}]"),
                                ("cosim", cosim_system, "wheel{}.sinkage")):
        system = dataclasses.replace(build(fmus["Rover"].parent, model, ruts=True), stop_time=10.0)
        data = run(system).data
        after = data[data["time"] >= 8.5]  # 3.8 m on: every wheel past the front wheels' start
        sinkage[plant] = np.array([after[wheel.format(i)].mean() for i in range(1, 7)])
        ruts = np.array([after[f"ruts.rutDepth[{i}]"].mean() for i in range(1, 7)])
        assert ruts[0] == 0.0 and ruts[1] > 0.02 and ruts[2] > ruts[1], plant
        assert sinkage[plant][2] > sinkage[plant][1] > sinkage[plant][0] + 2e-3, plant
    np.testing.assert_allclose(sinkage["cosim"], sinkage["monolithic"], rtol=2e-3)


def test_each_variant_has_its_effect_alone_on_the_chosen_wheel_made_smooth():
    """The ablation's variants on a grousered wheel and a soil with slip-sinkage (MSL's wheel): smooth
    and multi-pass without either, grousers with the wheel's own, slip-sinkage with the soil's own."""
    from dataclasses import replace

    from rover_cosim.jobs.effects import DEFAULT_GROUSERS, DEFAULT_N_SLIP, variant_choice
    from rover_cosim.terramechanics.library import choose

    msl = choose(wheel="msl")
    msl = replace(msl, soil=replace(msl.soil, n_slip=0.7))
    smooth = variant_choice(msl, "smooth")
    assert not smooth.wheel.grousered and smooth.soil.n_slip == 0 and smooth.wheel.r == msl.wheel.r
    assert variant_choice(msl, "multi_pass") == smooth
    grousers = variant_choice(msl, "grousers")
    assert (grousers.wheel.grouser_height, grousers.wheel.grouser_count) == (0.0075, 24.0)
    assert grousers.soil.n_slip == 0
    assert variant_choice(msl, "slip_sinkage").soil.n_slip == 0.7
    assert not variant_choice(msl, "slip_sinkage").wheel.grousered
    paper = choose()
    assert (variant_choice(paper, "grousers").wheel.grouser_height,
            variant_choice(paper, "grousers").wheel.grouser_count) == DEFAULT_GROUSERS
    assert variant_choice(paper, "slip_sinkage").soil.n_slip == DEFAULT_N_SLIP
