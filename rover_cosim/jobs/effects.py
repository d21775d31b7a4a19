"""``rover-cosim simulate --only effects``: the paper's straight run (Sec. 4, Table 3) with each wheel
effect of issue 48 switched on alone (grousers, slip-sinkage, multi-pass ruts), on Rover.fmu with the
controller and the model identified on the smooth wheel: how much each effect changes the sinkage of
every wheel and the controller's force error (the ablation of Table 3), and the trends each model
claims (drawbar pull against grouser height and count, sinkage against slip).

results/simulation/
  effects_ablation.csv   variant, limb, rms_N (RMS(Fx - Fx_des), Table 3), sinkage_mean_m and slip_mean
                         (cruise, t >= 10 s) per wheel
  effects_sinkage.csv    wheel, sinkage [m] at cruise of every variant side by side
  effects_trends.png     drawbar pull at 20 % slip against grouser height and count; sinkage against slip
  effects.json           parameters, the variants' wheel and soil, FMU hashes, versions
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rover_cosim.common.outputs import json_bytes
from rover_cosim.terramechanics.library import Choice, as_choice
from rover_cosim.terramechanics.sinkage import wheel_state

from . import effects_figures
from .campaign import Campaign
from .effects_figures import Trends
from .plants import rover_fmu
from .ruts import RutBlock
from .simulate import STEP, checked_models, monolithic_builder, rms, trajectories

#: The variants in the order they run, and what each switches on.
VARIANTS = {"smooth": "the paper's smooth wheel on virgin soil",
            "grousers": "grousers (terramechanics.grousers)",
            "slip_sinkage": "slip-sinkage (Soil.n_slip)",
            "multi_pass": "multi-pass ruts (RutBlock on the rutDepth inputs)"}
#: Grousers for a wheel that has none of its own: 10 mm, 24 around the rim (illustrative: the size
#: class of the single-wheel test beds' grousers, e.g. Ding et al. 2011's 10 mm).
DEFAULT_GROUSERS = (0.01, 24.0)
#: Slip-sinkage growth of the sinkage exponent for a soil without its own (illustrative).
DEFAULT_N_SLIP = 0.5
CRUISE_FROM = 10.0  # s


@dataclass
class EffectsResult:
    files: list[Path]
    record: dict[str, Any]
    ablation: pd.DataFrame
    sinkage: pd.DataFrame


def variant_choice(choice: Choice, variant: str) -> Choice:
    """The choice with the variant's effect on: its own grousers or DEFAULT_GROUSERS, its own n_slip
    or DEFAULT_N_SLIP; the others unchanged."""
    if variant == "grousers" and not choice.wheel.grousered:
        height, count = DEFAULT_GROUSERS
        return replace(choice, wheel=replace(choice.wheel, grouser_height=height, grouser_count=count))
    if variant == "slip_sinkage" and choice.soil.n_slip == 0:
        return replace(choice, soil=replace(choice.soil, n_slip=DEFAULT_N_SLIP))
    return choice


def straight_system(fmu_dir: Path, models: Any, choice: Choice, variant: str) -> Any:
    """The monolithic straight run of ``variant`` on ``choice`` (its variant_choice: the effect on; a rut
    block on Rover.fmu's rutDepth for multi_pass)."""
    builder = monolithic_builder(fmu_dir, models, choice)
    if variant == "multi_pass":
        rover = choice.rover
        block = RutBlock("ruts", rover.x_limb, rover.y_limb, choice.wheel.b)
        builder.add_block("ruts", block)
        builder.connect("rover.x", "ruts.x")
        for i in range(1, block.wheels + 1):
            builder.connect(f"rover.sinkage[{i}]", f"ruts.sinkage[{i}]").connect(f"ruts.rutDepth[{i}]",
                                                                                  f"rover.rutDepth[{i}]")
    return builder.build()


def cruise(table: pd.DataFrame) -> pd.DataFrame:
    """Per wheel: the mean sinkage [m] and slip at cruise (t >= CRUISE_FROM)."""
    after = table[table["time"] >= CRUISE_FROM]
    wheels = sorted(int(c.split("_")[1]) for c in table.columns if c.startswith("sinkage_"))
    return pd.DataFrame({"wheel": wheels, "sinkage_mean_m": [float(after[f"sinkage_{i}"].mean()) for i in wheels],
                         "slip_mean": [float(after[f"slip_{i}"].mean()) for i in wheels]})


def trends(choice: Choice) -> Trends:
    """The models' trends on the choice's wheel (without its grousers) and soil at the rover's static
    wheel load: drawbar pull at 20 % slip against grouser height (24 grousers) and count (10 mm),
    sinkage against slip for some n_slip."""
    load = choice.rover.static_wheel_load(choice.soil.gravity)
    wheel, soil = replace(choice.wheel, grouser_height=0.0, grouser_count=0.0), choice.soil
    heights, counts, slips = np.linspace(0.0, 0.04, 9), np.arange(0.0, 49.0, 4.0), np.linspace(0.0, 0.8, 17)
    count_at, height_at = 24.0, 0.01
    pull_by_height = np.array([float(wheel_state(load, 0.2, replace(wheel, grouser_height=h, grouser_count=count_at),
                                                 soil).Fx) for h in heights])
    pull_by_count = np.array([float(wheel_state(load, 0.2, replace(wheel, grouser_height=height_at, grouser_count=n),
                                                soil).Fx) for n in counts])
    sinkage = {n_slip: wheel_state(load, slips, wheel, replace(soil, n_slip=n_slip)).sinkage
               for n_slip in (0.0, 0.25, 0.5, 1.0)}
    return Trends(heights, count_at, pull_by_height, counts, height_at, pull_by_count, slips, sinkage,
                  f"wheel r = {wheel.r:g} m, b = {wheel.b:g} m at {load:.0f} N on the chosen soil")


def run_effects(fmu_dir: Path, model: Path, out_dir: Path, choice: Choice | None = None, *,
                allow_model_mismatch: bool = False, progress: Callable[[float], None] | None = None) -> EffectsResult:
    """The four straight runs, the ablation and the trends; writes every file (all or none)."""
    choice = as_choice(choice)
    campaign = Campaign("rover-cosim simulate --only effects", len(VARIANTS), progress)
    fmu_dir = Path(fmu_dir).resolve()
    models, mismatch = checked_models(model, choice, allow_model_mismatch)
    chosen = {v: variant_choice(choice, v) for v in VARIANTS}
    rows, sinkage = [], {}
    for variant, variant_chosen in chosen.items():
        table = trajectories(campaign.run(variant, straight_system(fmu_dir, models, variant_chosen, variant)).data,
                             "monolithic")
        errors = rms(table).rename(columns={"limb": "wheel"})
        at_cruise = cruise(table).merge(errors, on="wheel")
        at_cruise.insert(0, "variant", variant)
        rows.append(at_cruise)
        sinkage[f"sinkage_{variant}_m"] = at_cruise["sinkage_mean_m"].to_numpy()
    ablation = pd.concat(rows, ignore_index=True)[["variant", "wheel", "rms_N", "sinkage_mean_m", "slip_mean"]]
    sinkage_table = pd.DataFrame({"wheel": rows[0]["wheel"], **sinkage})
    variants = {v: {"wheel": asdict(c.wheel), "soil_n_slip": c.soil.n_slip, "what": VARIANTS[v]}
                for v, c in chosen.items()}
    record = campaign.record({"stop_time_s": 20.0, "step_s": STEP, "cruise_from_s": CRUISE_FROM, "model": str(model),
                              "variants": variants,
                              "controller": "the model identified on the smooth wheel, in every variant"},
                             fmu_dir=fmu_dir, fmus=(rover_fmu(fmu_dir, "Rover", choice),), model=model, choice=choice,
                             mismatch=mismatch)
    out = Path(out_dir)
    files = {out / "effects_ablation.csv": ablation.to_csv(index=False, float_format="%.6g").encode(),
             out / "effects_sinkage.csv": sinkage_table.to_csv(index=False, float_format="%.6g").encode(),
             out / "effects_trends.png": effects_figures.trends(trends(choice)),
             out / "effects.json": json_bytes(record)}
    written = campaign.write(out, files)
    return EffectsResult(written, record, ablation, sinkage_table)
