"""System description files (TOML): FMUs, Python blocks, connections, step, stop time, master
algorithm and recorded variables. :func:`load_system` reads and validates one; every problem is a
:class:`SystemFileError` naming the file and the entry.

```toml
[simulation]
stop_time = 6.0            # s
step = 1e-3                # s, communication step
algorithm = "gauss-seidel" # or "jacobi"
# order = ["torque", "body", "wheel1"]   # Gauss-Seidel order (default: sources, FMUs, other blocks)

[[fmu]]
name = "body"
path = "RoverBody.fmu"     # relative to this file (or to --fmu-dir)
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

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import fmpy

from fmubuild.units import base_units

from .blocks import Block, make_block

ALGORITHMS = ("jacobi", "gauss-seidel")


class SystemFileError(ValueError):
    """A system file that cannot be run; the message names the file and the entry."""


@dataclass(frozen=True)
class Port:
    instance: str
    variable: str

    def __str__(self) -> str:
        return f"{self.instance}.{self.variable}"


@dataclass
class FmuEntry:
    name: str
    path: Path
    parameters: dict[str, float]
    start: dict[str, float]
    description: Any  # fmpy ModelDescription

    def variables(self) -> dict[str, Any]:
        return {v.name: v for v in self.description.modelVariables}


@dataclass
class BlockEntry:
    name: str
    kind: str
    block: Block


@dataclass(frozen=True)
class Connection:
    number: int  # 1-based position among the [[connection]] entries
    source: Port
    target: Port


@dataclass
class System:
    path: Path | None
    fmus: list[FmuEntry]
    blocks: list[BlockEntry]
    connections: list[Connection]
    step: float
    stop_time: float
    start_time: float = 0.0
    algorithm: str = "gauss-seidel"
    order: list[str] = field(default_factory=list)
    record: list[Port] = field(default_factory=list)

    def participant(self, name: str) -> FmuEntry | BlockEntry:
        for entry in [*self.fmus, *self.blocks]:
            if entry.name == name:
                return entry
        raise KeyError(name)


def _port(text: Any, where: str) -> Port:
    if not isinstance(text, str) or "." not in text:
        raise SystemFileError(f"{where}: {text!r}: expected \"instance.variable\"")
    instance, _, variable = text.partition(".")
    return Port(instance, variable)


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SystemFileError(f"{where}: {value!r}: expected a number")
    return float(value)


def _table(value: Any, where: str) -> dict[str, Any]:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise SystemFileError(f"{where}: expected a table, e.g. {{ \"name\" = 1.0 }}")
    return value


def load_system(path: Path | str, *, fmu_dir: Path | None = None) -> System:
    """Read and validate a system file. Relative FMU paths are resolved against ``fmu_dir`` if
    given, else against the file's folder."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise SystemFileError(f"{path}: no such system file") from None
    except tomllib.TOMLDecodeError as error:
        raise SystemFileError(f"{path}: not valid TOML: {error}") from None
    return system_from_dict(data, name=str(path), base=fmu_dir or path.parent, path=path)


def system_from_dict(data: dict[str, Any], *, name: str, base: Path, path: Path | None = None) -> System:
    def error(where: str, message: str) -> SystemFileError:
        return SystemFileError(f"{name}: {where}: {message}")

    simulation = _table(data.get("simulation"), f"{name}: [simulation]")
    for key in ("stop_time", "step"):
        if key not in simulation:
            raise error("[simulation]", f"{key} is missing (seconds)")
    step = _number(simulation["step"], f"{name}: [simulation] step")
    stop_time = _number(simulation["stop_time"], f"{name}: [simulation] stop_time")
    start_time = _number(simulation.get("start_time", 0.0), f"{name}: [simulation] start_time")
    if not step > 0:
        raise error("[simulation] step", f"{step!r}: expected a communication step > 0 s")
    if not stop_time > start_time:
        raise error("[simulation] stop_time", f"{stop_time!r}: expected a stop time > start time {start_time} s")
    if step > stop_time - start_time:
        raise error("[simulation] step", f"{step!r} s is longer than the run ({stop_time - start_time!r} s)")
    algorithm = simulation.get("algorithm", "gauss-seidel")
    if algorithm not in ALGORITHMS:
        raise error("[simulation] algorithm", f"{algorithm!r}: expected one of {', '.join(ALGORITHMS)}")
    unknown_keys = set(simulation) - {"stop_time", "step", "start_time", "algorithm", "order"}
    if unknown_keys:
        raise error("[simulation]", f"unknown key(s) {sorted(unknown_keys)}")

    names: set[str] = set()

    def claim(instance: str, where: str) -> None:
        if not isinstance(instance, str) or not instance or "." in instance:
            raise error(where, f"name = {instance!r}: expected a non-empty name without dots")
        if instance in names:
            raise error(where, f"name {instance!r} is used twice")
        names.add(instance)

    fmus: list[FmuEntry] = []
    for i, entry in enumerate(data.get("fmu", []), start=1):
        where = f"[[fmu]] {i}"
        entry = _table(entry, f"{name}: {where}")
        instance = entry.get("name")
        claim(instance, where)
        where = f"[[fmu]] {instance!r}"
        if "path" not in entry:
            raise error(where, "path is missing")
        fmu_path = Path(entry["path"])
        if not fmu_path.is_absolute():
            fmu_path = base / fmu_path
        if not fmu_path.is_file():
            raise error(where, f"FMU file {fmu_path} not found (run `make fmus`?)")
        try:
            description = fmpy.read_model_description(str(fmu_path))
        except Exception as failure:  # noqa: BLE001 - fmpy raises many kinds
            raise error(where, f"{fmu_path} is not a readable FMU: {failure}") from None
        if description.fmiVersion != "2.0" or description.coSimulation is None:
            raise error(where, f"{fmu_path}: expected an FMI 2.0 Co-Simulation FMU "
                        f"(got FMI {description.fmiVersion}, CS {'yes' if description.coSimulation else 'no'})")
        fmu = FmuEntry(instance, fmu_path, {}, {}, description)
        variables = fmu.variables()
        for key, table in (("parameters", fmu.parameters), ("start", fmu.start)):
            for variable, value in _table(entry.get(key), f"{name}: {where} {key}").items():
                if variable not in variables:
                    raise error(f"{where} {key}", f"{instance} has no variable {variable!r}")
                v = variables[variable]
                if key == "parameters" and v.causality != "parameter":
                    raise error(f"{where} parameters", f"{instance}.{variable} is not a parameter "
                                f"(causality {v.causality}); inputs and states go under start")
                if key == "start" and not (v.causality == "input" or v.initial in ("exact", "approx")):
                    raise error(f"{where} start", f"{instance}.{variable} cannot be given a start value "
                                f"(causality {v.causality}, initial {v.initial})")
                table[variable] = _number(value, f"{name}: {where} {key} {variable}")
        unknown_keys = set(entry) - {"name", "path", "parameters", "start"}
        if unknown_keys:
            raise error(where, f"unknown key(s) {sorted(unknown_keys)}")
        fmus.append(fmu)

    blocks: list[BlockEntry] = []
    for i, entry in enumerate(data.get("block", []), start=1):
        where = f"[[block]] {i}"
        entry = _table(entry, f"{name}: {where}")
        instance = entry.get("name")
        claim(instance, where)
        kind = entry.get("type")
        params = {k: v for k, v in entry.items() if k not in ("name", "type")}
        try:
            block = make_block(instance, kind, params)
        except ValueError as failure:
            raise error(f"[[block]] {instance!r}", str(failure)) from None
        blocks.append(BlockEntry(instance, kind, block))

    if not fmus and not blocks:
        raise error("[[fmu]]", "the system has no FMU and no block")

    def lookup(port: Port, where: str) -> tuple[str, str | None]:
        """(causality, unit) of a port; errors for unknown instances and variables."""
        if port.instance not in names:
            raise error(where, f"no instance {port.instance!r}; expected one of {', '.join(sorted(names))}")
        for fmu in fmus:
            if fmu.name == port.instance:
                variables = fmu.variables()
                if port.variable not in variables:
                    raise error(where, f"{fmu.name} ({fmu.path.name}) has no variable {port.variable!r}")
                v = variables[port.variable]
                return v.causality, v.unit
        block = next(b.block for b in blocks if b.name == port.instance)
        if port.variable in block.inputs:
            return "input", block.units.get(port.variable)
        if port.variable in block.outputs:
            return "output", block.units.get(port.variable)
        raise error(where, f"block {port.instance} has no variable {port.variable!r} "
                    f"(inputs {list(block.inputs)}, outputs {list(block.outputs)})")

    connections: list[Connection] = []
    driven: dict[Port, int] = {}
    for i, entry in enumerate(data.get("connection", []), start=1):
        entry = _table(entry, f"{name}: [[connection]] {i}")
        where = f"[[connection]] {i} (from = {entry.get('from')!r}, to = {entry.get('to')!r})"
        source = _port(entry.get("from"), f"{name}: {where} from")
        target = _port(entry.get("to"), f"{name}: {where} to")
        source_causality, source_unit = lookup(source, where)
        target_causality, target_unit = lookup(target, where)
        if source_causality != "output":
            raise error(where, f"{source} is not an output (causality {source_causality}); "
                        "a connection goes from an output to an input")
        if target_causality != "input":
            raise error(where, f"{target} is not an input (causality {target_causality}); "
                        "a connection goes from an output to an input")
        if source_unit is not None and target_unit is not None and base_units(source_unit) != base_units(target_unit):
            raise error(where, f"unit mismatch: {source} is in {source_unit}, {target} in {target_unit}")
        if target in driven:
            raise error(where, f"input {target} is connected twice (also by [[connection]] {driven[target]})")
        driven[target] = i
        connections.append(Connection(i, source, target))

    for fmu in fmus:
        for v in fmu.description.modelVariables:
            if v.causality == "input" and Port(fmu.name, v.name) not in driven and v.name not in fmu.start:
                raise error(f"[[fmu]] {fmu.name!r}", f"input {fmu.name}.{v.name} is neither connected nor "
                            "given a value (add a [[connection]] or start = {{ ... }})")
    for entry in blocks:
        for variable in entry.block.inputs:
            if Port(entry.name, variable) not in driven:
                raise error(f"[[block]] {entry.name!r}", f"input {entry.name}.{variable} is not connected")

    order = simulation.get("order")
    if order is None:
        order = ([b.name for b in blocks if not b.block.inputs] + [f.name for f in fmus]
                 + [b.name for b in blocks if b.block.inputs])
    elif not isinstance(order, list) or sorted(order) != sorted(names):
        raise error("[simulation] order", f"{order!r}: expected every instance once: {sorted(names)}")

    record_table = _table(data.get("record"), f"{name}: [record]")
    record: list[Port] = []
    if "variables" in record_table:
        for text in record_table["variables"]:
            port = _port(text, f"{name}: [record] variables")
            lookup(port, f"[record] variables {text!r}")
            record.append(port)
    else:
        for instance in order:
            participant = next(e for e in [*fmus, *blocks] if e.name == instance)
            if isinstance(participant, FmuEntry):
                record += [Port(instance, v.name) for v in participant.description.modelVariables
                           if v.causality == "output"]
            else:
                record += [Port(instance, o) for o in participant.block.outputs]
    return System(path, fmus, blocks, connections, step, stop_time, start_time, algorithm, list(order), record)
