"""Recorded values of a run: one row per communication point, in a preallocated array; the
:class:`Table` of typed columns it gives, and the :class:`RunResult` a run returns.

Neither imports pandas: a command that only writes its rows (``rover-cosim run``) does not pay
for it; ``Table.frame()`` and ``RunResult.data`` build the DataFrame when asked.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from .fmi_access import StringTable
from .model import INTEGER_RANGES, Port


def communication_points(t0: float, stop_time: float, h: float) -> np.ndarray:
    """t0, t0 + h, ... up to stop_time; a stop time that is not a whole number of steps after t0
    gets one shorter final step (the run ends exactly at stop_time, never early)."""
    whole = int(np.floor((stop_time - t0) / h + 1e-9))
    times = t0 + h * np.arange(whole + 1)
    if stop_time - times[-1] > 1e-9 * h:
        times = np.append(times, stop_time)
    times[-1] = min(times[-1], stop_time)
    return times


@dataclass(frozen=True)
class Table:
    """Recorded rows as typed columns: ``names`` ("time" [s] first, then "instance.variable") and
    one array per name (float64, float32, int64/uint64, bool; String columns as object arrays of
    text)."""

    names: tuple[str, ...]
    columns: tuple[np.ndarray, ...]

    def __len__(self) -> int:
        return len(self.columns[0]) if self.columns else 0

    def frame(self) -> Any:
        """The table as a pandas DataFrame (pandas imported here)."""
        import pandas as pd

        return pd.DataFrame(dict(zip(self.names, self.columns)), columns=list(self.names))


class Recorder:
    """One row per communication point ``times``; :meth:`sample` copies the recorded slots of the
    value vector into row ``k``; :meth:`table` gives time [s] and one column per port (the rows
    sampled so far, when a run stops early), typed as the variables (``types``: their FMI types;
    whole-number and Enumeration columns as integers, Boolean ones as true/false, String ones as
    text from the run's ``strings``; default Real)."""

    def __init__(self, ports: list[Port], slots: np.ndarray, times: np.ndarray, types: list[str] | None = None,
                 strings: StringTable | None = None, every: int = 1):
        self.columns = [str(port) for port in ports]
        self.types = types or ["Real"] * len(ports)
        self.strings = strings
        self.every = every  # rows kept in the table: every ``every``-th communication point, and the last
        self.slots = slots
        self.times = times
        self.rows = np.empty((len(times), slots.size))
        self.filled = 0

    def sample(self, k: int, values: np.ndarray) -> None:
        self.rows[k] = values[self.slots]
        self.filled = k + 1

    def table(self) -> Table:
        kept: Any = slice(0, self.filled)
        if self.every > 1 and self.filled:
            kept = np.union1d(np.arange(0, self.filled, self.every), [self.filled - 1])
        rows = self.rows[kept]
        columns: list[np.ndarray] = [np.array(self.times[kept])]
        for j, kind in enumerate(self.types):
            columns.append(typed(rows[:, j], kind, self.strings))
        return Table(("time", *self.columns), tuple(columns))

    def frame(self) -> Any:
        """The rows so far as a pandas DataFrame."""
        return self.table().frame()


def typed(values: np.ndarray, kind: str, strings: StringTable | None = None) -> np.ndarray:
    """A recorded column (float64 slots of the value vector) as its FMI type ``kind``."""
    if kind in INTEGER_RANGES:  # a value beyond the type's range (a float rounded up from its largest) saturates
        low, high = INTEGER_RANGES[kind]
        column = np.empty(len(values), dtype="uint64" if kind == "UInt64" else "int64")
        above, below = values >= float(high), values < float(low)
        inside = ~(above | below)
        column[inside] = values[inside].astype(column.dtype)
        column[above], column[below] = high - 1, low
        return column
    if kind == "Boolean":
        return values != 0.0
    if kind == "String":
        table = strings or StringTable()
        return np.array([table.text(v) for v in values], dtype=object)
    if kind == "Float32":
        return values.astype("float32")
    return np.array(values)


@dataclass
class RunResult:
    table: Table  # time [s] and one column per recorded "instance.variable"
    wall_seconds: float
    steps: int
    step_seconds: dict[str, float] = field(default_factory=dict)  # time inside each participant's step
    #: Why an observer ended the run before its stop time (None: it ran to the end).
    stopped: str | None = None
    #: What went wrong after the last step, the rows being complete (e.g. an FMU that crashed or
    #: hung in fmi2Terminate or fmi2FreeInstance, in its child process).
    notes: list[str] = field(default_factory=list)

    @cached_property
    def data(self) -> Any:
        """The recorded rows as a pandas DataFrame: time [s] and one column per "instance.variable"."""
        return self.table.frame()

    @property
    def columns(self) -> Sequence[str]:
        return self.table.names

    def __repr__(self) -> str:
        end = f", stopped: {self.stopped}" if self.stopped else ""
        return (f"RunResult({len(self.table)} rows x {len(self.table.names)} columns, {self.steps} steps in "
                f"{self.wall_seconds:.3g} s{end})")

    @property
    def master_overhead_seconds(self) -> float:
        return self.wall_seconds - sum(self.step_seconds.values())
