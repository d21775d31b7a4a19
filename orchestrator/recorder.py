"""Recorded values of a run: one row per communication point, in a preallocated array."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .system import Port


class Recorder:
    """Rows ``0 .. n_steps`` at ``t0 + k h``; :meth:`sample` copies the recorded slots of the
    value vector into row ``k``; :meth:`frame` gives time [s] and one column per port."""

    def __init__(self, ports: list[Port], slots: np.ndarray, t0: float, h: float, n_steps: int):
        self.columns = [str(port) for port in ports]
        self.slots = slots
        self.times = t0 + h * np.arange(n_steps + 1)
        self.rows = np.empty((n_steps + 1, slots.size))

    def sample(self, k: int, values: np.ndarray) -> None:
        self.rows[k] = values[self.slots]

    def frame(self) -> pd.DataFrame:
        data = pd.DataFrame(self.rows, columns=self.columns)
        data.insert(0, "time", self.times)
        return data
