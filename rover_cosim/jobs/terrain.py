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

import dataclasses
import hashlib
import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, ClassVar, NamedTuple

import numpy as np
import pandas as pd

from rover_cosim.common.outputs import file_sha256, json_bytes
from rover_cosim.common.paper import STATIC_WHEEL_LOAD
from rover_cosim.common.rows import csv_bytes, every, indices, steps_between_rows
from rover_cosim.control.path import Line
from rover_cosim.control.path import Path as ReferencePath
from rover_cosim.control.terrain_controller import TerrainPathController
from rover_cosim.identification.fits import FIT_TORQUE_MAX
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.identification.online import (
    ADAPTED_FIT_TORQUE_MAX,
    identify_lateral_on_soil,
    identify_on_soil,
    sweep_loads,
)
from rover_cosim.identification.plan import plan_for, static_load
from rover_cosim.identification.sweep import SweepPlan
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.model import System
from rover_cosim.terramechanics import PlaneTerrain, Soil, Wheel
from rover_cosim.terramechanics.library import Choice, as_choice, choose, soil_parameters
from rover_cosim.terramechanics.terrain import HeightMap, SoilMap, crater, soil_boundary

from . import terrain_figures
from .campaign import Campaign
from .ground import SIGNALS, GroundBlock, SoilBlock
from .path_following import BODY, STEP, PathResult, agreement, connect_controller, rover_geometry, trajectories
from .path_following import metrics as path_metrics
from .plants import add_plant_fmu, add_rover, hubs, rover_fmu
from .simulate import RECORD_INTERVAL, checked_models, models_of

SPEED = 0.3          # m/s, the traverse's target speed
TRAVERSE = 6.0       # m, the traverse's length (20 s at 0.3 m/s: the ablation settles in about 15 s)
RUNS = ("inverse", "cosim", "kinematic", "unaware")
#: N: the loads the second soil's models are identified around (the rover's per-wheel loads on the
#: crossing's slope, 1570 kg x 1.62 m/s² / 6 = 424 N, shifted by the roll and the pitch)
CROSSING_LOADS = (300.0, 550.0)
FMUS = ("SteerableRover", "SteerableRoverBody", "Wheel")
G = 1.62             # m/s², the rover's gravity (RoverParameters.g, the FMUs' default)
MASS = 1570.0        # kg, RoverParameters.M


class TerrainScenario:
    """A terrain scenario: a straight traverse along +x of ``length`` [m] at ``speed`` [m/s] on a
    ground plane with a side slope of ``side_slope_deg``, the runs it has (of RUNS), and what it adds
    to the ground (``prepare``) and to the record (``details``). A new scenario is a subclass (or an
    instance of one) and its entry in ``scenarios``."""

    name: str
    runs: tuple[str, ...]
    length: float
    speed: float

    @property
    def side_slope_deg(self) -> float:
        """deg: the side slope (the valley to the right of the path)."""
        return 0.0

    def plane(self) -> PlaneTerrain:
        """The ground plane."""
        return PlaneTerrain.side_slope(self.side_slope_deg, valley="right") if self.side_slope_deg else PlaneTerrain()

    def prepare(self, out: Path, fmu_dir: Path, choice: Choice, models: ModelSet) -> Prepared:
        """The ground of the runs (written maps are read back from their bytes: the runs use the files)."""
        return Prepared(Ground(self.plane()), {}, None)

    def details(self) -> dict[str, Any]:
        """What the record says of the scenario besides its ground, speed, length and stop time."""
        return {}


@dataclass(frozen=True)
class SlopeScenario(TerrainScenario):
    """A traverse across a side slope of ``slope_deg`` [deg]; its ablation kinematic steering (the
    downhill pull left to the cross-track feedback); on the co-simulated rover too if ``cosim``."""

    name: str
    slope_deg: float
    length: float = TRAVERSE
    speed: float = SPEED
    cosim: bool = True

    @property
    def runs(self) -> tuple[str, ...]:  # type: ignore[override]
        return ("inverse", "cosim", "kinematic") if self.cosim else ("inverse", "kinematic")

    @property
    def side_slope_deg(self) -> float:
        return self.slope_deg


@dataclass(frozen=True)
class CraterScenario(TerrainScenario):
    """The crater scenario: path ``length`` [m] along x at ``speed`` [m/s], a crater of ``depth`` [m]
    and ``radius`` [m] centred at ``centre`` [m] (``terramechanics.terrain.crater``), given hub by
    hub by the ground participant; the ablation ``unaware``: the controller without the map."""

    name: ClassVar[str] = "crater"  # type: ignore[misc]
    runs: ClassVar[tuple[str, ...]] = ("inverse", "cosim", "unaware")  # type: ignore[misc]
    length: float = 20.0
    speed: float = 1.0
    centre: tuple[float, float] = (10.0, -2.5)
    depth: float = 0.12
    radius: float = 4.0

    def prepare(self, out: Path, fmu_dir: Path, choice: Choice, models: ModelSet) -> Prepared:
        files = {out / "terrain_crater_heightmap.csv": crater_map(self).write("")}
        height_map = _read_back(files[out / "terrain_crater_heightmap.csv"])
        height_map.source = "crater (terrain_crater_heightmap.csv)"
        return Prepared(Ground(self.plane(), height_map), files, None)

    def details(self) -> dict[str, Any]:
        return {"crater": asdict(self)}


CRATER = CraterScenario()


@dataclass(frozen=True)
class SoilCrossingScenario(TerrainScenario):
    """The soil-crossing scenario: a straight traverse of ``length`` [m] at ``speed`` [m/s] across a
    side slope of ``slope_deg`` [deg], from the run's soil onto ``soil_b`` (a name of the soil
    library) beyond a boundary across the path at x = ``boundary`` [m], the share of ``soil_b``
    rising over ``width`` [m] (``terramechanics.terrain.soil_boundary``); the controller that
    believes the map takes ``believed_soil_b`` for the second soil; the ablation ``unaware``: the
    controller believing the first soil everywhere."""

    name: ClassVar[str] = "soil_crossing"  # type: ignore[misc]
    runs: ClassVar[tuple[str, ...]] = ("inverse", "cosim", "unaware")  # type: ignore[misc]
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

    def believed(self) -> Soil:
        """The second soil the controller believes in."""
        return choose(soil=self.believed_soil_b or self.soil_b).soil

    @property
    def side_slope_deg(self) -> float:
        return self.slope_deg

    def check(self) -> None:
        """ValueError naming a soil of the scenario that is not known (before anything runs)."""
        choose(soil=self.soil_b)
        self.believed()

    def prepare(self, out: Path, fmu_dir: Path, choice: Choice, models: ModelSet) -> Prepared:
        path = out / "terrain_soil_crossing_soilmap.csv"
        files = {path: soil_map_of(choice.soil, self).write("")}
        soil_map = _read_back(files[path], lambda name: SoilMap.read(name, choice.soil, choose(soil=self.soil_b).soil))
        soil_map.source = f"{self.soil_b} beyond x = {self.boundary:g} m"
        model_b = identify_second_soil(fmu_dir / "SingleWheel.fmu", self.believed(), choice.wheel,
                                       models.model().degree, choice)
        files[out / "terrain_soil_crossing_model_b.json"] = model_b.to_json()
        return Prepared(Ground(self.plane(), None, soil_map), files, model_b)

    def details(self) -> dict[str, Any]:
        chosen = choose(soil=self.soil_b)
        return {"soil_crossing": {**asdict(self), "soil_b_values": asdict(chosen.soil),
                                  "soil_b_title": chosen.soil_entry.get("title"),
                                  "soil_b_source": chosen.soil_entry.get("source"),
                                  "believed_soil_b_values": asdict(self.believed())}}


SOIL_CROSSING = SoilCrossingScenario()


def terrain_scenarios(length: float | None = None, crater_scenario: CraterScenario = CRATER,
              crossing: SoilCrossingScenario = SOIL_CROSSING) -> dict[str, TerrainScenario]:
    """The terrain scenarios by name, in the order they run: the side-slope traverses of ``length``
    [m] (None: TRAVERSE; the co-simulated rover only on the steeper one, for time), the crater, the
    soil crossing."""
    slope_length = TRAVERSE if length is None else length
    traverse_path(slope_length)  # a bad length refused before anything runs
    listed: tuple[TerrainScenario, ...] = (
        SlopeScenario("slope_traverse_10", 10.0, slope_length, cosim=False),
        SlopeScenario("slope_traverse_20", 20.0, slope_length), crater_scenario, crossing)
    return {scenario.name: scenario for scenario in listed}


class TerrainResult(PathResult):
    """What ``run_terrain`` wrote and measured: the files, the tables by (scenario, run) (the
    terrain_*.csv columns), terrain_metrics.csv, terrain_agreement.csv and the record."""


def crater_map(scenario: CraterScenario = CRATER) -> HeightMap:
    """The crater scenario's height map."""
    return crater(scenario.centre, scenario.depth, scenario.radius, rim=0.0)


def soil_map_of(soil: Soil, crossing: SoilCrossingScenario = SOIL_CROSSING) -> SoilMap:
    """The soil crossing's map: ``soil`` (the run's) up to the boundary, the library's
    ``crossing.soil_b`` beyond it."""
    soil_b = choose(soil=crossing.soil_b).soil
    return soil_boundary(crossing.boundary, soil, soil_b, crossing.width, x_span=(-5.0, crossing.length + 5.0))


def identify_second_soil(fmu_path: Path, soil: Soil, wheel: Wheel, degree: int,
                         choice: Choice | None = None) -> ModelSet:
    """The longitudinal (of ``degree``) and lateral models of ``soil`` (the second soil the controller
    believes in) and ``wheel``, identified by the sweeps on ``fmu_path`` (SingleWheel.fmu) around
    CROSSING_LOADS, as the adaptive controller identifies them on an estimated soil
    (``identification.online``), the sweeps on every core. For a rover or wheel other than the paper's
    (``choice``), the loads scaled by its static wheel load and the torques and fit range of the
    identification plan for it on ``soil`` (``identification.plan``)."""
    import tempfile

    loads = sweep_loads(np.array(CROSSING_LOADS))
    plan, torque_max, torques, lateral_max = SweepPlan(loads=loads), ADAPTED_FIT_TORQUE_MAX, None, FIT_TORQUE_MAX
    paper = choose()
    if choice is not None and (wheel != paper.wheel or choice.rover != paper.rover):
        scaled = plan_for(dataclasses.replace(choice, soil=soil, wheel=wheel))
        loads = sweep_loads(np.array(CROSSING_LOADS) * static_load(choice) / STATIC_WHEEL_LOAD)
        torques = scaled.torques
        plan = SweepPlan(loads=loads, torques=torques)
        torque_max = ADAPTED_FIT_TORQUE_MAX / FIT_TORQUE_MAX * scaled.fit_torque_max
        lateral_max = scaled.fit_torque_max
    with tempfile.TemporaryDirectory(prefix="rover-cosim-soil-b-") as cache:
        model, _ = identify_on_soil(fmu_path, soil, wheel, Path(cache), degree, plan, torque_max, workers=None)
        lateral, _ = identify_lateral_on_soil(fmu_path, soil, wheel, Path(cache), loads, torques, lateral_max,
                                              workers=None)
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


class Prepared(NamedTuple):
    """What a scenario drives on, with the files that describe it (maps written beside the results)
    and the models of a second soil its controller believes in (None: none)."""

    ground: Ground
    files: dict[Path, bytes]
    model_b: ModelSet | None


def traverse_path(length: float = TRAVERSE) -> ReferencePath:
    """The straight traverse of ``length`` [m] along +x from the origin."""
    if not (math.isfinite(length) and length > 0):
        raise ValueError(f"length = {length!r} m: expected a traverse length > 0")
    return ReferencePath((Line(length),))


def stop_time(length: float = TRAVERSE, speed: float = SPEED) -> float:
    """s: until the reference point reaches the end of the traverse (to the step)."""
    return float(np.floor(traverse_path(length).length / speed / STEP) * STEP)


#: The scenarios' names, and the side slopes' angles [deg] by name.
SCENARIOS = tuple(terrain_scenarios())
SLOPES = {s.name: s.slope_deg for s in terrain_scenarios().values() if isinstance(s, SlopeScenario)}


def _radius(choice: Choice | None) -> float:
    return (choice.wheel if choice else Wheel()).r


def _hubs_of(choice: Choice | None) -> dict[str, Any]:
    """Where the rover's hubs are (x_limb, y_limb [m]) for the ground and soil participants."""
    return {"x_limb": choice.rover.x_limb, "y_limb": choice.rover.y_limb} if choice is not None else {}


def _add_ground(builder: SystemBuilder, body: str, height_map: HeightMap | None, hubs: range,
                choice: Choice | None = None) -> list[str]:
    """The ground participant on ``body``'s ``hubs`` (none without a map); its name in a list."""
    if height_map is None:
        return []
    builder.add_block("ground", GroundBlock("ground", height_map, **_hubs_of(choice)))
    for name in BODY:
        builder.connect(f"{body}.{name}", f"ground.{name}")
    for signal in SIGNALS:
        for i in hubs:
            builder.connect(f"ground.{signal}[{i}]", f"{body}.{signal}[{i}]")
    return ["ground"]


def _add_soil(builder: SystemBuilder, body: str, soil_map: SoilMap | None, share_of: Callable[[int], str],
              hubs: range, choice: Choice | None = None) -> list[str]:
    """The soil participant on ``body``'s ``hubs`` (none without a map) feeding ``share_of(i)``; its
    name in a list."""
    if soil_map is None:
        return []
    builder.add_block("soil", SoilBlock("soil", soil_map, **_hubs_of(choice)))
    for name in BODY[:3]:
        builder.connect(f"{body}.{name}", f"soil.{name}")
    for i in hubs:
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
                                    steering="kinematic" if run_ == "kinematic" else "inverse",
                                    terrain=None if run_ == "unaware" and soil_map is None else terrain,
                                    g=choice.soil.gravity if choice is not None else G,
                                    **(rover_geometry(choice) if choice is not None else {"mass": MASS}),
                                    ground_map=height_map if run_ in ("inverse", "cosim") else None,
                                    soil_map=soil_map if believes_soil else None,
                                    model_b=model_b if believes_soil else None)
    soil_b = soil_parameters(soil_map.soil_b, "soilB") if soil_map is not None else {}
    if run_ == "cosim":
        body = rover_fmu(fmu_dir, "SteerableRoverBody", choice)
        limbs = hubs(body)
        wheels = add_rover(builder, body, Path(fmu_dir) / "Wheel.fmu", len(limbs), choice, lateral=True,
                           body_start={"v": speed}, wheel_start={"omega": spin})
        builder.set_parameters("body", terrain.fmu_parameters())
        builder.add_block("ctrl", block)
        connect_controller(builder, "body", lambda i, name: f"wheel{i}.{name}", limbs)
        for i, wheel in zip(limbs, wheels):
            builder.connect(f"ctrl.tau[{i}]", f"{wheel}.tau").connect(f"ctrl.tau[{i}]", f"body.tau[{i}]")
            builder.connect(f"ctrl.steer[{i}]", f"body.steer[{i}]")
            if soil_b:
                builder.set_parameters(wheel, soil_b)
        ground = _add_ground(builder, "body", height_map, limbs, choice)
        soil = _add_soil(builder, "body", soil_map, lambda i: f"{wheels[i - 1]}.soilShare", limbs, choice)
        return builder.simulation(order=["ctrl", "body", *ground, *soil, *wheels]).build()
    plant = rover_fmu(fmu_dir, "SteerableRover", choice)
    limbs = hubs(plant)
    add_plant_fmu(builder, "rover", plant, choice,
                  {"v": speed, **{f"omega[{i}]": spin for i in limbs}})
    builder.set_parameters("rover", {**terrain.fmu_parameters(), **soil_b})
    builder.add_block("ctrl", block)
    connect_controller(builder, "rover", lambda i, name: f"rover.{name}[{i}]", limbs)
    for i in limbs:
        builder.connect(f"ctrl.tau[{i}]", f"rover.tau[{i}]").connect(f"ctrl.steer[{i}]", f"rover.steer[{i}]")
    ground = _add_ground(builder, "rover", height_map, limbs, choice)
    soil = _add_soil(builder, "rover", soil_map, lambda i: f"rover.soilShare[{i}]", limbs, choice)
    if ground or soil:
        builder.simulation(order=["ctrl", "rover", *ground, *soil])
    return builder.build()


def motor_energy(table: pd.DataFrame) -> float:
    """J: the motors' work on the wheels, the time integral of sum_i tau_i omega_i (trapezoid)."""
    power = sum(table[f"tau_{i}"].to_numpy() * table[f"omega_{i}"].to_numpy() for i in indices(table.columns, "tau"))
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
        for i in indices(table.columns, name):
            row[f"mean_{name}_{i}_{unit}"] = float(steady[f"{name}_{i}"].mean())
    distance = float(table["s"].iloc[-1] - table["s"].iloc[0])
    row["energy_per_metre_J_m"] = motor_energy(table) / distance if distance > 0 else math.nan
    return row


def run_terrain(fmu_dir: Path, model: Path, out_dir: Path, scenarios: tuple[str, ...] = SCENARIOS,
                choice: Choice | Soil | Wheel | None = None, *, allow_model_mismatch: bool = False,
                progress: Callable[[float], None] | None = None, record_interval: float = RECORD_INTERVAL,
                length: float | None = None, runs: tuple[str, ...] = RUNS,
                crater_scenario: CraterScenario = CRATER,
                crossing: SoilCrossingScenario = SOIL_CROSSING) -> TerrainResult:
    """Every scenario of ``scenarios`` (names of ``terrain_scenarios``) with the runs of ``runs`` it
    has (``inverse`` and ``cosim`` with compensation, the ablation ``kinematic`` or ``unaware``) on
    the soil and wheel of ``choice`` (default: the paper's); writes every file (all or none).
    ``length`` [m]: the slope traverses' length (None: 6 m; the tests run shorter ones);
    ``crater_scenario``: the crater's path and bowl; ``crossing``: the soil crossing's path, slope
    and soils."""
    choice = as_choice(choice)
    steps_between_rows(record_interval, STEP)  # a bad interval refused before anything runs
    table = terrain_scenarios(length, crater_scenario, crossing)
    unknown = [s for s in scenarios if s not in table] + [r for r in runs if r not in RUNS]
    if unknown or not scenarios or "inverse" not in runs:
        raise ValueError(f"scenarios {scenarios!r}, runs {runs!r}: expected scenarios of {list(table)} and runs "
                         f"of {RUNS} with 'inverse' among them")
    chosen = [table[name] for name in scenarios]
    for scenario in chosen:  # e.g. the soils of a crossing named before anything runs
        check = getattr(scenario, "check", None)
        if check is not None:
            check()
    fmu_dir = Path(fmu_dir).resolve()
    out = Path(out_dir)
    models, mismatch = checked_models(model, choice, allow_model_mismatch)
    plan = [(scenario, label) for scenario in chosen for label in runs if label in scenario.runs]
    campaign = Campaign("rover-cosim simulate (terrain)", len(plan), progress)
    tables: dict[tuple[str, str], pd.DataFrame] = {}
    prepared: dict[str, Prepared] = {}
    files: dict[Path, bytes] = {}
    systems = {}
    for scenario, label in plan:
        if scenario.name not in prepared:
            prepared[scenario.name] = scenario.prepare(out, fmu_dir, choice, models)
            files.update(prepared[scenario.name].files)
        ground, model_b = prepared[scenario.name].ground, prepared[scenario.name].model_b
        systems[f"{scenario.name}/{label}"] = traverse_system(
            fmu_dir, models, ground.plane, label, choice, scenario.length, speed=scenario.speed,
            height_map=ground.map, soil_map=ground.soil_map, model_b=model_b)
    outcomes = campaign.run_all(systems)  # side by side on the cores
    for scenario, label in plan:
        trajectory = trajectories(outcomes[f"{scenario.name}/{label}"].data, cosim=label == "cosim")
        trajectory["z_ground"] = prepared[scenario.name].ground.height(trajectory["x"], trajectory["y"])
        tables[scenario.name, label] = trajectory
    metric_table = pd.DataFrame([{"scenario": s.name, "run": label, "side_slope_deg": s.side_slope_deg,
                                  "target_speed_m_s": s.speed, **metrics(tables[s.name, label], s.speed)}
                                 for s, label in plan])
    agreement_table = pd.DataFrame([{"scenario": s.name, **agreement(tables[s.name, "inverse"],
                                                                     tables[s.name, "cosim"], s.speed)}
                                    for s in chosen if (s.name, "cosim") in tables])
    record = campaign.record(
        {"scenarios": {s.name: {"terrain": vars(s.plane()), "side_slope_deg": s.side_slope_deg,
                                "target_speed_m_s": s.speed, "length_m": s.length,
                                "stop_time_s": stop_time(s.length, s.speed), **s.details()} for s in chosen},
         "model": str(model), "runs": list(runs), "record_interval_s": record_interval},
        fmu_dir=fmu_dir, fmus=(rover_fmu(fmu_dir, "SteerableRover", choice),
                               rover_fmu(fmu_dir, "SteerableRoverBody", choice), "Wheel"),
        model=model, choice=choice, mismatch=mismatch,
        metrics=metric_table.to_dict("records"), agreement=agreement_table.to_dict("records"))
    for name, ready in prepared.items():
        if ready.model_b is not None:
            record[f"{name}_model_b_sha256"] = hashlib.sha256(ready.model_b.to_json()).hexdigest()
    suffix = {"inverse": "", "cosim": "_cosim", "kinematic": "_kinematic", "unaware": "_unaware"}
    files.update({out / f"terrain_{s}{suffix[label]}.csv": csv_bytes(every(table, record_interval, STEP), "%.8g")
                  for (s, label), table in tables.items()})
    files.update({
        out / "terrain_metrics.csv": metric_table.to_csv(index=False, float_format="%.5g").encode(),
        out / "terrain_agreement.csv": agreement_table.to_csv(index=False, float_format="%.5g").encode(),
        out / "terrain_xy.png": terrain_figures.paths_over_terrain(
            {s.name: (traverse_path(s.length), prepared[s.name].ground) for s in chosen}, tables),
        out / "terrain.json": json_bytes(record),
    })
    for s in chosen:
        files[out / f"terrain_wheels_{s.name}.png"] = terrain_figures.wheels(
            {label: tables[s.name, label] for label in runs if label in s.runs and label != "cosim"}, s.name)
    written = campaign.write(out, files, stale=("terrain_*",))  # the straight run's and the paths' files stay
    return TerrainResult(written, tables, metric_table, agreement_table, record)


def _read_back(text: bytes, reader: Callable[[Path], Any] = HeightMap.read) -> Any:
    """The map of the CSV ``text`` as ``reader`` reads the written file (HeightMap.read: the crater's)."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "map.csv"
        path.write_bytes(text)
        read = reader(path)
    return read


__all__ = ["BODY", "CRATER", "RUNS", "SCENARIOS", "SLOPES", "SOIL_CROSSING", "SPEED", "TRAVERSE", "Ground",
           "TerrainResult", "TerrainScenario", "SlopeScenario", "CraterScenario", "SoilCrossingScenario", "Prepared",
           "identify_second_soil", "soil_map_of", "crater_map", "metrics", "motor_energy", "run_terrain", "stop_time",
           "terrain_scenarios", "traverse_path", "traverse_system"]
