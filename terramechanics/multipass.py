"""Multi-pass: the ruts wheels leave and what a following wheel meets there.

Law (the choice and its assumptions). A wheel that passed at a place left a rut as deep as it sank,
z_r, and the soil under the rut's floor carried the pressure of that depth, p = k z_r^n (Eq. 5 at
z_r, k = kc/b + kφ). A following wheel meets the rut's floor and loads the soil on from there: at a
depth d below the floor the pressure is k (z_r + d)^n. This is Wong's repetitive-loading model
(Wong, Theory of Ground Vehicles, Sec. 2.2, after Wong 1984: reloading follows the unloading line to
the previous maximum pressure, then the virgin curve) with a rigid unloading line (no rebound): the
following wheel sinks less below the floor than the first did, its patch is shorter, and the
total sinkage grows pass by pass by less each time (the trend Holm's multi-pass tests and the
single-wheel repeated passes of the literature report). The shear strength and the shear
modulus are the virgin soil's. ``pressure_from_cosines`` evaluates it (its ``rut`` argument), so
the contact, the sinkage solve and the FMUs (input ``rutDepth``) take it the same way.

Memory: ``RutMap`` keeps, cell by cell over the ground, the deepest sinkage each wheel left there;
a wheel meets the deepest rut any *other* wheel left in the cell under its hub (its own track is
not a rut to itself: a wheel passing the same place twice, e.g. reversing, is not modelled).
"""

from __future__ import annotations

import math

import numpy as np

from .kinematics import FloatArray


class RutMap:
    """The ruts of ``wheels`` wheels over the ground, on cells of ``cell`` [m] (square), each cell
    the deepest sinkage [m] each wheel left in it; empty at the start."""

    def __init__(self, wheels: int, cell: float = 0.02):
        if isinstance(wheels, bool) or not isinstance(wheels, int) or wheels < 1:
            raise ValueError(f"wheels = {wheels!r}: expected a number of wheels >= 1")
        if not (isinstance(cell, (int, float)) and math.isfinite(cell) and cell > 0):
            raise ValueError(f"cell = {cell!r} m: expected a cell size > 0 m")
        self.wheels, self.cell = wheels, float(cell)
        self._cells: dict[tuple[int, int], FloatArray] = {}

    def _key(self, x: float, y: float) -> tuple[int, int]:
        return math.floor(x / self.cell), math.floor(y / self.cell)

    def stamp(self, x: FloatArray, y: FloatArray, sinkage: FloatArray, half_width: float) -> None:
        """Wheel i at (x[i], y[i]) [m] sunk sinkage[i] [m] marks the cells its width (±half_width
        [m] across y) covers with that depth, where it is deeper than what the wheel left there."""
        across = max(1, math.ceil(half_width / self.cell))
        for i in range(self.wheels):
            depth = float(sinkage[i])
            if not depth > 0:
                continue
            ix, iy = self._key(float(x[i]), float(y[i]))
            for j in range(iy - across + 1, iy + across):
                cell = self._cells.get((ix, j))
                if cell is None:
                    cell = self._cells[(ix, j)] = np.zeros(self.wheels)
                if depth > cell[i]:
                    cell[i] = depth

    def depths(self, x: FloatArray, y: FloatArray) -> FloatArray:
        """The rut under each wheel i at (x[i], y[i]) [m]: the deepest sinkage [m] another wheel left
        in that cell (0: virgin soil)."""
        out = np.zeros(self.wheels)
        for i in range(self.wheels):
            cell = self._cells.get(self._key(float(x[i]), float(y[i])))
            if cell is not None:
                others = np.delete(cell, i)
                out[i] = float(others.max()) if others.size else 0.0
        return out

    def get_state(self) -> dict[tuple[int, int], FloatArray]:
        return {key: value.copy() for key, value in self._cells.items()}

    def set_state(self, state: dict[tuple[int, int], FloatArray]) -> None:
        self._cells = {key: value.copy() for key, value in state.items()}
