"""Recorded values of a run: one row per communication point, in a preallocated array (or, with
a ``sink``, in a buffer of CHUNK_ROWS rows handed to the sink whenever it is full, so that a run's
memory does not grow with its length); the :class:`Table` of typed columns it gives, and the
:class:`RunResult` a run returns.

Neither imports pandas: a command that only writes its rows (``rover-cosim run``) does not pay
for it; ``Table.frame()`` and ``RunResult.data`` build the DataFrame when asked.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
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
        """The table as a pandas DataFrame (pandas imported here) on the columns' own arrays, not
        copied into one block (pandas 3 copies on write): a leg-wheel run's 262 columns of 20,001
        rows 20 -> 3.5 ms."""
        import pandas as pd

        return pd.DataFrame(dict(zip(self.names, self.columns)), columns=list(self.names), copy=False)


#: Rows a recorder with a sink holds before it hands them over (more than a native stretch).
CHUNK_ROWS = 8192


class Recorder:
    """One row per communication point ``times``; :meth:`sample` copies the recorded slots of the
    value vector into row ``k``; :meth:`table` gives time [s] and one column per port (the rows
    sampled so far, when a run stops early), typed as the variables (``types``: their FMI types;
    whole-number and Enumeration columns as integers, Boolean ones as true/false, String ones as
    text from the run's ``strings``; default Real).

    ``sink``: called with each full buffer of rows as a Table (and with the rest by
    :meth:`finish`); the recorder then holds CHUNK_ROWS rows at most, ``rows[i]`` being the
    communication point ``base + i``, and :meth:`table` gives the rows not yet handed over."""

    def __init__(self, ports: list[Port], slots: np.ndarray, times: np.ndarray, types: list[str] | None = None,
                 strings: StringTable | None = None, every: int = 1, sink: Callable[[Table], None] | None = None):
        self.columns = [str(port) for port in ports]
        self.types = types or ["Real"] * len(ports)
        self.strings = strings
        self.every = every  # rows kept in the table: every ``every``-th communication point, and the last
        self.slots = slots
        self.times = times
        self.sink = sink
        self.rows = np.empty((len(times) if sink is None else min(len(times), CHUNK_ROWS), slots.size))
        self.base = 0     # the communication point of rows[0]
        self.filled = 0   # communication points sampled (rows[filled - 1 - base] is the last)
        self.handed = 0   # rows handed to the sink

    def sample(self, k: int, values: np.ndarray) -> None:
        if k - self.base >= len(self.rows):
            self.hand_over(k)
        self.rows[k - self.base] = values[self.slots]
        self.filled = k + 1

    def room(self, rows: int) -> None:
        """Make room for ``rows`` more rows after the last sampled (a native stretch writes them in place)."""
        if self.sink is not None and self.filled + rows - self.base > len(self.rows):
            self.hand_over(self.filled)

    def hand_over(self, upto: int) -> None:
        """Give the sink the rows before communication point ``upto`` (and start the buffer there)."""
        assert self.sink is not None, "a recorder without a sink holds every row"
        if upto > self.base:
            self.sink(self._table(self.base, upto, last=False))
            self.handed += len(self._kept(self.base, upto, last=False))
        self.base = upto

    def finish(self) -> None:
        """Give the sink the rows not yet handed over (the last one always)."""
        if self.sink is not None and self.filled > self.base:
            self.sink(self._table(self.base, self.filled, last=True))
            self.handed += len(self._kept(self.base, self.filled, last=True))
            self.base = self.filled

    def _kept(self, start: int, stop: int, last: bool) -> np.ndarray:
        """The communication points from ``start`` to ``stop`` kept in the table: every
        ``every``-th, and ``stop - 1`` where ``last``."""
        kept = np.arange(start + (-start) % self.every, stop, self.every)
        if last and stop > start and (not len(kept) or kept[-1] != stop - 1):
            kept = np.append(kept, stop - 1)
        return kept

    def _table(self, start: int, stop: int, last: bool) -> Table:
        if self.every == 1:  # every row: slices, not copies
            rows, times = self.rows[start - self.base:stop - self.base], self.times[start:stop]
        else:
            kept = self._kept(start, stop, last)
            rows, times = self.rows[kept - self.base], self.times[kept]
        columns: list[np.ndarray] = [np.array(times)]
        for j, kind in enumerate(self.types):
            columns.append(typed(rows[:, j], kind, self.strings))
        return Table(("time", *self.columns), tuple(columns))

    def table(self) -> Table:
        return self._table(self.base, self.filled, last=True)

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
    #: Per FMU instance, its error messages too long to print, whole (for a log file beside the results).
    fmu_log: dict[str, list[str]] = field(default_factory=dict)

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
