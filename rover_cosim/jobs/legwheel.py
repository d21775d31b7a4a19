"""``make simulate`` (``--only legwheel``): the paper's own plant, the leg-wheel rover with six
joints per limb (LegWheelRover.fmu, issue 47), on the paper's straight run and across a side slope.

Scenario ``straight`` (paper Sec. 4, Table 3): 20 s at 1 ms, the paper's controller
(``InverseModelController``: identified model, inverse law, filter) on LegWheelRover.fmu with its
limbs held in the paper's symmetric posture (hubs at x = 1.5, 0, -1.5 m, y = ±1.5 m, 1.0 m below
the centre of gravity), started at rest on its limbs (the centre of gravity at 1.0 m less the static
heave of ``limbs.static_heave``); beside it the same run on Rover.fmu (the body on six vertical
spring-dampers), the reference of the comparison.

Scenario ``slope``: a 6 m traverse along +x across a 20 deg side slope (the valley to the right) at
0.3 m/s, the path follower of the terrain scenarios (``TerrainPathController``: identified models,
the downhill pull fed forward) steering through the ankle steer joints (``PostureController``),
run ``fixed`` (the paper's posture, the body parallel to the slope) and ``posture`` (the posture
controller levels the body and shifts the centre of gravity uphill until the wheels' loads
balance).

Scenario ``climb``: the same 6 m at 0.3 m/s straight up a 10 deg slope, ``fixed`` against
``posture`` (the body pitched level, nose down against the slope, its centre of gravity carried
uphill with the pitch so that the middle hubs stay under their hips: ``control.posture``).

Scenario ``patch``: the front-left wheel starts in a soft patch (``PATCH``, ``soft_soil``: it sinks
about 115 mm against 24 mm), the soil under each wheel from its hub's place (``LimbSoilBlock``);
the rover creeps 0.8 m at 0.1 m/s; run ``roll`` (posture control, the wheel rolls out) and ``step``
(the posture controller lifts the wheel that sank past 60 mm, carries it 1.0 m ahead onto firm soil
and sets it down, its motor held at 0 while it is in the air; ``control.posture.StepOver``).

results/simulation/
  legwheel_straight.csv     LegWheelRover.fmu: time, x, v, per limb tau, Tx, Fz, sinkage, slip, Fx,
                            Fx_des and the six joint torques (hipYawTorque_i ...)
  legwheel_rms.csv          limb, RMS(Fx - Fx_des) [N] on the leg-wheel rover, on Rover.fmu, the paper's
  legwheel_slope_<run>.csv  the columns of path_*.csv, z, roll, pitch, the posture's commands and
                            per limb the joint torques
  legwheel_climb_<run>.csv  the same columns for the climb
  legwheel_patch_<run>.csv  time, x, v; per wheel the applied torque, load, sinkage, slip, Fx, the
                            soft soil's share, the hub's x, spin and the joint torques
  legwheel_metrics.csv      per scenario and run: slope and climb: load spread (max/min of the mean loads over the
                            second half), sinkage spread (max - min) [m], cross-track RMS and max [m],
                            the motors' energy per metre [J/m], RMS(Fx - Fx_des) per limb [N]; patch:
                            distance [m], mean speed [m/s], energy per metre [J/m], the front-left
                            wheel's deepest sinkage [m] and time in the patch [s]
  legwheel_stance.png       side, front and top views of the stances (paper's posture, levelled on the
                            side slope, levelled on the climb)
  legwheel_limbs_<scenario>.png  per limb: joint torques, load, sinkage, slip (straight, slope, climb, patch)
  legwheel.json             parameters, FMU hashes, versions, wall times, metrics, the posture's report
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rover_cosim.common.figures import drawn
from rover_cosim.common.outputs import json_bytes, summary_repr
from rover_cosim.common.paper import TABLE_3_RMS
from rover_cosim.common.rows import csv_bytes, every, indices
from rover_cosim.control.posture import JOINT_INPUTS, Posture, PostureController, posture_joints
from rover_cosim.control.terrain_controller import TerrainPathController
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.limbs import athlete_limbs, holding_torques, static_heave, static_loads
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.model import System
from rover_cosim.terramechanics import PlaneTerrain, Soil, Wheel
from rover_cosim.terramechanics.library import Choice, as_choice

from . import legwheel_figures
from .campaign import Campaign
from .path_following import connect_controller
from .plants import add_rover
from .simulate import RECORD_INTERVAL, STEP, STOP_TIME, checked_models, controller, models_of, rms
from .simulate import monolithic_system as spring_damper_system
from .simulate import trajectories as straight_trajectories
from .terrain import metrics as traverse_metrics
from .terrain import motor_energy, stop_time, traverse_path

FMUS = ("LegWheelRover", "LegWheelRoverBody", "Wheel", "Rover")
SLOPE_DEG = 20.0      # deg, the side slope (the valley to the right)
CLIMB_DEG = 10.0      # deg, the slope climbed straight up
SPEED = 0.3           # m/s
TRAVERSE = 6.0        # m
RUNS = ("fixed", "posture")
LEVEL_HEIGHT = 1.2    # m, the centre of gravity over the hubs the posture controller holds (see control.posture)
LABELS = {"fixed": "paper's posture, parallel to the slope", "posture": "posture control (level, load balanced)"}
CLIMB_LABELS = {"fixed": "paper's posture, parallel to the slope", "posture": "posture control (pitched level)"}
TORQUES = tuple(f"{joint}Torque" for joint in JOINT_INPUTS)


@dataclass
class LegWheelResult:
    """What ``run_legwheel`` wrote and measured."""

    files: list[Path]
    tables: dict[str, pd.DataFrame]   # "straight", "straight_spring_damper", "slope_fixed", "slope_posture"
    rms: pd.DataFrame                 # legwheel_rms.csv
    metrics: pd.DataFrame             # legwheel_metrics.csv
    record: dict[str, Any]

    def __repr__(self) -> str:
        return summary_repr(type(self).__name__, self.files, runs=len(self.tables))


#: N·m, the joint servos' torque limit of the leg-wheel FMUs (``LegWheelParameters.tauJointMax``).
TAU_JOINT_MAX = 2.0e3
#: N·m/rad, their stiffness (``LegWheelParameters.kJoint``).
K_JOINT = 2.0e4


def check_carryable(choice: Choice) -> None:
    """ValueError naming the rover's mass, the largest joint torque it needs at rest in the paper's
    posture and the servos' limit, where its limbs cannot hold it (they would yield and the body
    fall through the ground: no run can say anything of such a rover)."""
    limbs = athlete_limbs()
    joints = PostureController("posture").loops.joints
    mass, gravity = choice.rover.mass, choice.soil.gravity
    loads = static_loads(limbs, joints, K_JOINT, mass, gravity)
    largest = float(np.abs(holding_torques(limbs, joints, loads)).max())
    if largest > TAU_JOINT_MAX:
        raise ValueError(f"rover mass = {mass:g} kg under {gravity:g} m/s²: its limbs would need {largest:.0f} N·m "
                         f"at a joint to stand in the paper's posture; the joint servos hold {TAU_JOINT_MAX:.0f} N·m "
                         f"(LegWheelParameters.tauJointMax): expected a rover the limbs can carry (up to about "
                         f"{mass * TAU_JOINT_MAX / largest:.0f} kg)")


def leg_parameters(choice: Choice) -> dict[str, float]:
    """The leg-wheel FMU's parameters of the choice: its soil and wheel, the rover's mass, inertias
    and gravity (the soil's); the limbs are the FMU's own (ATHLETE-like, ``LegWheelParameters``)."""
    from rover_cosim.terramechanics.library import fmu_parameters

    rover = choice.rover
    return {**fmu_parameters(choice.soil, choice.wheel), "rover.M": rover.mass, "rover.g": choice.soil.gravity,
            "rover.Iyy": rover.Iyy, "rover.Ixx": rover.Ixx, "rover.Izz": rover.Izz}


def settled_height(choice: Choice, height: float = 1.0) -> float:
    """m: where the centre of gravity comes to rest in the paper's posture set ``height`` above the
    hubs (the limbs' static heave below it)."""
    limbs = athlete_limbs()
    joints = PostureController("posture", posture=Posture(height)).loops.joints
    return height - static_heave(limbs, joints, K_JOINT, choice.rover.mass, choice.soil.gravity)


def _add_leg_wheel_rover(builder: SystemBuilder, fmu_dir: Path, choice: Choice, start: dict[str, float]) -> str:
    path = Path(fmu_dir) / "LegWheelRover.fmu"
    builder.add_fmu("rover", path, start=start)
    builder.set_parameters("rover", leg_parameters(choice), only_known=True)
    return "rover"


def straight_system(fmu_dir: Path, model: ModelSet | Path, choice: Choice | None = None,
                    stop: float = STOP_TIME) -> System:
    """The paper's straight run on LegWheelRover.fmu in the paper's posture (the set-points its inputs'
    start values), started at rest on its limbs."""
    choice = as_choice(choice)
    builder = SystemBuilder("leg-wheel straight run").simulation(stop_time=stop, step=STEP, algorithm="gauss-seidel")
    _add_leg_wheel_rover(builder, fmu_dir, choice, {"height0": settled_height(choice)})
    builder.add_block("ctrl", controller(models_of(model), wheels=6, mass=choice.rover.mass))
    builder.connect("rover.x", "ctrl.x").connect("rover.v", "ctrl.v")
    for i in range(1, 7):
        builder.connect(f"rover.Fz[{i}]", f"ctrl.W[{i}]").connect(f"ctrl.tau[{i}]", f"rover.tau[{i}]")
    return builder.build()


def straight_cosim_system(fmu_dir: Path, model: ModelSet | Path, choice: Choice | None = None,
                          stop: float = STOP_TIME) -> System:
    """:func:`straight_system` on LegWheelRoverBody + 6 Wheel, cut at the hubs as the steerable rover
    is (W, v_hub, v_lat to each wheel; its Fx, Fy back), the controller first in the Gauss-Seidel order;
    the wheels take the body's hub values as a ramp over each step (``gauss-seidel-interpolated``: with
    them held at their end value, half a step ahead of an accelerating body, the rover was 33 mm
    ahead of the monolithic one after 18 m; ramped, under 1 mm)."""
    choice = as_choice(choice)
    builder = SystemBuilder("leg-wheel straight run (co-simulated)").simulation(stop_time=stop, step=STEP,
                                                                                algorithm="gauss-seidel-interpolated")
    wheels = add_rover(builder, Path(fmu_dir) / "LegWheelRoverBody.fmu", Path(fmu_dir) / "Wheel.fmu", 6, None,
                       lateral=True, body_start={"height0": settled_height(choice)})
    builder.set_parameters("body", leg_parameters(choice), only_known=True)
    for wheel in wheels:
        builder.set_parameters(wheel, leg_parameters(choice), only_known=True)
    builder.add_block("ctrl", controller(models_of(model), wheels=6, mass=choice.rover.mass))
    builder.connect("body.x", "ctrl.x").connect("body.v", "ctrl.v")
    for i, wheel in enumerate(wheels, start=1):
        builder.connect(f"body.W[{i}]", f"ctrl.W[{i}]").connect(f"ctrl.tau[{i}]", f"{wheel}.tau")
        builder.connect(f"ctrl.tau[{i}]", f"body.tau[{i}]")
    return builder.simulation(order=["ctrl", "body", *wheels]).build()


def _add_path_and_posture(builder: SystemBuilder, model: ModelSet | Path, choice: Choice, length: float,
                          speed: float, posture: PostureController, terrain: PlaneTerrain | None = None) -> None:
    """The terrain path follower ``ctrl`` (a straight of ``length`` [m] at ``speed`` [m/s], the pull
    of ``terrain`` fed forward) and the posture block on the rover: the path follower's steering
    through the ankle steer joints, the body's height and attitude and the loads to the posture
    block; the torques straight to the motors, or through the posture block where it steps wheels
    out (it holds a lifted wheel's at 0)."""
    rover = choice.rover
    builder.add_block("ctrl", TerrainPathController(
        "ctrl", models_of(model), path=traverse_path(length), v_target=speed, steering="inverse", terrain=terrain,
        g=choice.soil.gravity, mass=rover.mass, yaw_inertia=rover.Izz, x_limb=(1.5, 0.0, -1.5), y_limb=1.5))
    builder.add_block("posture", posture)
    connect_controller(builder, "rover", lambda i, name: f"rover.{name}[{i}]", range(1, 7))
    for name in ("z", "roll", "pitch", "yaw"):
        builder.connect(f"rover.{name}", f"posture.{name}")
    for i in range(1, 7):
        builder.connect(f"ctrl.steer[{i}]", f"posture.steer[{i}]").connect(f"rover.Fz[{i}]", f"posture.W[{i}]")
        if posture.step_over is not None:
            builder.connect(f"ctrl.tau[{i}]", f"posture.tau_cmd[{i}]").connect(f"posture.tau[{i}]", f"rover.tau[{i}]")
            builder.connect(f"rover.sinkage[{i}]", f"posture.sinkage[{i}]")
        else:
            builder.connect(f"ctrl.tau[{i}]", f"rover.tau[{i}]")
        for joint in JOINT_INPUTS:
            builder.connect(f"posture.{joint}[{i}]", f"rover.{joint}[{i}]")


def slope_system(fmu_dir: Path, model: ModelSet | Path, run_: str, choice: Choice | None = None, *,
                 slope_deg: float = SLOPE_DEG, length: float = TRAVERSE, speed: float = SPEED) -> System:
    """The side-slope traverse on LegWheelRover.fmu, run ``run_`` "fixed" or "posture" (see the module)."""
    return _plane_system(fmu_dir, model, run_, choice, PlaneTerrain.side_slope(slope_deg, valley="right"),
                         f"leg-wheel traverse, {slope_deg:g} deg side slope ({run_})", length, speed)


def climb_system(fmu_dir: Path, model: ModelSet | Path, run_: str, choice: Choice | None = None, *,
                 slope_deg: float = CLIMB_DEG, length: float = TRAVERSE, speed: float = SPEED) -> System:
    """The climb straight up a slope on LegWheelRover.fmu, run ``run_`` "fixed" or "posture" (see the module)."""
    return _plane_system(fmu_dir, model, run_, choice, PlaneTerrain(math.radians(slope_deg), math.pi),
                         f"leg-wheel climb, {slope_deg:g} deg slope ({run_})", length, speed)


def _plane_system(fmu_dir: Path, model: ModelSet | Path, run_: str, choice: Choice | None, terrain: PlaneTerrain,
                  title: str, length: float, speed: float) -> System:
    """A straight of ``length`` [m] along +x at ``speed`` [m/s] over ``terrain`` on LegWheelRover.fmu,
    in the paper's posture ("fixed") or under posture control ("posture")."""
    if run_ not in RUNS:
        raise ValueError(f"run {run_!r}: expected one of {', '.join(RUNS)}")
    choice = as_choice(choice)
    builder = SystemBuilder(title).simulation(
        stop_time=stop_time(length, speed), step=STEP, algorithm=RAMPED, allow_algebraic_loops=True)
    radius = choice.wheel.r
    start = {"v": speed, "height0": settled_height(choice), **{f"omega[{i}]": speed / radius for i in range(1, 7)}}
    _add_leg_wheel_rover(builder, fmu_dir, choice, start)
    builder.set_parameters("rover", terrain.fmu_parameters())
    posture = PostureController("posture", control=run_ == "posture", slope=terrain.slope, downhill=terrain.downhill,
                                height=LEVEL_HEIGHT)
    _add_path_and_posture(builder, model, choice, length, speed, posture, terrain)
    return builder.simulation(order=["ctrl", "posture", "rover"]).build()


#: The master of the runs under the posture block: its set-points reach the FMU as the ramps they
#: are over each step (``PostureController.ramped_outputs``), not held at their end values.
RAMPED = "gauss-seidel-interpolated"

#: The soft patch: a drift of loose dust ours (the paper's soil with its pressure-sinkage moduli a
#: tenth, its cohesion a quarter and a 30 deg friction angle: the wheel sinks about 115 mm at
#: 424 N against 24 mm), a patch of radius 0.5 m about the front-left wheel's start; the rover
#: creeps 0.8 m at 0.1 m/s (the middle wheel stops short of the patch).
PATCH = {"centre": (1.5, 1.5), "radius": 0.5, "speed": 0.1, "length": 0.8}
PATCH_RUNS = ("roll", "step")
PATCH_LABELS = {"roll": "rolls through (posture control)", "step": "steps the stuck wheel out"}


def soft_soil(soil: Soil) -> Soil:
    """The soft patch's soil (see PATCH): ``soil`` with kc, kphi a tenth, c a quarter, phi 30 deg."""
    return dataclasses.replace(soil, kc=soil.kc / 10, kphi=soil.kphi / 10, c=soil.c / 4, phi=math.radians(30.0))


def patch_system(fmu_dir: Path, model: ModelSet | Path, run_: str, choice: Choice | None = None) -> System:
    """The soft patch (PATCH) on LegWheelRover.fmu, the soil under each wheel from its hub's place
    (``LimbSoilBlock``); run ``run_`` "roll" (posture control, the stuck wheel rolls on) or "step"
    (the posture controller steps the wheel that sinks past 60 mm out of the patch)."""
    from rover_cosim.control.posture import StepOver
    from rover_cosim.terramechanics.library import soil_parameters
    from rover_cosim.terramechanics.terrain import soil_patch

    from .ground import LimbSoilBlock

    if run_ not in PATCH_RUNS:
        raise ValueError(f"run {run_!r}: expected one of {', '.join(PATCH_RUNS)}")
    choice = as_choice(choice)
    speed, length = float(PATCH["speed"]), float(PATCH["length"])  # type: ignore[arg-type]
    soil_map = soil_patch(PATCH["centre"], float(PATCH["radius"]), choice.soil, soft_soil(choice.soil))  # type: ignore[arg-type]
    builder = SystemBuilder(f"leg-wheel rover, a wheel in a soft patch ({run_})").simulation(
        stop_time=stop_time(length, speed), step=STEP, algorithm=RAMPED, allow_algebraic_loops=True)
    _add_leg_wheel_rover(builder, fmu_dir, choice, {"height0": settled_height(choice)})
    builder.set_parameters("rover", soil_parameters(soil_map.soil_b, "soilB"))
    posture = PostureController("posture", control=True, step_over=StepOver() if run_ == "step" else None)
    _add_path_and_posture(builder, model, choice, length, speed, posture)
    builder.add_block("soil", LimbSoilBlock("soil", soil_map))
    for name in ("x", "y", "yaw"):
        builder.connect(f"rover.{name}", f"soil.{name}")
    for i in range(1, 7):
        builder.connect(f"rover.hubX[{i}]", f"soil.hubX[{i}]").connect(f"rover.hubY[{i}]", f"soil.hubY[{i}]")
        builder.connect(f"soil.soilShare[{i}]", f"rover.soilShare[{i}]")
    return builder.simulation(order=["ctrl", "posture", "rover", "soil"]).build()


def _joint_torques(data: pd.DataFrame, body: str = "rover") -> dict[str, Any]:
    return {f"{name}_{i}": data[f"{body}.{name}[{i}]"] for i in range(1, 7) for name in TORQUES}


def patch_table(data: pd.DataFrame) -> pd.DataFrame:
    """The soft patch's columns: time, x, v; per wheel the torque applied to it (``tau_i``: 0 while
    its limb steps), load, sinkage, slip, drawbar pull, the soft soil's share under it, its hub's x
    (body frame), spin and the joint torques."""
    applied = "posture.tau" if "posture.tau[1]" in data.columns else "ctrl.tau"
    table: dict[str, Any] = {"time": data["time"], "x": data["rover.x"], "v": data["rover.v"]}
    for i in range(1, 7):
        table.update({f"tau_{i}": data[f"{applied}[{i}]"], f"Fz_{i}": data[f"rover.Fz[{i}]"],
                      f"sinkage_{i}": data[f"rover.sinkage[{i}]"], f"slip_{i}": data[f"rover.slip[{i}]"],
                      f"Fx_{i}": data[f"rover.Fx[{i}]"], f"soilShare_{i}": data[f"soil.soilShare[{i}]"],
                      f"hubX_{i}": data[f"rover.hubX[{i}]"], f"omega_{i}": data[f"rover.omega[{i}]"]})
    return pd.concat([pd.DataFrame(table), pd.DataFrame(_joint_torques(data))], axis=1)


def patch_metrics(table: pd.DataFrame) -> dict[str, float]:
    """How far the rover got [m], its mean speed [m/s], the motors' energy per metre [J/m] and the
    front-left wheel's deepest sinkage after the first half second [m] (its start in the patch
    settled)."""
    distance = float(table["x"].iloc[-1] - table["x"].iloc[0])
    later = table[table["time"] >= 0.5]
    return {"distance_m": distance, "mean_speed_m_s": distance / float(table["time"].iloc[-1]),
            "energy_per_metre_J_m": motor_energy(table) / max(distance, 1e-9),
            "sinkage_1_max_m": float(later["sinkage_1"].max()),
            "in_patch_s": float((table["soilShare_1"] > 0.5).sum() * STEP)}


def straight_table(data: pd.DataFrame, cosim: bool = False) -> pd.DataFrame:
    """The straight run's columns (simulate's trajectories.csv) and the joint torques."""
    table = straight_trajectories(data, "cosim" if cosim else "monolithic")
    return pd.concat([table, pd.DataFrame(_joint_torques(data, "body" if cosim else "rover"))], axis=1)


def slope_table(data: pd.DataFrame) -> pd.DataFrame:
    """The traverse's columns (path_*.csv), the body's height and attitude, the posture's commands
    and the joint torques."""
    from .path_following import trajectories

    table = trajectories(data, cosim=False)
    extra = {name: data[f"rover.{name}"] for name in ("z", "roll", "pitch")}
    extra.update({name: data[f"posture.{name}"] for name in ("height_cmd", "shift_x", "shift_y", "roll_cmd",
                                                             "pitch_cmd")})
    return pd.concat([table, pd.DataFrame({**extra, **_joint_torques(data)})], axis=1)


def slope_metrics(table: pd.DataFrame, length: float = TRAVERSE, speed: float = SPEED) -> dict[str, float]:
    """The traverse's metrics (``terrain.metrics``) and the spreads over the second half: the
    largest over the least mean load [1], the largest less the least mean sinkage [m]."""
    row = traverse_metrics(table, speed)
    steady = table[table["time"] >= table["time"].iloc[-1] / 2]
    loads = np.array([steady[f"Fz_{i}"].mean() for i in range(1, 7)])
    sinkages = np.array([steady[f"sinkage_{i}"].mean() for i in range(1, 7)])
    row["load_spread"] = float(loads.max() / loads.min()) if loads.min() > 0 else math.inf
    row["sinkage_spread_m"] = float(sinkages.max() - sinkages.min())
    row["energy_per_metre_J_m"] = motor_energy(table) / max(float(table["x"].iloc[-1] - table["x"].iloc[0]), 1e-9)
    row["roll_end_deg"] = float(np.degrees(table["roll"].iloc[-1]))
    row["pitch_end_deg"] = float(np.degrees(table["pitch"].iloc[-1]))
    row["shift_x_end_m"] = float(table["shift_x"].iloc[-1])
    row["shift_y_end_m"] = float(table["shift_y"].iloc[-1])
    row["mean_speed_m_s"] = float(table["v"][table["time"] >= table["time"].iloc[-1] / 2].mean())
    return row


def run_legwheel(fmu_dir: Path, model: Path, out_dir: Path, choice: Choice | Soil | Wheel | None = None, *,
                 allow_model_mismatch: bool = False, progress: Callable[[float], None] | None = None,
                 record_interval: float = RECORD_INTERVAL, stop: float = STOP_TIME, length: float = TRAVERSE,
                 slope_deg: float = SLOPE_DEG, climb_deg: float = CLIMB_DEG,
                 patch_stop: float = math.inf) -> LegWheelResult:
    """The leg-wheel scenarios (see the module); writes every file (all or none). The rover is the
    paper's (the leg-wheel limbs are its); ``choice`` gives the soil and wheel (and the rover's mass
    and inertias); ``stop`` [s], ``length`` [m] and ``patch_stop`` [s] shorten the runs (tests)."""
    choice = as_choice(choice)
    if choice.rover_name != "paper":
        raise ValueError(f"rover {choice.rover_name!r}: the leg-wheel scenarios are the paper's rover's (its "
                         "ATHLETE-like limbs); run them with --rover paper")
    check_carryable(choice)
    fmu_dir = Path(fmu_dir).resolve()
    models, mismatch = checked_models(model, choice, allow_model_mismatch)
    campaign = Campaign("rover-cosim simulate --only legwheel", 3 + 2 * len(RUNS) + len(PATCH_RUNS), progress)
    results = campaign.run_all(_systems(fmu_dir, models, choice, stop, length, slope_deg, climb_deg, patch_stop),
                               longest=LONGEST)
    tables = {"straight": straight_table(results["straight"].data),
              "straight_cosim": straight_table(results["straight_cosim"].data, cosim=True),
              "straight_spring_damper": straight_trajectories(results["straight_spring_damper"].data, "monolithic")}
    reports = {}
    for scenario in ("slope", "climb"):
        for run_ in RUNS:
            tables[f"{scenario}_{run_}"] = slope_table(results[f"{scenario}_{run_}"].data)
            reports[run_ if scenario == "slope" else f"{scenario}_{run_}"] = _posture_report(
                campaign.ran[f"{scenario}_{run_}"])
    for run_ in PATCH_RUNS:
        tables[f"patch_{run_}"] = patch_table(results[f"patch_{run_}"].data)
        reports[f"patch_{run_}"] = _posture_report(campaign.ran[f"patch_{run_}"])
    legs, spring_rms = rms(tables["straight"]), rms(tables["straight_spring_damper"])
    rms_table = pd.DataFrame({"limb": legs["limb"], "rms_legwheel_N": legs["rms_N"],
                              "rms_legwheel_cosim_N": rms(tables["straight_cosim"])["rms_N"],
                              "rms_spring_damper_N": spring_rms["rms_N"],
                              "rms_paper_N": [TABLE_3_RMS.get(int(i), TABLE_3_RMS.get(int(i) - 3, math.nan))
                                              for i in legs["limb"]]})
    rows = [{"scenario": scenario, "run": run_, **slope_metrics(tables[f"{scenario}_{run_}"], length)}
            for scenario in ("slope", "climb") for run_ in RUNS]
    rows += [{"scenario": "patch", "run": run_, **patch_metrics(tables[f"patch_{run_}"])} for run_ in PATCH_RUNS]
    metrics = pd.DataFrame(rows)
    agreement = {"spring_damper": _straight_agreement(tables["straight"], tables["straight_spring_damper"]),
                 "cosim": _straight_agreement(tables["straight"], tables["straight_cosim"])}
    record = campaign.record({"stop_time_s": stop, "model": str(model), "record_interval_s": record_interval,
                              "slope_deg": slope_deg, "climb_deg": climb_deg, "traverse_m": length,
                              "speed_m_s": SPEED,
                              "posture": "paper's: hubs at x = 1.5, 0, -1.5 m, y = +-1.5 m, 1.0 m below the "
                                         "centre of gravity"},
                             fmu_dir=fmu_dir, fmus=FMUS, model=model, choice=choice, mismatch=mismatch,
                             rms_N={"legwheel": legs["rms_N"].tolist(), "spring_damper": spring_rms["rms_N"].tolist()},
                             straight_agreement=agreement, metrics=metrics.to_dict(orient="records"),
                             posture=reports)
    out = Path(out_dir)
    side, climb = math.radians(slope_deg), math.radians(climb_deg)
    stance = {f"paper's posture on the {slope_deg:g} deg side slope": (posture_joints(), 0.0, 0.0, (side, 0.0)),
              "posture control, side slope (its end)": (*_end_posture(tables["slope_posture"], reports["posture"]),
                                                        (side, 0.0)),
              f"posture control, {climb_deg:g} deg climb (its end)": (
                  *_end_posture(tables["climb_posture"], reports["climb_posture"]), (0.0, climb))}
    limbs = legwheel_figures.limbs
    figures: dict[Path, Callable[[], bytes]] = {
        out / "legwheel_stance.png": lambda: legwheel_figures.stance(stance),
        out / "legwheel_limbs_straight.png": lambda: limbs({"leg-wheel rover": tables["straight"]},
                                                           "straight run, paper's posture"),
        out / "legwheel_limbs_slope.png": lambda: limbs({LABELS[r]: tables[f"slope_{r}"] for r in RUNS},
                                                        f"{slope_deg:g} deg side slope at {SPEED:g} m/s"),
        out / "legwheel_limbs_climb.png": lambda: limbs({CLIMB_LABELS[r]: tables[f"climb_{r}"] for r in RUNS},
                                                        f"{climb_deg:g} deg climb at {SPEED:g} m/s"),
        out / "legwheel_limbs_patch.png": lambda: limbs(
            {PATCH_LABELS[r]: tables[f"patch_{r}"] for r in PATCH_RUNS},
            f"front-left wheel in a soft patch, {float(PATCH['speed']):g} m/s"),  # type: ignore[arg-type]
    }
    runs_csv = {out / "legwheel_straight.csv": tables["straight"],
                **{out / f"legwheel_{scenario}_{run_}.csv": tables[f"{scenario}_{run_}"]
                   for scenario in ("slope", "climb") for run_ in RUNS},
                **{out / f"legwheel_patch_{run_}.csv": tables[f"patch_{run_}"] for run_ in PATCH_RUNS}}
    made = drawn({**figures, **{path: functools.partial(_csv, table, record_interval)
                                for path, table in runs_csv.items()}})  # side by side on the cores
    files = {
        **made,
        out / "legwheel_rms.csv": rms_table.to_csv(index=False, float_format="%.4f").encode(),
        out / "legwheel_metrics.csv": metrics.to_csv(index=False, float_format="%.6g").encode(),
        out / "legwheel.json": json_bytes(record),
    }
    written = campaign.write(out, files, stale=("legwheel_*",))
    return LegWheelResult(written, tables, rms_table, metrics, record)


def _csv(table: pd.DataFrame, record_interval: float) -> bytes:
    """A run's table as its CSV: a row every ``record_interval`` [s], eight digits."""
    return csv_bytes(every(table, record_interval, STEP), "%.8g")


#: The runs that take longest (the posture controller's Python updates, the co-simulated rover's
#: seven FMUs, the soft patch's stiff soil): the campaign starts them first.
LONGEST = ("slope_posture", "climb_posture", "straight_cosim", "patch_roll", "patch_step")


def _systems(fmu_dir: Path, models: ModelSet, choice: Choice, stop: float, length: float, slope_deg: float,
             climb_deg: float, patch_stop: float) -> dict[str, System]:
    """Every run of the job by its key (independent runs: the campaign steps them side by side)."""
    systems = {"straight": straight_system(fmu_dir, models, choice, stop),
               "straight_cosim": straight_cosim_system(fmu_dir, models, choice, stop),
               "straight_spring_damper": dataclasses.replace(spring_damper_system(fmu_dir, models, choice),
                                                             stop_time=stop)}
    for scenario, make, degrees in (("slope", slope_system, slope_deg), ("climb", climb_system, climb_deg)):
        for run_ in RUNS:
            systems[f"{scenario}_{run_}"] = make(fmu_dir, models, run_, choice, slope_deg=degrees, length=length)
    patch = min(stop_time(float(PATCH["length"]), float(PATCH["speed"])), patch_stop)  # type: ignore[arg-type]
    for run_ in PATCH_RUNS:
        systems[f"patch_{run_}"] = dataclasses.replace(patch_system(fmu_dir, models, run_, choice), stop_time=patch)
    return systems


def _posture_report(system: System) -> dict[str, Any]:
    return next(b.block for b in system.blocks if b.name == "posture").report()  # type: ignore[attr-defined]


def _end_posture(table: pd.DataFrame, report: dict[str, Any]) -> tuple[dict[str, float], float, float]:
    """The set-points of the posture at the end of a traverse (its commanded posture over the
    footprint of the block's ``report``, wheels straight), its roll and pitch [rad] against the ground."""
    last = table.iloc[-1]
    posture = Posture(float(last["height_cmd"]), (float(last["shift_x"]), float(last["shift_y"])),
                      float(last["roll_cmd"]), float(last["pitch_cmd"]), tuple(report["lift_m"]))
    footprint = [(float(x), float(y)) for x, y in report["footprint_m"]]
    return posture_joints(posture, footprint=footprint), posture.roll, posture.pitch


def _straight_agreement(legs: pd.DataFrame, other: pd.DataFrame) -> dict[str, float]:
    """The leg-wheel rover against another plant on the straight run: the largest speed difference
    [m/s] and [% of 1 m/s], the largest load difference [N] and [% of the static load] and the final
    positions' difference [m]."""
    wheels = indices(legs.columns, "Fz")
    static = float(np.mean([legs[f"Fz_{i}"].iloc[0] for i in wheels]))
    speed = float(np.abs(legs["v"] - other["v"]).max())
    load = float(max(np.abs(legs[f"Fz_{i}"] - other[f"Fz_{i}"]).max() for i in wheels))
    return {"speed_max_difference_m_s": speed, "speed_max_difference_percent": 100 * speed / 1.0,
            "load_max_difference_N": load, "load_max_difference_percent": 100 * load / static,
            "final_x_difference_m": float(legs["x"].iloc[-1] - other["x"].iloc[-1])}
