"""One FMU run alone, as ``fmpy simulate`` runs it: the system of ``rover-cosim run model.fmu``.

The FMU is instance ``model``; its DefaultExperiment gives the stop time and step unless the
settings do; values given by name go to its parameters or start values (by the variable's
causality); an input file (a CSV, ``blocks.CsvInput``) drives the inputs its columns name
(continuous Real inputs interpolated, the others held); every output of the FMU is recorded.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from .blocks import CsvInput
from .builder import SystemBuilder, recordable
from .model import System, SystemFileError, elements_of

#: The instance name of the one FMU.
INSTANCE = "model"


def single_fmu_system(path: Path, settings: Mapping[str, Any] | None = None, *, interface: str | None = None,
                      values: Mapping[str, Any] | None = None, input_file: Path | None = None,
                      record: Sequence[str] = (), validation: str = "strict") -> tuple[System, list[str]]:
    """The system of the FMU ``path`` alone, and notes for the user (input columns that name no
    input of the FMU, left out; a run that would record nothing but time). ``record``: the
    variables to record, names or glob patterns of the FMU's variables, locals too (default: every
    output); ``validation``: how its model description is checked (``model.VALIDATION``).
    SystemFileError for anything that does not fit the FMU."""
    builder = SystemBuilder(str(path), validation=validation)
    if settings:
        builder.simulation(**settings)
    builder.add_fmu(INSTANCE, Path(path).resolve(), interface=interface, where=f"FMU {Path(path).name}")
    entry = builder.fmu_entry(INSTANCE)
    variables = entry.variables()
    notes = _fill_experiment(builder, entry.description, dict(settings or {}))
    parameters = {k: v for k, v in (values or {}).items() if k in variables and variables[k].causality == "parameter"}
    builder.set_parameters(INSTANCE, parameters, where="--start")
    builder.set_start(INSTANCE, {k: v for k, v in (values or {}).items() if k not in parameters}, where="--start")
    if input_file is not None:
        notes += _connect_input(builder, variables, Path(input_file))
    if record:
        builder.record(*[f"{INSTANCE}.{name}" for name in _matching(Path(path), variables, record)], where="--record",
                       replace=True)
        return builder.build(), notes
    outputs = [v for v in variables.values() if v.causality == "output"]
    left = [f"{v.name} ({'an array of a size known only at run time' if v.dimensions else v.type})"
            for v in outputs if not recordable(v) and not elements_of(v)]
    if left:
        raise SystemFileError(f"{path}: outputs {', '.join(left)} cannot be recorded (Binary and Clock variables, and "
                              "arrays whose size depends on structural parameters, are not supported): name what to "
                              "record with --record (names or glob patterns) to leave them out")
    builder.record(*[f"{INSTANCE}.{v.name}" for v in outputs if recordable(v)], where="outputs", replace=True)
    system = builder.build()
    if not system.record:
        notes.append(nothing_recorded(variables.values()))
    return system, notes


def _matching(path: Path, variables: Mapping[str, Any], patterns: Sequence[str]) -> list[str]:
    """The FMU's variables that ``patterns`` (names or glob patterns; an FMI 3.0 array's name: its
    elements) name, each once, in the order of the patterns; SystemFileError for a pattern that
    names none."""
    from fnmatch import fnmatchcase

    found: list[str] = []
    for pattern in patterns:
        elements = [e.name for e in elements_of(variables[pattern])] if pattern in variables else []
        names = [pattern] if pattern in variables and recordable(variables[pattern]) else elements or [
            name for name, v in variables.items() if fnmatchcase(name, pattern) and recordable(v)]
        if not names:
            raise SystemFileError(f"{path.name}: --record {pattern!r}: names no variable of the FMU that can be "
                                  "recorded (scalars, not Binary or Clock; `--record '*'` records them all)")
        found += [name for name in names if name not in found]
    return found


def nothing_recorded(variables: Iterable[Any]) -> str:
    """What a run that would record nothing but time says: what it could record instead."""
    candidates = [v.name for v in variables if recordable(v) and v.causality in ("local", "parameter", "input")]
    shown = ", ".join(candidates[:8]) + (f" and {len(candidates) - 8} more" if len(candidates) > 8 else "")
    return ("the FMU has no output that can be recorded: only time would be; name what to record with --record "
            f"(names or glob patterns, e.g. --record '*'){': it has ' + shown if shown else ''}")


def _fill_experiment(builder: SystemBuilder, description: Any, settings: dict[str, Any]) -> list[str]:
    """As FMPy: a stop time neither the settings nor the DefaultExperiment give is 1 s; a step
    neither gives divides the run into 500 to 1000 steps (FMPy's auto_interval). Says so."""
    from fmpy.util import auto_interval

    experiment = description.defaultExperiment
    start = float(settings.get("start_time", getattr(experiment, "startTime", None) or 0.0))
    chosen: dict[str, float] = {}
    if "stop_time" not in settings and getattr(experiment, "stopTime", None) is None:
        chosen["stop_time"] = start + 1.0
    stop = float(settings.get("stop_time", chosen.get("stop_time", getattr(experiment, "stopTime", None) or 1.0)))
    if "step" not in settings and getattr(experiment, "stepSize", None) is None:
        chosen["step"] = float(auto_interval(stop - start))
    if chosen:
        builder.simulation(where="defaults", **chosen)
        for key in chosen:
            builder.setting_from(key, "chosen as fmpy simulate does (the FMU's DefaultExperiment gives none)")
    return [f"{key} = {value:g} s: the FMU's DefaultExperiment gives none (as fmpy simulate chooses it)"
            for key, value in chosen.items()]


def _connect_input(builder: SystemBuilder, variables: dict[str, Any], input_file: Path) -> list[str]:
    """The input file as a block driving the FMU inputs its columns name."""
    try:
        probe = CsvInput("input", input_file)
    except ValueError as error:
        raise SystemFileError(f"{builder.name}: --input: {error}") from None
    inputs = {name for name, v in variables.items() if v.causality == "input"}
    used = [c for c in probe.outputs if c in inputs]
    unused = [c for c in probe.outputs if c not in inputs]
    if not used:
        raise SystemFileError(f"{builder.name}: --input {input_file}: no column names an input of the FMU (columns: "
                              f"{', '.join(probe.outputs)}; inputs: {', '.join(sorted(inputs)) or 'none'})")
    continuous = {"Real", "Float64", "Float32"}
    hold = [c for c in used if str(variables[c].type) not in continuous or variables[c].variability == "discrete"]
    types = {c: str(variables[c].type) for c in used if str(variables[c].type) not in ("Real",)}
    try:
        block = CsvInput("input", input_file, hold=hold, types=types)
    except ValueError as error:
        raise SystemFileError(f"{builder.name}: --input: {error}") from None
    builder.add_block("input", block, kind="csv", keys={"file": str(input_file), "hold": hold, "types": types})
    for column in used:
        builder.connect(f"input.{column}", f"{INSTANCE}.{column}", where=f"--input column {column!r}")
    return [f"input columns {', '.join(unused)}: not inputs of the FMU, left out"] if unused else []
