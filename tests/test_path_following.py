"""Path following with the identified longitudinal and lateral models: the path geometry, the
force allocation, the per-wheel inverse, and `make simulate`'s turn and lane change on the
monolithic and the co-simulated steerable rover, with the kinematic-steering ablation."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from rover_cosim.control.allocation import allocate, allocation_matrix
from rover_cosim.control.path import Arc, LaneChange, Line, Path, lane_change_path, turn_path
from rover_cosim.control.path_controller import PathFollowingController
from rover_cosim.jobs.path_following import SCENARIOS, PathResult, run_path_following

X_HUB = np.array([1.5, 0.0, -1.5, 1.5, 0.0, -1.5])
Y_HUB = np.array([1.5, 1.5, 1.5, -1.5, -1.5, -1.5])


def test_paths_have_the_scenarios_geometry():
    turn = turn_path()
    assert turn.length == pytest.approx(20.0 + 10.0 * math.pi / 2, abs=1e-9)
    assert (turn.x[-1], turn.y[-1]) == pytest.approx((20.0, 20.0), abs=1e-9)
    assert turn.heading[-1] == pytest.approx(math.pi / 2)
    on_arc = (turn.s > 10.5) & (turn.s < 25.0)
    np.testing.assert_allclose(turn.curvature[on_arc], 0.1)
    lane = lane_change_path()
    assert (lane.x[-1], lane.y[-1], lane.heading[-1]) == pytest.approx((35.0, 3.0, 0.0), abs=1e-6)
    assert np.abs(np.diff(lane.heading)).max() < 1e-3          # continuous heading
    assert lane.curvature.max() == pytest.approx(3.0 / 2 * (math.pi / 15) ** 2, rel=1e-3)


def test_locate_gives_the_signed_cross_track_error():
    path = Path((Line(10.0), Arc(10.0, math.pi / 2)))
    left = path.locate(5.0, 0.3)
    assert (left.s, left.cross_track, left.heading) == pytest.approx((5.0, 0.3, 0.0), abs=1e-9)
    # On the arc (centre (10, 10)), a point 0.2 m outside the turn lies to the path's right.
    angle = math.radians(30)
    point = (10 + 10.2 * math.sin(angle), 10 - 10.2 * math.cos(angle))
    where = path.locate(*point)
    assert where.cross_track == pytest.approx(-0.2, abs=1e-5)  # the arc's 1 cm chords: 1.3e-6 m
    assert where.s == pytest.approx(10 + 10 * angle, abs=1e-3)
    with pytest.raises(ValueError, match="radius"):
        Path((Arc(-1.0, 1.0),))
    with pytest.raises(ValueError, match="length"):
        Path((LaneChange(0.0, 3.0),))


def test_allocation_meets_the_demand_and_follows_the_loads():
    matrix = allocation_matrix(X_HUB, Y_HUB)
    loads = np.array([300.0, 400.0, 500.0, 350.0, 450.0, 550.0])
    demand = np.array([120.0, -40.0, 35.0])
    fx, fy = allocate(demand, matrix, loads)
    np.testing.assert_allclose(matrix @ np.concatenate([fx, fy]), demand, atol=1e-9)
    mirrored = np.array([300.0, 400.0, 500.0, 300.0, 400.0, 500.0])   # left and right alike
    pure = allocate(np.array([60.0, 0.0, 0.0]), matrix, mirrored)
    np.testing.assert_allclose(pure[0], 60.0 * mirrored / mirrored.sum(), rtol=1e-12)
    np.testing.assert_allclose(pure[1], 0.0, atol=1e-12)
    lifted = loads.copy()
    lifted[0] = 0.0
    assert allocate(demand, matrix, lifted)[0][0] == 0.0
    with pytest.raises(ValueError, match="at least two wheels"):
        allocate(demand, matrix, np.array([400.0, 0, 0, 0, 0, 0]))


def test_inverse_steering_gives_the_lateral_models_force(identified):
    """The steering found per wheel makes the identified lateral model give Fy_des at
    beta = gamma - delta (to 0.01 N), and (Fx_des, Fy_des) is the allocated force in the wheel frame."""
    model = identified.files[0].parent / "model.json"
    controller = PathFollowingController("ctrl", str(model))
    loads = np.array([380.0, 420.0, 470.0, 380.0, 420.0, 470.0])
    gamma = np.radians([1.0, 0.5, -1.0, 2.0, 0.0, -0.5])
    fx, fy = np.full(6, 12.0), np.array([30.0, -20.0, 50.0, 10.0, 0.0, -60.0])
    for _ in range(5):  # the controller warm-starts from its last steering, as it does step by step
        steer, fx_des, fy_des = controller._inverse_steering(loads, gamma, fx, fy)
        controller.steer = steer
    slips = controller.inverse.slips_for_forces(loads, fx_des)
    np.testing.assert_allclose(controller.lateral.fy(loads, gamma - steer, slips), fy_des, atol=0.01)
    np.testing.assert_allclose(fx_des * np.cos(steer) - fy_des * np.sin(steer), fx, atol=1e-9)
    assert np.all(np.sign(fy_des) == -np.sign(gamma - steer))   # Fy opposes the slip angle


def test_controller_refuses_unknown_paths_and_models_without_lateral_part(identified, tmp_path):
    model = identified.files[0].parent / "model.json"
    with pytest.raises(ValueError, match="path = 'circle'"):
        PathFollowingController("ctrl", str(model), path="circle")
    with pytest.raises(ValueError, match="steering = 'magic'"):
        PathFollowingController("ctrl", str(model), steering="magic")
    import json

    data = json.loads(model.read_text())
    del data["lateral"]
    (tmp_path / "model.json").write_text(json.dumps(data))
    with pytest.raises(ValueError, match="no lateral model"):
        PathFollowingController("ctrl", str(tmp_path / "model.json"))


#: m, the tests' straights before and after each path's curve (`make simulate`: 10 m).
STRAIGHT = 3.0


@pytest.fixture(scope="module")
def followed(fmu_dir, identified, results_root) -> PathResult:
    """`make simulate`'s path following (both scenarios, three runs each), with straights of
    STRAIGHT instead of 10 m before and after the curves (the curves whole): 40 % less to run."""
    return run_path_following(fmu_dir, identified.files[0].parent / "model.json", results_root / "simulation",
                              straight=STRAIGHT)


def test_path_following_meets_the_issues_floors(followed):
    """Cross-track RMS < 0.10 m and max < 0.30 m, speed within 5 %, RMS(Fx - Fx_des) and
    RMS(Fy - Fy_des) < 2 N at every wheel, for both plants and both scenarios."""
    table = followed.metrics.set_index(["scenario", "run"])
    for scenario in SCENARIOS:
        for run in ("inverse", "cosim"):
            row = table.loc[(scenario, run)]
            assert row["cross_track_rms_m"] < 0.10 and row["cross_track_max_m"] < 0.30, (scenario, run)
            assert row["speed_error_max_percent"] < 5.0, (scenario, run)
            forces = row.filter(like="rms_F")
            assert len(forces) == 12 and (forces < 2.0).all(), (scenario, run, forces.to_dict())


def test_kinematic_steering_ablation_tracks_worse(followed):
    table = followed.metrics.set_index(["scenario", "run"])
    for scenario in SCENARIOS:
        assert table.loc[(scenario, "kinematic"), "cross_track_rms_m"] > table.loc[(scenario, "inverse"),
                                                                                  "cross_track_rms_m"]


def test_monolithic_and_cosimulated_rover_agree(followed):
    """Velocity within 1 %, loads within 2 %, path within 1 cm over each scenario."""
    for _, row in followed.agreement.iterrows():
        assert row["speed_max_difference_percent"] < 1.0, row.to_dict()
        assert row["load_max_difference_percent"] < 2.0, row.to_dict()
        assert row["path_max_difference_m"] < 0.01, row.to_dict()


def test_the_rover_turns_and_changes_lane(followed):
    turn, lane = followed.tables["turn", "inverse"], followed.tables["lane_change", "inverse"]
    assert turn["yaw"].iloc[-1] == pytest.approx(math.pi / 2, abs=0.02)
    end = turn_path(STRAIGHT).at(turn_path(STRAIGHT).length)[:2]  # (STRAIGHT + 10, 10 + STRAIGHT) m
    assert math.hypot(turn["x"].iloc[-1] - end[0], turn["y"].iloc[-1] - end[1]) < 1.0
    assert lane["y"].iloc[-1] == pytest.approx(3.0, abs=0.05)
    # Turning left loads the right (outer) wheels and rolls the body out of the turn.
    arc = (turn["s"] > STRAIGHT + 2) & (turn["s"] < STRAIGHT + 14)
    assert (turn["Fz_4"][arc] > turn["Fz_1"][arc]).all()
    assert (turn["Fy_1"][arc] > 0).all()   # the soil pushes the wheels towards the centre of the turn


def test_outputs_are_written(followed):
    names = {p.name for p in followed.files}
    for scenario in SCENARIOS:
        assert {f"path_{scenario}.csv", f"path_{scenario}_cosim.csv", f"path_{scenario}_kinematic.csv",
                f"path_wheels_{scenario}.png"} <= names
    assert {"path_metrics.csv", "path_agreement.csv", "path_xy.png", "path_following.json"} <= names
    table = pd.read_csv(next(p for p in followed.files if p.name == "path_turn.csv"))
    for column in ("x", "y", "yaw", "cross_track", "Fx_1", "Fy_6", "Fz_3", "slip_2", "slipAngle_5", "steer_4",
                   "sinkage_1", "Fx_des_1", "Fy_des_6"):
        assert column in table
    # the files keep a row every 10 ms (the runs step at 1 ms; the metrics use every step)
    assert np.allclose(np.diff(table["time"].to_numpy())[:-1], 0.01)


def test_report_shows_the_path_following(followed, results_root):
    from rover_cosim.report import build_report

    page = build_report(results_root)
    assert "Path following" in page and "kinematic steering" in page
    assert "path_xy.png not produced" not in page and "path_metrics.csv not produced" not in page


@pytest.mark.parametrize("straight", [0.0, -1.0, float("nan"), float("inf")])
def test_a_bad_straight_length_is_refused_naming_it(straight):
    from rover_cosim.jobs.path_following import scenario_path

    with pytest.raises(ValueError, match="straight = .* m: expected a length > 0"):
        scenario_path("turn", straight)
