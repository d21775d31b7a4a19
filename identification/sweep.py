"""The identification sweep: a torque step on SingleWheel.fmu, rolling at the plan's start speed,
for every (load, torque, slip angle) of a plan, run on local processes (default: all cores),
serially (``workers=1``) or on a Dask cluster (``scheduler="tcp://host:port"``).

Each run is cached as one CSV with a checksum under ``cache_dir/<FMU SHA-256>/<plan digest>/``
(``identification.cache``): a re-run takes only whole files and computes what is missing or
damaged (with a warning naming the file). Without a cache folder the runs stay in memory, at full
precision (a cached run is read back at the 12 digits its file keeps): an adaptive run's sweep on
the soil it has just estimated, which no other run shares. A run that fails is reported with its error; the
others go on. The worker processes end with the sweep: on an error, Ctrl-C or SIGTERM the pool
is cancelled and its workers terminated, and each worker asks Linux to end it when its parent
dies (PR_SET_PDEATHSIG), so a killed sweep leaves no workers behind.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import NamedTuple

import pandas as pd

from rover_cosim import terramechanics
from rover_cosim.common.outputs import file_sha256
from rover_cosim.common.paper import LOADS as PAPER_LOADS
from rover_cosim.common.paper import TARGET_VELOCITY
from rover_cosim.common.parallel import parallel_map
from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.library import fmu_parameters

from .cache import discard, read_run, remove_partial_files, write_run
from .testbed import RECORDED, TorqueProfile, shared_test_bed

#: Torque levels [N·m]: 5-80 N·m covers what the rover's wheels get (the open-loop run uses
#: 9-40 N·m at 290-560 N per wheel; the closed loop asks ~5-30 N of drawbar pull per wheel on
#: top of the rolling resistance), i.e. slips from ~0.01 to ~0.35 at 300-800 N. At 100-200 N the
#: upper levels exceed what the soil carries and the wheel spins out (slip -> 1): those runs are
#: kept in the tables, but left out of the Fx(slip) fits (see fits.SLIP_FIT_RANGE).
PAPER_TORQUES = (5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0, 60.0, 80.0)


class Case(NamedTuple):
    """One run of a sweep: load W [N], torque step [N·m], slip angle of the carriage's track [deg]."""

    load: float
    torque: float
    slip_angle_deg: float = 0.0


@dataclass(frozen=True)
class SweepPlan:
    """What an identification sweep runs: every (load [N], torque step [N·m], slip angle [deg])
    of ``loads`` x ``torques`` x ``slip_angles_deg``, each a run of ``stop_time`` [s] sampled every
    ``sample_time`` [s], starting rolling at ``start_speed`` [m/s], on ``soil`` and ``wheel``
    (None: the FMU's own, the paper's). The default is the paper's longitudinal sweep;
    ``run_identification`` takes one for the longitudinal and one for the lateral model."""

    loads: tuple[float, ...] = PAPER_LOADS
    torques: tuple[float, ...] = PAPER_TORQUES
    #: deg; the carriage's track to the wheel plane (0: the paper's longitudinal sweep)
    slip_angles_deg: tuple[float, ...] = (0.0,)
    stop_time: float = 0.1      # s; slip and Fx settle within a millisecond on this test bed
    sample_time: float = 1e-4   # s; fixed sample time = communication step
    tolerance: float = 1e-8     # integrator tolerance inside the FMU
    #: The soil and wheel of every run (part of the cache key); None: the plant's own (the paper's).
    soil: Soil | None = None
    wheel: Wheel | None = None
    #: m/s; every run starts rolling at this speed with zero slip (omega = v/r): the regime where
    #: the paper's model applies. From rest a torque below the rolling resistance does not drive
    #: the wheel (it stays in the static regime), which the identified model is not made for.
    start_speed: float = TARGET_VELOCITY

    def __post_init__(self) -> None:
        if not self.loads or any(not (w > 0) for w in self.loads):
            raise ValueError(f"loads = {self.loads!r}: expected loads > 0 N")
        if not self.torques:
            raise ValueError("torques: expected at least one torque level [N·m]")
        if not self.slip_angles_deg or any(not (abs(b) < 90) for b in self.slip_angles_deg):
            raise ValueError(f"slip_angles_deg = {self.slip_angles_deg!r}: expected at least one angle, each "
                             "in (-90, 90) deg")
        if not (math.isfinite(self.start_speed) and self.start_speed >= 0):
            raise ValueError(f"start_speed = {self.start_speed!r}: expected a finite speed >= 0 m/s")
        if not 0 < self.sample_time <= self.stop_time:
            raise ValueError(f"sample_time = {self.sample_time!r}, stop_time = {self.stop_time!r}: "
                             "expected 0 < sample_time <= stop_time [s]")

    def digest(self) -> str:
        settings: dict[str, object] = {"stop_time": self.stop_time, "sample_time": self.sample_time,
                                       "tolerance": self.tolerance, "start_speed": self.start_speed,
                                       "recorded": list(RECORDED)}
        if self.parameters:
            settings["parameters"] = sorted(self.parameters.items())
        return hashlib.sha256(json.dumps(settings, sort_keys=True).encode()).hexdigest()[:12]

    @property
    def parameters(self) -> dict[str, float]:
        """The soil and wheel as FMU parameters, by name (empty: the plant's own)."""
        if self.soil is None and self.wheel is None:
            return {}
        return dict(sorted(fmu_parameters(self.soil or Soil(), self.wheel or Wheel()).items()))

    def cases(self) -> list[Case]:
        return [Case(w, tau, b) for b in self.slip_angles_deg for w in self.loads for tau in self.torques]


@dataclass
class SweepOutcome:
    runs: dict[Case, pd.DataFrame]
    failures: dict[Case, str]
    computed: int
    cached: int
    wall_seconds: float
    cache_folder: Path | None  # None: the runs were kept in memory
    run_seconds: dict[Case, float] = field(default_factory=dict)
    rejected: dict[Path, str] = field(default_factory=dict)  # cache files not whole, computed again (why)

    def at_slip_angle(self, slip_angle_deg: float = 0.0) -> dict[tuple[float, float], pd.DataFrame]:
        """The runs at one slip angle [deg], keyed by (load, torque)."""
        return {(c.load, c.torque): run for c, run in self.runs.items() if c.slip_angle_deg == slip_angle_deg}


def run_file(folder: Path, load: float, torque: float, slip_angle_deg: float = 0.0) -> Path:
    """The cache file of one case, a gzip-compressed CSV (the paper's longitudinal runs keep their
    name without the angle)."""
    angle = f"_beta{slip_angle_deg:g}" if slip_angle_deg else ""
    return folder / f"W{load:g}_tau{torque:g}{angle}.csv.gz"


def compute_run(fmu_path: str | None, case: Case, stop_time: float, sample_time: float,
                tolerance: float, start_speed: float, target: str | None, soil: Soil | None = None,
                wheel: Wheel | None = None) -> Result:
    """Run one case on the ``soil`` and ``wheel`` (None: the plant's own) and write it to
    ``target`` atomically (None: return it instead). Returns (case, error, seconds, the run where
    ``target`` is None); never raises, so one failing case does not stop the others (runs in
    worker processes). ``fmu_path`` None runs the numpy reference test bed instead of the FMU."""
    started = time.perf_counter()
    case = Case(*case)
    try:
        profile = TorqueProfile.step(case.torque)
        slip_angle = math.radians(case.slip_angle_deg)
        plan = SweepPlan(soil=soil, wheel=wheel)
        if fmu_path is None:
            from .reference_plant import StartState, run_reference_test_bed

            soil, wheel = soil or Soil(), wheel or Wheel()
            start = StartState(v=start_speed, omega=start_speed * math.cos(slip_angle) / wheel.r)
            data = run_reference_test_bed(case.load, profile, stop_time, sample_time, start=start,
                                          slip_angle=slip_angle, soil=soil, wheel=wheel)
        else:
            data = shared_test_bed(Path(fmu_path)).run(case.load, profile, stop_time, sample_time, tolerance,
                                                       start_speed=start_speed, slip_angle=slip_angle,
                                                       parameters=plan.parameters)
        if target is None:
            return case, None, time.perf_counter() - started, data
        write_run(Path(target), data)
        return case, None, time.perf_counter() - started, None
    except Exception as error:  # noqa: BLE001 - reported per run, the sweep goes on
        return case, f"{type(error).__name__}: {error}", time.perf_counter() - started, None


def _plant_key(fmu_path: Path | None) -> str:
    """The cache key of the plant: the FMU's SHA-256, or a digest of the numpy reference wheel's
    source and of the reference test bed when ``fmu_path`` is None."""
    if fmu_path is not None:
        return file_sha256(fmu_path)[:16]
    sources = sorted(Path(terramechanics.__file__).parent.glob("*.py"))
    sources.append(Path(__file__).with_name("reference_plant.py"))
    return "reference-" + hashlib.sha256(b"".join(p.read_bytes() for p in sources)).hexdigest()[:12]


Arguments = tuple[str | None, Case, float, float, float, float, str | None, Soil | None, Wheel | None]
#: A run's outcome: its case, the error (None: it ran), wall seconds, and the run itself where it
#: was kept in memory (None where it went to its cache file, or failed).
Result = tuple[Case, str | None, float, pd.DataFrame | None]


def _results(arguments: list[Arguments], workers: int | None, scheduler: str | None,
             timeout: float | None = None) -> Iterator[Result]:
    """compute_run for every argument tuple, on a Dask cluster or local processes; results in the
    order they complete (common.parallel); a run whose worker crashed or overran ``timeout`` [s]
    is a failed run saying so."""
    return parallel_map(compute_run, arguments, workers, scheduler, lost=_lost, timeout=timeout)


def _lost(arguments: Arguments, reason: str) -> Result:
    """The failure of a run whose worker process was lost (``reason``)."""
    return Case(*arguments[1]), f"lost: {reason}", 0.0, None


def _cached(folder: Path, plan: SweepPlan) -> tuple[dict[Case, pd.DataFrame], dict[Path, str]]:
    """The plan's runs whose cache files are whole, and the files that are not (removed, why)."""
    rows = round(plan.stop_time / plan.sample_time) + 1
    columns = ["time", "tau", *RECORDED]
    runs: dict[Case, pd.DataFrame] = {}
    rejected: dict[Path, str] = {}
    for c in plan.cases():
        path = run_file(folder, *c)
        data, problem = read_run(path, rows, columns)
        if data is not None:
            runs[c] = data
        elif problem is not None:
            rejected[path] = problem
            warnings.warn(f"sweep cache: {path}: {problem}; computing it again", stacklevel=3)
            discard(path)
    return runs, rejected


def _read_computed(folder: Path, plan: SweepPlan, cases: list[Case], runs: dict[Case, pd.DataFrame],
                   failures: dict[Case, str]) -> None:
    """Read the runs just computed into ``runs`` (a file that is not whole is a failure)."""
    rows, columns = round(plan.stop_time / plan.sample_time) + 1, ["time", "tau", *RECORDED]
    for c in cases:
        data, problem = read_run(run_file(folder, *c), rows, columns)
        if data is None:
            failures[c] = f"its file {run_file(folder, *c)} is not whole after writing: {problem}"
        else:
            runs[c] = data


def run_sweep(fmu_path: Path | None, plan: SweepPlan, cache_dir: Path | None, *, workers: int | None = None,
              scheduler: str | None = None, progress: Callable[[float], None] | None = None,
              run_timeout: float | None = None) -> SweepOutcome:
    """Run (or take from the cache) every case of ``plan`` on the FMU, or on the numpy reference
    test bed when ``fmu_path`` is None; ``cache_dir`` None: every case run and kept in memory."""
    started = time.perf_counter()
    if fmu_path is not None:
        fmu_path = Path(fmu_path).resolve()
        if not fmu_path.is_file():
            raise FileNotFoundError(f"FMU {fmu_path} not found (build them with `rover-cosim build-fmus`)")
    folder = None if cache_dir is None else Path(cache_dir) / _plant_key(fmu_path) / plan.digest()
    runs: dict[Case, pd.DataFrame] = {}
    rejected: dict[Path, str] = {}
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "plan.json").write_text(json.dumps({**asdict(plan), "plant": str(fmu_path or "numpy reference")},
                                                     indent=2) + "\n")
        remove_partial_files(folder)
        runs, rejected = _cached(folder, plan)
    cases = plan.cases()
    missing = [c for c in cases if c not in runs]
    failures: dict[Case, str] = {}
    run_seconds: dict[Case, float] = {}
    done = len(runs)
    if progress:
        progress(done / len(cases))
    arguments = [(str(fmu_path) if fmu_path else None, c, plan.stop_time, plan.sample_time, plan.tolerance,
                  plan.start_speed, None if folder is None else str(run_file(folder, *c)), plan.soil, plan.wheel)
                 for c in missing]
    for case, error, seconds, data in _results(arguments, workers, scheduler, run_timeout):
        case = Case(*case)
        run_seconds[case] = seconds
        if error is not None:
            failures[case] = error
        elif data is not None:
            runs[case] = data
        done += 1
        if progress:
            progress(done / len(cases))
    if folder is not None:
        _read_computed(folder, plan, [c for c in missing if c not in failures], runs, failures)
    return SweepOutcome({c: runs[c] for c in cases if c in runs}, failures, len(missing), len(cases) - len(missing),
                        time.perf_counter() - started, folder, run_seconds, rejected)
