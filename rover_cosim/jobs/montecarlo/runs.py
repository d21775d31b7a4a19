"""One closed-loop run of a Monte Carlo study: one sample's soil (and rover) on one scenario,
with the controller and the identified model unchanged, cached as a one-row CSV of its metrics.

The plant is the one ``make simulate`` runs, built by the same functions (simulate.
monolithic_system: Rover.fmu, 1 ms, Gauss-Seidel; path_following.monolithic_system: the lane
change on SteerableRover.fmu); the sample changes only the FMUs' parameters: its soil and wheel
values make the sample's Soil and Wheel from the nominal ones (``library.vary``, exactly as
``--set soil.c=500`` does, so a sample the soil model refuses, e.g. a negative cohesion, fails
with the library's message), other names (``rover.M``) are FMU parameters. Sample 0 changes
nothing: it is the nominal run, the same system as ``make simulate``'s.

The cache file of a run is named by a key: SHA-256 of the FMU's and the model's SHA-256, the
scenario and its stop time and step, the nominal soil and wheel, the sample's values and the
metrics' version; so a changed FMU, model or sample is computed again and nothing else is.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import fmpy
import pandas as pd

from rover_cosim.control.calibration import Calibration
from rover_cosim.identification.cache import read_run, write_run
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.master import run
from rover_cosim.orchestrator.model import System
from rover_cosim.terramechanics.library import DEGREES, Choice, vary

from .. import simulate
from .metrics import ESTIMATED
from .scenarios import PATH_SCENARIO as PATH_SCENARIO  # noqa: F401 - where users found it
from .scenarios import RUN_SCENARIOS
from .study import Study, StudyError

#: Bumped when a metric's definition changes: every cached run is then computed again.
METRICS_VERSION = 4


#: (name, value) pairs of a sample.
Values = tuple[tuple[str, float], ...]


@dataclass(frozen=True)
class RunSpec:
    """Everything a worker needs for one run (it travels to other processes)."""

    sample: int
    scenario: str                               # a name of scenarios.RUN_SCENARIOS
    fmu_dir: str
    model: ModelSet                             # the identified models, read once by the study
    stop_time: float                            # s
    nominal: Choice                             # the soil and wheel the model was identified on
    changes: Values                             # the sample's soil.X and wheel.X values (SI, X_deg in degrees)
    parameters: Values                          # the sample's other FMU parameters (rover.M ...)
    target: str                                 # the cache file
    calibration: Calibration = Calibration()    # the adaptive controller's (and the "after" RMS window)

    def choice(self) -> Choice:
        """The sample's soil and wheel (ValueError: one the soil model refuses)."""
        kinds: dict[str, dict[str, float]] = {"soil": {}, "wheel": {}}
        for name, value in self.changes:
            kind, _, key = name.partition(".")
            kinds[kind][key] = value
        return vary(self.nominal, kinds["soil"], kinds["wheel"])


def library_value(name: str, choice: Choice) -> float | None:
    """The value of ``soil.X`` / ``wheel.X`` (degrees for *_deg) in ``choice``; None for other names."""
    kind, _, key = name.partition(".")
    if kind not in ("soil", "wheel"):
        return None
    record = choice.soil if kind == "soil" else choice.wheel
    return math.degrees(getattr(record, DEGREES[key])) if key in DEGREES else float(getattr(record, key))


def fmu_starts(fmu: Path) -> dict[str, float]:
    """The parameters of an FMU with their start values."""
    return {v.name: float(v.start) for v in fmpy.read_model_description(str(fmu)).modelVariables
            if v.causality == "parameter" and v.start is not None}


def nominal_values(study: Study, choice: Choice, fmu_dir: Path) -> dict[str, float]:
    """Each study parameter's nominal value: the soil library's (the soil the model was identified
    on), or the start value the FMU of every scenario has; StudyError for a name no FMU has."""
    values: dict[str, float] = {}
    starts = {scenario: fmu_starts(Path(fmu_dir) / RUN_SCENARIOS[scenario].fmu) for scenario in study.scenarios}
    for name in study.names:
        value = library_value(name, choice)
        if value is None:
            lacking = [RUN_SCENARIOS[s].fmu for s in study.scenarios if name not in starts[s]]
            if lacking:
                raise StudyError(f"parameter {name!r}: not a parameter of {', '.join(lacking)}; expected soil.NAME, "
                                 "wheel.NAME or one of the FMU's parameters (e.g. rover.M)")
            value = starts[study.scenarios[0]][name]
        values[name] = value
    return values


def split(values: dict[str, float], nominal: bool) -> tuple[Values, Values]:
    """A sample's values as (soil and wheel changes, other FMU parameters); the nominal sample has none."""
    if nominal:
        return (), ()
    changes = tuple((name, float(value)) for name, value in values.items() if name.split(".")[0] in ("soil", "wheel"))
    parameters = tuple((name, float(value)) for name, value in values.items()
                       if name.split(".")[0] not in ("soil", "wheel"))
    return changes, parameters


def cache_key(fingerprint: dict[str, Any], scenario: str, stop_time: float,
              changes: Values, parameters: Values, calibration: Calibration = Calibration()) -> str:
    """The run's cache key (hex): ``fingerprint`` holds the FMUs', the model's and the nominal soil's;
    of the calibration, an adaptive run's whole, another run's the duration alone (its "after the
    calibration" RMS window), so that the other settings of the calibration do not run it again."""
    adaptive = RUN_SCENARIOS[scenario].adapted_from is not None
    content = {"fingerprint": fingerprint, "scenario": scenario,
               "fmu": fingerprint["fmus"][RUN_SCENARIOS[scenario].fmu],
               "extra_fmus": [fingerprint["fmus"].get(name) for name in RUN_SCENARIOS[scenario].extra_fmus],
               "stop_time": stop_time, "step": simulate.STEP, "changes": [list(c) for c in changes],
               "parameters": [list(p) for p in parameters],
               "calibration": asdict(calibration) if adaptive else {"duration": calibration.duration},
               "metrics_version": METRICS_VERSION}
    return hashlib.sha256(json.dumps(content, sort_keys=True, default=str).encode()).hexdigest()


def fingerprint(fmu_hashes: dict[str, str], model_hash: str, nominal: Choice) -> dict[str, Any]:
    """What every run of a study shares in its cache key."""
    return {"fmus": fmu_hashes, "model": model_hash, "soil": asdict(nominal.soil), "wheel": asdict(nominal.wheel)}


def plant(spec: RunSpec) -> System:
    """The run's system: the scenario's plant and controller on the sample's soil, wheel and parameters."""
    system = RUN_SCENARIOS[spec.scenario].system(Path(spec.fmu_dir), spec.model, spec.choice(), spec.calibration)
    builder = SystemBuilder.from_system(system, f"Monte Carlo sample {spec.sample} ({spec.scenario})")
    builder.simulation(stop_time=spec.stop_time).set_parameters("rover", dict(spec.parameters))
    return builder.build()


def adaptation_metrics(system: System) -> dict[str, float]:
    """What the adaptive controller of ``system`` (block ``ctrl``) estimated, and when."""
    block = next(b.block for b in system.blocks if b.name == "ctrl")
    report = block.report()  # type: ignore[attr-defined]
    soil = report.get("estimated_soil") or {}
    values = {"c": soil.get("c"), "phi_deg": math.degrees(soil["phi"]) if "phi" in soil else None,
              "kphi": soil.get("kphi"), "n": soil.get("n"), "kx": soil.get("kx")}
    row = {"switched_at_s": report["switched_at_s"], "adapt_wall_s": report["adapt_wall_s"],
           "estimate_rows": report["samples"], **{f"estimated_{n}": values[n] for n in ESTIMATED}}
    return {k: float("nan") if v is None else float(v) for k, v in row.items()}


def simulate_run(spec: RunSpec) -> dict[str, float | bool]:
    """The run's metrics (raises on a sample the soil library or the FMU refuses)."""
    scenario = RUN_SCENARIOS[spec.scenario]
    system = plant(spec)
    outcome = run(system)
    window = spec.calibration.duration
    adapted = scenario.adapted_from is not None
    if adapted:  # after its own calibration, longer on a rover that crawls
        block = next(b.block for b in system.blocks if b.name == "ctrl")
        window = block.calibrated_until or window  # type: ignore[attr-defined]
    row = scenario.metrics(outcome.data, window)
    if adapted:
        row.update(adaptation_metrics(system))
    row["wall_s"] = outcome.wall_seconds
    return row


def compute_run(spec: RunSpec) -> tuple[int, str, str | None, float]:
    """Run one sample on one scenario and cache its metrics. Returns (sample, scenario, error,
    seconds); never raises, so that a failing sample does not stop the study (runs in workers)."""
    started = time.perf_counter()
    try:
        write_run(Path(spec.target), pd.DataFrame([simulate_run(spec)]), float_format=None)
        return spec.sample, spec.scenario, None, time.perf_counter() - started
    except Exception as error:  # noqa: BLE001 - recorded per run, the study goes on
        return spec.sample, spec.scenario, f"{type(error).__name__}: {error}", time.perf_counter() - started


def read_cached(spec: RunSpec) -> tuple[dict[str, Any] | None, str | None]:
    """(the run's metrics, None) from a whole cache file; (None, why not) for a damaged one;
    (None, None) when there is none."""
    data, problem = read_run(Path(spec.target), 1, [*RUN_SCENARIOS[spec.scenario].columns, "wall_s"], exact=True)
    return (None, problem) if data is None else (data.iloc[0].to_dict(), None)
