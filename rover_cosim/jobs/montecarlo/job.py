"""``make montecarlo``: how the identified-model controller does when the soil is not the one it
was identified on. Every sample of a study (study.py, sampling.py) runs the paper's closed loop
(runs.py), on local processes, serially or on a Dask cluster (common.parallel); each run is
cached, so an interrupted study resumes where it stopped, and a run that fails is recorded while
the others go on.

results/montecarlo/
  runs.csv          one row per run: sample, scenario, status (ok/failed), the sample's values, the
                    metrics (metrics.py), wall time
  failures.csv      sample, scenario, error, the sample's values (header only when none failed)
  sensitivity.csv   output, parameter, spearman, prcc, p_value, rank, n (sensitivity.py)
  summary.json      the study, counts, share of runs meeting the paper's 1 N RMS, quantiles, the
                    nominal run (and its check against make simulate's RMS), FMU and model hashes,
                    versions, wall time, runs per minute
  fig_distributions.png, fig_sensitivity.png, fig_scatter.png
"""

from __future__ import annotations

import functools
import json
import os
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rover_cosim.common.figures import drawn
from rover_cosim.common.outputs import file_sha256, json_bytes, run_record, summary_repr, write_all
from rover_cosim.common.parallel import parallel_map
from rover_cosim.identification.cache import discard, remove_partial_files
from rover_cosim.identification.model_set import ModelMismatch, ModelSet
from rover_cosim.terramechanics.library import Choice, choose, describe

from . import figures
from .metrics import RMS_FLOOR
from .runs import RunSpec, cache_key, compute_run, fingerprint, nominal_values, read_cached, split
from .sampling import sample_table
from .scenarios import RUN_SCENARIOS
from .sensitivity import OUTPUTS, sensitivity
from .study import ADAPTED, Study


@dataclass
class MonteCarloResult:
    """What ``run_montecarlo`` wrote and found."""

    files: list[Path]
    runs: pd.DataFrame              # runs.csv
    failures: pd.DataFrame          # failures.csv
    sensitivity: pd.DataFrame       # sensitivity.csv
    summary: dict[str, Any]         # summary.json
    computed: int                   # runs computed now (the others came from the cache)
    cached: int
    rejected: dict[Path, str] = field(default_factory=dict)  # cache files not whole, computed again (why)

    def __repr__(self) -> str:
        return summary_repr("MonteCarloResult", self.files, runs=len(self.runs), computed=self.computed,
                            cached=self.cached, failed=len(self.failures))


def _stop_time(study: Study, scenario: str) -> float:
    return study.stop_time_of(scenario)


def _specs(study: Study, samples: pd.DataFrame, fmu_dir: Path, models: ModelSet, nominal: Choice, cache: Path,
           shared: dict[str, Any]) -> list[RunSpec]:
    specs = []
    for row in samples.to_dict("records"):
        changes, parameters = split({n: row[n] for n in study.names}, bool(row["nominal"]))
        for scenario in study.scenarios:
            stop = _stop_time(study, scenario)
            key = cache_key(shared, scenario, stop, changes, parameters, study.calibration)
            specs.append(RunSpec(int(row["sample"]), scenario, str(fmu_dir), models, stop, nominal, changes,
                                 parameters, str(cache / f"{key[:24]}.csv"), study.calibration))
    return specs


def _cached(specs: list[RunSpec]) -> tuple[dict[tuple[int, str], dict[str, Any]], dict[Path, str]]:
    found: dict[tuple[int, str], dict[str, Any]] = {}
    rejected: dict[Path, str] = {}
    for spec in specs:
        row, problem = read_cached(spec)
        if row is not None:
            found[spec.sample, spec.scenario] = row
        elif problem is not None:
            rejected[Path(spec.target)] = problem  # said by the caller (the CLI prints one line each)
            discard(Path(spec.target))
    return found, rejected


def _lost(arguments: tuple[RunSpec], reason: str) -> tuple[int, str, str | None, float]:
    """The failure of a run whose worker process was lost (``reason``: a crash, exit(), the time limit)."""
    spec = arguments[0]
    return spec.sample, spec.scenario, f"lost: {reason}", 0.0


def _compute(specs: list[RunSpec], workers: int | None, scheduler: str | None,
             progress: Callable[[float], None] | None, done: int, total: int,
             run_timeout: float | None = None) -> tuple[dict[tuple[int, str], dict[str, Any]],
                                                        dict[tuple[int, str], str]]:
    """Run ``specs``: the metrics of those that completed, the errors of those that failed."""
    results: dict[tuple[int, str], dict[str, Any]] = {}
    errors: dict[tuple[int, str], str] = {}
    if progress:
        progress(done / max(total, 1))
    for sample, scenario, error, _seconds in parallel_map(compute_run, [(s,) for s in specs], workers, scheduler,
                                                          lost=_lost, timeout=run_timeout):
        if error is not None:
            errors[sample, scenario] = error
        done += 1
        if progress:
            progress(done / max(total, 1))
    for spec in specs:  # the files just written
        if (spec.sample, spec.scenario) not in errors:
            row, problem = read_cached(spec)
            if row is None:
                errors[spec.sample, spec.scenario] = f"its cache file {spec.target} is not whole: {problem}"
            else:
                results[spec.sample, spec.scenario] = row
    return results, errors


def _tables(study: Study, samples: pd.DataFrame, results: dict[tuple[int, str], dict[str, Any]],
            errors: dict[tuple[int, str], str]) -> tuple[pd.DataFrame, pd.DataFrame]:
    rows, failed = [], []
    for row in samples.to_dict("records"):
        for scenario in study.scenarios:
            key = (int(row["sample"]), scenario)
            base = {"sample": key[0], "scenario": scenario, "nominal": bool(row["nominal"]),
                    **{n: row[n] for n in study.names}}
            if key in results:
                rows.append({**base, "status": "ok", "error": "", **results[key]})
            else:
                error = errors.get(key, "not run")
                rows.append({**base, "status": "failed", "error": error})
                failed.append({"sample": key[0], "scenario": scenario, "error": error,
                               **{n: row[n] for n in study.names}})
    runs = pd.DataFrame(rows)
    if "stuck" in runs:
        runs["stuck"] = runs["stuck"].astype("boolean")
    return runs, pd.DataFrame(failed, columns=["sample", "scenario", "error", *study.names])


def _quantiles(values: pd.Series) -> dict[str, float | None]:
    finite = values.dropna()
    return {q: (float(finite.quantile(p)) if len(finite) else None)
            for q, p in (("p05", 0.05), ("median", 0.5), ("p95", 0.95))}


def _share(ok: pd.DataFrame, column: str) -> float | None:
    """The share of the completed runs ``ok`` whose ``column`` (an RMS [N]) is at most RMS_FLOOR."""
    return float((ok[column] <= RMS_FLOOR).sum()) / len(ok) if len(ok) and column in ok else None


def _summary_numbers(study: Study, runs: pd.DataFrame) -> dict[str, Any]:
    """Per scenario: counts, share meeting the 1 N RMS (over the whole run and after the
    calibration phase), stuck, quantiles; the nominal run. The adapted scenario's shares also
    stand beside the scenario it adapts, as ``adapted_share_...``."""
    numbers: dict[str, Any] = {}
    for scenario in study.scenarios:
        all_runs = runs[runs["scenario"] == scenario]
        ok = all_runs[all_runs["status"] == "ok"]
        meeting = int((ok["rms_Fx_max_N"] <= RMS_FLOOR).sum()) if len(ok) else 0
        nominal = ok[ok["nominal"]]
        numbers[scenario] = {
            "runs": len(all_runs), "completed": len(ok), "failed": len(all_runs) - len(ok),
            "meeting_1N_rms": meeting,
            "share_meeting_1N_rms_of_completed": meeting / len(ok) if len(ok) else None,
            "share_meeting_1N_rms_of_all": meeting / len(all_runs) if len(all_runs) else None,
            "share_meeting_1N_rms_after_calibration_of_completed": _share(ok, "rms_Fx_max_after_calibration_N"),
            "stuck": int(ok["stuck"].astype(bool).sum()) if len(ok) else 0,
            "quantiles": {c: _quantiles(ok[c]) for c in OUTPUTS if c in ok},
            "nominal": {c: _plain(v) for c, v in nominal.iloc[0].items()} if len(nominal) else None}
        if scenario in ADAPTED.values():
            numbers[scenario]["quantiles"].update({c: _quantiles(ok[c]) for c in ("adapt_wall_s", "switched_at_s")
                                                   if c in ok})
    for base, adapted in ADAPTED.items():
        if base in numbers and adapted in numbers:
            numbers[base]["adapted_share_meeting_1N_rms_of_completed"] = \
                numbers[adapted]["share_meeting_1N_rms_after_calibration_of_completed"]
            numbers[base]["adapted_share_meeting_1N_rms_whole_run_of_completed"] = \
                numbers[adapted]["share_meeting_1N_rms_of_completed"]
            numbers[base]["after_calibration_from_s"] = study.calibration.duration
    return numbers


def _plain(value: Any) -> Any:
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.floating, float)):
        return None if np.isnan(value) else float(value)
    if isinstance(value, np.integer):
        return int(value)
    return value


def _cost(runs: pd.DataFrame, computed: int, seconds: float, workers: int | None,
          scheduler: str | None) -> dict[str, Any]:
    """What the runs cost: wall time of the computing, runs per minute, mean wall time of one run."""
    walls = runs["wall_s"].dropna() if "wall_s" in runs else pd.Series(dtype=float)
    local = None if scheduler else (workers or os.cpu_count() or 1)   # parallel_map's default: all cores
    return {"workers": local, "scheduler": scheduler, "compute_wall_seconds": seconds,
            "runs_per_minute": 60 * computed / seconds if computed and seconds > 0 else None,
            "mean_run_wall_seconds": float(walls.mean()) if len(walls) else None}


def simulate_check(simulation: Path, nominal: dict[str, Any] | None, study: Study, hashes: dict[str, Any]) -> dict:
    """The nominal run's RMS against ``make simulate``'s (simulation.json), when that was made with
    the same FMU, model and stop time: equal to the last bit, or the difference."""
    record_path = simulation / "simulation.json"
    if nominal is None or not record_path.exists():
        return {"compared": False, "why": f"{record_path} not found" if nominal else "no nominal run"}
    record = json.loads(record_path.read_text())
    same = (record.get("fmus", {}).get("Rover") == hashes["fmus"]["Rover.fmu"]
            and record.get("model_sha256") == hashes["model"]
            and record.get("parameters", {}).get("stop_time_s") == study.stop_time
            and record.get("soil", {}).get("values") == hashes["soil"])
    if not same:
        return {"compared": False, "why": "make simulate ran another FMU, model, soil or stop time"}
    theirs = record["rms_N"]["monolithic"]
    ours = [nominal[f"rms_Fx_{i}_N"] for i in range(1, len(theirs) + 1)]
    return {"compared": True, "equal": ours == theirs, "simulate_rms_N": theirs, "montecarlo_rms_N": ours,
            "largest_difference_N": max(abs(a - b) for a, b in zip(ours, theirs))}


def identified_on(models: ModelSet, nominal: Choice) -> dict[str, Any]:
    """The soil and wheel the models were identified on (model.json's record), and whether they
    are the study's nominal ones (and if not, why)."""
    soil, wheel = models.details.get("soil", {}), models.details.get("wheel", {})
    if not soil.get("values"):
        return {"known": False, "why": f"{models.source} does not record its soil"}
    why = models.mismatch(asdict(nominal.soil), asdict(nominal.wheel), nominal.soil_name, nominal.wheel_name)
    return {"known": True, "soil": soil.get("name"), "wheel": wheel.get("name"), "same_as_nominal": why is None,
            "mismatch": why}


def run_montecarlo(study: Study, fmu_dir: Path, model: Path, out_dir: Path, *, workers: int | None = None,
                   scheduler: str | None = None, cache_dir: Path | None = None,
                   progress: Callable[[float], None] | None = None, samples: pd.DataFrame | None = None,
                   simulation: Path | None = None, allow_model_mismatch: bool = False,
                   run_timeout: float | None = None) -> MonteCarloResult:
    """Run (or take from the cache) every sample of ``study`` and write every file (all or none).
    ``samples`` replaces the study's drawn samples (a table like sampling.sample_table's);
    ``simulation``: make simulate's folder, for the nominal check (default: beside ``out_dir``)."""
    started = time.perf_counter()
    fmu_dir, model, out = Path(fmu_dir).resolve(), Path(model).resolve(), Path(out_dir)
    if not model.is_file():
        raise FileNotFoundError(f"identified model {model} not found (make it with `rover-cosim identify`)")
    for scenario in study.scenarios:
        for name in RUN_SCENARIOS[scenario].fmus:
            if not (fmu_dir / name).is_file():
                raise FileNotFoundError(f"FMU {fmu_dir / name} not found (build them with `rover-cosim build-fmus`)")
    study.check_calibration()
    nominal_choice = choose(study.soil, study.wheel)
    models = ModelSet.read(model)
    identified = identified_on(models, nominal_choice)
    if identified.get("mismatch") and not allow_model_mismatch:  # sample 0 would not be the model's soil
        raise ModelMismatch(f"{identified['mismatch']} (the study's nominal soil and wheel: {study.soil}, "
                            f"{study.wheel})")
    if samples is None:
        samples = sample_table(study, nominal_values(study, nominal_choice, fmu_dir))
    names = sorted({name for scenario in RUN_SCENARIOS.values() for name in scenario.fmus})
    hashes = fingerprint({name: file_sha256(fmu_dir / name) for name in names if (fmu_dir / name).is_file()},
                         file_sha256(model), nominal_choice)
    cache = Path(cache_dir) if cache_dir is not None else out / "cache"
    cache.mkdir(parents=True, exist_ok=True)
    remove_partial_files(cache)
    specs = _specs(study, samples, fmu_dir, models, nominal_choice, cache, hashes)
    results, rejected = _cached(specs)
    # the adaptive runs (3x as long) first: the workers then end close together, not one of them
    # alone on a long run at the end
    missing = sorted((s for s in specs if (s.sample, s.scenario) not in results),
                     key=lambda s: RUN_SCENARIOS[s.scenario].adapted_from is None)
    compute_started = time.perf_counter()
    computed, errors = _compute(missing, workers, scheduler, progress, len(specs) - len(missing), len(specs),
                                run_timeout)
    compute_seconds = time.perf_counter() - compute_started
    results.update(computed)
    runs, failures = _tables(study, samples, results, errors)
    straight = runs[(runs["scenario"] == "straight") & (runs["status"] == "ok")] if "straight" in study.scenarios \
        else runs.iloc[0:0]
    logarithmic = {p.name for p in study.parameters if p.kind == "lognormal"}
    ranking = sensitivity(straight, study.names, OUTPUTS if len(straight) else {},
                          nominal_values(study, nominal_choice, fmu_dir), logarithmic)
    numbers = _summary_numbers(study, runs)
    summary = run_record("rover-cosim montecarlo", study.settings())
    summary.update({
        "fmus": hashes["fmus"], "model": str(model), "model_sha256": hashes["model"], **describe(nominal_choice),
        "nominal": f"sample 0: the soil and wheel the model was identified on ({study.soil}, {study.wheel}), "
                   "no parameter changed",
        "model_identified_on": identified, "allow_model_mismatch": allow_model_mismatch, "scenarios": numbers,
        "runs_computed": len(missing), "runs_cached": len(specs) - len(missing), "runs_failed": len(failures),
        **_cost(runs, len(missing), compute_seconds, workers, scheduler),
        "simulate_check": simulate_check(simulation or out.parent / "simulation",
                                         numbers.get("straight", {}).get("nominal"), study, hashes),
        "wall_seconds": time.perf_counter() - started})
    files = {out / "runs.csv": runs.to_csv(index=False).encode(),
             out / "failures.csv": failures.to_csv(index=False).encode(),
             out / "sensitivity.csv": ranking.to_csv(index=False).encode(),
             out / "summary.json": json_bytes(summary)}
    to_draw = _figures(study, straight, ranking)
    if "straight_adapted" in study.scenarios and len(straight):
        adapted = runs[(runs["scenario"] == "straight_adapted") & (runs["status"] == "ok")]
        if len(adapted):
            to_draw["fig_adaptation.png"] = functools.partial(figures.adaptation, straight, adapted,
                                                              study.calibration.duration)
    # side by side on the cores (the scatter, about half of the drawing, first), the same bytes
    files.update({out / name: png for name, png in drawn(to_draw).items()})
    write_all(files, folder=out, stale=("fig_*",))
    return MonteCarloResult(sorted(files), runs, failures, ranking, summary, len(missing),
                            len(specs) - len(missing), rejected)


def _figures(study: Study, straight: pd.DataFrame, ranking: pd.DataFrame) -> dict[str, Callable[[], bytes]]:
    """What draws each fig_*.png of the completed straight runs (none without any)."""
    if not len(straight):
        return {}
    labels = {p.name: f"{p.name} [{p.unit}]" if p.unit else p.name for p in study.parameters}
    nominal = straight[straight["nominal"]].iloc[0] if straight["nominal"].any() else None
    logarithmic = {p.name for p in study.parameters if p.kind == "lognormal"}
    out: dict[str, Callable[[], bytes]] = {
        "fig_scatter.png": functools.partial(figures.scatter, straight, study.names, labels, nominal, logarithmic),
        "fig_distributions.png": functools.partial(figures.distributions, straight, nominal)}
    if len(ranking) and ranking["rank"].notna().any():
        out["fig_sensitivity.png"] = functools.partial(figures.ranking, ranking, labels)
    return out
