"""Soil that varies (issue 35, item 2): each wheel on the soil under it.

The blend of two soils (``Soil.blend``, RigidWheel's ``soilShare``: the same law in numpy and in
the FMUs, exact at both ends), the FMUs' checks of the share, the soil map (``SoilMap``,
``soil_boundary``) and its participant, the controller that believes a soil map, and the
scenario that crosses from the paper's soil onto a softer one."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pytest
from fmpy import simulate_fmu

from rover_cosim.control.terrain_controller import TerrainPathController
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.jobs.ground import SoilBlock
from rover_cosim.jobs.terrain import SoilCrossingScenario, run_terrain, traverse_path
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.master import run
from rover_cosim.terramechanics import PlaneTerrain, Soil, Wheel, wheel_forces
from rover_cosim.terramechanics.library import choose, soil_parameters
from rover_cosim.terramechanics.terrain import SoilMap, soil_boundary

PAPER = Soil()
SOFT = choose(soil="hit_lss1").soil          # the scenario's second soil
WHEELS = range(1, 7)


# --- the blend and the map (no FMU) -------------------------------------------------------------------------

def test_a_blend_is_each_parameter_between_the_soils_and_exact_at_both_ends():
    assert PAPER.blend(SOFT, 0.0) == PAPER and PAPER.blend(SOFT, 1.0) == SOFT
    half = PAPER.blend(SOFT, 0.5)
    for field in dataclasses.fields(Soil):
        a, b, m = getattr(PAPER, field.name), getattr(SOFT, field.name), getattr(half, field.name)
        assert min(a, b) <= m <= max(a, b) and math.isclose(m, (a + b) / 2, rel_tol=1e-15), field.name


@pytest.mark.parametrize("share", [-0.1, 1.5, math.nan, "half"])
def test_a_share_outside_0_1_is_refused_naming_it(share):
    with pytest.raises(ValueError, match=r"share = .*expected a share of the other soil in \[0, 1\]"):
        PAPER.blend(SOFT, share)


def test_a_soil_boundary_rises_smoothly_from_one_soil_to_the_other():
    soil_map = soil_boundary(2.0, PAPER, SOFT, width=0.5)
    x = np.linspace(-5.0, 10.0, 3001)
    share = soil_map.share(x, np.full_like(x, 0.7))
    assert np.all(share[x <= 1.7] == 0.0) and np.all(share[x >= 2.3] == 1.0)     # each soil exactly
    assert np.all(np.diff(share) >= -1e-9) and 0.45 < float(soil_map.share(2.0, 0.0)) < 0.55
    assert np.abs(np.diff(share)).max() < 0.02                                     # no jump
    assert soil_map.soil_at(-3.0, 0.0) == PAPER and soil_map.soil_at(8.0, 0.0) == SOFT
    assert soil_map.share(100.0, -100.0) == 1.0                                     # beyond the grid: its edge


def test_a_soil_map_reads_back_what_it_wrote_and_refuses_a_bad_share(tmp_path):
    soil_map = soil_boundary(1.0, PAPER, SOFT)
    soil_map.write(tmp_path / "map.csv")
    again = SoilMap.read(tmp_path / "map.csv", PAPER, SOFT)
    points = np.random.default_rng(35).uniform(-6, 16, (2, 200))
    np.testing.assert_allclose(again.share(*points), soil_map.share(*points), rtol=0, atol=1e-9)  # 10 digits
    grid = soil_map.grid.heights.copy()
    grid[3, 4] = 1.5
    with pytest.raises(ValueError, match=r"share at grid point \(row 4, column 5\) is 1.5: expected a share"):
        SoilMap(soil_map.grid.x, soil_map.grid.y, grid, PAPER, SOFT)
    with pytest.raises(TypeError, match="soil_b = 'sand': expected a Soil"):
        SoilMap(soil_map.grid.x, soil_map.grid.y, soil_map.grid.heights, PAPER, "sand")  # type: ignore[arg-type]


def test_the_soil_participant_gives_each_wheel_the_share_under_its_hub():
    """The body at x = 1.0 m heading along +x over a boundary at 2.5 m: the front hubs (1.5 m ahead,
    at 2.5 m) on the blend's midpoint, the middle and rear hubs on the first soil; turned round,
    the rear hubs are there instead."""
    block = SoilBlock("soil", soil_boundary(2.5, PAPER, SOFT, width=0.5))
    shares = block.start(0.0, np.array([1.0, 0.0, 0.0]))
    np.testing.assert_allclose(shares[[0, 3]], 0.5, atol=1e-3)
    assert np.all(shares[[1, 2, 4, 5]] == 0.0)
    turned = block.step(0.0, 1e-3, np.array([1.0, 0.0, math.pi]))
    assert np.all(turned[[0, 1, 3, 4]] == 0.0)
    np.testing.assert_allclose(turned[[2, 5]], 0.5, atol=1e-3)
    assert block.outputs == tuple(f"soilShare[{i}]" for i in WHEELS)


# --- the FMUs -----------------------------------------------------------------------------------------------

def _wheel_run(fmu, start: dict, share: float) -> np.ndarray:
    names = ["tau", "W", "v_hub", "v_lat", "soilShare"]
    values = [30.0, 424.0, 0.5, 0.02, share]
    signal = np.array([(0.0, *values), (1.0, *values)], dtype=[("time", float)] + [(n, float) for n in names])
    return simulate_fmu(str(fmu), stop_time=1.0, step_size=1e-3, output_interval=0.01, input=signal,
                        start_values={"omega": 0.5 / 0.355, **start}, fmi_type="CoSimulation",
                        output=["Fx", "Fy", "Fz", "Tx", "slip", "sinkage", "omega"])


def test_the_wheel_fmu_on_a_share_is_the_wheel_fmu_on_the_blended_soil(fmus):
    """Wheel.fmu with soil, soilB and soilShare s gives what it gives on Soil.blend(soil, soilB, s)
    alone (the blend is the same law; it moved the wheel's sinkage by far more than the tolerance);
    at s = 1 soilB is the soil, bit for bit."""
    both = {**soil_parameters(PAPER), **soil_parameters(SOFT, "soilB")}
    for share in (0.3, 0.7):
        blended = _wheel_run(fmus["Wheel"], both, share)
        alone = _wheel_run(fmus["Wheel"], soil_parameters(PAPER.blend(SOFT, share)), 0.0)
        for name in ("Fx", "Fy", "Fz", "Tx", "slip", "sinkage", "omega"):
            np.testing.assert_allclose(blended[name], alone[name], rtol=1e-12, atol=1e-12, err_msg=name)
    paper = _wheel_run(fmus["Wheel"], soil_parameters(PAPER), 0.0)
    assert abs(blended["sinkage"][-1] - paper["sinkage"][-1]) > 1e-3
    on_b = _wheel_run(fmus["Wheel"], both, 1.0)
    soft = _wheel_run(fmus["Wheel"], soil_parameters(SOFT), 0.0)
    for name in ("Fx", "Fy", "sinkage", "omega"):
        np.testing.assert_array_equal(on_b[name], soft[name], err_msg=name)


def test_a_wheel_entering_a_soil_whose_destructive_angle_is_given_blends_it_as_the_reference_does(fmus):
    """The FMU's own soil with its destructive angle from phi (xc = 0, the default) and the second
    soil's given: a wheel that has just entered the second soil (shares 1e-12 .. 1e-3) gives what it
    gives on Soil.blend alone, whose xc blends the two resolved angles. The FMU blended the raw
    parameters: xc = s xc_B, an angle of almost 0 taken as given, and the sidewall force grew as
    1/s^3 (1.7e34 N at s = 1e-12): a SteerableRover driving onto HIT-LSS1 then failed its step."""
    soil_b = soil_parameters(SOFT, "soilB")
    assert soil_b["soilB.xc"] > 0
    for share in (1e-12, 1e-6, 1e-3):
        entering = _wheel_run(fmus["Wheel"], soil_b, share)
        alone = _wheel_run(fmus["Wheel"], soil_parameters(PAPER.blend(SOFT, share)), 0.0)
        for name in ("Fx", "Fy", "Fz", "Tx", "slip", "sinkage", "omega"):
            np.testing.assert_allclose(entering[name], alone[name], rtol=1e-12, atol=1e-12, err_msg=f"{name}, {share}")


def test_the_reference_wheel_on_the_blended_soil_gives_the_wheel_fmus_forces(fmus):
    """Cross-check against the numpy reference: Wheel.fmu on a share s of HIT-LSS1 gives, at its own
    spin and the hub's velocity, terramechanics.wheel_forces on Soil.blend(paper, HIT-LSS1, s):
    Fx, Fy, Tx within 1e-6 of the largest and the sinkage within 1e-6 relative (the sinkage solve's
    tolerance); at s = 0.5 the forces differ from the paper soil's by far more."""
    both = {**soil_parameters(PAPER), **soil_parameters(SOFT, "soilB")}
    for share in (0.25, 0.5, 0.9):
        run = _wheel_run(fmus["Wheel"], both, share)
        blended = PAPER.blend(SOFT, share)
        expected = wheel_forces(424.0, run["omega"], 0.5, Wheel(), blended, v_lateral=0.02)
        for name, ours in (("Fx", "Fx"), ("Fy", "Fy"), ("Tx", "Tx")):
            scale = np.abs(getattr(expected, name)).max()
            assert np.abs(run[ours] - getattr(expected, name)).max() <= 1e-6 * scale, (name, share)
        np.testing.assert_allclose(run["sinkage"], expected.sinkage, rtol=1e-6)
    paper = wheel_forces(424.0, run["omega"], 0.5, Wheel(), PAPER, v_lateral=0.02)
    assert np.abs(_wheel_run(fmus["Wheel"], both, 0.5)["sinkage"] - paper.sinkage).min() > 1e-3


def test_on_a_blend_reverse_mirrors_forward(fmus):
    """Half on each soil, driven backwards (torque, hub speeds and spin negated) the wheel gives the
    forces of the forward run mirrored (Fx, Tx, Fy, the spin and the signed slip negated, as on one
    soil: tests/test_fmu_regimes.py) and sinks as deep."""
    both = {**soil_parameters(PAPER), **soil_parameters(SOFT, "soilB")}
    names = ["tau", "W", "v_hub", "v_lat", "soilShare"]
    runs = []
    for sign in (1.0, -1.0):
        values = [sign * 30.0, 424.0, sign * 0.5, sign * 0.02, 0.5]
        signal = np.array([(0.0, *values), (1.0, *values)], dtype=[("time", float)] + [(n, float) for n in names])
        runs.append(simulate_fmu(str(fmus["Wheel"]), stop_time=1.0, step_size=1e-3, output_interval=0.01,
                                 input=signal, start_values={"omega": sign * 0.5 / 0.355, **both},
                                 fmi_type="CoSimulation", output=["Fx", "Fy", "Tx", "slip", "sinkage", "omega"]))
    forward, backward = runs
    for name, sign in (("Fx", -1.0), ("Fy", -1.0), ("Tx", -1.0), ("omega", -1.0), ("slip", -1.0), ("sinkage", 1.0)):
        scale = np.abs(forward[name]).max()
        np.testing.assert_allclose(backward[name], sign * forward[name], rtol=0, atol=1e-9 * scale, err_msg=name)
    assert np.abs(forward["Fx"]).max() > 10.0


def test_at_rest_on_a_blend_the_wheel_stays_at_rest(fmus):
    """No torque, no hub motion, a load, half on each soil: the wheel does not start to spin and
    the soil pushes it nowhere (the static regime on the blended soil)."""
    names = ["tau", "W", "v_hub", "v_lat", "soilShare"]
    values = [0.0, 424.0, 0.0, 0.0, 0.5]
    signal = np.array([(0.0, *values), (1.0, *values)], dtype=[("time", float)] + [(n, float) for n in names])
    run = simulate_fmu(str(fmus["Wheel"]), stop_time=1.0, step_size=1e-3, output_interval=0.01, input=signal,
                       start_values={**soil_parameters(PAPER), **soil_parameters(SOFT, "soilB")},
                       fmi_type="CoSimulation", output=["omega", "Fx", "Fy", "sinkage"])
    assert np.abs(run["omega"]).max() == 0.0 and np.abs(run["Fx"]).max() == 0.0 and np.abs(run["Fy"]).max() == 0.0
    assert run["sinkage"].min() > 0.005


def test_energy_is_never_created_driving_across_a_soil_boundary(fmus):
    """The rover driving and turning from the paper's soil onto HIT-LSS1 (the shares given by the soil
    participant, every wheel crossing): what the soil and the limb dampers take out never falls
    (beyond 0.1 % of the energy that changed hands): a change of soil under a wheel creates none."""
    from test_terrain import TURN, _energy

    builder = SystemBuilder("across a boundary").simulation(stop_time=6.0, step=1e-3, algorithm="gauss-seidel")
    start = {"v": 0.6, **{f"omega[{i}]": 0.6 / Wheel().r for i in WHEELS},
             **{f"tau[{i}]": 25.0 for i in WHEELS}, **{f"steer[{i}]": TURN[i] for i in WHEELS},
             **soil_parameters(SOFT, "soilB")}
    builder.add_fmu("rover", fmus["SteerableRover"], start=start)
    builder.add_block("soil", SoilBlock("soil", soil_boundary(1.8, PAPER, SOFT, width=0.5)))
    for name in ("x", "y", "yaw"):
        builder.connect(f"rover.{name}", f"soil.{name}")
    for i in WHEELS:
        builder.connect(f"soil.soilShare[{i}]", f"rover.soilShare[{i}]")
    names = ("x", "y", "v", "vy", "yawRate", "body.w", "body.p", "body.q", "body.z",
             *[f"{n}[{i}]" for n in ("omega", "body.deflection", "body.tau", "body.steer") for i in WHEELS])
    builder.record(*[f"rover.{n}" for n in names], *[f"soil.soilShare[{i}]" for i in WHEELS])
    data = run(builder.simulation(order=["rover", "soil"]).build()).data
    table = {"time": data["time"].to_numpy(), **{n: data[f"rover.{n}"].to_numpy() for n in names}}
    energy, work = _energy(table, PlaneTerrain())
    dissipated = work - (energy - energy[0])
    scale = max(np.abs(energy - energy[0]).max(), np.abs(work).max())
    shares = data[[f"soil.soilShare[{i}]" for i in WHEELS]].to_numpy()
    assert scale > 100.0 and shares[0].max() == 0.0 and shares[-1].min() == 1.0   # every wheel crossed
    assert dissipated.min() > -1e-3 * scale
    assert np.diff(dissipated).min() > -1e-3 * scale


@pytest.mark.parametrize("model, variable", [("Wheel", "soilShare"), ("SteerableRover", "soilShare[2]")])
def test_the_fmus_refuse_a_share_outside_0_1_naming_it(fmus, model: str, variable: str):
    from test_fmu_regimes import logged_messages

    text = logged_messages(fmus[model], {variable: 1.25})
    assert "soilShare" in text and "[0, 1]" in text, text


@pytest.mark.parametrize("model", ["Wheel", "SteerableRover"])
def test_the_fmus_refuse_a_bad_second_soil_naming_it(fmus, model: str):
    from test_fmu_regimes import logged_messages

    text = logged_messages(fmus[model], {"soilB.kphi": -5.0})
    assert "soilB.kphi" in text and "-5" in text and "must" in text, text


# --- the controller -----------------------------------------------------------------------------------------

def _other_models(models: ModelSet) -> ModelSet:
    """The identified models with a soil that gives 20 % less force at every slip and 30 % less
    lateral force at every slip angle: a second soil for the controller's belief."""
    longitudinal = models.model()
    assert models.lateral is not None
    weaker = dataclasses.replace(longitudinal, fx_coefficients=0.8 * np.asarray(longitudinal.fx_coefficients))
    lateral = dataclasses.replace(models.lateral, coefficients=0.7 * np.asarray(models.lateral.coefficients))
    return ModelSet(models.recommended, {models.recommended: weaker}, lateral, {}, source="weaker")


def _steps(block, inputs: np.ndarray) -> np.ndarray:
    rows = [block.start(0.0, inputs[0])]
    rows += [block.step(k * 1e-3, 1e-3, u) for k, u in enumerate(inputs[1:])]
    return np.array(rows)


def _inputs(count: int) -> np.ndarray:
    """A body moving along +x at about 0.3 m/s, the loads and slip angles wandering."""
    rng = np.random.default_rng(7)
    rows = []
    for k in range(count):
        x = 0.3 * k * 1e-3 + 0.01 * rng.standard_normal()
        rows.append([x, 0.01 * rng.standard_normal(), 0.01 * rng.standard_normal(), 0.3, 0.0, 0.0,
                     *rng.uniform(300, 550, 6), *rng.uniform(-0.05, 0.05, 6)])
    return np.array(rows)


def test_the_controller_believing_a_map_is_on_each_soil_the_controller_of_that_soil(identified):
    """A map of the first soil everywhere: outputs bit for bit those of the controller without a
    map; of the second soil everywhere: those of the controller identified on the second soil; a
    boundary under the rover: between them, and not equal to either."""
    models = ModelSet.read(identified.files[0].parent / "model.json")
    weaker = _other_models(models)
    terrain, path = PlaneTerrain.side_slope(10.0), traverse_path(6.0)
    options: dict[str, Any] = dict(path=path, v_target=0.3, terrain=terrain, step=1e-3)
    inputs = _inputs(300)
    plain = _steps(TerrainPathController("a", models, **options), inputs)
    on_b = _steps(TerrainPathController("b", weaker, **options), inputs)
    everywhere = {"first": 0.0, "second": 1.0}
    results = {}
    for name, share in everywhere.items():
        grid = np.full((4, 4), share)
        soil_map = SoilMap([-10, 0, 10, 20], [-10, -5, 5, 10], grid, PAPER, SOFT)
        results[name] = _steps(TerrainPathController(name, models, soil_map=soil_map, model_b=weaker, **options),
                               inputs)
    np.testing.assert_array_equal(results["first"], plain)
    np.testing.assert_array_equal(results["second"][:, :24], on_b[:, :24])        # torques, steering, demands
    across = _steps(TerrainPathController("x", models, soil_map=soil_boundary(0.0, PAPER, SOFT, width=1.0),
                                          model_b=weaker, **options), inputs)
    torques = slice(0, 6)
    front, rear = across[-1, [0, 3]], across[-1, [2, 5]]
    assert not np.array_equal(across[:, torques], plain[:, torques])
    np.testing.assert_array_equal(rear, plain[-1, [2, 5]])                        # behind the boundary
    assert np.all(np.abs(front - on_b[-1, [0, 3]]) < np.abs(plain[-1, [0, 3]] - on_b[-1, [0, 3]]) + 1e-12)


def test_the_controller_needs_both_the_map_and_the_second_soils_models(identified):
    models = ModelSet.read(identified.files[0].parent / "model.json")
    with pytest.raises(ValueError, match="expected both"):
        TerrainPathController("c", models, soil_map=soil_boundary(0.0, PAPER, SOFT))
    with pytest.raises(ValueError, match="expected both"):
        TerrainPathController("c", models, model_b=models)


# --- the scenario -------------------------------------------------------------------------------------------

def test_crossing_onto_a_softer_soil_the_controller_that_believes_the_map_holds_the_path(fmu_dir, identified,
                                                                                          tmp_path):
    """The soil crossing, shortened (3.5 m at 0.3 m/s on the 10 deg side slope, the boundary at
    2 m: the front wheels cross it at x = 0.5 m, the middle ones at 2 m): believing the map, the
    controller keeps the rover within 3 cm of the path; with the paper soil's models everywhere it
    drifts downhill, five times further; the co-simulated rover agrees with the monolithic one as
    on the level; the front wheels sink less on HIT-LSS1 (stiffer in pressure-sinkage) and need a
    larger slip angle (weaker in shear); the map and the second soil's models are written beside
    the results, with their record."""
    short = SoilCrossingScenario(length=3.5, boundary=2.0)
    result = run_terrain(fmu_dir, identified.files[0].parent / "model.json", tmp_path, scenarios=("soil_crossing",),
                         crossing=short)
    rows = result.metrics.set_index("run")
    assert set(rows.index) == {"inverse", "cosim", "unaware"}
    assert rows.loc["inverse", "cross_track_max_m"] < 0.03
    assert rows.loc["unaware", "cross_track_max_m"] > 5 * rows.loc["inverse", "cross_track_max_m"]
    assert result.tables["soil_crossing", "unaware"]["cross_track"].min() < -0.05    # downhill (right)
    agreement = result.agreement.set_index("scenario").loc["soil_crossing"]
    assert agreement["speed_max_difference_percent"] < 1.0 and agreement["load_max_difference_percent"] < 2.0
    assert agreement["path_max_difference_m"] < 0.01
    table = result.tables["soil_crossing", "inverse"]
    before, after = table[table["x"] < 0.2], table[table["x"] > 1.0]               # front wheels: paper, soft
    for i in (1, 4):
        assert after[f"sinkage_{i}"].mean() < 0.8 * before[f"sinkage_{i}"].mean()
        assert after[f"slipAngle_{i}"].abs().mean() > 1.2 * before[f"slipAngle_{i}"].abs().mean()
    soil_map = SoilMap.read(tmp_path / "terrain_soil_crossing_soilmap.csv", PAPER, SOFT)
    assert soil_map.share(1.7, 0.0) == 0.0 and soil_map.share(2.3, 0.0) == 1.0
    model_b = ModelSet.read(tmp_path / "terrain_soil_crossing_model_b.json")
    assert model_b.lateral is not None and model_b.details["soil"]["c"] == SOFT.c
    scenario = result.record["parameters"]["scenarios"]["soil_crossing"]
    assert scenario["soil_crossing"]["soil_b"] == "hit_lss1" and scenario["side_slope_deg"] == 10.0
    assert len(result.record["soil_crossing_model_b_sha256"]) == 64


def test_the_crossings_controller_believes_the_soil_estimated_from_test_bed_data(fmu_dir, identified, tmp_path):
    """The soil-estimation issue's route into the crossing: HIT-LSS1 measured on a test bed (1 %
    noise), its soil estimated from the paper's (``rover-cosim estimate-soil``'s soil.toml), and the
    controller believing that soil beyond the boundary: its second soil's models identified on the
    estimate (recorded), the rover held on the path as with the true soil (within 3 cm), and the
    command line offering it."""
    import subprocess
    import sys

    from rover_cosim.jobs.estimate_soil import run_estimate_soil, write_testbed_data

    write_testbed_data(tmp_path / "bed.csv", choose(soil="hit_lss1"), slip_angles_deg=(0.0, 5.0, 10.0),
                       noise=0.01, seed=35)
    estimate = run_estimate_soil(tmp_path / "bed.csv", tmp_path / "estimate")
    believed = tmp_path / "estimate" / "soil.toml"
    short = SoilCrossingScenario(length=3.5, boundary=2.0, believed_soil_b=str(believed))
    result = run_terrain(fmu_dir, identified.files[0].parent / "model.json", tmp_path / "run",
                         scenarios=("soil_crossing",), runs=("inverse",), crossing=short)
    assert result.metrics.set_index("run").loc["inverse", "cross_track_max_m"] < 0.03
    record = result.record["parameters"]["scenarios"]["soil_crossing"]["soil_crossing"]
    assert record["believed_soil_b"] == str(believed)
    assert record["believed_soil_b_values"]["c"] == pytest.approx(estimate.estimate.soil.c, rel=1e-12)
    assert record["believed_soil_b_values"]["c"] != SOFT.c          # an estimate, not the truth
    model_b = ModelSet.read(tmp_path / "run" / "terrain_soil_crossing_model_b.json")
    assert model_b.details["soil"]["c"] == record["believed_soil_b_values"]["c"]
    done = subprocess.run([sys.executable, "-P", "-m", "rover_cosim", "simulate", "--only", "terrain", "--out",
                           str(tmp_path / "cli"), "--fmu-dir", str(fmu_dir), "--model",
                           str(identified.files[0].parent / "model.json"), "--crossing-belief", "no_such_soil"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "--crossing-belief" in done.stderr and "no_such_soil" in done.stderr
    assert "Traceback" not in done.stderr and not (tmp_path / "cli" / "terrain.json").exists()
