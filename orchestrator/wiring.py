"""Where every exchanged or recorded value lives: one slot of a value vector per port.

Each participant reads its inputs from the slots of their sources (one gather per step) and
writes its outputs into its own slots. An FMU publishes only what is needed (connected or
recorded); an FMU input that is not connected keeps its start value in a constant slot. Wiring
is pure bookkeeping on the checked :class:`System`: no FMU is loaded here.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .fmi_access import StringTable
from .model import FmuEntry, Port, System, Value, declared_start, numeric


@dataclass
class ParticipantWiring:
    """The ports of one participant: variable names and their slots, in matching order."""

    inputs: list[str] = field(default_factory=list)
    outputs: list[str] = field(default_factory=list)
    input_slots: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    output_slots: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))


@dataclass
class Wiring:
    participants: dict[str, ParticipantWiring]  # by instance name
    record_slots: np.ndarray                     # slots of system.record, in its order
    constants: dict[int, Value]                  # slot -> value of unconnected FMU inputs
    size: int                                    # length of the value vector
    extra_slots: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))  # of wire()'s extra ports

    def initial_values(self, strings: StringTable | None = None) -> np.ndarray:
        """The value vector before initialization: zeros and the constant inputs (a String as its
        number in the run's ``strings``)."""
        values = np.zeros(self.size)
        for slot, value in self.constants.items():
            if isinstance(value, str):
                values[slot] = strings.number(value) if strings is not None else 0.0
            else:
                values[slot] = numeric(value)
        return values


class _Slots:
    def __init__(self) -> None:
        self.index: dict[Port, int] = {}

    def __call__(self, port: Port) -> int:
        if port not in self.index:
            self.index[port] = len(self.index)
        return self.index[port]


class _Builder:
    """Resolves ports to slots, noting which FMU variables are read and which inputs are constant."""

    def __init__(self, system: System):
        self.source_of = {c.target: c.source for c in system.connections}
        self.entries = system.participants()
        self.slots = _Slots()
        self.reads: dict[str, list[str]] = {name: [] for name in self.entries}
        self._read: dict[str, set[str]] = {name: set() for name in self.entries}  # the same, to look up
        self.constants: dict[int, Value] = {}

    def slot_of(self, port: Port) -> int:
        """The slot holding the value of ``port`` (a connected input resolves to its source)."""
        if port in self.source_of:
            return self.slot_of(self.source_of[port])
        entry = self.entries[port.instance]
        if isinstance(entry, FmuEntry):
            variable = entry.variables()[port.variable]
            if variable.causality == "input":  # not connected: its start value, constant in time
                slot = self.slots(port)
                start = entry.start.get(port.variable, declared_start(variable))
                self.constants[slot] = start if start is not None else 0.0
                return slot
            if port.variable not in self._read[port.instance]:
                self._read[port.instance].add(port.variable)
                self.reads[port.instance].append(port.variable)
        return self.slots(port)

    def inputs_of(self, name: str) -> list[str]:
        entry = self.entries[name]
        if isinstance(entry, FmuEntry):
            return [target.variable for target in self.source_of if target.instance == name]
        return list(entry.block.inputs)

    def outputs_of(self, name: str) -> list[str]:
        entry = self.entries[name]
        return list(self.reads[name]) if isinstance(entry, FmuEntry) else list(entry.block.outputs)


def wire(system: System, extra: Sequence[Port] = ()) -> Wiring:
    """Slots for every connection, FMU read and recorded variable of ``system``, and for the
    ``extra`` ports (what observers watch)."""
    builder = _Builder(system)
    wired = {name: ParticipantWiring() for name in builder.entries}
    for name, ports in wired.items():
        ports.inputs = builder.inputs_of(name)
        ports.input_slots = np.array([builder.slot_of(builder.source_of[Port(name, v)]) for v in ports.inputs],
                                     dtype=int)
    for entry in system.blocks:
        for output in entry.block.outputs:
            builder.slots(Port(entry.name, output))
    record_slots = np.array([builder.slot_of(port) for port in system.record], dtype=int)
    extra_slots = np.array([builder.slot_of(port) for port in extra], dtype=int)
    for name, ports in wired.items():
        ports.outputs = builder.outputs_of(name)
        ports.output_slots = np.array([builder.slots(Port(name, v)) for v in ports.outputs], dtype=int)
    return Wiring(wired, record_slots, builder.constants, len(builder.slots.index), extra_slots)
