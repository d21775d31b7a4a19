"""Recorded values of a run: one row per communication point, in a preallocated array, and the
:class:`RunResult` a run returns."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

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


class Recorder:
    """One row per communication point ``times``; :meth:`sample` copies the recorded slots of the
    value vector into row ``k``; :meth:`frame` gives time [s] and one column per port (the rows
    sampled so far, when a run stops early), typed as the variables (``types``: their FMI types;
    whole-number and Enumeration columns as integers, Boolean ones as true/false, String ones as
    text from the run's ``strings``; default Real)."""

    def __init__(self, ports: list[Port], slots: np.ndarray, times: np.ndarray, types: list[str] | None = None,
                 strings: StringTable | None = None, every: int = 1):
        self.columns = [str(port) for port in ports]
        self.types = types or ["Real"] * len(ports)
        self.strings = strings
        self.every = every  # rows kept in the frame: every ``every``-th communication point, and the last
        self.slots = slots
        self.times = times
        self.rows = np.empty((len(times), slots.size))
        self.filled = 0

    def sample(self, k: int, values: np.ndarray) -> None:
        self.rows[k] = values[self.slots]
        self.filled = k + 1

    def frame(self) -> pd.DataFrame:
        kept = np.arange(self.filled)
        if self.every > 1 and self.filled:
            kept = np.union1d(kept[::self.every], [self.filled - 1])
        data = pd.DataFrame(self.rows[kept], columns=self.columns)
        for column, kind in zip(self.columns, self.types):
            if kind in INTEGER_RANGES:
                data[column] = data[column].astype("uint64" if kind == "UInt64" else "int64")
            elif kind == "Boolean":
                data[column] = data[column] != 0.0
            elif kind == "String":
                strings = self.strings or StringTable()
                data[column] = [strings.text(v) for v in data[column]]
            elif kind == "Float32":
                data[column] = data[column].astype("float32")
        data.insert(0, "time", self.times[kept])
        return data


@dataclass
class RunResult:
    data: pd.DataFrame  # time [s] and one column per recorded "instance.variable"
    wall_seconds: float
    steps: int
    step_seconds: dict[str, float] = field(default_factory=dict)  # time inside each participant's step
    #: Why an observer ended the run before its stop time (None: it ran to the end).
    stopped: str | None = None

    def __repr__(self) -> str:
        end = f", stopped: {self.stopped}" if self.stopped else ""
        return (f"RunResult({len(self.data)} rows x {self.data.shape[1]} columns, {self.steps} steps in "
                f"{self.wall_seconds:.3g} s{end})")

    @property
    def master_overhead_seconds(self) -> float:
        return self.wall_seconds - sum(self.step_seconds.values())
