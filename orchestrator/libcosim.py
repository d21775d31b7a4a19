"""The same system run by Open Simulation Platform's libcosim (libcosimpy), an independent FMI
importer and master (fixed step; every slave steps from the values at t, like Jacobi).

FMUs, parameters, start values and FMU-to-FMU connections map one to one. Python source blocks
have no place inside libcosim: their values are written to the inputs they drive through an
override manipulator before each step (the run then advances one step per Python call); a system
without blocks runs in one ``simulate_until`` call. Blocks with inputs (controllers) are not
supported here.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .blocks import takes_step
from .system import Port, System


@dataclass
class LibcosimResult:
    data: pd.DataFrame | None  # recorded variables (None for a run without recording)
    wall_seconds: float


class _Execution:
    """A libcosim execution of ``system``: slaves, initial values, FMU-to-FMU connections, and the
    FMU inputs driven by Python source blocks (set through an override manipulator)."""

    def __init__(self, system: System):
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimObserver import CosimObserver
        from libcosimpy.CosimSlave import CosimLocalSlave

        self.system = system
        self.execution = CosimExecution.from_step_size(round(system.step * 1e9))
        self.index: dict[str, int] = {}
        self.refs: dict[str, dict[str, int]] = {}
        for fmu in system.fmus:
            self.index[fmu.name] = self.execution.add_local_slave(
                CosimLocalSlave(fmu_path=str(fmu.path), instance_name=fmu.name))
            self.refs[fmu.name] = {v.name: v.valueReference for v in fmu.description.modelVariables}
            for variable, value in {**fmu.parameters, **fmu.start}.items():
                self.execution.real_initial_value(self.index[fmu.name], self.refs[fmu.name][variable], value)
        self.driven = self._connect()
        self.blocks = {b.name: b.block for b in system.blocks}
        t0 = self.block_values(system.start_time)
        for source, target in self.driven:
            self.execution.real_initial_value(self.index[target.instance], self.ref(target), t0[source])
        self.observer = CosimObserver.create_last_value()
        self.execution.add_observer(self.observer)

    def ref(self, port: Port) -> int:
        return self.refs[port.instance][port.variable]

    def _connect(self) -> list[tuple[Port, Port]]:
        """Connect FMU outputs to FMU inputs; returns the (block output, FMU input) pairs."""
        driven: list[tuple[Port, Port]] = []
        for connection in self.system.connections:
            source, target = connection.source, connection.target
            if source.instance in self.index and target.instance in self.index:
                self.execution.connect_real_variables(self.index[source.instance], self.ref(source),
                                                      self.index[target.instance], self.ref(target))
            elif target.instance in self.index:
                driven.append((source, target))
        return driven

    def block_values(self, t: float) -> dict[Port, float]:
        outputs: dict[Port, float] = {}
        for name, block in self.blocks.items():
            step = (self.system.step,) if takes_step(block) else ()
            values = block.start(t, np.zeros(0), *step)
            outputs.update({Port(name, o): float(v) for o, v in zip(block.outputs, values)})
        return outputs

    def sample(self) -> list[float]:
        """The recorded values now (NaN for block outputs, which libcosim does not see)."""
        return [self.observer.last_real_values(self.index[port.instance], [self.ref(port)])[0]
                if port.instance in self.index else float("nan") for port in self.system.record]

    def run(self, record: bool) -> list[list[float]]:
        from libcosimpy.CosimManipulator import CosimManipulator

        system = self.system
        n_steps = round((system.stop_time - system.start_time) / system.step)
        if not self.driven and not record:
            self.execution.simulate_until(round(system.stop_time * 1e9))
            return []
        manipulator = None
        if self.driven:
            manipulator = CosimManipulator.create_override()
            self.execution.add_manipulator(manipulator)
        rows: list[list[float]] = []
        for k in range(n_steps):
            if manipulator is not None:
                values = self.block_values(system.start_time + k * system.step)
                for source, target in self.driven:
                    manipulator.slave_real_values(self.index[target.instance], [self.ref(target)], [values[source]])
            self.execution.step(1)
            if record:
                rows.append(self.sample())
        return rows


def run_libcosim(system: System, *, record: bool = True) -> LibcosimResult:
    """Run ``system`` with libcosim; source blocks only (no blocks with inputs)."""
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    if any(b.block.inputs for b in system.blocks):
        raise ValueError("libcosim runs support source blocks only (no blocks with inputs)")
    log_output_level(CosimLogLevel.ERROR)
    started = time.perf_counter()
    rows = _Execution(system).run(record)
    wall = time.perf_counter() - started
    if not record:
        return LibcosimResult(None, wall)
    n_steps = len(rows)
    data = pd.DataFrame(rows, columns=[str(p) for p in system.record])
    data.insert(0, "time", system.start_time + system.step * np.arange(1, n_steps + 1))
    return LibcosimResult(data, wall)
