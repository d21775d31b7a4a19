"""System description files (TOML): FMUs, Python blocks, connections, step, stop time, master
algorithm and recorded variables. :func:`load_system` reads and validates one; every problem is a
:class:`SystemFileError` naming the file and the entry.

```toml
[simulation]
stop_time = 6.0            # s
step = 1e-3                # s, communication step
algorithm = "gauss-seidel" # or "jacobi"
# order = ["torque", "body", "wheel1"]   # Gauss-Seidel order (default: sources, FMUs, other blocks)
# threads = 2              # FMUs stepped at the same time (default: the cores)
# native = true            # FMUs stepped from C (orchestrator.native; default true)

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

import json
import os
import re
import tomllib
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import fmpy

from rover_cosim.common.units import base_units

from .blocks import Block, make_block
from .loops import describe, find_loop

ALGORITHMS = ("jacobi", "gauss-seidel", "iterative")
#: Instance names: identifiers, so that a name is never a path or a port separator.
IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


@dataclass(frozen=True)
class Iteration:
    """Settings of the iterative master (``algorithm = "iterative"``): a step is repeated, the
    participants rolled back, until every exchanged value changes by less than
    ``tolerance`` x (1 + |value|) between two passes, at most ``max_iterations`` passes; the next
    guess moves ``relaxation`` (0 < relaxation <= 1) of the way to the new values."""

    tolerance: float = 1e-6
    max_iterations: int = 20
    relaxation: float = 1.0


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
    keys: dict[str, Any] = field(default_factory=dict)  # the entry's own keys, as in the system file


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
    iteration: Iteration = field(default_factory=Iteration)
    algebraic_loop: list[Port] | None = None  # a cycle of direct feedthrough, if there is one
    threads: int = 1  # FMUs stepped at the same time where the algorithm allows (Jacobi, Gauss-Seidel)
    native: bool = True  # Jacobi/Gauss-Seidel step the FMUs from C (orchestrator.native) where it builds

    def participants(self) -> dict[str, FmuEntry | BlockEntry]:
        """Every FMU and block entry by instance name."""
        entries: dict[str, FmuEntry | BlockEntry] = {f.name: f for f in self.fmus}
        entries.update({b.name: b for b in self.blocks})
        return entries


#: The keys each section of a system file may have.
SECTION_KEYS = {
    "simulation": {"stop_time", "step", "start_time", "algorithm", "order", "tolerance", "max_iterations",
                   "relaxation", "allow_algebraic_loops", "threads",
                   "native"},
    "fmu": {"name", "path", "parameters", "start"},
    "connection": {"from", "to"},
    "record": {"variables"},
}


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


def _tables(value: Any, where: str) -> list[dict[str, Any]]:
    """An array of tables (``[[fmu]]``, ``[[block]]``, ``[[connection]]``); absent is empty."""
    if value is None:
        return []
    if not isinstance(value, list):
        raise SystemFileError(f"{where}: expected an array of tables ([[...]] entries)")
    return [_table(entry, f"{where} {i}") for i, entry in enumerate(value, start=1)]


class _Context:
    """The file being parsed (for messages), where relative FMU paths start, the names in use."""

    def __init__(self, name: str, base: Path):
        self.name, self.base = name, base
        self.names: set[str] = set()

    def error(self, where: str, message: str) -> SystemFileError:
        return SystemFileError(f"{self.name}: {where}: {message}")

    def number(self, value: Any, where: str) -> float:
        return _number(value, f"{self.name}: {where}")

    def known_keys(self, entry: dict[str, Any], section: str, where: str) -> None:
        unknown = set(entry) - SECTION_KEYS[section]
        if unknown:
            raise self.error(where, f"unknown key(s) {sorted(unknown)}; expected {sorted(SECTION_KEYS[section])}")

    def claim(self, instance: Any, where: str) -> str:
        if not isinstance(instance, str) or not IDENTIFIER.fullmatch(instance):
            raise self.error(where, f"name = {instance!r}: expected an identifier (letters, digits and _, not "
                             "starting with a digit; it names the instance and its folder)")
        if instance in self.names:
            raise self.error(where, f"name {instance!r} is used twice")
        self.names.add(instance)
        return instance


def load_system(path: Path | str, *, fmu_dir: Path | None = None) -> System:
    """Read and validate a system file. Relative FMU paths are resolved against ``fmu_dir`` if
    given, else against the file's folder."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise SystemFileError(f"{path}: no such system file") from None
    except (IsADirectoryError, PermissionError, UnicodeDecodeError) as error:
        raise SystemFileError(f"{path}: cannot be read as a system file ({type(error).__name__})") from None
    except tomllib.TOMLDecodeError as error:
        raise SystemFileError(f"{path}: not valid TOML: {error}") from None
    return system_from_dict(data, name=str(path), base=fmu_dir or path.parent, path=path)


def system_from_dict(data: dict[str, Any], *, name: str, base: Path, path: Path | None = None) -> System:
    """A checked :class:`System` from the parsed TOML ``data`` (``name`` is used in messages)."""
    context = _Context(name, base)
    unknown = set(data) - {"simulation", "fmu", "block", "connection", "record"}
    if unknown:
        raise context.error("top level", f"unknown table(s) {sorted(unknown)}; expected [simulation], [[fmu]], "
                            "[[block]], [[connection]], [record]")
    simulation = _table(data.get("simulation"), f"{name}: [simulation]")
    step, stop_time, start_time, algorithm = parse_simulation(simulation, context)
    fmus = [parse_fmu(entry, i, context) for i, entry in enumerate(_tables(data.get("fmu"), f"{name}: [[fmu]]"), 1)]
    folder = path.parent if path is not None else None
    blocks = [parse_block(entry, i, context, folder)
              for i, entry in enumerate(_tables(data.get("block"), f"{name}: [[block]]"), 1)]
    if not fmus and not blocks:
        raise context.error("[[fmu]]", "the system has no FMU and no block")
    ports = _PortTable(fmus, blocks, context)
    connections = parse_connections(_tables(data.get("connection"), f"{name}: [[connection]]"), ports, context)
    check_inputs_driven(fmus, blocks, connections, context)
    order = parse_order(simulation.get("order"), fmus, blocks, context)
    record = parse_record(_table(data.get("record"), f"{name}: [record]"), order, ports, context)
    iteration = parse_iteration(simulation, algorithm, context)
    loop = check_loops(fmus, blocks, connections, simulation, algorithm, context)
    threads = simulation.get("threads", os.cpu_count() or 1)
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise context.error("[simulation] threads", f"{threads!r}: expected a whole number >= 1 (FMUs stepped "
                            "at the same time)")
    native = simulation.get("native", True)
    if not isinstance(native, bool):
        raise context.error("[simulation] native", f"{native!r}: expected true or false (FMUs stepped from C)")
    return System(path, fmus, blocks, connections, step, stop_time, start_time, algorithm, order, record, iteration,
                  loop, threads, native)


def dependency_graph(fmus: list[FmuEntry], blocks: list[BlockEntry],
                     connections: list[Connection]) -> dict[Port, list[Port]]:
    """port -> the ports that depend on it directly: connections, and each participant's outputs
    on its inputs (FMUs: ModelStructure, an output without a dependency list on every input;
    blocks: their ``feedthrough``, True by default for a block with inputs)."""
    graph: dict[Port, list[Port]] = {}
    for connection in connections:
        graph.setdefault(connection.source, []).append(connection.target)
    for fmu in fmus:
        inputs = [v.name for v in fmu.description.modelVariables if v.causality == "input"]
        for unknown in fmu.description.outputs:
            sources = inputs if unknown.dependencies is None else [d.name for d in unknown.dependencies
                                                                   if d.causality == "input"]
            for name in sources:
                graph.setdefault(Port(fmu.name, name), []).append(Port(fmu.name, unknown.variable.name))
    for entry in blocks:
        block = entry.block
        if getattr(block, "feedthrough", bool(block.inputs)):
            for name in block.inputs:
                graph.setdefault(Port(entry.name, name), []).extend(Port(entry.name, o) for o in block.outputs)
    return graph


def check_loops(fmus: list[FmuEntry], blocks: list[BlockEntry], connections: list[Connection],
                simulation: dict[str, Any], algorithm: str, context: _Context) -> list[Port] | None:
    """A cycle of direct feedthrough is an error for Jacobi and Gauss-Seidel unless
    ``allow_algebraic_loops = true`` (then the order breaks it with a one-step delay); the
    iterative master solves it."""
    allow = simulation.get("allow_algebraic_loops", False)
    if not isinstance(allow, bool):
        raise context.error("[simulation] allow_algebraic_loops", f"{allow!r}: expected true or false")
    loop = find_loop(dependency_graph(fmus, blocks, connections))
    if loop and algorithm != "iterative" and not allow:
        raise context.error("connections", f"algebraic loop (direct feedthrough all the way round): {describe(loop)}; "
                            "use algorithm = \"iterative\" to solve it, or allow_algebraic_loops = true in "
                            "[simulation] to break it with a one-step delay in the order of the participants")
    return loop


def parse_iteration(simulation: dict[str, Any], algorithm: str, context: _Context) -> Iteration:
    """[simulation] tolerance, max_iterations, relaxation: only with algorithm = "iterative"."""
    given = {key: simulation[key] for key in ("tolerance", "max_iterations", "relaxation") if key in simulation}
    if given and algorithm != "iterative":
        raise context.error("[simulation]", f"{', '.join(sorted(given))} only apply to algorithm = \"iterative\" "
                            f"(this system uses {algorithm!r})")
    default = Iteration()
    tolerance = context.number(given.get("tolerance", default.tolerance), "[simulation] tolerance")
    relaxation = context.number(given.get("relaxation", default.relaxation), "[simulation] relaxation")
    bound = given.get("max_iterations", default.max_iterations)
    if not tolerance > 0:
        raise context.error("[simulation] tolerance", f"{tolerance!r}: expected > 0")
    if not 0 < relaxation <= 1:
        raise context.error("[simulation] relaxation", f"{relaxation!r}: expected 0 < relaxation <= 1")
    if isinstance(bound, bool) or not isinstance(bound, int) or bound < 1:
        raise context.error("[simulation] max_iterations", f"{bound!r}: expected a whole number >= 1")
    return Iteration(tolerance, bound, relaxation)


def parse_simulation(simulation: dict[str, Any], context: _Context) -> tuple[float, float, float, str]:
    """[simulation]: (step, stop_time, start_time [s], algorithm)."""
    context.known_keys(simulation, "simulation", "[simulation]")
    for key in ("stop_time", "step"):
        if key not in simulation:
            raise context.error("[simulation]", f"{key} is missing (seconds)")
    step = context.number(simulation["step"], "[simulation] step")
    stop_time = context.number(simulation["stop_time"], "[simulation] stop_time")
    start_time = context.number(simulation.get("start_time", 0.0), "[simulation] start_time")
    if not step > 0:
        raise context.error("[simulation] step", f"{step!r}: expected a communication step > 0 s")
    if not stop_time > start_time:
        raise context.error("[simulation] stop_time",
                            f"{stop_time!r}: expected a stop time > start time {start_time} s")
    if step > stop_time - start_time:
        raise context.error("[simulation] step", f"{step!r} s is longer than the run ({stop_time - start_time!r} s)")
    algorithm = simulation.get("algorithm", "gauss-seidel")
    if algorithm not in ALGORITHMS:
        raise context.error("[simulation] algorithm", f"{algorithm!r}: expected one of {', '.join(ALGORITHMS)}")
    return step, stop_time, start_time, algorithm


def _read_fmu(fmu_path: Path, where: str, context: _Context) -> Any:
    """The model description of an FMI 2.0 Co-Simulation FMU file."""
    if not fmu_path.is_file():
        raise context.error(where, f"FMU file {fmu_path} not found (run `make fmus`?)")
    try:
        description = fmpy.read_model_description(str(fmu_path))
    except Exception as failure:  # noqa: BLE001 - fmpy raises many kinds
        raise context.error(where, f"{fmu_path} is not a readable FMU: {failure}") from None
    if description.fmiVersion != "2.0" or description.coSimulation is None:
        raise context.error(where, f"{fmu_path}: expected an FMI 2.0 Co-Simulation FMU (got FMI "
                            f"{description.fmiVersion}, CS {'yes' if description.coSimulation else 'no'})")
    return description


def _fmu_values(fmu: FmuEntry, key: str, values: dict[str, Any], where: str, context: _Context) -> dict[str, float]:
    """``parameters`` or ``start`` of an [[fmu]] entry, checked against the FMU's variables."""
    variables = fmu.variables()
    checked: dict[str, float] = {}
    for variable, value in values.items():
        if variable not in variables:
            raise context.error(f"{where} {key}", f"{fmu.name} has no variable {variable!r}")
        v = variables[variable]
        if key == "parameters" and v.causality != "parameter":
            raise context.error(f"{where} parameters", f"{fmu.name}.{variable} is not a parameter "
                                f"(causality {v.causality}); inputs and states go under start")
        if key == "start" and not (v.causality == "input" or v.initial in ("exact", "approx")):
            raise context.error(f"{where} start", f"{fmu.name}.{variable} cannot be given a start value "
                                f"(causality {v.causality}, initial {v.initial})")
        checked[variable] = context.number(value, f"{where} {key} {variable}")
    return checked


def parse_fmu(entry: dict[str, Any], number: int, context: _Context) -> FmuEntry:
    """One [[fmu]] entry: name, path (relative to the base folder), parameters, start values."""
    instance = context.claim(entry.get("name"), f"[[fmu]] {number}")
    where = f"[[fmu]] {instance!r}"
    context.known_keys(entry, "fmu", where)
    if "path" not in entry:
        raise context.error(where, "path is missing")
    if not isinstance(entry["path"], str):
        raise context.error(where, f"path = {entry['path']!r}: expected a file name")
    fmu_path = Path(entry["path"])
    if not fmu_path.is_absolute():
        fmu_path = context.base / fmu_path
    fmu = FmuEntry(instance, fmu_path, {}, {}, _read_fmu(fmu_path, where, context))
    for key in ("parameters", "start"):
        values = _table(entry.get(key), f"{context.name}: {where} {key}")
        getattr(fmu, key).update(_fmu_values(fmu, key, values, where, context))
    return fmu


def parse_block(entry: dict[str, Any], number: int, context: _Context, folder: Path | None = None) -> BlockEntry:
    """One [[block]] entry: name, type and the block's own keys (a python block's module is
    looked up in ``folder``, the system file's, first)."""
    instance = context.claim(entry.get("name"), f"[[block]] {number}")
    kind = entry.get("type")
    if not isinstance(kind, str):
        raise context.error(f"[[block]] {instance!r}", f"type = {kind!r}: expected a block type name")
    params = {k: v for k, v in entry.items() if k not in ("name", "type")}
    try:
        block = make_block(instance, kind, params, folder)
    except ValueError as failure:
        raise context.error(f"[[block]] {instance!r}", str(failure)) from None
    return BlockEntry(instance, kind, block, params)


class _PortTable:
    """Causality and unit of every port of the system's participants."""

    def __init__(self, fmus: list[FmuEntry], blocks: list[BlockEntry], context: _Context):
        self.fmus = {f.name: f for f in fmus}
        self.blocks = {b.name: b.block for b in blocks}
        self.context = context

    def lookup(self, port: Port, where: str) -> tuple[str, str | None]:
        """(causality, unit) of ``port``; errors for unknown instances and variables."""
        names = sorted([*self.fmus, *self.blocks])
        if port.instance in self.fmus:
            fmu = self.fmus[port.instance]
            variables = fmu.variables()
            if port.variable not in variables:
                raise self.context.error(where, f"{fmu.name} ({fmu.path.name}) has no variable {port.variable!r}")
            v = variables[port.variable]
            return v.causality, v.unit
        if port.instance not in self.blocks:
            raise self.context.error(where, f"no instance {port.instance!r}; expected one of {', '.join(names)}")
        block = self.blocks[port.instance]
        if port.variable in block.inputs:
            return "input", block.units.get(port.variable)
        if port.variable in block.outputs:
            return "output", block.units.get(port.variable)
        raise self.context.error(where, f"block {port.instance} has no variable {port.variable!r} "
                                 f"(inputs {list(block.inputs)}, outputs {list(block.outputs)})")

    def outputs(self, instance: str) -> list[Port]:
        if instance in self.fmus:
            return [Port(instance, v.name) for v in self.fmus[instance].description.modelVariables
                    if v.causality == "output"]
        return [Port(instance, o) for o in self.blocks[instance].outputs]


def _check_connection(source: Port, target: Port, ports: _PortTable, where: str, context: _Context) -> None:
    source_causality, source_unit = ports.lookup(source, where)
    target_causality, target_unit = ports.lookup(target, where)
    if source_causality != "output":
        raise context.error(where, f"{source} is not an output (causality {source_causality}); "
                            "a connection goes from an output to an input")
    if target_causality != "input":
        raise context.error(where, f"{target} is not an input (causality {target_causality}); "
                            "a connection goes from an output to an input")
    if source_unit is not None and target_unit is not None and base_units(source_unit) != base_units(target_unit):
        raise context.error(where, f"unit mismatch: {source} is in {source_unit}, {target} in {target_unit}")


def parse_connections(entries: list[dict[str, Any]], ports: _PortTable, context: _Context) -> list[Connection]:
    """[[connection]] entries: from an output to an input of the same unit, each input once."""
    connections: list[Connection] = []
    driven: dict[Port, int] = {}
    for i, entry in enumerate(entries, start=1):
        where = f"[[connection]] {i} (from = {entry.get('from')!r}, to = {entry.get('to')!r})"
        context.known_keys(entry, "connection", where)
        source = _port(entry.get("from"), f"{context.name}: {where} from")
        target = _port(entry.get("to"), f"{context.name}: {where} to")
        _check_connection(source, target, ports, where, context)
        if target in driven:
            raise context.error(where, f"input {target} is connected twice (also by [[connection]] {driven[target]})")
        driven[target] = i
        connections.append(Connection(i, source, target))
    return connections


def optional_inputs(fmu_path: Path) -> set[str]:
    """Inputs an FMU built by rover-cosim declares optional (``optional_inputs`` of its
    documentation/build.json): they keep their start value when left unconnected. Other FMUs: none."""
    try:
        with zipfile.ZipFile(fmu_path) as archive:
            return set(json.loads(archive.read("documentation/build.json")).get("optional_inputs", []))
    except (OSError, KeyError, ValueError, zipfile.BadZipFile):
        return set()


def check_inputs_driven(fmus: list[FmuEntry], blocks: list[BlockEntry], connections: list[Connection],
                        context: _Context) -> None:
    """Every FMU input connected or given a start value (unless the FMU's build record marks it
    optional: an input its Modelica source gives a default); every block input connected."""
    driven = {c.target for c in connections}
    for fmu in fmus:
        optional = optional_inputs(fmu.path)
        for v in fmu.description.modelVariables:
            if (v.causality == "input" and Port(fmu.name, v.name) not in driven and v.name not in fmu.start
                    and v.name not in optional):
                raise context.error(f"[[fmu]] {fmu.name!r}", f"input {fmu.name}.{v.name} is neither connected nor "
                                    "given a value (add a [[connection]] or start = { ... })")
    for entry in blocks:
        for variable in entry.block.inputs:
            if Port(entry.name, variable) not in driven:
                raise context.error(f"[[block]] {entry.name!r}", f"input {entry.name}.{variable} is not connected")


def parse_order(order: Any, fmus: list[FmuEntry], blocks: list[BlockEntry], context: _Context) -> list[str]:
    """[simulation] order: every instance once; default: sources, FMUs, other blocks."""
    if order is None:
        return ([b.name for b in blocks if not b.block.inputs] + [f.name for f in fmus]
                + [b.name for b in blocks if b.block.inputs])
    if not isinstance(order, list) or sorted(map(str, order)) != sorted(context.names):
        raise context.error("[simulation] order", f"{order!r}: expected every instance once: {sorted(context.names)}")
    return [str(name) for name in order]


def parse_record(record_table: dict[str, Any], order: list[str], ports: _PortTable, context: _Context) -> list[Port]:
    """[record] variables: the recorded ports; default: every output of every participant."""
    context.known_keys(record_table, "record", "[record]")
    if "variables" not in record_table:
        return [port for instance in order for port in ports.outputs(instance)]
    variables = record_table["variables"]
    if not isinstance(variables, list):
        raise context.error("[record] variables", f"{variables!r}: expected a list of \"instance.variable\"")
    record: list[Port] = []
    for text in variables:
        port = _port(text, f"{context.name}: [record] variables")
        ports.lookup(port, f"[record] variables {text!r}")
        record.append(port)
    return record
