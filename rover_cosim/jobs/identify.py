"""``make identify``: sweep, fits, validation and every output file, written all at once.

results/identification/
  runs.csv         every recorded run, long format (load_N, torque_N_m, time, tau, slip, Fx, ...),
                   a row every record_interval (1 ms; the sweep samples every 0.1 ms)
  steps.csv        per run: settled slip and Fx, fitted K and T
  model.json       LUT grids, K and T tables, Fx coefficients of both models, the plan, FMU hash
  fit_table.csv    load_N, fit_percent (the recommended model) at 275, 575, 875 N
  fit_models.csv   Fit of the linear (Eq. 14) and the quadratic model beside the paper's Table 1
  fit_detail.csv   per load and torque level: settled Fx and slip of plant and models
  failures.csv     runs that failed, with their error (empty when none did)
  fig5_fx_vs_slip.png, fig6_a_of_W.png, fig7_b_of_W.png, fig8_validation_575N.png,
  fig_model_coefficients.png (the recommended model's c_k(W))
  lateral_runs.csv       every run of the lateral sweep (slip angles 0-30 deg), long format
  lateral_steps.csv      per lateral run: settled slip, Fx, Fy, whether it still rolls
  lateral_fit_table.csv  load_N, slip_angle_deg, fit_percent (Eq. 15) of the lateral model at 275,
                         575, 875 N and 7.5, 12.5 deg; its largest settled error
  lateral_forms.csv      every candidate form tried: coefficients, training RMS, Fits
  lateral_trends.csv     Ishigami's side-force trends, measured on the sweep
  fig_lateral_fy.png, fig_lateral_coefficients.png, fig_lateral_validation_575N.png
  identification.json  what ran: parameters, versions, wall times
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import pandas as pd

from rover_cosim.common.outputs import file_sha256, json_bytes, run_record, summary_repr, write_all
from rover_cosim.common.rows import csv_bytes, every, steps_between_rows
from rover_cosim.identification import figures, lateral_figures
from rover_cosim.identification.fits import SLIP_FIT_RANGE, fx_per_load, identify, step_table
from rover_cosim.identification.lateral import (
    FORMS,
    LATERAL_SAMPLE_TIME,
    LATERAL_SLIP_ANGLES_DEG,
    LateralModel,
    identify_lateral,
    ishigami_trends,
    lateral_table,
    per_load_coefficients,
    training_rms,
)
from rover_cosim.identification.lateral_validation import LateralValidation, validate_lateral
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.identification.plan import IdentificationPlan, plan_for
from rover_cosim.identification.sweep import SweepOutcome, SweepPlan, run_sweep
from rover_cosim.identification.testbed import RECORDED, shared_test_bed
from rover_cosim.identification.validate import validate
from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.library import Choice, as_choice, describe, soil_label

#: Rows kept in runs.csv [s]: 1 ms (the sweep samples every 0.1 ms; 10x smaller, as the lateral runs).
RECORD_INTERVAL = 1e-3
MODELS = {"quadratic": 2, "linear": 1}  # label -> degree in slip; the first is recommended
RECOMMENDED = "quadratic"
#: The lateral sweep: the longitudinal sweep's loads and torques at slip angles 0-30 deg.
LATERAL_PLAN = SweepPlan(slip_angles_deg=LATERAL_SLIP_ANGLES_DEG, sample_time=LATERAL_SAMPLE_TIME)


@dataclass
class IdentificationResult:
    """What ``run_identification`` wrote and found."""

    files: list[Path]           # every file written, sorted
    fit: pd.DataFrame           # Table 1: load_N, fit_percent (recommended model) and both models' Fits
    sweep: SweepOutcome          # the sweep's runs, failures and counts
    record: dict[str, Any]      # identification.json: parameters, versions, wall times
    model: dict[str, Any]       # model.json as written
    lateral_sweep: SweepOutcome  # the lateral sweep
    lateral_fit: pd.DataFrame    # lateral_fit_table.csv

    def __repr__(self) -> str:
        fits = ", ".join(f"{w:g} N: {f:.1f} %" for w, f in zip(self.fit["load_N"], self.fit["fit_percent"]))
        return summary_repr("IdentificationResult", self.files, fit=f"[{fits}]",
                            runs=f"{self.sweep.computed} computed, {self.sweep.cached} cached")


def _sweep(fmu_path: Path, plan: SweepPlan, cache_dir: Path, workers: int | None, scheduler: str | None,
           progress: Callable[[float], None] | None, run_timeout: float | None = None) -> SweepOutcome:
    sweep = run_sweep(fmu_path, plan, cache_dir, workers=workers, scheduler=scheduler, progress=progress,
                      run_timeout=run_timeout)
    if not sweep.runs:
        raise RuntimeError(f"every run of the sweep failed; first error: {next(iter(sweep.failures.values()))}")
    return sweep


def _long(runs: dict, columns: list[str], interval: float | None = None, sample_time: float = 1.0) -> pd.DataFrame:
    """The runs one below the other, each row tagged with its case; with ``interval`` [s], a row
    every ``interval`` of each run (sampled every ``sample_time`` [s]) and its last one."""
    frames = [(run if interval is None else every(run, interval, sample_time)).assign(
        load_N=c.load, torque_N_m=c.torque, slip_angle_deg=c.slip_angle_deg) for c, run in sorted(runs.items())]
    return pd.concat(frames, ignore_index=True)[columns]


def _lateral_files(out: Path, sweep: SweepOutcome, table: pd.DataFrame, models: dict[str, LateralModel],
                   validation: LateralValidation, middle: float,
                   torque_max: float) -> tuple[dict[Path, bytes], pd.DataFrame]:
    """lateral_*.csv and the lateral figures (``table``: the sweep's lateral_table), and the fit table."""
    recommended = next(iter(models.values()))
    detail = validation.detail
    error = (detail[f"Fy_{recommended.form.name}_N"] - detail["Fy_plant_N"]).abs()
    worst = detail.assign(error=error, relative=100 * error / detail["Fy_plant_N"].abs())
    worst = worst.groupby(["load_N", "slip_angle_deg"])[["error", "relative"]].max().reset_index()
    fit = validation.fit[["load_N", "slip_angle_deg", "fit_percent"]].merge(worst, on=["load_N", "slip_angle_deg"])
    fit = fit.rename(columns={"error": "max_settled_error_N", "relative": "max_settled_error_percent"})
    forms = pd.DataFrame([{"form": name, "basis": m.form.basis, "scales_deg": " ".join(map(str, m.form.scales_deg)),
                           "slip_degree": m.form.slip_degree, "load_degree": m.form.load_degree,
                           "coefficients": m.coefficients.size, "training_rms_N": training_rms(m, table, torque_max),
                           "min_fit_percent": validation.fit[f"fit_percent_{name}"].min(),
                           "mean_fit_percent": validation.fit[f"fit_percent_{name}"].mean()}
                          for name, m in models.items()])
    columns = ["load_N", "torque_N_m", "slip_angle_deg", "time", "tau", *RECORDED]
    return {
        out / "lateral_runs.csv": _long(sweep.runs, columns).to_csv(index=False, float_format="%.10g").encode(),
        out / "lateral_steps.csv": table.to_csv(index=False, float_format="%.10g").encode(),
        out / "lateral_fit_table.csv": fit.to_csv(index=False, float_format="%.3f").encode(),
        out / "lateral_fit_detail.csv": detail.to_csv(index=False, float_format="%.6g").encode(),
        out / "lateral_forms.csv": forms.to_csv(index=False, float_format="%.4g").encode(),
        out / "lateral_trends.csv": ishigami_trends(table, torque_max).to_csv(index=False).encode(),
        out / "fig_lateral_fy.png": lateral_figures.fy_against_beta_and_slip(table, recommended, torque_max),
        out / "fig_lateral_coefficients.png":
            lateral_figures.coefficient_curves(per_load_coefficients(table, recommended.form, torque_max),
                                               recommended),
        out / "fig_lateral_validation_575N.png":
            lateral_figures.validation_run(validation.runs[middle, 12.5], middle, 12.5, recommended.form.name),
    }, fit


def check_record_interval(record_interval: float, plan: SweepPlan | None = None) -> None:
    """ValueError unless ``record_interval`` [s] is a whole number of the plan's samples."""
    steps_between_rows(record_interval, (plan or SweepPlan()).sample_time)


def identification_plan(choice: Choice, plan: SweepPlan | None = None,
                        given: IdentificationPlan | None = None) -> IdentificationPlan:
    """The plan of a run: ``given``; else the loads and torques of an explicit sweep ``plan`` with
    the paper's fits and validation; else the plan for the choice (``plan.plan_for``: the paper's
    for the paper's soil, wheel and rover; NotDrivable before any sweep where it cannot be driven)."""
    if given is not None:
        return given
    if plan is not None:
        return IdentificationPlan(loads=plan.loads, torques=plan.torques, basis="the sweep plan given in code")
    return plan_for(choice)


def run_identification(fmu_path: Path, out_dir: Path, *, plan: SweepPlan | None = None,
                       lateral_plan: SweepPlan | None = None, workers: int | None = None,
                       scheduler: str | None = None, cache_dir: Path | None = None,
                       progress: Callable[[float], None] | None = None,
                       choice: Choice | Soil | Wheel | None = None,
                       record_interval: float = RECORD_INTERVAL,
                       run_timeout: float | None = None,
                       identification: IdentificationPlan | None = None) -> IdentificationResult:
    """Sweep, fit, validate and write every file of ``results/identification/`` (all or none):
    the paper's longitudinal model (``plan``) and the lateral model (``lateral_plan``), on the
    soil, wheel and rover of ``choice`` (default: the paper's), by the ``identification`` plan
    (loads, torques, fits and validation; default :func:`identification_plan`). runs.csv keeps a
    row every ``record_interval`` [s] of each run (a whole number of the plan's samples)."""
    started = time.perf_counter()
    choice = as_choice(choice)
    ident = identification_plan(choice, plan, identification)
    plan = replace(plan or SweepPlan(), loads=ident.loads, torques=ident.torques, soil=choice.soil,
                   wheel=choice.wheel)
    check_record_interval(record_interval, plan)  # a bad interval refused before anything runs
    lateral_plan = replace(lateral_plan or replace(LATERAL_PLAN, loads=ident.loads, torques=ident.torques),
                           soil=choice.soil, wheel=choice.wheel)
    cache_dir = cache_dir or out_dir / "cache"
    first, second = len(plan.cases()), len(lateral_plan.cases())

    def share(offset: int, count: int) -> Callable[[float], None] | None:
        if progress is None:
            return None
        return lambda fraction: progress((offset + fraction * count) / (first + second))

    sweep = _sweep(fmu_path, plan, cache_dir, workers, scheduler, share(0, first), run_timeout)
    lateral_sweep = _sweep(fmu_path, lateral_plan, cache_dir, workers, scheduler, share(first, second), run_timeout)
    table = step_table(sweep.at_slip_angle(0.0))
    torque_max = ident.fit_torque_max
    models = {label: identify(table, degree, torque_max) for label, degree in MODELS.items()}
    per_load = fx_per_load(table, 1, torque_max)
    bed = shared_test_bed(Path(fmu_path))
    bed.parameters = plan.parameters
    validation = validate(bed, models, ident.validation_loads, ident.validation_torques)
    lateral_table_ = lateral_table(lateral_sweep.runs)
    lateral_models = {form.name: identify_lateral(lateral_table_, form, torque_max) for form in FORMS}
    lateral_validation = validate_lateral(bed, lateral_models, ident.validation_loads,
                                          torques=ident.validation_torques)

    long = _long(sweep.runs, ["load_N", "torque_N_m", "time", "tau", *[c for c in RECORDED if c not in ("Fy", "beta")]],
                 record_interval, plan.sample_time)
    failed = sorted({**sweep.failures, **lateral_sweep.failures}.items())
    failures = pd.DataFrame([{"load_N": c.load, "torque_N_m": c.torque, "slip_angle_deg": c.slip_angle_deg,
                              "error": e} for c, e in failed],
                            columns=["load_N", "torque_N_m", "slip_angle_deg", "error"])
    recommended_lateral = lateral_models[FORMS[0].name]
    fmu_sha = file_sha256(Path(fmu_path))
    model_set = ModelSet(RECOMMENDED, models, recommended_lateral, {
        "lut_interpolation": "linear in 1/W and tau, extended linearly beyond the grid",
        "fx_fit": {"torque_max_N_m": torque_max, "slip_range": list(SLIP_FIT_RANGE)},
        "plan": asdict(plan),
        "identification_plan": ident.to_dict(),
        "fmu": {"path": str(fmu_path), "sha256": fmu_sha},
        **describe(choice),
        "failures": len(sweep.failures),
        "lateral_details": {"plan": asdict(lateral_plan),
                            "inputs": "load W [N], slip angle beta [rad], slip ratio (fit rule as fx_fit)",
                            "failures": len(lateral_sweep.failures)},
    })
    fit_models = validation.fit.drop(columns=["fit_percent"])
    record = run_record("rover-cosim identify", {"plan": asdict(plan), "lateral_plan": asdict(lateral_plan),
                                                 "identification_plan": ident.to_dict(),
                                                 "workers": workers, "scheduler": scheduler,
                                                 "record_interval_s": record_interval})
    record.update({**describe(choice), "fmu_sha256": fmu_sha, "runs_computed": sweep.computed + lateral_sweep.computed,
                   "runs_cached": sweep.cached + lateral_sweep.cached,
                   "runs_failed": len(failed), "sweep_wall_seconds": sweep.wall_seconds + lateral_sweep.wall_seconds,
                   "wall_seconds": time.perf_counter() - started, "cache_folder": str(sweep.cache_folder)})
    out = Path(out_dir)
    middle = ident.validation_loads[len(ident.validation_loads) // 2]  # 575 N: the paper's Fig. 8
    files = {
        out / "runs.csv": csv_bytes(long, "%.10g"),
        out / "steps.csv": table.to_csv(index=False, float_format="%.10g").encode(),
        out / "model.json": model_set.to_json(),
        out / "fit_table.csv":
            validation.fit[["load_N", "fit_percent"]].to_csv(index=False, float_format="%.3f").encode(),
        out / "fit_models.csv": fit_models.to_csv(index=False, float_format="%.3f").encode(),
        out / "fit_detail.csv": validation.detail.to_csv(index=False, float_format="%.6g").encode(),
        out / "failures.csv": failures.to_csv(index=False).encode(),
        out / "fig5_fx_vs_slip.png": figures.fig5_fx_vs_slip(table, per_load, soil_label(choice)),
        out / "fig6_a_of_W.png": figures.fig_coefficient(per_load, models["linear"], 1, "a(W)", "N",
                                                          "Fig. 6: slope a of Fx = a slip + b against load"),
        out / "fig7_b_of_W.png": figures.fig_coefficient(per_load, models["linear"], 0, "b(W)", "N",
                                                          "Fig. 7: offset b of Fx = a slip + b against load"),
        out / "fig8_validation_575N.png": figures.fig8_validation(validation.runs[middle], middle, list(MODELS),
                                                                  soil_label(choice)),
        out / "fig_model_coefficients.png":
            figures.fig_model_coefficients(fx_per_load(table, MODELS[RECOMMENDED]), models[RECOMMENDED]),
        out / "identification.json": json_bytes(record),
    }
    lateral_files, lateral_fit = _lateral_files(out, lateral_sweep, lateral_table_, lateral_models,
                                                lateral_validation, middle, torque_max)
    files.update(lateral_files)
    write_all(files, folder=out, stale=("*.png", "*.pdf", "*.svg"))  # its figures: all written anew
    return IdentificationResult(sorted(files), validation.fit, sweep, record, json.loads(files[out / "model.json"]),
                                lateral_sweep, lateral_fit)


def model_file(given: Path, fmu_dir: Path, workers: int = 2) -> Path:
    """``given`` where it is a file; else a model identified now on ``fmu_dir``'s SingleWheel.fmu
    into a temporary folder (what a benchmark uses when `make identify` has not run)."""
    if Path(given).is_file():
        return Path(given)
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="rover-cosim-model-"))
    run_identification(Path(fmu_dir) / "SingleWheel.fmu", folder, workers=workers)
    return folder / "model.json"
