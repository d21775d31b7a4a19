"""The typed system model at the centre of the engine: components (FMUs and Python blocks) with
their parameter and start values, connections between their ports, what is recorded, and the
simulation settings. A :class:`System` is data, checked once where it is made
(:class:`~rover_cosim.orchestrator.builder.SystemBuilder`); system files (TOML, ``system``) and
SSP archives (``ssp``) are readers and writers of it, and the masters only read it.

Units: times and steps in seconds; parameter and start values in the unit of their FMU variable
(SI throughout for the FMUs of this project).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .blocks import Block

ALGORITHMS = ("jacobi", "gauss-seidel", "iterative")


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


@dataclass
class FmuEntry:
    """An FMU component: its instance name, file, parameter and start values (by variable name,
    in the variables' units) and its model description (FMPy's)."""

    name: str
    path: Path
    parameters: dict[str, float]
    start: dict[str, float]
    description: Any  # fmpy ModelDescription

    def variables(self) -> dict[str, Any]:
        return {v.name: v for v in self.description.modelVariables}


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
