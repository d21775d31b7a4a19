"""Master algorithms at a fixed communication step: Jacobi and Gauss-Seidel.

Every value exchanged or recorded has a slot in one vector ``values``; each participant reads its
inputs from the slots of their sources (one gather and one batched set per step) and writes its
outputs into its own slots (one batched get). Jacobi steps all participants from the values at
``t`` and then exchanges; Gauss-Seidel steps them in order, each seeing the outputs at ``t + h``
of those before it. Recorded values go into a preallocated array.
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .participants import FmuParticipant, RunError
from .system import BlockEntry, FmuEntry, Port, System


@dataclass
class RunResult:
    data: pd.DataFrame  # time [s] and one column per recorded "instance.variable"
    wall_seconds: float
    steps: int
    step_seconds: dict[str, float] = field(default_factory=dict)  # time inside each participant's step

    @property
    def master_overhead_seconds(self) -> float:
        return self.wall_seconds - sum(self.step_seconds.values())


class _Slots:
    def __init__(self) -> None:
        self.index: dict[Port, int] = {}

    def __call__(self, port: Port) -> int:
        if port not in self.index:
            self.index[port] = len(self.index)
        return self.index[port]


def run(system: System, *, progress: Callable[[float], None] | None = None) -> RunResult:
    """Run ``system``; raises :class:`RunError` naming the participant, call and time on failure."""
    started = time.perf_counter()
    source_of = {c.target: c.source for c in system.connections}
    slots = _Slots()
    entries: dict[str, FmuEntry | BlockEntry] = {e.name: e for e in [*system.fmus, *system.blocks]}

    with tempfile.TemporaryDirectory(prefix="rover-cosim-run-") as unzip_root:
        fmus: dict[str, FmuParticipant] = {}
        try:
            for entry in system.fmus:
                fmus[entry.name] = FmuParticipant(entry, Path(unzip_root))
            return _run(system, entries, fmus, source_of, slots, progress, started)
        finally:
            for participant in fmus.values():
                participant.close()


def _run(system: System, entries, fmus, source_of, slots, progress, started) -> RunResult:
    # --- what each participant reads and where its inputs come from ------------------------------
    reads: dict[str, list[str]] = {name: [] for name in entries}
    constants: dict[int, float] = {}

    def slot_of(port: Port) -> int:
        """The slot holding the value of ``port`` (an input resolves to its source)."""
        if port in source_of:
            return slot_of(source_of[port])
        entry = entries[port.instance]
        if isinstance(entry, FmuEntry):
            variable = entry.variables()[port.variable]
            if variable.causality == "input":  # not connected: a start value, constant in time
                slot = slots(port)
                constants[slot] = entry.start.get(port.variable, float(variable.start or 0.0))
                return slot
            if port.variable not in reads[port.instance]:
                reads[port.instance].append(port.variable)
        return slots(port)

    input_slots: dict[str, np.ndarray] = {}
    connected_inputs: dict[str, list[str]] = {}
    for name, entry in entries.items():
        if isinstance(entry, FmuEntry):
            inputs = [t.variable for t in source_of if t.instance == name]
        else:
            inputs = list(entry.block.inputs)
        connected_inputs[name] = inputs
        input_slots[name] = np.array([slot_of(source_of[Port(name, v)]) for v in inputs], dtype=int)
    for entry in system.blocks:
        for output in entry.block.outputs:
            slots(Port(entry.name, output))
    record_slots = np.array([slot_of(port) for port in system.record], dtype=int)
    output_slots: dict[str, np.ndarray] = {}
    for name, entry in entries.items():
        if isinstance(entry, FmuEntry):
            fmus[name].configure(connected_inputs[name], reads[name])
            output_slots[name] = np.array([slots(Port(name, v)) for v in reads[name]], dtype=int)
        else:
            output_slots[name] = np.array([slots(Port(name, v)) for v in entry.block.outputs], dtype=int)

    values = np.zeros(len(slots.index))
    for slot, value in constants.items():
        values[slot] = value

    # --- initialization ---------------------------------------------------------------------------
    t0, h = system.start_time, system.step
    n_steps = round((system.stop_time - t0) / h)
    order = system.order
    blocks = {e.name: e.block for e in system.blocks}
    for name in order:
        if name in blocks and not blocks[name].inputs:
            values[output_slots[name]] = blocks[name].start(t0, np.zeros(0))
    for name in order:
        if name in fmus:
            fmus[name].setup(t0, system.stop_time)
    for _ in range(2):  # outputs in Initialization Mode, exchanged twice so chains settle
        for name in order:
            if name in fmus:
                fmus[name].set_inputs(values[input_slots[name]], t0)
                values[output_slots[name]] = fmus[name].get_values(t0)
    for name in order:
        if name in blocks and blocks[name].inputs:
            values[output_slots[name]] = blocks[name].start(t0, values[input_slots[name]])
    for name in order:
        if name in fmus:
            fmus[name].set_inputs(values[input_slots[name]], t0)
            fmus[name].finish_initialization()
            values[output_slots[name]] = fmus[name].get_values(t0)

    record = np.empty((n_steps + 1, record_slots.size))
    times = t0 + h * np.arange(n_steps + 1)
    record[0] = values[record_slots]
    step_seconds = dict.fromkeys(order, 0.0)
    gauss_seidel = system.algorithm == "gauss-seidel"
    clock = time.perf_counter

    # --- stepping ---------------------------------------------------------------------------------
    for k in range(n_steps):
        t = float(times[k])
        if gauss_seidel:
            for name in order:
                begin = clock()
                if name in fmus:
                    fmu = fmus[name]
                    fmu.set_inputs(values[input_slots[name]], t)
                    fmu.do_step(t, h)
                    values[output_slots[name]] = fmu.get_values(t + h)
                else:
                    values[output_slots[name]] = blocks[name].step(t, h, values[input_slots[name]])
                step_seconds[name] += clock() - begin
        else:
            gathered = {name: values[input_slots[name]] for name in order}
            for name in order:
                begin = clock()
                if name in fmus:
                    fmus[name].set_inputs(gathered[name], t)
                    fmus[name].do_step(t, h)
                else:
                    values[output_slots[name]] = blocks[name].step(t, h, gathered[name])
                step_seconds[name] += clock() - begin
            for name in fmus:
                begin = clock()
                values[output_slots[name]] = fmus[name].get_values(t + h)
                step_seconds[name] += clock() - begin
        record[k + 1] = values[record_slots]
        if progress is not None:
            progress((k + 1) / n_steps)

    wall = time.perf_counter() - started
    columns = [str(port) for port in system.record]
    data = pd.DataFrame(record, columns=columns)
    data.insert(0, "time", times)
    return RunResult(data, wall, n_steps, step_seconds)


__all__ = ["RunError", "RunResult", "run"]
