"""``make simulate``: the closed-loop rover of the paper's Sec. 4 on two plants, 20 s at 1 ms,
Gauss-Seidel: the monolithic Rover.fmu and the co-simulated RoverBody + N Wheel (N: the rover's
wheels; an FMU built for them where the rover has not six, see ``plants.rover_fmu``).

results/simulation/
  trajectories.csv         Rover.fmu: time, x, v and per limb tau_i, Tx_i, Fz_i, sinkage_i, slip_i, Fx_i, Fx_des_i
  trajectories_cosim.csv   the same for RoverBody + N Wheel
  rms.csv                  limb, rms_N = RMS(Fx_i - Fx_des_i) on Rover.fmu (Table 3); rms_cosim.csv likewise
  ablation_fixed_load.csv  RMS per limb with one model at the rover's static wheel load (424 N) instead of the LUT
  fig10_closed_loop.png    Fig. 10 (a)-(h), limbs 1-3
  simulation.json          parameters, FMU hashes, versions, wall times, checks
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rover_cosim.common.outputs import json_bytes, summary_repr
from rover_cosim.common.rows import csv_bytes, every, indices
from rover_cosim.control.adaptive import AdaptiveController
from rover_cosim.control.calibration import Calibration
from rover_cosim.control.controller import InverseModelController
from rover_cosim.control.figures import fig10, tracking
from rover_cosim.identification.model_set import ModelMismatch, ModelSet
from rover_cosim.identification.online import Adaptation, adapt_model
from rover_cosim.identification.testbed_data import TestBedData
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.model import System
from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.library import Choice, as_choice, choose

from .campaign import Campaign
from .plants import add_plant_fmu, add_rover, hubs, rover_fmu, wire_hub
from .ruts import add_ruts
from .straight_run import RECORD_INTERVAL, STEP, STOP_TIME, check_options


@dataclass
class SimulationResult:
    """What ``run_simulation`` wrote and measured."""

    files: list[Path]                   # every file written, sorted
    record: dict[str, Any]              # simulation.json: parameters, hashes, wall times, checks
    tables: dict[str, pd.DataFrame]     # per plant ("monolithic", "cosim"): trajectories.csv columns
    rms: dict[str, pd.DataFrame]        # per plant: limb, rms_N (Table 3)
    ablation: pd.DataFrame              # limb, rms_lut_N, rms_fixed_load_N

    def checks_table(self) -> pd.DataFrame:
        """The checks of each plant (``checks``) by their labels, a column per plant."""
        plants = {"monolithic": "Rover.fmu", "cosim": f"RoverBody + {len(self.rms['cosim'])} Wheel"}
        return pd.DataFrame({plants.get(p, p): {CHECKS[k][0]: v for k, v in values.items() if k in CHECKS}
                             for p, values in self.record["checks"].items()})

    def __repr__(self) -> str:
        worst = {plant: f"{float(table['rms_N'].max()):.3g} N" for plant, table in self.rms.items()}
        return summary_repr("SimulationResult", self.files, largest_rms=worst)


def models_of(model: ModelSet | Path) -> ModelSet:
    """The identified models: ``model`` itself, or the model.json it names (read once here)."""
    return model if isinstance(model, ModelSet) else ModelSet.read(model)


def controller(models: ModelSet, **options: Any) -> InverseModelController:
    """The paper's controller block ``ctrl`` (``options``: its keyword arguments); the run tells it
    its step at the start."""
    return InverseModelController("ctrl", models, **options)


def _rover_options(choice: Choice | None) -> dict[str, Any]:
    """What the controller knows of the rover: its mass [kg] (the demand is M a, Eq. 16)."""
    return {"mass": choice.rover.mass} if choice is not None else {}


def _geometry(choice: Choice | None) -> dict[str, Any]:
    """Where the adaptive controller's telemetry places the hubs: x_limb [m], h_cog [m]."""
    return {"x_limb": choice.rover.x_limb, "h_cog": choice.rover.h_cog} if choice is not None else {}


def _closed_loop(name: str) -> SystemBuilder:
    return SystemBuilder(name).simulation(stop_time=STOP_TIME, step=STEP, algorithm="gauss-seidel")


def monolithic_system(fmu_dir: Path, model: ModelSet | Path, choice: Choice | None = None, *, ruts: bool = False,
                      **options: Any) -> System:
    """The closed loop on Rover.fmu (``options``: the controller's keyword arguments); with ``ruts``,
    a rut block gives each wheel the rut the wheels ahead left (multi-pass, ``jobs.ruts``)."""
    builder = monolithic_builder(fmu_dir, model, choice, **options)
    if ruts:
        add_ruts(builder, as_choice(choice), "rover", lambda i, name: f"rover.{name}[{i}]")
    return builder.build()


def monolithic_builder(fmu_dir: Path, model: ModelSet | Path, choice: Choice | None = None,
                       **options: Any) -> SystemBuilder:
    """monolithic_system's builder, for a caller that adds participants (e.g. a rut block) to it."""
    builder = _closed_loop("closed loop (monolithic)")
    plant = rover_fmu(fmu_dir, "Rover", choice)
    limbs = hubs(plant)
    add_plant_fmu(builder, "rover", plant, choice)
    builder.add_block("ctrl", controller(models_of(model), **{"wheels": len(limbs), **_rover_options(choice),
                                                              **options}))
    builder.connect("rover.x", "ctrl.x").connect("rover.v", "ctrl.v")
    for i in limbs:
        builder.connect(f"rover.Fz[{i}]", f"ctrl.W[{i}]").connect(f"ctrl.tau[{i}]", f"rover.tau[{i}]")
    return builder


def soil_and_wheel_of(models: ModelSet) -> tuple[Soil, Wheel]:
    """The soil and wheel the models were identified on (model.json's record; the paper's where it
    records none)."""
    soil, wheel = models.details.get("soil", {}).get("values"), models.details.get("wheel", {}).get("values")
    return (Soil(**soil) if soil else Soil()), (Wheel(**wheel) if wheel else Wheel())


def adapter_for(models: ModelSet, fmu_dir: Path, cache_dir: Path | None, lateral: bool = False,
                optional: bool = False) -> Callable[[TestBedData], Adaptation]:
    """What an adaptive block calls at the end of its calibration: the soil estimated from the data
    starting from the soil ``models`` were identified on (their wheel: the rover's own; the
    optional parameters too with ``optional``), the models identified again on SingleWheel.fmu of
    ``fmu_dir`` (the sweeps' cache in ``cache_dir``; None: their runs kept in memory), the lateral
    one too with ``lateral``."""
    prior, wheel = soil_and_wheel_of(models)
    degree = models.model().degree
    single_wheel = Path(fmu_dir) / "SingleWheel.fmu"
    cache = None if cache_dir is None else Path(cache_dir)

    def adapter(data: TestBedData) -> Adaptation:
        return adapt_model(data, single_wheel, wheel, prior, cache, degree, lateral, optional)

    return adapter


def adaptive_system(fmu_dir: Path, model: ModelSet | Path, choice: Choice | None = None, *,
                    calibration: Calibration = Calibration(), cache_dir: Path | None = None,
                    **options: Any) -> System:
    """The closed loop on Rover.fmu (on the soil and wheel of ``choice``) with the adaptive
    controller: a calibration phase, the soil estimated from the rover's telemetry starting from
    the soil the model was identified on (the wheel is that one too: the rover's own), the model
    identified again on SingleWheel.fmu (the sweep's cache in ``cache_dir``; None: its runs kept
    in memory), then the paper's law with it."""
    models = models_of(model)
    wheel = soil_and_wheel_of(models)[1]
    adapter = adapter_for(models, fmu_dir, cache_dir, optional=calibration.optional_parameters)
    builder = _closed_loop("closed loop (adaptive)")
    plant = rover_fmu(fmu_dir, "Rover", choice)
    add_plant_fmu(builder, "rover", plant, choice)
    block = AdaptiveController("ctrl", models, adapter, radius=wheel.r, inertia=wheel.J,
                               calibration=calibration,
                               **{**_rover_options(choice), **_geometry(choice), **options})
    builder.add_block("ctrl", block)
    builder.connect("rover.x", "ctrl.x").connect("rover.v", "ctrl.v")
    for i in hubs(plant):
        builder.connect(f"rover.Fz[{i}]", f"ctrl.W[{i}]").connect(f"ctrl.tau[{i}]", f"rover.tau[{i}]")
    connect_telemetry(builder, "rover", calibration, ("pitch",), hubs(plant))
    return builder.build()


def connect_telemetry(builder: SystemBuilder, plant: str, calibration: Calibration, angles: tuple[str, ...],
                      limbs: range) -> None:
    """The telemetry of an adaptive controller ``ctrl`` from the monolithic ``plant``: the body's
    ``angles``, each wheel's (of ``limbs``) spin, and its sinkage where the rover has a sensor."""
    for angle in angles:
        builder.connect(f"{plant}.{angle}", f"ctrl.{angle}")
    for i in limbs:
        builder.connect(f"{plant}.omega[{i}]", f"ctrl.omega[{i}]")
        if calibration.sinkage_sensor:
            builder.connect(f"{plant}.sinkage[{i}]", f"ctrl.sinkage[{i}]")


def cosim_system(fmu_dir: Path, model: ModelSet | Path, choice: Choice | None = None, *, ruts: bool = False,
                 **options: Any) -> System:
    """The closed loop on RoverBody + N Wheel (``options``: the controller's keyword arguments; ``ruts``
    as for monolithic_system, on the Wheel FMUs' rutDepth inputs)."""
    builder = _closed_loop("closed loop (cosim)")
    body = rover_fmu(fmu_dir, "RoverBody", choice)
    limbs = hubs(body)
    wheels = add_rover(builder, body, Path(fmu_dir) / "Wheel.fmu", len(limbs), choice, wire=False)
    builder.add_block("ctrl", controller(models_of(model), **{"wheels": len(limbs), **_rover_options(choice),
                                                              **options}))
    builder.connect("body.x", "ctrl.x").connect("body.v", "ctrl.v")
    for i, wheel in zip(limbs, wheels):
        wire_hub(builder, "body", wheel, i)
        builder.connect(f"body.W[{i}]", f"ctrl.W[{i}]").connect(f"ctrl.tau[{i}]", f"{wheel}.tau")
        builder.connect(f"ctrl.tau[{i}]", f"body.tau[{i}]")
    if ruts:
        add_ruts(builder, as_choice(choice), "body", lambda i, name: f"wheel{i}.{name}")
    return builder.build()


def trajectories(data: pd.DataFrame, plant: str) -> pd.DataFrame:
    """The recorded run in the columns of trajectories.csv."""
    if plant == "monolithic":
        body, wheel = "rover", lambda i, name: f"rover.{name}[{i}]"
    else:
        body, wheel = "body", lambda i, name: f"wheel{i}.{name}"
    table = {"time": data["time"], "x": data[f"{body}.x"], "v": data[f"{body}.v"]}
    for i in indices(data.columns, "ctrl.tau"):
        table[f"tau_{i}"] = data[f"ctrl.tau[{i}]"]
        for name in ("Tx", "Fz", "sinkage", "slip", "Fx"):
            table[f"{name}_{i}"] = data[wheel(i, name)]
        table[f"Fx_des_{i}"] = data[f"ctrl.Fx_des[{i}]"]
    return pd.DataFrame(table)


def rms(table: pd.DataFrame) -> pd.DataFrame:
    limbs = indices(table.columns, "Fx_des")
    return pd.DataFrame({"limb": list(limbs),
                         "rms_N": [float(np.sqrt(np.mean((table[f"Fx_{i}"] - table[f"Fx_des_{i}"]) ** 2)))
                                   for i in limbs]})


#: What ``checks`` measures of a run: its key -> (label with unit, format).
CHECKS = {"time_to_98_percent_s": ("time to reach 0.98 m/s [s]", "{:.2f}"),
          "max_abs_v_error_after_m_s": ("largest |v - 1 m/s| afterwards [m/s]", "{:.4f}"),
          "final_v_m_s": ("final velocity [m/s]", "{:.4f}"),
          "Fz1_min_while_accelerating_N": ("least load, limb 1 (front), accelerating [N]", "{:.1f}"),
          "Fz3_max_while_accelerating_N": ("largest load, rear limb (3 of 6), accelerating [N]", "{:.1f}"),
          "Fz_at_start_N": ("load at the start [N]", "{:.1f}")}


def checks(table: pd.DataFrame) -> dict[str, Any]:
    v = table["v"].to_numpy()
    reached = np.nonzero(v >= 0.98)[0]
    after = v[reached[0]:] if reached.size else np.array([])
    accelerating = table["time"] < (table["time"][reached[0]] if reached.size else 0.0)
    rear = len(indices(table.columns, "Fz")) // 2  # the left side's rear limb: 3 of six
    fz1, fz3 = table["Fz_1"][accelerating], table[f"Fz_{max(rear, 1)}"][accelerating]
    return {"time_to_98_percent_s": float(table["time"][reached[0]]) if reached.size else None,
            "max_abs_v_error_after_m_s": float(np.abs(after - 1.0).max()) if after.size else None,
            "final_v_m_s": float(v[-1]),
            "Fz1_min_while_accelerating_N": float(fz1.min()) if len(fz1) else None,
            "Fz3_max_while_accelerating_N": float(fz3.max()) if len(fz3) else None,
            "Fz_at_start_N": float(table["Fz_1"].iloc[0])}


def checked_models(model: Path, choice: Choice | None, allow_mismatch: bool) -> tuple[ModelSet, str | None]:
    """The models of ``model`` and why they do not belong to the soil and wheel of ``choice``
    (None: they do); ModelMismatch naming both unless ``allow_mismatch``."""
    models = ModelSet.read(model)
    choice = choice or choose()
    why = models.mismatch(asdict(choice.soil), asdict(choice.wheel), choice.soil_name, choice.wheel_name)
    if why is not None and not allow_mismatch:
        raise ModelMismatch(why)
    return models, why


def run_simulation(fmu_dir: Path, model: Path, out_dir: Path, choice: Choice | Soil | Wheel | None = None, *,
                   allow_model_mismatch: bool = False, progress: Callable[[float], None] | None = None,
                   record_interval: float = RECORD_INTERVAL, adapt: Calibration | None = None,
                   ruts: bool = False) -> SimulationResult:
    """The closed loop on both plants and the ablation; writes every file (all or none). The
    FMUs run on the soil and wheel of ``choice`` (default: the paper's); a model identified on
    another soil or wheel is refused (ModelMismatch) unless ``allow_model_mismatch``; ``progress``
    is told how far the three runs are; the trajectory files keep a row every ``record_interval``
    [s] (the metrics and figures use every step). ``adapt``: also the run with the adaptive
    controller and that calibration (trajectories_adaptive.csv, rms_adaptive.csv, and what it
    estimated and when it switched in simulation.json's ``adaptation``). ``ruts``: the three runs with
    multi-pass ruts (``jobs.ruts``; the adaptive one without)."""
    choice = as_choice(choice)
    check_options(record_interval, adapt)  # refused before anything runs
    campaign = Campaign("rover-cosim simulate", 4 if adapt else 3, progress)
    results: dict[str, Any] = {}
    tables: dict[str, pd.DataFrame] = {}
    fmu_dir = Path(fmu_dir).resolve()
    models, mismatch = checked_models(model, choice, allow_model_mismatch)
    static_load = choice.rover.static_wheel_load(choice.soil.gravity)  # N, the fixed load of the ablation
    cosim_label = f"RoverBody + {choice.rover.wheels} Wheel"
    systems = {"monolithic": monolithic_system(fmu_dir, models, choice, ruts=ruts),
               "cosim": cosim_system(fmu_dir, models, choice, ruts=ruts),
               "fixed_load_ablation": monolithic_system(fmu_dir, models, choice, ruts=ruts, fixed_load=static_load)}
    if adapt is not None:
        systems["adaptive"] = adaptive_system(fmu_dir, models, choice, calibration=adapt)
    outcomes = campaign.run_all(systems)  # side by side on the cores
    for plant in ("monolithic", "cosim"):
        tables[plant] = trajectories(outcomes[plant].data, plant)
        results[plant] = checks(tables[plant])
    ablation = rms(trajectories(outcomes["fixed_load_ablation"].data, "monolithic"))
    adaptation = None
    if adapt is not None:
        tables["adaptive"] = trajectories(outcomes["adaptive"].data, "monolithic")
        results["adaptive"] = checks(tables["adaptive"])
        block = next(b.block for b in campaign.ran["adaptive"].blocks if b.name == "ctrl")
        after = tables["adaptive"][tables["adaptive"]["time"] >= adapt.duration]
        adaptation = {**block.report(), "rms_after_calibration_N": rms(after)["rms_N"].tolist(),  # type: ignore[attr-defined]
                      "rms_after_calibration_nominal_model_N":
                          rms(tables["monolithic"][tables["monolithic"]["time"] >= adapt.duration])["rms_N"].tolist()}
    rms_mono, rms_cosim = rms(tables["monolithic"]), rms(tables["cosim"])
    ablation_table = pd.DataFrame({"limb": rms_mono["limb"], "rms_lut_N": rms_mono["rms_N"],
                                   "rms_fixed_load_N": ablation["rms_N"]})
    record = campaign.record({"stop_time_s": STOP_TIME, "model": str(model), "record_interval_s": record_interval,
                              "fixed_load_ablation_N": static_load,
                              **({"ruts": "multi-pass ruts (jobs.ruts.RutBlock on the wheels' rutDepth)"} if ruts
                                 else {})},
                             fmu_dir=fmu_dir, fmus=(rover_fmu(fmu_dir, "Rover", choice),
                                                    rover_fmu(fmu_dir, "RoverBody", choice), "Wheel"),
                             model=model, choice=choice,
                             mismatch=mismatch, checks=results,
                             rms_N={"monolithic": rms_mono["rms_N"].tolist(), "cosim": rms_cosim["rms_N"].tolist(),
                                    "fixed_load_ablation": ablation["rms_N"].tolist()})
    if adaptation is not None:
        record["adaptation"] = adaptation
    out = Path(out_dir)
    files = {
        out / "trajectories.csv": csv_bytes(every(tables["monolithic"], record_interval, STEP), "%.8g"),
        out / "trajectories_cosim.csv": csv_bytes(every(tables["cosim"], record_interval, STEP), "%.8g"),
        out / "rms.csv": rms_mono.to_csv(index=False, float_format="%.4f").encode(),
        out / "rms_cosim.csv": rms_cosim.to_csv(index=False, float_format="%.4f").encode(),
        out / "ablation_fixed_load.csv": ablation_table.to_csv(index=False, float_format="%.4f").encode(),
        out / "fig10_closed_loop.png": fig10(tables["monolithic"], "Rover.fmu"),
        out / "fig10_closed_loop_cosim.png": fig10(tables["cosim"], cosim_label),
        out / "fig_tracking.png": tracking(tables["monolithic"], tables["cosim"], cosim_label=cosim_label),
        out / "simulation.json": json_bytes(record),
    }
    if adapt is not None:
        files[out / "trajectories_adaptive.csv"] = csv_bytes(every(tables["adaptive"], record_interval, STEP), "%.8g")
        files[out / "rms_adaptive.csv"] = rms(tables["adaptive"]).to_csv(index=False, float_format="%.4f").encode()
        files[out / "fig10_closed_loop_adaptive.png"] = fig10(tables["adaptive"], "Rover.fmu, adaptive controller")
    written = campaign.write(out, files, stale=("fig10_*", "fig_tracking.*", "*_adaptive.*"))  # the paths' stay
    return SimulationResult(written, record, tables, {"monolithic": rms_mono, "cosim": rms_cosim},
                            ablation_table)
