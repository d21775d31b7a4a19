"""``make simulate`` (after the paper's straight run): the steerable rover following a curved
path with the identified longitudinal and lateral wheel models, on SteerableRover.fmu and on the
co-simulated SteerableRoverBody + 6 Wheel (wired as the shipped steerable_rover_cosim.toml is,
by ``plants``),
and the same paths with kinematic steering (the ablation).

The controller's steering reaches the wheels' slip angles, which it reads, within the same
instant (SteerableRover's slipAngle depends directly on steer): an algebraic loop, broken as in
the paper's loop by the controller coming first in the Gauss-Seidel order (it sees the slip
angles of the step before; ``allow_algebraic_loops``).

Scenarios: ``turn`` (10 m straight, 90 deg left turn of radius 10 m, 10 m straight, 0.5 m/s);
``lane_change`` (10 m straight, 3 m to the left over 15 m, 10 m straight, 1.0 m/s). Each starts
rolling at its speed (wheels at omega = v/r) and ends when the reference reaches the path's end.

results/simulation/
  path_<scenario>.csv, path_<scenario>_cosim.csv, path_<scenario>_kinematic.csv
                        time, body pose and rates, s, s_ref, cross_track, heading_error; per wheel
                        tau, steer, Fx, Fy, Fz, slip, slipAngle, sinkage, omega, Fx_des, Fy_des
  path_metrics.csv      per scenario and run: cross-track RMS and max, speed error, RMS force errors
  path_agreement.csv    per scenario: monolithic against co-simulated (speed, loads, path)
  path_xy.png, path_wheels_<scenario>.png
  path_following.json   parameters, FMU hashes, versions, wall times, metrics
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rover_cosim.common.outputs import json_bytes, summary_repr
from rover_cosim.common.rows import csv_bytes, every, indices, steps_between_rows
from rover_cosim.control import path_figures
from rover_cosim.control.adaptive import AdaptivePathController
from rover_cosim.control.calibration import Calibration
from rover_cosim.control.path import Path as ReferencePath
from rover_cosim.control.path_controller import PATHS, PathFollowingController
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.model import System
from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.library import Choice, as_choice

from .campaign import Campaign
from .plants import add_plant_fmu, add_rover, hubs, rover_fmu
from .simulate import RECORD_INTERVAL, adapter_for, checked_models, connect_telemetry, models_of, soil_and_wheel_of

STEP = 1e-3  # s
SCENARIOS = {"turn": 0.5, "lane_change": 1.0}  # path -> target speed [m/s]
STRAIGHT = 10.0  # m, the straights before and after each path's curve
BODY = ("x", "y", "yaw", "v", "vy", "yawRate")
PER_WHEEL = ("tau", "steer", "Fx", "Fy", "Fz", "slip", "slipAngle", "sinkage", "omega", "Fx_des", "Fy_des")
FMUS = ("SteerableRover", "SteerableRoverBody", "Wheel")


@dataclass
class PathResult:
    """What ``run_path_following`` wrote and measured."""

    files: list[Path]
    tables: dict[tuple[str, str], pd.DataFrame]   # (scenario, run) -> path_*.csv columns
    metrics: pd.DataFrame                        # path_metrics.csv
    agreement: pd.DataFrame                      # path_agreement.csv
    record: dict[str, Any]

    def __repr__(self) -> str:
        return summary_repr(type(self).__name__, self.files, runs=len(self.tables))


def scenario_path(scenario: str, straight: float = STRAIGHT) -> ReferencePath:
    """The path of ``scenario`` with straights of ``straight`` [m] before and after its curve."""
    if not (math.isfinite(straight) and straight > 0):
        raise ValueError(f"straight = {straight!r} m: expected a length > 0")
    return PATHS[scenario](straight)


def stop_time(scenario: str, straight: float = STRAIGHT) -> float:
    """s: until the reference point reaches the end of the path (to the step)."""
    return float(np.floor(scenario_path(scenario, straight).length / SCENARIOS[scenario] / STEP) * STEP)


def rover_geometry(choice: Choice | None) -> dict[str, Any]:
    """What the path controllers know of the rover: mass [kg], yaw inertia [kg·m²] and where its
    hubs are (x_limb, y_limb [m]); none without a choice (the paper's, the blocks' defaults)."""
    if choice is None:
        return {}
    rover = choice.rover
    return {"mass": rover.mass, "yaw_inertia": rover.Izz, "x_limb": rover.x_limb, "y_limb": rover.y_limb}


def controller(models: ModelSet, scenario: str, steering: str, straight: float = STRAIGHT,
               choice: Choice | None = None) -> PathFollowingController:
    """The path-following controller block ``ctrl`` of ``scenario`` for the rover of ``choice``."""
    return PathFollowingController("ctrl", models, path=scenario_path(scenario, straight),
                                   v_target=SCENARIOS[scenario], steering=steering, **rover_geometry(choice))


def connect_controller(builder: SystemBuilder, body: str, wheel: Any, wheels: range) -> None:
    """Body state, loads and slip angles to the controller (``wheel(i, name)``: an output of wheel
    ``i`` of ``wheels``)."""
    for name in BODY:
        builder.connect(f"{body}.{name}", f"ctrl.{name}")
    for i in wheels:
        builder.connect(wheel(i, "Fz"), f"ctrl.W[{i}]").connect(wheel(i, "slipAngle"), f"ctrl.slipAngle[{i}]")


def _path_run(name: str, scenario: str, straight: float) -> SystemBuilder:
    # The controller's steering reaches the slip angles it reads within the instant: an algebraic
    # loop, broken by the order (the controller first sees the slip angles of the step before).
    return SystemBuilder(name).simulation(stop_time=stop_time(scenario, straight), step=STEP,
                                          algorithm="gauss-seidel", allow_algebraic_loops=True)


def monolithic_system(fmu_dir: Path, model: ModelSet | Path, scenario: str, steering: str = "inverse",
                      choice: Choice | None = None, straight: float = STRAIGHT) -> System:
    """``scenario`` on SteerableRover.fmu, started rolling at its speed."""
    return monolithic_builder(fmu_dir, model, scenario, steering, choice, straight).build()


def monolithic_builder(fmu_dir: Path, model: ModelSet | Path, scenario: str, steering: str = "inverse",
                       choice: Choice | None = None, straight: float = STRAIGHT) -> SystemBuilder:
    """monolithic_system's builder, for a caller that adds participants (e.g. a rut block) to it."""
    speed = SCENARIOS[scenario]
    builder = _path_run(f"path {scenario} ({steering})", scenario, straight)
    plant = rover_fmu(fmu_dir, "SteerableRover", choice)
    wheels = hubs(plant)
    start = {"v": speed, **{f"omega[{i}]": speed / _radius(choice) for i in wheels}}
    add_plant_fmu(builder, "rover", plant, choice, start)
    builder.add_block("ctrl", controller(models_of(model), scenario, steering, straight, choice))
    connect_controller(builder, "rover", lambda i, name: f"rover.{name}[{i}]", wheels)
    for i in wheels:
        builder.connect(f"ctrl.tau[{i}]", f"rover.tau[{i}]").connect(f"ctrl.steer[{i}]", f"rover.steer[{i}]")
    return builder


def adaptive_system(fmu_dir: Path, model: ModelSet | Path, scenario: str, choice: Choice | None = None, *,
                    calibration: Calibration = Calibration(), cache_dir: Path | None = None,
                    straight: float = STRAIGHT) -> System:
    """``scenario`` on SteerableRover.fmu with the adaptive path controller: a calibration on the
    path's first straight, the soil estimated from the rover's telemetry (wheel spins and torques,
    loads, the body's velocity and attitude), both models identified again on the estimated soil
    (its lateral moduli kept nominal: a rover measures no lateral force), then the path law."""
    models = models_of(model)
    wheel = soil_and_wheel_of(models)[1]
    speed = SCENARIOS[scenario]
    builder = _path_run(f"path {scenario} (adaptive)", scenario, straight)
    plant = rover_fmu(fmu_dir, "SteerableRover", choice)
    wheels = hubs(plant)
    start = {"v": speed, **{f"omega[{i}]": speed / _radius(choice) for i in wheels}}
    add_plant_fmu(builder, "rover", plant, choice, start)
    adapter = adapter_for(models, fmu_dir, cache_dir, lateral=True, optional=calibration.optional_parameters)
    block = AdaptivePathController("ctrl", models, adapter,
                                   radius=wheel.r, inertia=wheel.J, calibration=calibration,
                                   path=scenario_path(scenario, straight), v_target=speed,
                                   **rover_geometry(choice))
    builder.add_block("ctrl", block)
    connect_controller(builder, "rover", lambda i, name: f"rover.{name}[{i}]", wheels)
    for i in wheels:
        builder.connect(f"ctrl.tau[{i}]", f"rover.tau[{i}]").connect(f"ctrl.steer[{i}]", f"rover.steer[{i}]")
    connect_telemetry(builder, "rover", calibration, ("pitch", "roll"), wheels)
    return builder.build()


def _radius(choice: Choice | None) -> float:
    return (choice.wheel if choice else Wheel()).r


def cosim_system(fmu_dir: Path, model: ModelSet | Path, scenario: str, choice: Choice | None = None,
                 straight: float = STRAIGHT) -> System:
    """``scenario`` on SteerableRoverBody + N Wheel (the hubs of the shipped
    steerable_rover_cosim.toml), started rolling at its speed, the controller first in the order."""
    speed = SCENARIOS[scenario]
    builder = _path_run(f"path {scenario} (cosim)", scenario, straight)
    body = rover_fmu(fmu_dir, "SteerableRoverBody", choice)
    limbs = hubs(body)
    wheels = add_rover(builder, body, Path(fmu_dir) / "Wheel.fmu", len(limbs),
                       choice, lateral=True, body_start={"v": speed}, wheel_start={"omega": speed / _radius(choice)})
    builder.add_block("ctrl", controller(models_of(model), scenario, "inverse", straight, choice))
    connect_controller(builder, "body", lambda i, name: f"wheel{i}.{name}", limbs)
    for i, wheel in zip(limbs, wheels):
        builder.connect(f"ctrl.tau[{i}]", f"{wheel}.tau").connect(f"ctrl.tau[{i}]", f"body.tau[{i}]")
        builder.connect(f"ctrl.steer[{i}]", f"body.steer[{i}]")
    return builder.simulation(order=["ctrl", "body", *wheels]).build()


def trajectories(data: pd.DataFrame, cosim: bool) -> pd.DataFrame:
    """The recorded run in the columns of path_*.csv."""
    body = "body" if cosim else "rover"

    def wheel(i: int, name: str) -> str:
        if name in ("tau", "steer", "Fx_des", "Fy_des"):
            return f"ctrl.{name}[{i}]"
        return f"wheel{i}.{name}" if cosim else f"rover.{name}[{i}]"

    table = {"time": data["time"], **{name: data[f"{body}.{name}"] for name in BODY}}
    table.update({name: data[f"ctrl.{name}"] for name in ("s", "s_ref", "cross_track", "heading_error")})
    for i in indices(data.columns, "ctrl.tau"):
        table.update({f"{name}_{i}": data[wheel(i, name)] for name in PER_WHEEL})
    return pd.DataFrame(table)


def metrics(table: pd.DataFrame, speed: float) -> dict[str, float]:
    """Cross-track RMS and max [m], largest speed error [%], RMS(Fx - Fx_des), RMS(Fy - Fy_des) per wheel [N]."""
    row = {"cross_track_rms_m": float(np.sqrt(np.mean(table["cross_track"] ** 2))),
           "cross_track_max_m": float(np.abs(table["cross_track"]).max()),
           "speed_error_max_percent": float(100 * np.abs(np.hypot(table["v"], table["vy"]) - speed).max() / speed)}
    wheels = indices(table.columns, "Fx_des")
    for i in wheels:
        row[f"rms_Fx_{i}_N"] = float(np.sqrt(np.mean((table[f"Fx_{i}"] - table[f"Fx_des_{i}"]) ** 2)))
    for i in wheels:
        row[f"rms_Fy_{i}_N"] = float(np.sqrt(np.mean((table[f"Fy_{i}"] - table[f"Fy_des_{i}"]) ** 2)))
    return row


def agreement(mono: pd.DataFrame, cosim: pd.DataFrame, speed: float) -> dict[str, float]:
    """Monolithic against co-simulated: speed [% of the target], loads [% of the static load],
    path [m] (largest distance between the two positions at the same time)."""
    wheels = indices(mono.columns, "Fz")
    static = float(np.mean([mono[f"Fz_{i}"].iloc[0] for i in wheels]))
    return {"speed_max_difference_percent": float(100 * np.abs(mono["v"] - cosim["v"]).max() / speed),
            "load_max_difference_percent": float(100 * max(np.abs(mono[f"Fz_{i}"] - cosim[f"Fz_{i}"]).max()
                                                           for i in wheels) / static),
            "path_max_difference_m": float(np.hypot(mono["x"] - cosim["x"], mono["y"] - cosim["y"]).max())}


def run_path_following(fmu_dir: Path, model: Path, out_dir: Path, scenarios: tuple[str, ...] = tuple(SCENARIOS),
                       choice: Choice | Soil | Wheel | None = None, *, allow_model_mismatch: bool = False,
                       progress: Callable[[float], None] | None = None,
                       record_interval: float = RECORD_INTERVAL, straight: float = STRAIGHT) -> PathResult:
    """Every scenario on both plants and with kinematic steering, on the soil and wheel of
    ``choice`` (default: the paper's); writes every file (all or none). A model identified on
    another soil or wheel is refused (ModelMismatch) unless ``allow_model_mismatch``.
    ``straight`` [m]: the straights before and after each path's curve (10 m; shorter ones keep
    the curve and shorten the run)."""
    choice = as_choice(choice)
    steps_between_rows(record_interval, STEP)  # a bad interval refused before anything runs
    scenario_path(next(iter(SCENARIOS)), straight)  # a bad length refused before anything runs
    fmu_dir = Path(fmu_dir).resolve()
    tables: dict[tuple[str, str], pd.DataFrame] = {}
    models, mismatch = checked_models(model, choice, allow_model_mismatch)
    builds = {"inverse": lambda s: monolithic_system(fmu_dir, models, s, choice=choice, straight=straight),
              "cosim": lambda s: cosim_system(fmu_dir, models, s, choice, straight),
              "kinematic": lambda s: monolithic_system(fmu_dir, models, s, "kinematic", choice, straight)}
    campaign = Campaign("rover-cosim simulate (path following)", len(scenarios) * len(builds), progress)
    outcomes = campaign.run_all({f"{scenario}/{label}": build(scenario) for scenario in scenarios
                                 for label, build in builds.items()})  # side by side on the cores
    for scenario in scenarios:
        for label in builds:
            tables[scenario, label] = trajectories(outcomes[f"{scenario}/{label}"].data, cosim=label == "cosim")
    rows = [{"scenario": s, "run": label, "target_speed_m_s": SCENARIOS[s], **metrics(tables[s, label], SCENARIOS[s])}
            for s in scenarios for label in builds]
    metric_table = pd.DataFrame(rows)
    agreement_table = pd.DataFrame([{"scenario": s, **agreement(tables[s, "inverse"], tables[s, "cosim"],
                                                                SCENARIOS[s])} for s in scenarios])
    record = campaign.record(
        {"scenarios": {s: {"target_speed_m_s": SCENARIOS[s], "stop_time_s": stop_time(s, straight)} for s in scenarios},
         "straight_m": straight, "model": str(model), "record_interval_s": record_interval},
        fmu_dir=fmu_dir, fmus=(rover_fmu(fmu_dir, "SteerableRover", choice),
                               rover_fmu(fmu_dir, "SteerableRoverBody", choice), "Wheel"),
        model=model, choice=choice, mismatch=mismatch,
        metrics=metric_table.to_dict("records"), agreement=agreement_table.to_dict("records"))
    out = Path(out_dir)
    suffix = {"inverse": "", "cosim": "_cosim", "kinematic": "_kinematic"}
    files = {out / f"path_{s}{suffix[label]}.csv": csv_bytes(every(table, record_interval, STEP), "%.8g")
             for (s, label), table in tables.items()}
    files.update({
        out / "path_metrics.csv": metric_table.to_csv(index=False, float_format="%.5g").encode(),
        out / "path_agreement.csv": agreement_table.to_csv(index=False, float_format="%.5g").encode(),
        out / "path_xy.png": path_figures.path_xy({s: scenario_path(s, straight) for s in scenarios}, tables),
        out / "path_following.json": json_bytes(record),
    })
    for s in scenarios:
        files[out / f"path_wheels_{s}.png"] = path_figures.wheels(tables[s, "inverse"], s)
    written = campaign.write(out, files, stale=("path_*",))  # the straight run's files stay
    return PathResult(written, tables, metric_table, agreement_table, record)
