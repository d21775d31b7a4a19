"""The identified model of the paper's Sec. 3 and its fits.

- tau -> slip: per (W, tau), a first-order step response slip(t) = K tau (1 - exp(-t/T)) fitted
  to the recorded slip; K and T form look-up tables over (W, tau); the settled slip K tau and
  log T are interpolated linearly in 1/W and tau (and extended linearly beyond the table). At a
  fixed torque the slip falls roughly like 1/W, so 1/W interpolates it far better than W (slip
  Fit at 275 N: 86 % with W, 95 % with 1/W).
- slip -> Fx: per load, Fx = a(W) slip + b(W) (Eq. 14) fitted to the settled (slip, Fx) points;
  a and b are then quadratic in W (Figs. 6, 7). ``degree`` > 1 gives the higher-degree variant the
  paper suggests: Fx = sum_k c_k(W) slip^k, each c_k quadratic in W.
- Eq. (15), :func:`fit_percent`, measures a model output against the plant's.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

#: Settled points enter the Fx(slip) fits when the wheel still rolls (see step_table), their torque
#: is within what the rover uses (its open-loop run drives with 9-40 N·m) and their slip is in
#: SLIP_FIT_RANGE (beyond it the wheel spins out or skids). The sweep's higher torques still shape
#: the K, T tables.
FIT_TORQUE_MAX = 40.0
SLIP_FIT_RANGE = (-0.1, 0.5)
#: m/s: a run whose settled carriage speed is below this has stopped rolling (static regime).
ROLLING_SPEED = 0.01
#: The settled value of a run is the mean over its last fraction.
SETTLED_FRACTION = 0.2


def fit_percent(model: np.ndarray, plant: np.ndarray) -> float:
    """Eq. (15): 100 (1 - ||model - plant|| / ||plant - mean(plant)||)."""
    model, plant = np.asarray(model, float), np.asarray(plant, float)
    spread = np.linalg.norm(plant - plant.mean())
    if spread == 0:
        raise ValueError("fit_percent: the plant output is constant; Eq. (15) is undefined")
    return float(100.0 * (1.0 - np.linalg.norm(model - plant) / spread))


def settled(run: pd.DataFrame, column: str) -> float:
    tail = max(1, int(len(run) * SETTLED_FRACTION))
    return float(run[column].iloc[-tail:].mean())


def first_order_fit(time: np.ndarray, slip: np.ndarray, torque: float) -> tuple[float, float]:
    """(K [1/(N·m)], T [s]) of slip(t) = K torque (1 - exp(-t/T)) by least squares."""
    if torque == 0:
        raise ValueError("first_order_fit: torque = 0 N·m gives no step to fit")
    final = float(np.mean(slip[-max(1, len(slip) // 5):]))
    # Start: the time to reach 63 % of the final value.
    reached = np.nonzero(np.abs(slip) >= 0.632 * abs(final))[0] if final != 0 else np.array([], int)
    t63 = float(time[reached[0]]) if reached.size and time[reached[0]] > 0 else float(time[1])
    dt = float(time[1] - time[0])
    # imported here: scipy.optimize is a fifth of a second that a command fitting nothing waits for
    from scipy.optimize import least_squares

    def residual(parameters: np.ndarray) -> np.ndarray:
        gain, log_t = parameters
        return gain * torque * (1.0 - np.exp(-time / np.exp(log_t))) - slip

    result = least_squares(residual, x0=[final / torque, np.log(max(t63, dt / 10))],
                           bounds=([-np.inf, np.log(1e-7)], [np.inf, np.log(10.0 * time[-1])]))
    return float(result.x[0]), float(np.exp(result.x[1]))


@dataclass
class IdentifiedModel:
    loads: np.ndarray     # LUT axis W [N]
    torques: np.ndarray   # LUT axis tau [N·m]
    gain: np.ndarray      # K [1/(N·m)], shape (loads, torques)
    time_constant: np.ndarray  # T [s], shape (loads, torques)
    fx_coefficients: np.ndarray  # [k, j]: coefficient of slip^k is sum_j c[k, j] W^j (j = 0, 1, 2) [N]
    degree: int

    def __post_init__(self) -> None:
        # Linear in 1/W and tau inside the table, extended linearly beyond it (875 N lies outside
        # the 100-800 N grid of the paper). 1/W decreases with W: the axis is reversed.
        # The table interpolated is the settled slip K tau, not K: K changes sign at small torques
        # under heavy loads, and K linear in tau bends the slip between the table's torques
        # (closed-loop RMS(Fx - Fx_des) 2.1 N that way, 0.2 N interpolating K tau).
        self._inverse_loads = 1.0 / np.asarray(self.loads, float)  # decreasing
        self._settled_table = np.asarray(self.gain, float) * np.asarray(self.torques, float)[None, :]
        self._log_t_table = np.log(np.asarray(self.time_constant, float))

    def _interpolator(self, table: np.ndarray) -> Any:
        """``table`` over (1/W, tau), linear inside and extended linearly beyond. Made when first
        asked for: scipy.interpolate is half a second of imports, and the controllers read the
        tables themselves (a command that only steps them never imports it)."""
        from scipy.interpolate import RegularGridInterpolator

        axes = (self._inverse_loads[::-1], np.asarray(self.torques, float))
        return RegularGridInterpolator(axes, table[::-1], bounds_error=False, fill_value=None)

    @functools.cached_property
    def _settled(self) -> Any:
        return self._interpolator(self._settled_table)

    @functools.cached_property
    def _t(self) -> Any:
        return self._interpolator(self._log_t_table)

    @staticmethod
    def _point(load: float, torque: float) -> np.ndarray:
        if not load > 0:
            raise ValueError(f"load = {load!r} N: expected > 0")
        return np.array([[1.0 / load, torque]])

    def settled_slip_at(self, load: float, torque: float) -> float:
        """K(W, tau) tau: the slip a torque step settles to."""
        return float(self._settled(self._point(load, torque))[0])

    def gain_at(self, load: float, torque: float) -> float:
        if torque == 0:
            raise ValueError("gain_at: torque = 0 N·m; use settled_slip_at")
        return self.settled_slip_at(load, torque) / torque

    def time_constant_at(self, load: float, torque: float) -> float:
        return float(np.exp(self._t(self._point(load, torque))[0]))

    def fx(self, load: float | np.ndarray, slip: float | np.ndarray) -> np.ndarray:
        """Fx(W, slip) [N] (Eq. 14, or its higher-degree variant)."""
        load, slip = np.asarray(load, float), np.asarray(slip, float)
        total = np.zeros(np.broadcast(load, slip).shape)
        for k in range(self.degree + 1):
            total = total + np.polyval(self.fx_coefficients[k][::-1], load) * slip**k
        return total

    def slip_response(self, load: float, time: np.ndarray, torque: np.ndarray) -> np.ndarray:
        """The first-order tau -> slip block under a sampled, piecewise-constant torque, with K and
        T looked up at (W, tau) of each sample; exact for a torque held over each sample."""
        slip = np.zeros(len(time))
        for k in range(1, len(time)):
            h = time[k] - time[k - 1]
            target = self.settled_slip_at(load, torque[k - 1])
            decay = np.exp(-h / self.time_constant_at(load, torque[k - 1]))
            slip[k] = target + (slip[k - 1] - target) * decay
        return slip

    def to_dict(self) -> dict[str, object]:
        return {"loads_N": list(map(float, self.loads)), "torques_N_m": list(map(float, self.torques)),
                "gain_K_per_N_m": np.asarray(self.gain).tolist(),
                "time_constant_T_s": np.asarray(self.time_constant).tolist(),
                "fx_degree_in_slip": self.degree,
                "fx_coefficients_N": np.asarray(self.fx_coefficients).tolist(),
                "fx_coefficients_meaning": "Fx = sum_k (c[k][0] + c[k][1] W + c[k][2] W^2) slip^k"}

    @staticmethod
    def from_dict(data: dict) -> IdentifiedModel:
        return IdentifiedModel(np.array(data["loads_N"]), np.array(data["torques_N_m"]),
                               np.array(data["gain_K_per_N_m"]), np.array(data["time_constant_T_s"]),
                               np.array(data["fx_coefficients_N"]), int(data["fx_degree_in_slip"]))


def step_table(runs: dict[tuple[float, float], pd.DataFrame]) -> pd.DataFrame:
    """One row per run: load, torque, settled slip and Fx, fitted K and T, and whether the wheel
    still rolls at the end (settled speed above ROLLING_SPEED). A wheel that has come to rest is
    in the static regime, where the paper's torque -> slip -> force model does not apply; such
    runs are left out of the fits."""
    rows = []
    for (load, torque), run in sorted(runs.items()):
        gain, constant = first_order_fit(run["time"].to_numpy(), run["slip"].to_numpy(), torque)
        rolling = "v" not in run or settled(run, "v") > ROLLING_SPEED
        rows.append({"load_N": load, "torque_N_m": torque, "slip": settled(run, "slip"), "Fx_N": settled(run, "Fx"),
                     "K_per_N_m": gain, "T_s": constant, "rolling": bool(rolling)})
    return pd.DataFrame(rows)


def _rolling(table: pd.DataFrame) -> pd.DataFrame:
    """The rows of runs in which the wheel still rolls (all rows of a table without that column)."""
    return table[table["rolling"].astype(bool)] if "rolling" in table else table


def fx_per_load(table: pd.DataFrame, degree: int = 1, torque_max: float = FIT_TORQUE_MAX) -> pd.DataFrame:
    """Per load, the polynomial Fx(slip) of ``degree`` through the settled points with torque up
    to ``torque_max`` [N·m] and slip in SLIP_FIT_RANGE: columns load_N, c0 (= b), c1 (= a), ...
    A fit narrower than the paper's (``torque_max`` < FIT_TORQUE_MAX) whose load has too few such
    points takes that load's degree + 2 lowest-torque points in the slip range instead."""
    rows = []
    for load, part in _rolling(table).groupby("load_N"):
        in_range = part[(part["slip"] >= SLIP_FIT_RANGE[0]) & (part["slip"] <= SLIP_FIT_RANGE[1])]
        inside = in_range[in_range["torque_N_m"] <= torque_max]
        if len(inside) < degree + 1 and torque_max < FIT_TORQUE_MAX:  # a narrower fit: the lowest torques instead
            inside = in_range.nsmallest(degree + 2, "torque_N_m")
        if len(inside) < degree + 1:
            raise ValueError(f"load {load} N: {len(inside)} settled points with slip in {SLIP_FIT_RANGE} and torque "
                             f"<= {torque_max} N·m, need {degree + 1} for a degree-{degree} fit")
        coefficients = np.polynomial.polynomial.polyfit(inside["slip"], inside["Fx_N"], degree)
        rows.append({"load_N": load, **{f"c{k}": float(c) for k, c in enumerate(coefficients)}})
    return pd.DataFrame(rows)


def _filled(table: pd.DataFrame, column: str, loads: np.ndarray, torques: np.ndarray) -> np.ndarray:
    """The (load, torque) grid of ``column``; a cell without a run (a failed one, or one where the
    wheel stopped rolling) is interpolated along the torque axis of its load (the nearest value
    beyond either end)."""
    grid = table.pivot(index="load_N", columns="torque_N_m", values=column).reindex(index=loads, columns=torques)
    values = grid.to_numpy(dtype=float, copy=True)
    for i, row in enumerate(values):
        known = np.isfinite(row)
        if not known.any():
            raise ValueError(f"load {loads[i]} N: no successful run in which the wheel rolls, to fill the "
                             f"look-up table")
        values[i] = np.interp(torques, torques[known], row[known])
    return values


def identify(table: pd.DataFrame, degree: int = 1, torque_max: float = FIT_TORQUE_MAX) -> IdentifiedModel:
    """The identified model from the step table (LUTs) and the Fx fits (quadratic in W) through the
    points with torque up to ``torque_max`` [N·m]."""
    loads = np.array(sorted(table["load_N"].unique()))
    torques = np.array(sorted(table["torque_N_m"].unique()))
    gain = _filled(_rolling(table), "K_per_N_m", loads, torques)
    constant = _filled(_rolling(table), "T_s", loads, torques)
    per_load = fx_per_load(table, degree, torque_max)
    coefficients = np.array([np.polynomial.polynomial.polyfit(per_load["load_N"], per_load[f"c{k}"], 2)
                             for k in range(degree + 1)])
    return IdentifiedModel(loads, torques, gain, constant, coefficients, degree)
