"""The skeleton the closed-loop jobs share (simulate's straight run, the path following, the terrain
scenarios): their runs stepped one after the other, each with its share of the progress, or
independent runs side by side on the cores (``run_all``); what each system was and how long it
ran; the record's common part, with the master's algorithm and step read from the systems that
ran; the files written as one set, all or none.

A job builds its systems and makes tables of the runs' data; the campaign does the rest::

    campaign = Campaign("rover-cosim simulate", runs=3, progress=progress)
    data = campaign.run("monolithic", system).data
    record = campaign.record(parameters, fmu_dir=..., fmus=(...), model=..., choice=..., mismatch=None)
    files = campaign.write(out, {out / "x.csv": ...}, stale=("x_*",))
"""

from __future__ import annotations

import dataclasses
import math
import pickle
import time
from collections.abc import Callable, Collection, Mapping, Sequence
from pathlib import Path
from typing import Any

from rover_cosim.common.heap import freeze_imports
from rover_cosim.common.outputs import file_sha256, run_record, write_all
from rover_cosim.common.parallel import cores, parallel_map
from rover_cosim.orchestrator.master import RunError, run
from rover_cosim.orchestrator.model import System
from rover_cosim.orchestrator.recorder import RunResult
from rover_cosim.orchestrator.runs import system_record
from rover_cosim.progress import Stages
from rover_cosim.terramechanics.library import Choice, describe


class Campaign:
    """The runs of one job (``runs``: how many it plans, for the progress) and what they record."""

    def __init__(self, command: str, runs: int, progress: Callable[[float], None] | None = None):
        freeze_imports()  # the job's modules are imported: its work's garbage collections skip them
        self.command = command
        self.started = time.perf_counter()
        self.stages = Stages(progress, runs)
        self.ran: dict[str, System] = {}
        self.systems: dict[str, Any] = {}
        self.walls: dict[str, float] = {}

    def run(self, key: str, system: System) -> RunResult:
        """Run ``system`` (recorded as ``key``) with the next share of the progress."""
        self.systems[key] = system_record(system)
        outcome = run(system, progress=self.stages.stage(len(self.ran)))
        self.ran[key] = system
        self.walls[key] = outcome.wall_seconds
        return outcome

    def run_all(self, systems: Mapping[str, System], workers: int | None = None,
                longest: Sequence[str] = ()) -> dict[str, RunResult]:
        """Run every system (recorded under its key), independent runs side by side in ``workers``
        processes (default: the cores; one, or a single system: one after the other here), the
        keys ``longest`` given to the workers first (a long run started last finishes last, alone:
        the job knows its long runs), the results and the record in the order of ``systems``. Each
        runs as it would alone, bit for bit (a run in a worker steps its FMUs on one thread: the
        runs share the cores); a block's state after its run (a report) is in ``self.ran[key]``,
        the system that ran. A system that cannot be sent to a worker (a block holding a local
        function: the adaptive controller) runs here first. The first run that fails raises its
        RunError (the others are ended)."""
        unknown = [key for key in longest if key not in systems]
        if unknown:
            raise ValueError(f"longest runs {unknown}: not among the systems {list(systems)}")
        workers = min(workers or cores(), len(systems))
        if workers <= 1:
            return {key: self.run(key, system) for key, system in systems.items()}
        # each system as it travels to a worker (pickled once, on one stepper thread: the runs share
        # the cores); one that cannot (a block holding a local function) runs here first
        packed = {key: _packed(dataclasses.replace(system, threads_setting=system.threads_setting or 1))
                  for key, system in systems.items()}
        here = [key for key in systems if packed[key] is None]
        done: dict[str, RunResult] = {key: self.run(key, systems[key]) for key in here}
        away = {key: system for key, system in systems.items() if key not in here}
        if len(away) < 2:
            done.update({key: self.run(key, system) for key, system in away.items()})
            return self._in_order(systems, done)
        first = len(self.ran)
        stage = {key: first + k for k, key in enumerate(away)}
        for key, system in away.items():
            self.systems[key] = system_record(system)
        dispatched = [key for key in longest if key in away] + [key for key in away if key not in longest]
        arguments = [(key, packed[key]) for key in dispatched]

        def lost(arguments: tuple[Any, ...], reason: str) -> Any:
            raise RunError(f"run {arguments[0]!r}: {reason}")

        for key, outcome, ran in parallel_map(_run_one, arguments, min(workers, len(away)), lost=lost,
                                              timeout=math.inf):
            if isinstance(outcome, str):
                raise RunError(outcome)
            assert ran is not None
            done[key], self.ran[key], self.walls[key] = outcome, ran, outcome.wall_seconds
            report = self.stages.stage(stage[key])
            if report is not None:
                report(1.0)
        return self._in_order(systems, done)

    def _in_order(self, systems: Mapping[str, System], done: dict[str, RunResult]) -> dict[str, RunResult]:
        """``done`` in the order of ``systems``, and so what the campaign recorded of them."""
        def ordered(recorded: dict[str, Any]) -> dict[str, Any]:
            return {**{k: v for k, v in recorded.items() if k not in systems}, **{k: recorded[k] for k in systems}}

        self.ran, self.walls, self.systems = ordered(self.ran), ordered(self.walls), ordered(self.systems)
        return {key: done[key] for key in systems}

    def settings(self) -> dict[str, Any]:
        """The master's settings of the systems that ran: the algorithm and the step [s], one value
        where every run shares it, else one per run."""
        found: dict[str, Any] = {}
        for name, read in (("algorithm", lambda s: s.algorithm), ("step_s", lambda s: s.step)):
            values = {key: read(system) for key, system in self.ran.items()}
            found[name] = next(iter(values.values())) if len(set(values.values())) == 1 else values
        return found

    def record(self, parameters: Mapping[str, Any], *, fmu_dir: Path, fmus: Collection[str | Path], model: Path,
               choice: Choice, mismatch: str | None, **results: Any) -> dict[str, Any]:
        """The job's record: ``parameters`` with the master's settings (``settings``); the FMUs'
        (names in ``fmu_dir``, or paths: an FMU built for the rover's wheel count is recorded as
        ``wheels4/Rover``) and the model's SHA-256; the soil, wheel and rover; the systems; the wall
        times; then ``results``."""
        record: dict[str, Any] = run_record(self.command, {**parameters, **self.settings()})
        record.update({"fmus": {_fmu_key(fmu, fmu_dir): file_sha256(_fmu_path(fmu, fmu_dir)) for fmu in fmus},
                       "model_sha256": file_sha256(model), "run_wall_seconds": self.walls, **describe(choice),
                       "model_mismatch": mismatch, "systems": self.systems,
                       "wall_seconds": time.perf_counter() - self.started, **results})
        return record

    def write(self, out: Path, files: Mapping[Path, bytes], stale: Collection[str] = ()) -> list[Path]:
        """Write ``files`` into the results folder ``out`` as one set (``stale``: patterns of the
        job's earlier files to remove); the files, sorted."""
        write_all(files, folder=Path(out), stale=stale)
        return sorted(files)


def _packed(system: System) -> bytes | None:
    """``system`` pickled for a worker process, or None where it cannot be."""
    try:
        return pickle.dumps(system)
    except (pickle.PicklingError, AttributeError, TypeError):
        return None


def _run_one(key: str, packed: bytes) -> tuple[str, RunResult | str, System | None]:
    """In a worker: (key, the run's result or its RunError's message, the system after the run)."""
    system = pickle.loads(packed)
    try:
        return key, run(system), system
    except RunError as error:
        return key, str(error), None


def _fmu_path(fmu: str | Path, fmu_dir: Path) -> Path:
    return fmu if isinstance(fmu, Path) else Path(fmu_dir) / f"{fmu}.fmu"


def _fmu_key(fmu: str | Path, fmu_dir: Path) -> str:
    """How the record names an FMU: its name, or its path under ``fmu_dir`` without ``.fmu``."""
    if not isinstance(fmu, Path):
        return fmu
    try:
        return Path(fmu).resolve().relative_to(Path(fmu_dir).resolve()).with_suffix("").as_posix()
    except ValueError:
        return str(fmu)
