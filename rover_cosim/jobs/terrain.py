"""``make simulate`` (after the path scenarios): the steerable rover on sloped ground and over a
height map (issue 35).

Scenario ``slope_traverse``: a straight traverse along +x across a side slope (the valley to the
right, ``PlaneTerrain.side_slope``) of 10 and 20 deg at 0.3 m/s on the paper's soil, started
rolling on the path, with

- ``inverse``: the identified longitudinal and lateral models, the downhill pull M g sin(slope)
  compensated as a feed-forward lateral force (``TerrainPathController(terrain=...)``), on
  SteerableRover.fmu;
- ``cosim``: the same controller on SteerableRoverBody + 6 Wheel (the body given the same ground);
- ``kinematic``: kinematic steering (the ablation): the wheels along their hubs' commanded
  velocities, the downhill pull left to the cross-track feedback.

Scenario ``crater``: 20 m along x at 1.0 m/s on level ground past a crater-like depression
(``terramechanics.terrain.crater``: a bowl 0.12 m deep of radius 4 m, centred 2.5 m to the right
of the path at x = 10 m; deeper or narrower bowls twist the footprint by more than the limbs'
21 mm static compression and lift wheels off), the height map given hub by hub by the ground participant
(``jobs.ground.GroundBlock``), with the identified models (``inverse``, ``cosim``); the
controller adds the pull of the loads on the map's local slopes at the hubs as a feed-forward
(``TerrainPathController(ground_map=...)``); the ablation ``unaware``: the same controller
without it (the bowl's slopes a disturbance). The map is written beside the results
(``terrain_crater_heightmap.csv``) and read back from there for the runs.

Scenario ``soil_crossing``: the 10 deg side-slope traverse (7 m at 0.3 m/s) from the run's soil
(the paper's) onto one softer in shear (``SoilCrossingScenario.soil_b``, HIT-LSS1 of the soil library:
cohesion 0.25 kPa against 0.80, friction angle 31.9 deg against 37.2) beyond a boundary across
the path at x = 2.5 m, the share of the second soil rising over 0.5 m
(``terramechanics.terrain.soil_boundary``). The soil map is written beside the results
(``terrain_soil_crossing_soilmap.csv``) and read back for the runs; the soil participant
(``jobs.ground.SoilBlock``) gives each wheel its share (SteerableRover's ``soilShare[i]``, each
Wheel's ``soilShare``; the second soil is the FMUs' ``soilB``). The controller's models of the
second soil are identified for the run (``identify_second_soil``: the sweep on SingleWheel.fmu at
the rover's loads, as the adaptive controller identifies again) and written beside the results
(``terrain_soil_crossing_model_b.json``). Runs: ``inverse`` and ``cosim``, the controller believing
the map (each wheel's models those of the soil under it); the ablation ``unaware``: the
controller believing the first soil everywhere (the slope still compensated).

results/simulation/
  terrain_crater_heightmap.csv  the crater's grid (HeightMap's CSV)
  terrain_soil_crossing_soilmap.csv, terrain_soil_crossing_model_b.json
                        the soil crossing's map (SoilMap's CSV) and the models of its second soil
  terrain_<scenario>.csv, terrain_<scenario>_cosim.csv, terrain_<scenario>_{kinematic,unaware}.csv
                        the columns of path_*.csv (``path_following.trajectories``) and the
                        ground height under the centre of gravity, z_ground [m]
  terrain_metrics.csv   per scenario and run: cross-track RMS and max [m], heading error RMS and max
                        [rad], speed error [%], per wheel the means over the run's second half of
                        slip [-], slip angle [rad], sinkage [m], load [N], and the motors' energy
                        per metre of path [J/m]
  terrain_agreement.csv per scenario: monolithic against co-simulated (speed, loads, path)
  terrain_xy.png        the paths over the terrain's height contours, cross-track error
  terrain_wheels_<scenario>.png  per wheel: slip, slip angle, sinkage, load (compensated and not)
  terrain.json          parameters, FMU hashes, versions, wall times, metrics
"""

from __future__ import annotations

import hashlib
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rover_cosim.common.outputs import file_sha256, json_bytes, run_record, write_all
from rover_cosim.common.rows import csv_bytes, every, steps_between_rows
from rover_cosim.control.path import Line
from rover_cosim.control.path import Path as ReferencePath
from rover_cosim.control.terrain_controller import TerrainPathController
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.identification.online import identify_lateral_on_soil, identify_on_soil, sweep_loads
from rover_cosim.identification.sweep import SweepPlan
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.master import run
from rover_cosim.orchestrator.model import System
from rover_cosim.orchestrator.runs import system_record
from rover_cosim.progress import Stages
from rover_cosim.terramechanics import PlaneTerrain, Soil, Wheel
from rover_cosim.terramechanics.library import Choice, as_choice, choose, describe, soil_parameters
from rover_cosim.terramechanics.terrain import HeightMap, SoilMap, crater, soil_boundary

from . import terrain_figures
from .ground import SIGNALS, GroundBlock, SoilBlock
from .path_following import BODY, STEP, WHEELS, PathResult, agreement, connect_controller, trajectories
from .path_following import metrics as path_metrics
from .plants import add_plant_fmu, add_rover
from .simulate import RECORD_INTERVAL, checked_models, models_of

SPEED = 0.3          # m/s, the traverse's target speed
TRAVERSE = 6.0       # m, the traverse's length (20 s at 0.3 m/s: the ablation settles in about 15 s)
SLOPES = {"slope_traverse_10": 10.0, "slope_traverse_20": 20.0}  # scenario -> side slope [deg]
RUNS = ("inverse", "cosim", "kinematic", "unaware")


@dataclass(frozen=True)
class CraterScenario:
    """The crater scenario: path ``length`` [m] along x at ``speed`` [m/s], a crater of ``depth`` [m]
    and ``radius`` [m] centred at ``centre`` [m] (``terramechanics.terrain.crater``)."""

    length: float = 20.0
    speed: float = 1.0
    centre: tuple[float, float] = (10.0, -2.5)
    depth: float = 0.12
    radius: float = 4.0


CRATER = CraterScenario()


@dataclass(frozen=True)
class SoilCrossingScenario:
    """The soil-crossing scenario: a straight traverse of ``length`` [m] at ``speed`` [m/s] across a
    side slope of ``slope_deg`` [deg], from the run's soil onto ``soil_b`` (a name of the soil
    library) beyond a boundary across the path at x = ``boundary`` [m], the share of ``soil_b``
    rising over ``width`` [m] (``terramechanics.terrain.soil_boundary``); the controller that
    believes the map takes ``believed_soil_b`` for the second soil."""

    def believed(self) -> Soil:
        """The second soil the controller believes in."""
        return choose(soil=self.believed_soil_b or self.soil_b).soil


    length: float = 7.0
    speed: float = 0.3
    slope_deg: float = 10.0
    boundary: float = 2.5
    width: float = 0.5
    soil_b: str = "hit_lss1"
    #: the soil the controller believes lies beyond the boundary, its second soil's models identified
    #: on it (as ``soil_b``: a library name, a TOML file or FILE:NAME, e.g. the soil.toml of
    #: ``rover-cosim estimate-soil``); None: the true one, ``soil_b``
    believed_soil_b: str | None = None


SOIL_CROSSING = SoilCrossingScenario()
SCENARIOS = (*SLOPES, "crater", "soil_crossing")
#: N: the loads the second soil's models are identified around (the rover's per-wheel loads on the
#: crossing's slope, 1570 kg x 1.62 m/s² / 6 = 424 N, shifted by the roll and the pitch)
CROSSING_LOADS = (300.0, 550.0)
FMUS = ("SteerableRover", "SteerableRoverBody", "Wheel")
G = 1.62             # m/s², the rover's gravity (RoverParameters.g, the FMUs' default)
MASS = 1570.0        # kg, RoverParameters.M


class TerrainResult(PathResult):
    """What ``run_terrain`` wrote and measured: the files, the tables by (scenario, run) (the
    terrain_*.csv columns), terrain_metrics.csv, terrain_agreement.csv and the record."""


def terrain_of(scenario: str, crossing: SoilCrossingScenario = SOIL_CROSSING) -> PlaneTerrain:
    """The ground plane of ``scenario``: a side slope, the valley to the right of the path along +x
    (the crater: level)."""
    if scenario not in SCENARIOS:
        raise ValueError(f"scenario = {scenario!r}: expected one of {list(SCENARIOS)}")
    if scenario == "soil_crossing":
        return PlaneTerrain.side_slope(crossing.slope_deg, valley="right")
    return PlaneTerrain.side_slope(SLOPES[scenario], valley="right") if scenario in SLOPES else PlaneTerrain()


def crater_map(scenario: CraterScenario = CRATER) -> HeightMap:
    """The crater scenario's height map."""
    return crater(scenario.centre, scenario.depth, scenario.radius, rim=0.0)


def speed_of(scenario: str, crater_scenario: CraterScenario = CRATER,
             crossing: SoilCrossingScenario = SOIL_CROSSING) -> float:
    """m/s: the scenario's target speed."""
    return {"crater": crater_scenario.speed, "soil_crossing": crossing.speed}.get(scenario, SPEED)


def soil_map_of(soil: Soil, crossing: SoilCrossingScenario = SOIL_CROSSING) -> SoilMap:
    """The soil crossing's map: ``soil`` (the run's) up to the boundary, the library's
    ``crossing.soil_b`` beyond it."""
    soil_b = choose(soil=crossing.soil_b).soil
    return soil_boundary(crossing.boundary, soil, soil_b, crossing.width, x_span=(-5.0, crossing.length + 5.0))


def identify_second_soil(fmu_path: Path, soil: Soil, wheel: Wheel, degree: int) -> ModelSet:
    """The longitudinal (of ``degree``) and lateral models of ``soil`` (the second soil the controller
    believes in) and ``wheel``, identified by the sweeps on ``fmu_path`` (SingleWheel.fmu) around
    CROSSING_LOADS, as the adaptive controller identifies them on an estimated soil
    (``identification.online``), in this process."""
    import tempfile

    loads = sweep_loads(np.array(CROSSING_LOADS))
    with tempfile.TemporaryDirectory(prefix="rover-cosim-soil-b-") as cache:
        model, _ = identify_on_soil(fmu_path, soil, wheel, Path(cache), degree, SweepPlan(loads=loads))
        lateral, _ = identify_lateral_on_soil(fmu_path, soil, wheel, Path(cache), loads)
    label = f"degree {degree}"
    return ModelSet(label, {label: model}, lateral, {
        "identified_for": "the soil crossing's second soil (rover-cosim simulate, terrain)",
        "loads_N": list(loads), "fmu": {"path": str(fmu_path), "sha256": file_sha256(fmu_path)},
        "soil": asdict(soil), "wheel": asdict(wheel)}, source="terrain_soil_crossing_model_b.json")


class Ground:
    """What a run drives on: the plane and, over it, a height map (or none); ``height`` [m] is the
    world height of the plane plus the map's (its height along the plane's normal)."""

    def __init__(self, plane: PlaneTerrain, height_map: HeightMap | None = None, soil_map: SoilMap | None = None):
        self.plane, self.map, self.soil_map = plane, height_map, soil_map

    def height(self, x: Any, y: Any) -> Any:
        base = self.plane.height(x, y)
        return base if self.map is None else base + math.cos(self.plane.slope) * self.map.height(x, y)

    def label(self) -> str:
        return (self.plane.label() + ("" if self.map is None else f", {self.map.source}")
                + ("" if self.soil_map is None else f",\n{self.soil_map.source}"))


def traverse_path(length: float = TRAVERSE) -> ReferencePath:
    """The straight traverse of ``length`` [m] along +x from the origin."""
    if not (math.isfinite(length) and length > 0):
        raise ValueError(f"length = {length!r} m: expected a traverse length > 0")
    return ReferencePath((Line(length),))


def stop_time(length: float = TRAVERSE, speed: float = SPEED) -> float:
    """s: until the reference point reaches the end of the traverse (to the step)."""
    return float(np.floor(traverse_path(length).length / speed / STEP) * STEP)


def _radius(choice: Choice | None) -> float:
    return (choice.wheel if choice else Wheel()).r


def _add_ground(builder: SystemBuilder, body: str, height_map: HeightMap | None) -> list[str]:
    """The ground participant on ``body``'s hubs (none without a map); its name in a list."""
    if height_map is None:
        return []
    builder.add_block("ground", GroundBlock("ground", height_map))
    for name in BODY:
        builder.connect(f"{body}.{name}", f"ground.{name}")
    for signal in SIGNALS:
        for i in WHEELS:
            builder.connect(f"ground.{signal}[{i}]", f"{body}.{signal}[{i}]")
    return ["ground"]


def _add_soil(builder: SystemBuilder, body: str, soil_map: SoilMap | None, share_of: Callable[[int], str]) -> list[str]:
    """The soil participant on ``body``'s hubs (none without a map) feeding ``share_of(i)``; its name in a list."""
    if soil_map is None:
        return []
    builder.add_block("soil", SoilBlock("soil", soil_map))
    for name in BODY[:3]:
        builder.connect(f"{body}.{name}", f"soil.{name}")
    for i in WHEELS:
        builder.connect(f"soil.soilShare[{i}]", share_of(i))
    return ["soil"]


def _check_traverse(terrain: PlaneTerrain, run_: str, choice: Choice | None, speed: float,
                    soil_map: SoilMap | None, model_b: ModelSet | None) -> None:
    """ValueError or TypeError naming what of a traverse is not as ``traverse_system`` needs it."""
    if run_ not in RUNS:
        raise ValueError(f"run = {run_!r}: expected one of {RUNS}")
    if not isinstance(terrain, PlaneTerrain):
        raise TypeError(f"terrain = {terrain!r}: expected a PlaneTerrain")
    if not (math.isfinite(speed) and speed > 0):
        raise ValueError(f"speed = {speed!r} m/s: expected > 0")
    if soil_map is not None and model_b is None:
        raise ValueError("soil_map without model_b: the controller needs the models of the map's second soil")
    if soil_map is not None and soil_map.soil != (choice.soil if choice else Soil()):
        raise ValueError(f"{soil_map.source}: its first soil {soil_map.soil} is not the run's soil "
                         f"{choice.soil if choice else Soil()}")


def traverse_system(fmu_dir: Path, model: ModelSet | Path, terrain: PlaneTerrain, run_: str = "inverse",
                    choice: Choice | None = None, length: float = TRAVERSE, *, speed: float = SPEED,
                    height_map: HeightMap | None = None, soil_map: SoilMap | None = None,
                    model_b: ModelSet | None = None) -> System:
    """The traverse along x of ``length`` [m] at ``speed`` [m/s] on ``terrain`` (and over
    ``height_map``, given by the ground participant; on the soils of ``soil_map``, given by the soil
    participant, the second one the FMUs' ``soilB``): ``run_`` "inverse" or "kinematic" on
    SteerableRover.fmu, "cosim" on SteerableRoverBody + 6 Wheel (the controller first in the
    Gauss-Seidel order, the ground and the soil after the body), "unaware" as "inverse" with a
    controller that does not know what the scenario adds: the slope and the height map (no
    feed-forward of their pull) or, with a soil map, the map (it believes the run's soil everywhere,
    the slope still compensated). With a soil map the other runs' controller believes it, with
    ``model_b`` the models of its second soil."""
    _check_traverse(terrain, run_, choice, speed, soil_map, model_b)
    builder = SystemBuilder(f"traverse {Ground(terrain, height_map).label()} ({run_})").simulation(
        stop_time=stop_time(length, speed), step=STEP, algorithm="gauss-seidel", allow_algebraic_loops=True)
    spin = speed / _radius(choice)
    believes_soil = soil_map is not None and run_ in ("inverse", "cosim")
    block = TerrainPathController("ctrl", models_of(model), path=traverse_path(length), v_target=speed,
                                    steering="kinematic" if run_ == "kinematic" else "inverse", step=STEP,
                                    terrain=None if run_ == "unaware" and soil_map is None else terrain, g=G,
                                    mass=MASS, ground_map=height_map if run_ in ("inverse", "cosim") else None,
                                    soil_map=soil_map if believes_soil else None,
                                    model_b=model_b if believes_soil else None)
    soil_b = soil_parameters(soil_map.soil_b, "soilB") if soil_map is not None else {}
    if run_ == "cosim":
        wheels = add_rover(builder, Path(fmu_dir) / "SteerableRoverBody.fmu", Path(fmu_dir) / "Wheel.fmu",
                           len(WHEELS), choice, lateral=True, body_start={"v": speed}, wheel_start={"omega": spin})
        builder.set_parameters("body", terrain.fmu_parameters())
        builder.add_block("ctrl", block)
        connect_controller(builder, "body", lambda i, name: f"wheel{i}.{name}")
        for i, wheel in zip(WHEELS, wheels):
            builder.connect(f"ctrl.tau[{i}]", f"{wheel}.tau").connect(f"ctrl.tau[{i}]", f"body.tau[{i}]")
            builder.connect(f"ctrl.steer[{i}]", f"body.steer[{i}]")
            if soil_b:
                builder.set_parameters(wheel, soil_b)
        ground = _add_ground(builder, "body", height_map)
        soil = _add_soil(builder, "body", soil_map, lambda i: f"{wheels[i - 1]}.soilShare")
        return builder.simulation(order=["ctrl", "body", *ground, *soil, *wheels]).build()
    add_plant_fmu(builder, "rover", Path(fmu_dir) / "SteerableRover.fmu", choice,
                  {"v": speed, **{f"omega[{i}]": spin for i in WHEELS}})
    builder.set_parameters("rover", {**terrain.fmu_parameters(), **soil_b})
    builder.add_block("ctrl", block)
    connect_controller(builder, "rover", lambda i, name: f"rover.{name}[{i}]")
    for i in WHEELS:
        builder.connect(f"ctrl.tau[{i}]", f"rover.tau[{i}]").connect(f"ctrl.steer[{i}]", f"rover.steer[{i}]")
    ground = _add_ground(builder, "rover", height_map)
    soil = _add_soil(builder, "rover", soil_map, lambda i: f"rover.soilShare[{i}]")
    if ground or soil:
        builder.simulation(order=["ctrl", "rover", *ground, *soil])
    return builder.build()


def motor_energy(table: pd.DataFrame) -> float:
    """J: the motors' work on the wheels, the time integral of sum_i tau_i omega_i (trapezoid)."""
    power = sum(table[f"tau_{i}"].to_numpy() * table[f"omega_{i}"].to_numpy() for i in WHEELS)
    return float(np.trapezoid(power, table["time"].to_numpy()))


def metrics(table: pd.DataFrame, speed: float = SPEED) -> dict[str, float]:
    """The path metrics (``path_following.metrics``), the heading error RMS and max [rad], per wheel
    the means over the second half of the run (the steady traverse) of slip [-], slip angle [rad],
    sinkage [m] and load [N], and the motors' energy per metre of path [J/m]."""
    row = path_metrics(table, speed)
    row["heading_error_rms_rad"] = float(np.sqrt(np.mean(table["heading_error"] ** 2)))
    row["heading_error_max_rad"] = float(np.abs(table["heading_error"]).max())
    steady = table[table["time"] >= table["time"].iloc[-1] / 2]
    for name, unit in (("slip", "1"), ("slipAngle", "rad"), ("sinkage", "m"), ("Fz", "N")):
        for i in WHEELS:
            row[f"mean_{name}_{i}_{unit}"] = float(steady[f"{name}_{i}"].mean())
    distance = float(table["s"].iloc[-1] - table["s"].iloc[0])
    row["energy_per_metre_J_m"] = motor_energy(table) / distance if distance > 0 else math.nan
    return row


def runs_of(scenario: str, runs: tuple[str, ...]) -> tuple[str, ...]:
    """The runs of ``scenario`` among ``runs``: the slopes' ablation is kinematic steering, the
    crater's the identified models with the map unknown to the controller (``unaware``); the
    co-simulated rover on the steeper slope and the crater (not again on the 10 deg slope: time)."""
    left_out = {"kinematic" if scenario in ("crater", "soil_crossing") else "unaware"} | (
        {"cosim"} if scenario == "slope_traverse_10" else set())
    return tuple(r for r in runs if r not in left_out)


def run_terrain(fmu_dir: Path, model: Path, out_dir: Path, scenarios: tuple[str, ...] = SCENARIOS,
                choice: Choice | Soil | Wheel | None = None, *, allow_model_mismatch: bool = False,
                progress: Callable[[float], None] | None = None, record_interval: float = RECORD_INTERVAL,
                length: float | None = None, runs: tuple[str, ...] = RUNS,
                crater_scenario: CraterScenario = CRATER,
                crossing: SoilCrossingScenario = SOIL_CROSSING) -> TerrainResult:
    """Every scenario with the runs of ``runs`` it has (``runs_of``: ``inverse`` and ``cosim`` with
    compensation, the ablation ``kinematic`` or, for the crater, ``unaware``) on the soil and wheel
    of ``choice`` (default: the paper's); writes every file (all or none). ``length`` [m]: the slope traverses' length
    (None: 6 m; the tests run shorter ones); ``crater_scenario``: the crater's path and bowl;
    ``crossing``: the soil crossing's path, slope and soils."""
    started = time.perf_counter()
    choice = as_choice(choice)
    steps_between_rows(record_interval, STEP)  # a bad interval refused before anything runs
    slope_length = TRAVERSE if length is None else length
    traverse_path(slope_length)
    unknown = [s for s in scenarios if s not in SCENARIOS] + [r for r in runs if r not in RUNS]
    if unknown or not scenarios or "inverse" not in runs:
        raise ValueError(f"scenarios {scenarios!r}, runs {runs!r}: expected scenarios of {list(SCENARIOS)} and runs "
                         f"of {RUNS} with 'inverse' among them")
    fmu_dir = Path(fmu_dir).resolve()
    out = Path(out_dir)
    models, mismatch = checked_models(model, choice, allow_model_mismatch)
    if "soil_crossing" in scenarios:  # its soils named before anything runs
        choose(soil=crossing.soil_b)
        crossing.believed()
    plan = [(s, label) for s in scenarios for label in runs_of(s, runs)]
    speeds = {s: speed_of(s, crater_scenario, crossing) for s in scenarios}
    lengths = {s: _length(s, slope_length, crater_scenario, crossing) for s in scenarios}
    model_b = None
    stages = Stages(progress, len(plan))
    tables: dict[tuple[str, str], pd.DataFrame] = {}
    walls: dict[str, float] = {}
    systems: dict[str, Any] = {}
    grounds: dict[str, Ground] = {}
    files: dict[Path, bytes] = {}
    for k, (scenario, label) in enumerate(plan):
        if scenario not in grounds:
            height_map = soil_map = None
            if scenario == "crater":  # written, then read back: the runs use the file's map
                files[out / "terrain_crater_heightmap.csv"] = crater_map(crater_scenario).write("")
                height_map = _read_back(files[out / "terrain_crater_heightmap.csv"])
                height_map.source = "crater (terrain_crater_heightmap.csv)"
            if scenario == "soil_crossing":  # the same for the soil map
                path = out / "terrain_soil_crossing_soilmap.csv"
                files[path] = soil_map_of((choice or choose()).soil, crossing).write("")
                soil_map = _read_back(files[path], lambda name: SoilMap.read(name, (choice or choose()).soil,
                                                                             choose(soil=crossing.soil_b).soil))
                soil_map.source = f"{crossing.soil_b} beyond x = {crossing.boundary:g} m"
                model_b = identify_second_soil(fmu_dir / "SingleWheel.fmu", crossing.believed(),
                                               (choice or choose()).wheel, models.model().degree)
                files[out / "terrain_soil_crossing_model_b.json"] = model_b.to_json()
            grounds[scenario] = Ground(terrain_of(scenario, crossing), height_map, soil_map)
        ground = grounds[scenario]
        system = traverse_system(fmu_dir, models, ground.plane, label, choice, lengths[scenario],
                                 speed=speeds[scenario], height_map=ground.map, soil_map=ground.soil_map,
                                 model_b=model_b if ground.soil_map is not None else None)
        systems[f"{scenario}/{label}"] = system_record(system)
        outcome = run(system, progress=stages.stage(k))
        table = trajectories(outcome.data, cosim=label == "cosim")
        table["z_ground"] = ground.height(table["x"], table["y"])
        tables[scenario, label] = table
        walls[f"{scenario}/{label}"] = outcome.wall_seconds
    metric_table = pd.DataFrame([{"scenario": s, "run": label, "side_slope_deg": _side_slope(s, crossing),
                                  "target_speed_m_s": speeds[s], **metrics(tables[s, label], speeds[s])}
                                 for s, label in plan])
    agreement_table = pd.DataFrame([{"scenario": s, **agreement(tables[s, "inverse"], tables[s, "cosim"], speeds[s])}
                                    for s in scenarios if (s, "cosim") in tables])
    record = run_record("rover-cosim simulate (terrain)",
                        {"scenarios": {s: {"terrain": vars(terrain_of(s, crossing)),
                                           "side_slope_deg": _side_slope(s, crossing),
                                           "target_speed_m_s": speeds[s], "length_m": lengths[s],
                                           "stop_time_s": stop_time(lengths[s], speeds[s]),
                                           **({"crater": asdict(crater_scenario)} if s == "crater" else {}),
                                           **({"soil_crossing": {**asdict(crossing), **_second_soil(crossing)}}
                                              if s == "soil_crossing" else {})}
                                       for s in scenarios},
                         "step_s": STEP, "model": str(model), "runs": list(runs),
                         "algorithm": "gauss-seidel", "record_interval_s": record_interval})
    record.update({"fmus": {name: file_sha256(fmu_dir / f"{name}.fmu") for name in FMUS},
                   "model_sha256": file_sha256(model), "run_wall_seconds": walls, **describe(choice or choose()),
                   "model_mismatch": mismatch, "systems": systems, "wall_seconds": time.perf_counter() - started,
                   "metrics": metric_table.to_dict("records"), "agreement": agreement_table.to_dict("records")})
    if model_b is not None:
        model_b_bytes = files[out / "terrain_soil_crossing_model_b.json"]
        record["soil_crossing_model_b_sha256"] = hashlib.sha256(model_b_bytes).hexdigest()
    suffix = {"inverse": "", "cosim": "_cosim", "kinematic": "_kinematic", "unaware": "_unaware"}
    files.update({out / f"terrain_{s}{suffix[label]}.csv": csv_bytes(every(table, record_interval, STEP), "%.8g")
                  for (s, label), table in tables.items()})
    files.update({
        out / "terrain_metrics.csv": metric_table.to_csv(index=False, float_format="%.5g").encode(),
        out / "terrain_agreement.csv": agreement_table.to_csv(index=False, float_format="%.5g").encode(),
        out / "terrain_xy.png": terrain_figures.paths_over_terrain(
            {s: (traverse_path(lengths[s]), grounds[s]) for s in scenarios}, tables),
        out / "terrain.json": json_bytes(record),
    })
    for s in scenarios:
        files[out / f"terrain_wheels_{s}.png"] = terrain_figures.wheels(
            {label: tables[s, label] for label in runs_of(s, runs) if label != "cosim"}, s)
    write_all(files, folder=out, stale=("terrain_*",))  # the straight run's and the paths' files stay
    return TerrainResult(sorted(files), tables, metric_table, agreement_table, record)


def _length(scenario: str, slope_length: float, crater_scenario: CraterScenario = CRATER,
            crossing: SoilCrossingScenario = SOIL_CROSSING) -> float:
    return {"crater": crater_scenario.length, "soil_crossing": crossing.length}.get(scenario, slope_length)


def _side_slope(scenario: str, crossing: SoilCrossingScenario = SOIL_CROSSING) -> float:
    """deg: the scenario's side slope."""
    return crossing.slope_deg if scenario == "soil_crossing" else SLOPES.get(scenario, 0.0)


def _second_soil(crossing: SoilCrossingScenario) -> dict[str, Any]:
    chosen = choose(soil=crossing.soil_b)
    return {"soil_b_values": asdict(chosen.soil), "soil_b_title": chosen.soil_entry.get("title"),
            "soil_b_source": chosen.soil_entry.get("source"), "believed_soil_b_values": asdict(crossing.believed())}


def _read_back(text: bytes, reader: Callable[[Path], Any] = HeightMap.read) -> Any:
    """The map of the CSV ``text`` as ``reader`` reads the written file (HeightMap.read: the crater's)."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "map.csv"
        path.write_bytes(text)
        read = reader(path)
    return read


__all__ = ["BODY", "CRATER", "RUNS", "SCENARIOS", "SLOPES", "SOIL_CROSSING", "SPEED", "TRAVERSE", "Ground",
           "TerrainResult", "CraterScenario", "SoilCrossingScenario", "identify_second_soil", "soil_map_of",
           "crater_map", "metrics", "motor_energy", "run_terrain", "speed_of", "stop_time",
           "terrain_of", "traverse_path", "traverse_system"]
