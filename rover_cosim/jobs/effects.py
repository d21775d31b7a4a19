"""``rover-cosim simulate --only effects``: the paper's straight run (Sec. 4, Table 3) with each wheel
effect of issue 48 switched on alone on the chosen wheel and soil made smooth (grousers, slip-sinkage,
multi-pass ruts), on Rover.fmu, with the controller and model given (identified on the chosen wheel and
soil: for the paper's, the smooth wheel) and with the variant's own model, identified again on
SingleWheel.fmu with its wheel and soil (the identification plan for it, ``identification.plan.plan_for``)
where these are not the chosen ones: how much each effect changes the sinkage of every wheel, Table 1's
Fit of both models on the variant's test bed, and the controller's force error with each (the ablation
of Table 1 and Table 3); and the trends each model claims (drawbar pull against grouser height and
count, sinkage against slip, with a source's measurement). Multi-pass takes the smooth variant's model:
a single-wheel test bed runs one pass on virgin soil. And the path following's turn
(``path_following``, SteerableRover.fmu) on the chosen wheel and soil without and with ruts: in a turn
the rear wheels leave the front wheels' tracks in part (off-tracking), so the ruts' share differs on
the straights and the arc.

results/simulation/
  effects_ablation.csv   variant, model (given_model / own_model), wheel, rms_N (RMS(Fx - Fx_des),
                         Table 3), sinkage_mean_m and slip_mean (cruise, t >= 10 s)
  effects_table1.csv     variant, load_N, fit_percent of the given model and of the variant's own
                         model (Table 1's Eq. (15) on the variant's validation staircase)
  effects_sinkage.csv    wheel, sinkage [m] at cruise of every variant side by side (given model)
  effects_path_sinkage.csv  the turn on the chosen wheel and soil: wheel, phase (straight before the arc,
                         arc), sinkage [m] on virgin soil and with ruts, the mean rut depth [m] under the wheel
  effects_model_<variant>.json   the models identified for the variants whose wheel or soil is not the
                         chosen one (for the paper's: grousers, slip_sinkage)
  effects_trends.png     drawbar pull at 20 % slip against grouser height and count; sinkage against slip
  effects.json           parameters, the variants' wheel, soil and plan, FMU hashes, versions
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rover_cosim.common.outputs import file_sha256, json_bytes
from rover_cosim.common.rows import indices
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.identification.online import identify_on_soil
from rover_cosim.identification.plan import IdentificationPlan, plan_for
from rover_cosim.identification.sweep import SweepPlan
from rover_cosim.identification.testbed import shared_test_bed
from rover_cosim.identification.validate import validate
from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.library import Choice, as_choice, describe
from rover_cosim.terramechanics.sinkage import wheel_state

from . import effects_figures, path_following
from .campaign import Campaign
from .effects_figures import Trends
from .plants import rover_fmu
from .ruts import add_ruts
from .simulate import STEP, checked_models, monolithic_builder, rms, trajectories

#: The variants in the order they run, and what each switches on.
VARIANTS = {"smooth": "the paper's smooth wheel on virgin soil",
            "grousers": "grousers (terramechanics.grousers)",
            "slip_sinkage": "slip-sinkage (Soil.n_slip)",
            "multi_pass": "multi-pass ruts (RutBlock on the rutDepth inputs)"}
#: The variants a test bed identifies (a single-wheel test bed runs one pass: multi_pass takes smooth's).
IDENTIFIABLE = ("smooth", "grousers", "slip_sinkage")
#: The ablation's two controllers: the model given (--model, identified on the chosen wheel and soil:
#: the smooth wheel's for the paper's), and the variant's own, identified with its wheel and soil.
GIVEN_MODEL, OWN_MODEL = "given_model", "own_model"
#: Slip-sinkage as measured: at 60 % slip lugged wheels sank 3-7 times their static sinkage (Ding, Gao,
#: Deng, Tao, "Wheel slip-sinkage and its prediction model of lunar rover", J. Cent. South Univ. Technol.
#: 17:129-135, 2010, abstract; three wheels with lugs of several heights and counts on a lunar simulant).
SLIP_SINKAGE_REPORTED = (0.6, 3.0, 7.0, "Ding et al. 2010")
#: Grousers for a wheel that has none of its own: 10 mm, 24 around the rim (illustrative: the size
#: class of the single-wheel test beds' grousers, e.g. Ding et al. 2011's 10 mm).
DEFAULT_GROUSERS = (0.01, 24.0)
#: Slip-sinkage growth of the sinkage exponent for a soil without its own: inside the band that gives
#: SLIP_SINKAGE_REPORTED on the paper's soil (n_slip 0.79-1.99; ``n_slip_band``).
DEFAULT_N_SLIP = 1.0
CRUISE_FROM = 10.0  # s


@dataclass
class EffectsResult:
    files: list[Path]
    record: dict[str, Any]
    ablation: pd.DataFrame
    sinkage: pd.DataFrame
    table1: pd.DataFrame
    path_sinkage: pd.DataFrame


def variant_choice(choice: Choice, variant: str) -> Choice:
    """The choice's wheel and soil with the variant's effect alone on: ``smooth`` and ``multi_pass``
    without grousers and slip-sinkage; ``grousers`` with the wheel's own grousers or DEFAULT_GROUSERS;
    ``slip_sinkage`` with the soil's own n_slip or DEFAULT_N_SLIP."""
    smooth = replace(choice, wheel=replace(choice.wheel, grouser_height=0.0, grouser_count=0.0),
                     soil=replace(choice.soil, n_slip=0.0))
    if variant == "grousers":
        height, count = ((choice.wheel.grouser_height, choice.wheel.grouser_count) if choice.wheel.grousered
                         else DEFAULT_GROUSERS)
        return replace(smooth, wheel=replace(smooth.wheel, grouser_height=height, grouser_count=count))
    if variant == "slip_sinkage":
        return replace(smooth, soil=replace(smooth.soil, n_slip=choice.soil.n_slip or DEFAULT_N_SLIP))
    return smooth


def _same_plant(a: Choice, b: Choice) -> bool:
    return a.wheel == b.wheel and a.soil == b.soil


def reidentified(single_wheel: Path, models: ModelSet, choice: Choice, plan: IdentificationPlan,
                 variant: str) -> ModelSet:
    """``models`` with the longitudinal model identified again by the sweep on ``single_wheel`` (on every
    core) with ``choice``'s soil and wheel (the variant's), by ``plan`` (the identification plan for
    it); the lateral model kept (the straight run does not steer)."""
    import tempfile

    label = models.recommended
    with tempfile.TemporaryDirectory(prefix="rover-cosim-effects-") as cache:
        model, _ = identify_on_soil(single_wheel, choice.soil, choice.wheel, Path(cache), models.model().degree,
                                    SweepPlan(loads=plan.loads, torques=plan.torques), plan.fit_torque_max,
                                    workers=None)
    return ModelSet(label, {label: model}, models.lateral, {
        "identified_for": f"the wheel effects' ablation, variant {variant} (rover-cosim simulate --only effects)",
        "identification_plan": plan.to_dict(), "fmu": {"path": str(single_wheel), "sha256": file_sha256(single_wheel)},
        **describe(choice)}, source=f"effects_model_{variant}.json")


def table1(single_wheel: Path, choice: Choice, plan: IdentificationPlan, models: dict[str, ModelSet]) -> pd.DataFrame:
    """Table 1 on ``choice``'s test bed (SingleWheel.fmu with its soil and wheel): the Fit [%] of
    Eq. (15) of each of ``models`` (by label) on the validation staircase of ``plan`` (the
    identification plan for ``choice``)."""
    bed = shared_test_bed(single_wheel)
    bed.parameters = SweepPlan(soil=choice.soil, wheel=choice.wheel).parameters
    fits = validate(bed, {label: m.model() for label, m in models.items()}, plan.validation_loads,
                    plan.validation_torques).fit
    return fits[["load_N", *(f"fit_percent_{label}" for label in models)]]


def straight_system(fmu_dir: Path, models: Any, choice: Choice, variant: str) -> Any:
    """The monolithic straight run of ``variant`` on ``choice`` (its variant_choice: the effect on; a rut
    block on Rover.fmu's rutDepth for multi_pass)."""
    builder = monolithic_builder(fmu_dir, models, choice)
    if variant == "multi_pass":
        add_ruts(builder, choice, "rover", lambda i, name: f"rover.{name}[{i}]")
    return builder.build()


#: The path scenario run without and with ruts.
PATH_SCENARIO = "turn"


def path_system(fmu_dir: Path, models: ModelSet, choice: Choice, ruts: bool,
                straight: float = path_following.STRAIGHT) -> Any:
    """The path following's PATH_SCENARIO on SteerableRover.fmu (straights of ``straight`` [m]); with
    ``ruts``, a rut block in the plane on its rutDepth inputs."""
    builder = path_following.monolithic_builder(fmu_dir, models, PATH_SCENARIO, choice=choice, straight=straight)
    if ruts:
        add_ruts(builder, choice, "rover", lambda i, name: f"rover.{name}[{i}]", planar=True)
    return builder.build()


def path_phases(data: pd.DataFrame, straight: float) -> pd.DataFrame:
    """Per wheel and phase of the turn (``straight``: on the first straight after its first metre;
    ``arc``: the reference on the arc), the mean sinkage [m] and, where the run had ruts, the mean rut
    depth [m] under the wheel."""
    table = path_following.trajectories(data, cosim=False)
    length = path_following.scenario_path(PATH_SCENARIO, straight).length
    phases = {"straight": (table["s"] > 1.0) & (table["s"] < straight),
              "arc": (table["s"] >= straight) & (table["s"] <= length - straight)}
    wheels = indices(data.columns, "ctrl.tau")
    rows = []
    for phase, rows_in in phases.items():
        for i in wheels:
            rut = data.get(f"ruts.rutDepth[{i}]")
            rows.append({"wheel": i, "phase": phase, "sinkage_m": float(table.loc[rows_in, f"sinkage_{i}"].mean()),
                         "rut_depth_m": float(rut[rows_in.to_numpy()].mean()) if rut is not None else 0.0})
    return pd.DataFrame(rows)


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
               for n_slip in (0.0, 0.25, 0.5, 1.0, 2.0)}
    return Trends(heights, count_at, pull_by_height, counts, height_at, pull_by_count, slips, sinkage,
                  f"wheel r = {wheel.r:g} m, b = {wheel.b:g} m at {load:.0f} N on the chosen soil",
                  SLIP_SINKAGE_REPORTED, n_slip_band(wheel, soil, load))


def sinkage_ratio(wheel: Wheel, soil: Soil, load: float, n_slip: float, slip: float) -> float:
    """The sinkage at ``slip`` over the static sinkage [1] under ``load`` [N] with ``n_slip``; inf where the
    wheel sinks to its radius."""
    try:
        state = wheel_state(load, np.array([0.0, slip]), wheel, replace(soil, n_slip=n_slip))
    except ValueError:
        return math.inf
    return float(state.sinkage[1] / state.sinkage[0])


def n_slip_band(wheel: Wheel, soil: Soil, load: float) -> tuple[float, float]:
    """The n_slip [1] whose sinkage ratio at the reported slip spans SLIP_SINKAGE_REPORTED's band on
    ``soil`` (the ratio grows with n_slip; bisection; nan where the band is out of reach)."""
    slip, low, high, _ = SLIP_SINKAGE_REPORTED

    def solve(ratio: float) -> float:
        below, above = 0.0, 4.0
        if not sinkage_ratio(wheel, soil, load, below, slip) < ratio < sinkage_ratio(wheel, soil, load, above, slip):
            return math.nan
        for _ in range(50):
            middle = 0.5 * (below + above)
            below, above = (middle, above) if sinkage_ratio(wheel, soil, load, middle, slip) < ratio else (below,
                                                                                                           middle)
        return 0.5 * (below + above)

    return solve(low), solve(high)


def run_effects(fmu_dir: Path, model: Path, out_dir: Path, choice: Choice | None = None, *,
                allow_model_mismatch: bool = False, progress: Callable[[float], None] | None = None,
                straight: float = path_following.STRAIGHT) -> EffectsResult:
    """The straight runs (each variant with the smooth wheel's model, grousers and slip-sinkage also with
    their own), the identifications, Table 1, the ablation, the turn without and with ruts (its straights
    ``straight`` [m] long) and the trends; writes every file (all or none)."""
    choice = as_choice(choice)
    fmu_dir = Path(fmu_dir).resolve()
    single_wheel = fmu_dir / "SingleWheel.fmu"
    models, mismatch = checked_models(model, choice, allow_model_mismatch)
    chosen = {v: variant_choice(choice, v) for v in VARIANTS}
    # the variant's own models: the given ones where its wheel and soil are the choice's
    plans = {v: plan_for(chosen[v]) for v in IDENTIFIABLE}
    own = {v: models if _same_plant(chosen[v], choice) else reidentified(single_wheel, models, chosen[v], plans[v], v)
           for v in IDENTIFIABLE}
    own["multi_pass"], plans["multi_pass"] = own["smooth"], plans["smooth"]  # the same wheel and soil
    runs = sum(1 if own[v] is models else 2 for v in VARIANTS) + 2
    campaign = Campaign("rover-cosim simulate --only effects", runs, progress)
    fits = []
    for variant in IDENTIFIABLE:
        fit = table1(single_wheel, chosen[variant], plans[variant], {GIVEN_MODEL: models, OWN_MODEL: own[variant]})
        fit.insert(0, "variant", variant)
        fits.append(fit)
    rows, sinkage = [], {}
    planned = [(variant, label, variant if label == GIVEN_MODEL else f"{variant}_{label}", controlled)
               for variant in chosen for label, controlled in ((GIVEN_MODEL, models), (OWN_MODEL, own[variant]))
               if not (label == OWN_MODEL and controlled is models)]
    systems = {key: straight_system(fmu_dir, controlled, chosen[variant], variant)
               for variant, _, key, controlled in planned}
    for ruts in (False, True):
        systems[f"{PATH_SCENARIO}{'_ruts' if ruts else ''}"] = path_system(fmu_dir, models, choice, ruts, straight)
    outcomes = campaign.run_all(systems)  # side by side on the cores
    for variant, label, key, _ in planned:
        table = trajectories(outcomes[key].data, "monolithic")
        at_cruise = cruise(table).merge(rms(table).rename(columns={"limb": "wheel"}), on="wheel")
        at_cruise.insert(0, "model", label)
        at_cruise.insert(0, "variant", variant)
        rows.append(at_cruise)
        if label == GIVEN_MODEL:
            sinkage[f"sinkage_{variant}_m"] = at_cruise["sinkage_mean_m"].to_numpy()
    turn = {ruts: path_phases(outcomes[f"{PATH_SCENARIO}{'_ruts' if ruts else ''}"].data, straight)
            for ruts in (False, True)}
    path_sinkage = turn[False][["wheel", "phase"]].assign(
        sinkage_virgin_m=turn[False]["sinkage_m"], sinkage_ruts_m=turn[True]["sinkage_m"],
        rut_depth_m=turn[True]["rut_depth_m"])
    ablation = pd.concat(rows, ignore_index=True)[["variant", "model", "wheel", "rms_N", "sinkage_mean_m",
                                                   "slip_mean"]]
    table_1 = pd.concat(fits, ignore_index=True)
    sinkage_table = pd.DataFrame({"wheel": rows[0]["wheel"], **sinkage})
    variants = {v: {"wheel": asdict(c.wheel), "soil_n_slip": c.soil.n_slip, "what": VARIANTS[v],
                    "identification_plan": plans[v].to_dict() if own[v] is not models else None}
                for v, c in chosen.items()}
    trend = trends(choice)
    record = campaign.record({"stop_time_s": 20.0, "step_s": STEP, "cruise_from_s": CRUISE_FROM, "model": str(model),
                              "path": {"scenario": PATH_SCENARIO, "straight_m": straight,
                                       "stop_time_s": path_following.stop_time(PATH_SCENARIO, straight)},
                              "variants": variants,
                              "slip_sinkage_reported": {"slip": SLIP_SINKAGE_REPORTED[0],
                                                        "sinkage_ratio": list(SLIP_SINKAGE_REPORTED[1:3]),
                                                        "source": SLIP_SINKAGE_REPORTED[3],
                                                        "n_slip_band": list(trend.n_slip_band)},
                              "controllers": {GIVEN_MODEL: "the model given (--model), identified on the chosen "
                                                           "wheel and soil",
                                              OWN_MODEL: "the variant's model, identified again on SingleWheel.fmu "
                                                         "with its wheel and soil (multi_pass: smooth's)"}},
                             fmu_dir=fmu_dir, model=model, choice=choice, mismatch=mismatch,
                             fmus=(rover_fmu(fmu_dir, "Rover", choice), rover_fmu(fmu_dir, "SteerableRover", choice),
                                   "SingleWheel"))
    out = Path(out_dir)
    files = {out / "effects_ablation.csv": ablation.to_csv(index=False, float_format="%.6g").encode(),
             out / "effects_table1.csv": table_1.to_csv(index=False, float_format="%.3f").encode(),
             out / "effects_sinkage.csv": sinkage_table.to_csv(index=False, float_format="%.6g").encode(),
             out / "effects_path_sinkage.csv": path_sinkage.to_csv(index=False, float_format="%.6g").encode(),
             **{out / f"effects_model_{v}.json": own[v].to_json() for v in IDENTIFIABLE if own[v] is not models},
             out / "effects_trends.png": effects_figures.trends(trend),
             out / "effects.json": json_bytes(record)}
    written = campaign.write(out, files)
    return EffectsResult(written, record, ablation, sinkage_table, table_1, path_sinkage)
