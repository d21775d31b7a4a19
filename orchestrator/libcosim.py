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

from .system import Port, System


@dataclass
class LibcosimResult:
    data: pd.DataFrame | None  # recorded variables (None for a run without recording)
    wall_seconds: float


def run_libcosim(system: System, *, record: bool = True) -> LibcosimResult:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    if any(b.block.inputs for b in system.blocks):
        raise ValueError("libcosim runs support source blocks only (no blocks with inputs)")
    log_output_level(CosimLogLevel.ERROR)
    started = time.perf_counter()
    nanoseconds = round(system.step * 1e9)
    execution = CosimExecution.from_step_size(nanoseconds)
    index: dict[str, int] = {}
    refs: dict[str, dict[str, int]] = {}
    for fmu in system.fmus:
        index[fmu.name] = execution.add_local_slave(CosimLocalSlave(fmu_path=str(fmu.path), instance_name=fmu.name))
        refs[fmu.name] = {v.name: v.valueReference for v in fmu.description.modelVariables}
        for variable, value in {**fmu.parameters, **fmu.start}.items():
            execution.real_initial_value(index[fmu.name], refs[fmu.name][variable], value)
    driven: list[tuple[Port, Port]] = []  # (block output, FMU input)
    for connection in system.connections:
        source, target = connection.source, connection.target
        if source.instance in index and target.instance in index:
            execution.connect_real_variables(index[source.instance], refs[source.instance][source.variable],
                                             index[target.instance], refs[target.instance][target.variable])
        elif target.instance in index:
            driven.append((source, target))
    blocks = {b.name: b.block for b in system.blocks}

    def block_values(t: float) -> dict[Port, float]:
        outputs: dict[Port, float] = {}
        for name, block in blocks.items():
            values = block.start(t, np.zeros(0))
            outputs.update({Port(name, o): float(v) for o, v in zip(block.outputs, values)})
        return outputs

    t0 = block_values(system.start_time)
    for source, target in driven:
        execution.real_initial_value(index[target.instance], refs[target.instance][target.variable], t0[source])

    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    n_steps = round((system.stop_time - system.start_time) / system.step)
    rows: list[list[float]] = []

    def sample() -> None:
        row = []
        for port in system.record:
            if port.instance in index:
                row.append(observer.last_real_values(index[port.instance], [refs[port.instance][port.variable]])[0])
            else:
                row.append(float("nan"))
        rows.append(row)

    if not driven and not record:
        execution.simulate_until(round(system.stop_time * 1e9))
    elif not driven:
        for _ in range(n_steps):
            execution.step(1)
            sample()
    else:
        manipulator = CosimManipulator.create_override()
        execution.add_manipulator(manipulator)
        for k in range(n_steps):
            t = system.start_time + k * system.step
            values = block_values(t)
            for source, target in driven:
                manipulator.slave_real_values(index[target.instance], [refs[target.instance][target.variable]],
                                              [values[source]])
            execution.step(1)
            if record:
                sample()
    wall = time.perf_counter() - started
    if not record:
        return LibcosimResult(None, wall)
    data = pd.DataFrame(rows, columns=[str(p) for p in system.record])
    data.insert(0, "time", system.start_time + system.step * np.arange(1, n_steps + 1))
    return LibcosimResult(data, wall)
