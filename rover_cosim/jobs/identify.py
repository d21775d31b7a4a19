"""``make identify``: sweep, fits, validation and every output file, written all at once.

results/identification/
  runs.csv         every recorded run, long format (load_N, torque_N_m, time, tau, slip, Fx, ...)
  steps.csv        per run: settled slip and Fx, fitted K and T
  model.json       LUT grids, K and T tables, Fx coefficients of both models, the plan, FMU hash
  fit_table.csv    load_N, fit_percent (the recommended model) at 275, 575, 875 N
  fit_models.csv   Fit of the linear (Eq. 14) and the quadratic model beside the paper's Table 1
  fit_detail.csv   per load and torque level: settled Fx and slip of plant and models
  failures.csv     runs that failed, with their error (empty when none did)
  fig5_fx_vs_slip.png, fig6_a_of_W.png, fig7_b_of_W.png, fig8_validation_575N.png
  identification.json  what ran: parameters, versions, wall times
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from rover_cosim.common.outputs import file_sha256, json_bytes, run_record, write_all
from rover_cosim.identification import figures
from rover_cosim.identification.fits import FIT_TORQUE_MAX, SLIP_FIT_RANGE, fx_per_load, identify, step_table
from rover_cosim.identification.sweep import SweepOutcome, SweepPlan, run_sweep
from rover_cosim.identification.testbed import shared_test_bed
from rover_cosim.identification.validate import validate

MODELS = {"quadratic": 2, "linear": 1}  # label -> degree in slip; the first is recommended
RECOMMENDED = "quadratic"


@dataclass
class IdentificationResult:
    """What ``run_identification`` wrote and found."""

    files: list[Path]           # every file written, sorted
    fit: pd.DataFrame           # Table 1: load_N, fit_percent (recommended model) and both models' Fits
    sweep: SweepOutcome          # the sweep's runs, failures and counts
    record: dict[str, Any]      # identification.json: parameters, versions, wall times
    model: dict[str, Any]       # model.json as written


def run_identification(fmu_path: Path, out_dir: Path, *, plan: SweepPlan | None = None, workers: int | None = None,
                       scheduler: str | None = None, cache_dir: Path | None = None,
                       progress: Callable[[float], None] | None = None) -> IdentificationResult:
    """Sweep, fit, validate and write every file of ``results/identification/`` (all or none)."""
    started = time.perf_counter()
    plan = plan or SweepPlan()
    cache_dir = cache_dir or out_dir / "cache"
    sweep = run_sweep(fmu_path, plan, cache_dir, workers=workers, scheduler=scheduler, progress=progress)
    if not sweep.runs:
        raise RuntimeError(f"every run of the sweep failed; first error: {next(iter(sweep.failures.values()))}")
    table = step_table(sweep.runs)
    models = {label: identify(table, degree) for label, degree in MODELS.items()}
    per_load = fx_per_load(table, 1)
    validation = validate(shared_test_bed(Path(fmu_path)), models)

    long = pd.concat([run.assign(load_N=load, torque_N_m=torque) for (load, torque), run in sorted(sweep.runs.items())],
                     ignore_index=True)
    long = long[["load_N", "torque_N_m", *[c for c in long.columns if c not in ("load_N", "torque_N_m")]]]
    failed = sorted(sweep.failures.items())
    failures = pd.DataFrame([{"load_N": w, "torque_N_m": t, "error": e} for (w, t), e in failed],
                            columns=["load_N", "torque_N_m", "error"])
    fmu_sha = file_sha256(Path(fmu_path))
    model_json = {
        "recommended": RECOMMENDED,
        "models": {label: model.to_dict() for label, model in models.items()},
        "lut_interpolation": "linear in 1/W and tau, extended linearly beyond the grid",
        "fx_fit": {"torque_max_N_m": FIT_TORQUE_MAX, "slip_range": list(SLIP_FIT_RANGE)},
        "plan": asdict(plan),
        "fmu": {"path": str(fmu_path), "sha256": fmu_sha},
        "failures": len(sweep.failures),
    }
    fit_models = validation.fit.drop(columns=["fit_percent"])
    record = run_record("rover-cosim identify", {"plan": asdict(plan), "workers": workers, "scheduler": scheduler})
    record.update({"fmu_sha256": fmu_sha, "runs_computed": sweep.computed, "runs_cached": sweep.cached,
                   "runs_failed": len(sweep.failures), "sweep_wall_seconds": sweep.wall_seconds,
                   "wall_seconds": time.perf_counter() - started, "cache_folder": str(sweep.cache_folder)})
    out = Path(out_dir)
    files = {
        out / "runs.csv": long.to_csv(index=False, float_format="%.10g").encode(),
        out / "steps.csv": table.to_csv(index=False, float_format="%.10g").encode(),
        out / "model.json": json_bytes(model_json),
        out / "fit_table.csv":
            validation.fit[["load_N", "fit_percent"]].to_csv(index=False, float_format="%.3f").encode(),
        out / "fit_models.csv": fit_models.to_csv(index=False, float_format="%.3f").encode(),
        out / "fit_detail.csv": validation.detail.to_csv(index=False, float_format="%.6g").encode(),
        out / "failures.csv": failures.to_csv(index=False).encode(),
        out / "fig5_fx_vs_slip.png": figures.fig5_fx_vs_slip(table, per_load),
        out / "fig6_a_of_W.png": figures.fig_coefficient(per_load, models["linear"], 1, "a(W)", "N",
                                                          "Fig. 6: slope a of Fx = a slip + b against load"),
        out / "fig7_b_of_W.png": figures.fig_coefficient(per_load, models["linear"], 0, "b(W)", "N",
                                                          "Fig. 7: offset b of Fx = a slip + b against load"),
        out / "fig8_validation_575N.png": figures.fig8_validation(validation.runs[575.0], 575.0, list(MODELS)),
        out / "identification.json": json_bytes(record),
    }
    write_all(files)
    return IdentificationResult(sorted(files), validation.fit, sweep, record, json.loads(files[out / "model.json"]))
