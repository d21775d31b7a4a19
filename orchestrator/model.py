"""The typed system model at the centre of the engine: components (FMUs and Python blocks) with
their parameter and start values, connections between their ports, what is recorded, and the
simulation settings. A :class:`System` is data, checked once where it is made
(:class:`~rover_cosim.orchestrator.builder.SystemBuilder`); system files (TOML, ``system``) and
SSP archives (``ssp``) are readers and writers of it, and the masters only read it.

Units: times and steps in seconds; parameter and start values in the unit of their FMU variable
(SI throughout for the FMUs of this project).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .blocks import Block

#: How a model description that fails FMPy's validation is treated: refused ("strict", the
#: default), run as FMPy runs it with validate=False after saying what is wrong ("warn"), or run
#: without a word ("off"; the record says so).
VALIDATION = ("strict", "warn", "off")
#: Where an FMU runs: "process" (in a child process of its own: a crash, exit() or hang of the FMU
#: ends its run with a message, not the tool), "none" (in the tool's process: the fastest, the
#: native stepper can step it) or "auto" ("none" for an FMU this project generated, else "process").
ISOLATION = ("auto", "process", "none")
#: How an FMU is run: its Co-Simulation interface (it steps itself) or its Model Exchange
#: interface (the engine integrates it, ``model_exchange``).
INTERFACES = ("co-simulation", "model-exchange")
#: Whole-number FMI types and their ranges (FMI 2.0 Integer is 32-bit; FMI 3.0 has eight).
INTEGER_RANGES = {"Integer": (-2**31, 2**31), "Int8": (-2**7, 2**7), "UInt8": (0, 2**8), "Int16": (-2**15, 2**15),
                  "UInt16": (0, 2**16), "Int32": (-2**31, 2**31), "UInt32": (0, 2**32), "Int64": (-2**63, 2**63),
                  "UInt64": (0, 2**64), "Enumeration": (-2**63, 2**63)}
#: The scalar variable types of FMI 2.0 and 3.0 the engine exchanges, and the Python type of a
#: value of each.
VARIABLE_TYPES: dict[str, type] = {"Real": float, "Float64": float, "Float32": float,
                                   **dict.fromkeys(INTEGER_RANGES, int), "Boolean": bool, "String": str}
#: A parameter or start value, typed as its variable (Real and Float: float, whole-number types
#: and Enumeration: int, Boolean: bool, String: str).
Value = float | int | bool | str


def _whole(value: object, variable_type: str) -> int:
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{value!r}: expected a whole number ({variable_type})")
    low, high = INTEGER_RANGES[variable_type]
    if not low <= value < high:
        raise ValueError(f"{value!r}: expected a whole number from {low} to {high - 1} (FMI {variable_type})")
    return value


def typed_value(value: object, variable_type: str) -> Value:
    """``value`` as a value of an FMI variable of ``variable_type``; ValueError saying what was
    expected (a number for Real and Float, a whole number in range for the integer types and
    Enumeration, true or false for Boolean, text for String)."""
    if variable_type in INTEGER_RANGES:
        return _whole(value, variable_type)
    if variable_type not in VARIABLE_TYPES:
        raise ValueError(f"a variable of type {variable_type!r}: expected one of {', '.join(VARIABLE_TYPES)} "
                         "(FMI 3.0 Binary and Clock variables are not supported)")
    kind = VARIABLE_TYPES[variable_type]
    text = {float: "a number", bool: "true or false", str: "text"}[kind]
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if not isinstance(value, kind) or (kind is float and isinstance(value, bool)):
        raise ValueError(f"{value!r}: expected {text} ({variable_type})")
    if kind is float and not math.isfinite(value):  # type: ignore[arg-type]
        raise ValueError(f"{value!r}: expected a finite number ({variable_type})")
    return value  # type: ignore[return-value]


def numeric(value: Value) -> float:
    """A value of a number, Enumeration or Boolean variable as it is held in the value vector of
    a run (a float: whole numbers up to 2^53 and true/false as 1.0/0.0 exactly)."""
    if isinstance(value, str):
        raise ValueError(f"{value!r}: a String has no place in the value vector")
    return float(value)


def declared_start(variable: Any) -> Value | None:
    """The start value a model description declares for ``variable`` (FMPy keeps it as text),
    typed as the variable; None where it declares none (or an array's several values)."""
    text = variable.start
    if text is None:
        return None
    kind = VARIABLE_TYPES.get(str(variable.type))
    if kind is str:
        return str(text)
    if kind is bool:
        return str(text).strip().lower() in ("true", "1")
    if len(str(text).split()) != 1:
        return None
    return int(text) if kind is int else float(text)


#: Types that are one another under another name (FMI 2.0 Real is FMI 3.0 Float64, Integer Int32).
SAME_TYPE = {"Real": "Float64", "Integer": "Int32"}


def compatible_types(source: str, target: str) -> bool:
    """Whether an output of type ``source`` may drive an input of type ``target``: the same type
    (FMI 2.0 Real and FMI 3.0 Float64 are; Integer and Int32 are), and an Enumeration with a
    whole-number type either way, as FMI allows."""
    source, target = SAME_TYPE.get(source, source), SAME_TYPE.get(target, target)
    if source == target:
        return True
    return "Enumeration" in (source, target) and source in INTEGER_RANGES and target in INTEGER_RANGES


class SystemFileError(ValueError):
    """A system that cannot be run; the message names the system (its file, or the name it was
    built under in code) and the entry or call at fault."""


@dataclass(frozen=True)
class Port:
    """One variable of one component: ``instance.variable``."""

    instance: str
    variable: str

    def __str__(self) -> str:
        return f"{self.instance}.{self.variable}"

    @staticmethod
    def parse(text: str) -> Port:
        """``"body.W[1]"`` -> Port("body", "W[1]") (the instance name ends at the first dot)."""
        instance, _, variable = text.partition(".")
        return Port(instance, variable)


@dataclass(frozen=True)
class Iteration:
    """Settings of the iterative master (``algorithm = "iterative"``): a step is repeated, the
    participants rolled back, until every exchanged value changes by less than
    ``tolerance`` x (1 + |value|) between two passes, at most ``max_iterations`` passes; the next
    guess moves ``relaxation`` (0 < relaxation <= 1) of the way to the new values."""

    tolerance: float = 1e-6
    max_iterations: int = 20
    relaxation: float = 1.0


class Element:
    """One element of an FMI 3.0 array variable, seen as a scalar named ``name[i]`` or
    ``name[i,j]`` (1-based, row-major, as the array's values follow each other): its type,
    causality, unit and value reference are the array's; ``index`` is its place among the array's
    ``size`` values, ``start`` its part of the array's start."""

    dimensions = None

    def __init__(self, array: Any, index: int, name: str, size: int):
        self.array, self.index, self.name, self.size = array, index, name, size
        starts = str(array.start).split() if array.start is not None else []
        self.start = starts[index] if len(starts) == size else (starts[0] if len(starts) == 1 else None)

    def __getattr__(self, attribute: str) -> Any:  # the array's type, causality, unit, valueReference ...
        return getattr(self.array, attribute)

    def __repr__(self) -> str:
        return f"Element({self.name!r} of {self.array.name!r})"


def elements_of(variable: Any) -> list[Element]:
    """The elements of an array ``variable`` of known shape (none for a scalar, or an array whose
    size is not known before the run)."""
    shape = tuple(getattr(variable, "shape", None) or ())
    if not getattr(variable, "dimensions", None) or not shape or not all(isinstance(n, int) and n > 0 for n in shape):
        return []
    size = int(np.prod(shape))
    return [Element(variable, k, f"{variable.name}[{','.join(str(i + 1) for i in np.unravel_index(k, shape))}]", size)
            for k in range(size)]


@dataclass
class FmuEntry:
    """An FMU component: its instance name, file, parameter and start values (by variable name,
    in the variables' units, typed as the variables: ``Value``) and its model description (FMPy's)."""

    name: str
    path: Path
    parameters: dict[str, Value]
    start: dict[str, Value]
    description: Any  # fmpy ModelDescription
    #: Which of the FMU's interfaces runs it (``INTERFACES``).
    interface: str = "co-simulation"
    #: How its model description was checked (``VALIDATION``), and what FMPy's validation found
    #: where it was run all the same ("warn", "off").
    validation: str = "strict"
    problems: tuple[str, ...] = ()
    #: Where it runs (``isolation.ISOLATION``): "auto" (in a child process unless this project
    #: generated it), "process" or "none" (in the tool's process).
    isolation: str = "auto"

    def variables(self) -> dict[str, Any]:
        """Every variable by name (made once), and every element of an FMI 3.0 array as a scalar
        ``name[i]`` (``Element``)."""
        cached = self.__dict__.get("_variables")
        if cached is None or cached[0] is not self.description:
            found: dict[str, Any] = {}
            for v in self.description.modelVariables:
                found[v.name] = v
                found.update((e.name, e) for e in elements_of(v))
            cached = self.__dict__["_variables"] = (self.description, found)
        return cached[1]

    @property
    def fmi_version(self) -> int:
        """2 or 3 (the major FMI version of the model description)."""
        return int(str(self.description.fmiVersion).split(".")[0])

    @property
    def capabilities(self) -> Any:
        """The model description's section of the interface that runs it (FMPy's CoSimulation or
        ModelExchange: modelIdentifier, canGetAndSetFMUstate, ...)."""
        d = self.description
        return d.coSimulation if self.interface == "co-simulation" else d.modelExchange

    def variable_type(self, name: str) -> str:
        """The FMI type of the variable ``name`` (Real, Integer, ..., Float64, Int8, ...)."""
        return str(self.variables()[name].type)


@dataclass
class BlockEntry:
    """A Python block component. ``kind``: its block type (``"constant"``, ..., ``"python"`` for
    a user block); ``keys``: the keys it was made from in a system file (None for a block object
    built in code, which no file can hold)."""

    name: str
    kind: str
    block: Block
    keys: dict[str, Any] | None = field(default_factory=dict)


@dataclass(frozen=True)
class Connection:
    number: int  # 1-based position among the system's connections
    source: Port
    target: Port


@dataclass
class System:
    """A checked system: components, connections, recorded ports and the simulation settings.
    ``path``: the file it was read from (None when built in code or from an SSP archive)."""

    path: Path | None
    fmus: list[FmuEntry]
    blocks: list[BlockEntry]
    connections: list[Connection]
    step: float                 # s, communication step
    stop_time: float            # s
    start_time: float = 0.0     # s
    algorithm: str = "gauss-seidel"
    order: list[str] = field(default_factory=list)
    record: list[Port] = field(default_factory=list)
    iteration: Iteration = field(default_factory=Iteration)
    algebraic_loop: list[Port] | None = None  # a cycle of direct feedthrough, if there is one
    #: FMUs stepped at the same time where the algorithm allows (Jacobi, Gauss-Seidel); None: the cores
    threads_setting: int | None = None
    native: bool = True  # Jacobi/Gauss-Seidel step the FMUs from C (orchestrator.native) where it builds
    allow_algebraic_loops: bool = False
    name: str = "system"        # what messages call the system
    #: Settings taken from elsewhere than the system's own (e.g. {"step": "DefaultExperiment ..."}).
    settings_from: dict[str, str] = field(default_factory=dict)
    #: Relative tolerance of the integrator of Model Exchange FMUs (CVode).
    relative_tolerance: float = 1e-6
    #: s, rows recorded every so often (a whole number of steps; the last row always); None: every step.
    output_interval: float | None = None
    #: s, the longest one call of an FMU run in a child process may take (None: no limit).
    fmu_timeout: float | None = None

    @property
    def record_every(self) -> int:
        """Communication steps between two recorded rows."""
        return 1 if self.output_interval is None else max(1, round(self.output_interval / self.step))

    @property
    def threads(self) -> int:
        """FMUs stepped at the same time: the setting, else the number of cores."""
        return self.threads_setting or os.cpu_count() or 1

    def participants(self) -> dict[str, FmuEntry | BlockEntry]:
        """Every FMU and block entry by instance name."""
        entries: dict[str, FmuEntry | BlockEntry] = {f.name: f for f in self.fmus}
        entries.update({b.name: b for b in self.blocks})
        return entries

    def fmu(self, name: str) -> FmuEntry:
        """The FMU component ``name``; KeyError naming the FMUs there are."""
        for entry in self.fmus:
            if entry.name == name:
                return entry
        raise KeyError(f"{self.name}: no FMU {name!r}; expected one of {', '.join(f.name for f in self.fmus)}")
