"""A co-simulation run written to disk: the CSV of recorded trajectories and a JSON sidecar (the
system file, SHA-256 of each FMU, package versions, wall time), both or neither."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rover_cosim.common.outputs import file_sha256, json_bytes, run_record, write_all

from .model import System
from .observers import Observer
from .participants import RunError
from .recorder import RunResult


def sidecar(system: System, result: RunResult, command: str) -> dict[str, object]:
    record = run_record(command, {"algorithm": system.algorithm, "step_s": system.step,
                                  "start_time_s": system.start_time, "stop_time_s": system.stop_time,
                                  "order": system.order})
    return {
        **record,
        "system_file": str(system.path) if system.path else None,
        "system_sha256": file_sha256(system.path) if system.path else None,
        "settings_from": system.settings_from,
        "stopped": result.stopped,
        "fmus": {fmu.name: {"path": str(fmu.path), "sha256": file_sha256(fmu.path), "guid": fmu.description.guid}
                 for fmu in system.fmus},
        "blocks": {block.name: block.kind for block in system.blocks},
        "steps": result.steps,
        "wall_seconds": result.wall_seconds,
        "participant_seconds": result.step_seconds,
        "master_overhead_seconds": result.master_overhead_seconds,
        "columns": list(result.data.columns),
    }


def sidecar_path(csv_path: Path) -> Path:
    """The JSON sidecar of ``csv_path``; ValueError when the two would be one file."""
    csv_path = Path(csv_path)
    if csv_path.suffix.lower() != ".csv":
        raise ValueError(f"output {csv_path}: expected a .csv file (its sidecar is the same name with .json)")
    return csv_path.with_suffix(".json")


def partial_path(csv_path: Path) -> Path:
    """Where a failed run's rows go: ``NAME.partial.csv`` beside ``NAME.csv``."""
    csv_path = Path(csv_path)
    return csv_path.with_name(f"{csv_path.stem}.partial.csv")


def write_partial(system: System, data: Any, csv_path: Path, failure: str,
                  command: str = "rover-cosim run") -> list[Path]:
    """The rows a failed run recorded, marked as partial in their file name and sidecar."""
    target = partial_path(csv_path)
    record = run_record(command, {"algorithm": system.algorithm, "step_s": system.step,
                                  "stop_time_s": system.stop_time})
    record.update({"partial": True, "failure": failure, "rows": len(data),
                   "last_time_s": float(data["time"].iloc[-1]) if len(data) else None,
                   "system_file": str(system.path) if system.path else None})
    json_path = sidecar_path(target)
    write_all({target: data.to_csv(index=False, float_format="%.10g").encode(), json_path: json_bytes(record)})
    return [target, json_path]


def write_run(system: System, result: RunResult, csv_path: Path, command: str = "rover-cosim run") -> list[Path]:
    """Write ``csv_path`` and ``csv_path`` with suffix ``.json`` atomically; returns both paths."""
    csv_path = Path(csv_path)
    json_path = sidecar_path(csv_path)
    csv_bytes = result.data.to_csv(index=False, float_format="%.10g").encode()
    write_all({csv_path: csv_bytes, json_path: json_bytes(sidecar(system, result, command))})
    return [csv_path, json_path]


class PartialWriter(Observer):
    """An observer that writes the rows of a failed run (more than the start) with
    :func:`write_partial`; ``written``: the files, once it did."""

    def __init__(self, system: System, csv_path: Path, command: str = "rover-cosim run"):
        self.system, self.csv_path, self.command = system, Path(csv_path), command
        self.written: list[Path] = []

    def fail(self, error: RunError) -> None:
        if error.partial is not None and len(error.partial) > 1:
            self.written = write_partial(self.system, error.partial, self.csv_path, str(error), self.command)
