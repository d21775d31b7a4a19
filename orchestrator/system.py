"""System description files (TOML): a reader and a writer of the typed system model (``model``).
:func:`load_system` reads a file into a checked :class:`System` through the
:class:`~rover_cosim.orchestrator.builder.SystemBuilder` (every problem a :class:`SystemFileError`
naming the file and the entry); :func:`system_to_toml` writes a System back (blocks built in code
from objects cannot be written: a file holds a block's type and keys).

```toml
[simulation]
stop_time = 6.0            # s
step = 1e-3                # s, communication step
algorithm = "gauss-seidel" # or "jacobi"
# order = ["torque", "body", "wheel1"]   # Gauss-Seidel order (default: sources, FMUs, other blocks)
# threads = 2              # FMUs stepped at the same time (default: the cores)
# native = true            # FMUs stepped from C (orchestrator.native; default true)
# relative_tolerance = 1e-6 # of the integrator of Model Exchange FMUs (CVode)
# output_interval = 0.01   # s, rows recorded every so often (a whole number of steps; default every step)

[[fmu]]
name = "body"
path = "RoverBody.fmu"     # relative to this file (or to --fmu-dir)
# interface = "model-exchange"   # run its ME interface (the engine integrates it); default CS where offered
parameters = { "rover.M" = 1570.0 }
start = { }                # start values of inputs (and of states with an exact start)

[[block]]
name = "torque"
type = "tanh_step"         # constant, step, ramp, tanh_step, table, python
begin = 40.0
end = 9.0
time = 3.0
width = 0.3
unit = "N.m"

[[connection]]
from = "body.W[1]"
to = "wheel1.W"

[record]
variables = ["body.v", "wheel1.Fz"]   # default: every output of every participant
```
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path
from typing import Any

import tomli_w

from .algorithms import ALGORITHMS
from .blocks import make_block
from .builder import SIMULATION_DEFAULTS, SystemBuilder, dependency_graph, optional_inputs
from .model import (
    INTERFACES,
    ISOLATION,
    BlockEntry,
    Connection,
    FmuEntry,
    Iteration,
    Port,
    System,
    SystemFileError,
)

#: Every key each section of a system file may have, with what it means (units in brackets); the
#: reader accepts exactly these and the documentation's reference is generated from this table.
KEY_MEANINGS: dict[str, dict[str, str]] = {
    "simulation": {
        "stop_time": "end of the run [s]",
        "step": "communication step [s]",
        "start_time": "start of the run [s]",
        "algorithm": f"the master algorithm: one of {', '.join(ALGORITHMS)}",
        "order": "Gauss-Seidel order: a list of instance names (default: sources, FMUs, other blocks; the sources "
                 "step after the others in any order, so every participant sees their value at t)",
        "tolerance": "iterative only: a step is repeated until every exchanged value changes by less than "
                     "tolerance x (1 + |value|) [1]",
        "max_iterations": "iterative only: the most passes per step",
        "relaxation": "iterative only: how far (0 < relaxation <= 1) each pass moves towards the new values [1]",
        "allow_algebraic_loops": "run a Jacobi/Gauss-Seidel system with a direct-feedthrough loop "
                                 "(its values then lag a step); else such a system is refused",
        "threads": "FMUs stepped at the same time (default: the cores)",
        "native": "step the FMUs from C (the native stepper) where the system allows it",
        "relative_tolerance": "of the integrator (CVode) of Model Exchange FMUs, and told to every FMU [1]",
        "output_interval": "rows recorded every so often [s] (a whole number of steps; default every step)",
        "fmu_timeout": "the longest one call of an FMU run in a child process may take [s] (default: no limit); "
                       "an FMU that takes longer is ended and the run fails with the rows so far kept",
    },
    "fmu": {
        "name": "instance name (letters, digits, _; it names a folder)",
        "path": "the FMU file, relative to the system file (or to --fmu-dir)",
        "parameters": "a table of parameter values by variable name, in the variables' units",
        "start": "a table of start values of inputs (and of states with an exact start)",
        "interface": f"which interface runs it: one of {', '.join(INTERFACES)} (default: co-simulation where "
                     "offered)",
        "isolation": "where it runs: \"process\" (a child process of its own: a crash, exit() or hang of the FMU "
                     "ends the run with a message, not the tool), \"none\" (this process: the fastest) or \"auto\" "
                     "(the default: none for an FMU this project generated, else process)",
    },
    "block": {
        "name": "instance name",
        "type": "the block type (see the block reference); every other key is the block's own",
    },
    "connection": {
        "from": "an output, \"instance.variable\"",
        "to": "an input, \"instance.variable\" (each input driven at most once)",
    },
    "record": {
        "variables": "the ports recorded, \"instance.variable\" (default: every output of every participant)",
    },
}

#: The keys each section of a system file may have (a block's own keys are checked by its type).
SECTION_KEYS = {section: set(keys) for section, keys in KEY_MEANINGS.items() if section != "block"}


def _table(value: Any, where: str) -> dict[str, Any]:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise SystemFileError(f"{where}: expected a table, e.g. {{ \"name\" = 1.0 }}")
    return value


def _tables(value: Any, where: str) -> list[dict[str, Any]]:
    """An array of tables (``[[fmu]]``, ``[[block]]``, ``[[connection]]``); absent is empty."""
    if value is None:
        return []
    if not isinstance(value, list):
        raise SystemFileError(f"{where}: expected an array of tables ([[...]] entries)")
    return [_table(entry, f"{where} {i}") for i, entry in enumerate(value, start=1)]


def _known_keys(builder: SystemBuilder, entry: dict[str, Any], section: str, where: str) -> None:
    unknown = set(entry) - SECTION_KEYS[section]
    if unknown:
        raise builder.error(where, f"unknown key(s) {sorted(unknown)}; expected {sorted(SECTION_KEYS[section])}")


def load_system(path: Path | str, *, fmu_dir: Path | None = None, validation: str = "strict") -> System:
    """Read and validate a system file. Relative FMU paths are resolved against ``fmu_dir`` if
    given, else against the file's folder; ``validation``: how the FMUs' model descriptions are
    checked (``model.VALIDATION``)."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise SystemFileError(f"{path}: no such system file") from None
    except (IsADirectoryError, PermissionError, UnicodeDecodeError) as error:
        raise SystemFileError(f"{path}: cannot be read as a system file ({type(error).__name__})") from None
    except tomllib.TOMLDecodeError as error:
        raise SystemFileError(f"{path}: not valid TOML: {error}") from None
    except RecursionError:
        raise SystemFileError(f"{path}: nested too deeply to be a system file") from None
    return system_from_dict(data, name=str(path), base=fmu_dir or path.parent, path=path, validation=validation)


def system_from_dict(data: dict[str, Any], *, name: str, base: Path, path: Path | None = None,
                     validation: str = "strict") -> System:
    """A checked :class:`System` from the parsed TOML ``data`` (``name`` is used in messages)."""
    builder = SystemBuilder(name, base=base, path=path, validation=validation)
    unknown = set(data) - {"simulation", "fmu", "block", "connection", "record"}
    if unknown:
        raise builder.error("top level", f"unknown table(s) {sorted(unknown)}; expected [simulation], [[fmu]], "
                            "[[block]], [[connection]], [record]")
    simulation = _table(data.get("simulation"), f"{name}: [simulation]")
    _known_keys(builder, simulation, "simulation", "[simulation]")
    builder.simulation(where="[simulation]", **simulation)  # a missing stop time or step: the FMUs' defaults
    for i, entry in enumerate(_tables(data.get("fmu"), f"{name}: [[fmu]]"), 1):
        _read_fmu_entry(builder, entry, i)
    folder = path.parent if path is not None else None
    for i, entry in enumerate(_tables(data.get("block"), f"{name}: [[block]]"), 1):
        _read_block_entry(builder, entry, i, folder)
    for i, entry in enumerate(_tables(data.get("connection"), f"{name}: [[connection]]"), 1):
        where = f"[[connection]] {i} (from = {entry.get('from')!r}, to = {entry.get('to')!r})"
        _known_keys(builder, entry, "connection", where)
        builder.connect(entry.get("from"), entry.get("to"), where=where, label=f"[[connection]] {i}")  # type: ignore[arg-type]
    record = _table(data.get("record"), f"{name}: [record]")
    _known_keys(builder, record, "record", "[record]")
    if "variables" in record:
        if not isinstance(record["variables"], list):
            raise builder.error("[record] variables", f"{record['variables']!r}: expected a list of "
                                "\"instance.variable\"")
        builder.record(*record["variables"], where="[record] variables")
    return builder.build()


def _read_fmu_entry(builder: SystemBuilder, entry: dict[str, Any], number: int) -> None:
    """One [[fmu]] entry: name, path (relative to the base folder), parameters, start values."""
    instance = builder.claim(entry.get("name"), f"[[fmu]] {number}")
    where = f"[[fmu]] {instance!r}"
    _known_keys(builder, entry, "fmu", where)
    if "path" not in entry:
        raise builder.error(where, "path is missing")
    if not isinstance(entry["path"], str):
        raise builder.error(where, f"path = {entry['path']!r}: expected a file name")
    values = {key: _table(entry.get(key), f"{builder.name}: {where} {key}") for key in ("parameters", "start")}
    interface = entry.get("interface")
    if interface is not None and interface not in INTERFACES:
        raise builder.error(f"{where} interface", f"{interface!r}: expected one of {', '.join(INTERFACES)}")
    isolation = entry.get("isolation", "auto")
    if isolation not in ISOLATION:
        raise builder.error(f"{where} isolation", f"{isolation!r}: expected one of {', '.join(ISOLATION)}")
    builder.add_fmu(instance, entry["path"], where=where, interface=interface, isolation=isolation, **values)


def _read_block_entry(builder: SystemBuilder, entry: dict[str, Any], number: int, folder: Path | None) -> None:
    """One [[block]] entry: name, type and the block's own keys (a python block's module is
    looked up in ``folder``, the system file's, first)."""
    instance = builder.claim(entry.get("name"), f"[[block]] {number}")
    kind = entry.get("type")
    where = f"[[block]] {instance!r}"
    if not isinstance(kind, str):
        raise builder.error(where, f"type = {kind!r}: expected a block type name")
    keys = {k: v for k, v in entry.items() if k not in ("name", "type")}
    try:
        block = make_block(instance, kind, keys, folder)
    except ValueError as failure:
        raise builder.error(where, str(failure)) from None
    builder.add_block(instance, block, kind=kind, keys=keys, where=where)


def system_to_dict(system: System, folder: Path | None = None) -> dict[str, Any]:
    """``system`` as the tables of a system file; FMU paths relative to ``folder`` where they
    lie below it. SystemFileError for a block that was built in code from an object."""
    simulation: dict[str, Any] = {"stop_time": system.stop_time, "step": system.step}
    settings = {"start_time": system.start_time, "algorithm": system.algorithm, "order": list(system.order),
                "allow_algebraic_loops": system.allow_algebraic_loops, "threads": system.threads_setting,
                "native": system.native, "relative_tolerance": system.relative_tolerance,
                "output_interval": system.output_interval, "fmu_timeout": system.fmu_timeout}
    simulation.update({k: v for k, v in settings.items() if v is not None and v != SIMULATION_DEFAULTS.get(k)})
    if system.algorithm == "iterative":
        simulation.update(tolerance=system.iteration.tolerance, max_iterations=system.iteration.max_iterations,
                          relaxation=system.iteration.relaxation)
    data: dict[str, Any] = {"simulation": simulation}
    data["fmu"] = []
    for f in system.fmus:
        entry: dict[str, Any] = {"name": f.name, "path": _relative(f.path, folder)}
        if f.interface != "co-simulation":
            entry["interface"] = f.interface
        if f.isolation != "auto":
            entry["isolation"] = f.isolation
        entry.update({key: dict(values) for key, values in (("parameters", f.parameters), ("start", f.start))
                      if values})
        data["fmu"].append(entry)
    blocks = []
    for block in system.blocks:
        if block.keys is None:
            raise SystemFileError(f"{system.name}: block {block.name!r} ({type(block.block).__name__}) was built in "
                                  "code from an object: a system file holds a block's type and keys, so it cannot "
                                  "be written")
        blocks.append({"name": block.name, "type": block.kind, **block.keys})
    if blocks:
        data["block"] = blocks
    if system.connections:
        data["connection"] = [{"from": str(c.source), "to": str(c.target)} for c in system.connections]
    data["record"] = {"variables": [str(p) for p in system.record]}
    return data


def _relative(path: Path, folder: Path | None) -> str:
    if folder is None or not path.is_absolute():
        return str(path)
    try:
        return os.path.relpath(path, folder) if path.resolve().is_relative_to(folder.resolve()) else str(path)
    except ValueError:
        return str(path)


def system_to_toml(system: System, folder: Path | None = None) -> str:
    """``system`` as the text of a system file (see :func:`system_to_dict`)."""
    return tomli_w.dumps(system_to_dict(system, folder))


__all__ = ["ALGORITHMS", "BlockEntry", "Connection", "FmuEntry", "Iteration", "Port", "System", "SystemFileError",
           "dependency_graph", "load_system", "optional_inputs", "system_from_dict", "system_to_dict",
           "system_to_toml"]
