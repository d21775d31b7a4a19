"""The rover's motion controller of the paper's Sec. 4.1, as an orchestrator block.

1. Mass-point feedback on the body: a_des = sat(kv (v_t - v) + kp (x_t - x), ±a_max) with
   x_t = v_t t, v_t = 1.0 m/s; F_all = M a_des.
2. Eq. (16): every wheel is asked for Fx_des = F_all / 6.
3. Per wheel i, the identified model inverted at that wheel's measured load W_i: the Fx(W, slip)
   block gives the slip that yields Fx_des; the second-order filter of Eq. (17),
   wn² / (s² + 2 wn s + wn²) with wn = 342 rad/s, smooths that slip and supplies its derivative,
   which makes the inverse of the first-order tau -> slip block proper:
   tau = (slip_f + T slip_f') / K, with K, T from the look-up tables at (W_i, tau).

Gains (M = 1570 kg): kv = 1.0 1/s settles the velocity in a few seconds once the demand is
below the limit; a_max = 0.1 m/s² keeps each wheel's demand near the ~26 N the paper's
Fig. 10(f, h) shows (M a_max / 6 = 26 N), well inside what a 290-560 N wheel carries on this
soil; kp = 0.001 1/s² only trims the position: the ~5 m the rover falls behind x_t = t while
accelerating would otherwise be caught up by running faster than v_t (the overshoot is about
kp x_lag / kv = 0.5 %).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.linalg import expm

from rover_cosim.identification.fits import IdentifiedModel

WHEELS = 6


class InverseModelController:
    """Orchestrator block: inputs x, v, W[1..6]; outputs tau[1..6], Fx_des[1..6], F_all."""

    def __init__(self, name: str, model: str, mass: float = 1570.0, v_target: float = 1.0, kv: float = 1.0,
                 kp: float = 0.001, a_max: float = 0.1, wn: float = 342.0, step: float = 1e-3,
                 fixed_load: float | None = None, model_label: str | None = None):
        path = Path(model)
        if not path.is_file():
            raise ValueError(f"block {name!r}: identified model {path} not found (run `make identify`)")
        data = json.loads(path.read_text())
        label = model_label or data["recommended"]
        if label not in data["models"]:
            raise ValueError(f"block {name!r}: model {label!r} not in {path} (has {sorted(data['models'])})")
        for key, value in (("mass", mass), ("a_max", a_max), ("wn", wn), ("step", step)):
            if not value > 0:
                raise ValueError(f"block {name!r}: {key} = {value!r}: expected > 0")
        self.name = name
        self.model = IdentifiedModel.from_dict(data["models"][label])
        self.model_label = label
        self.mass, self.v_target, self.kv, self.kp, self.a_max = mass, v_target, kv, kp, a_max
        self.fixed_load = fixed_load
        self.inputs = ("x", "v", *[f"W[{i}]" for i in range(1, WHEELS + 1)])
        self.outputs = (*[f"tau[{i}]" for i in range(1, WHEELS + 1)], *[f"Fx_des[{i}]" for i in range(1, WHEELS + 1)],
                        "F_all")
        self.units = {"x": "m", "v": "m/s", "F_all": "N",
                      **{f"W[{i}]": "N" for i in range(1, WHEELS + 1)},
                      **{f"tau[{i}]": "N.m" for i in range(1, WHEELS + 1)},
                      **{f"Fx_des[{i}]": "N" for i in range(1, WHEELS + 1)}}
        # Eq. (17) as x' = A x + B u, x = (slip_f, slip_f'), discretised exactly for a held input.
        a = np.array([[0.0, 1.0], [-wn**2, -2.0 * wn]])
        b = np.array([0.0, wn**2])
        self.step_size = step
        self.ad = expm(a * step)
        self.bd = np.linalg.solve(a, (self.ad - np.eye(2)) @ b)
        self.filter_state = np.zeros((WHEELS, 2))
        self.torque = np.zeros(WHEELS)

    # --- the inverse model ----------------------------------------------------------------------
    def slips_for_forces(self, loads: np.ndarray, forces: np.ndarray) -> np.ndarray:
        """The slip at which the Fx(W, slip) block gives each force (for the quadratic model, the
        root nearest the linear solution)."""
        powers = np.vstack([np.ones_like(loads), loads, loads**2])
        c = self.model.fx_coefficients @ powers  # (degree + 1, wheels): c_k(W)
        linear = (forces - c[0]) / c[1]
        if self.model.degree == 1:
            return linear
        if self.model.degree != 2:
            raise ValueError(f"block {self.name!r}: inverse of a degree-{self.model.degree} Fx model not implemented")
        discriminant = c[1] ** 2 - 4.0 * c[2] * (c[0] - forces)
        safe = (c[2] != 0) & (discriminant >= 0)
        root = np.sqrt(np.where(safe, discriminant, 0.0))
        denominator = np.where(safe, 2.0 * c[2], 1.0)
        plus, minus = (-c[1] + root) / denominator, (-c[1] - root) / denominator
        nearest = np.where(np.abs(plus - linear) <= np.abs(minus - linear), plus, minus)
        return np.where(safe, nearest, linear)

    def torques_for_slips(self, loads: np.ndarray, slips: np.ndarray,
                          rows: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(torque whose settled slip K(W, tau) tau is each slip, T there): the exact inverse of
        the tables as the identified model reads them (settled slip linear in tau between the
        table's torques, extended linearly beyond them). ``rows``: model.rows_at(loads), if known."""
        torques = self.model.torques
        settled_rows, constants = rows if rows is not None else self.model.rows_at(loads)
        result, time_constants = np.empty(len(loads)), np.empty(len(loads))
        for i, (row, slip) in enumerate(zip(settled_rows, slips)):
            j = int(np.clip(np.searchsorted(row, slip), 1, len(torques) - 1))
            torque = torques[j - 1] + (slip - row[j - 1]) * (torques[j] - torques[j - 1]) / (row[j] - row[j - 1])
            result[i] = torque
            time_constants[i] = np.interp(torque, torques, constants[i])
        return result, time_constants

    def _demand(self, t: float, x: float, v: float) -> float:
        acceleration = self.kv * (self.v_target - v) + self.kp * (self.v_target * t - x)
        return self.mass * float(np.clip(acceleration, -self.a_max, self.a_max))

    def _outputs(self, t: float, u: np.ndarray, advance: bool) -> np.ndarray:
        x, v = u[0], u[1]
        loads = np.full(WHEELS, float(self.fixed_load)) if self.fixed_load else np.asarray(u[2:2 + WHEELS], float)
        force_all = self._demand(t, x, v)
        forces = np.full(WHEELS, force_all / WHEELS)  # Eq. (16)
        targets = self.slips_for_forces(loads, forces)
        if advance:
            self.filter_state = self.filter_state @ self.ad.T + np.outer(targets, self.bd)
        else:
            self.filter_state = np.column_stack([targets, np.zeros(WHEELS)])
        slip, rate = self.filter_state[:, 0], self.filter_state[:, 1]
        # The inverse of K/(T s + 1): tau = (slip + T slip') / K, with T at the torque for slip.
        rows = self.model.rows_at(loads)
        _, constants = self.torques_for_slips(loads, slip, rows)
        self.torque, _ = self.torques_for_slips(loads, slip + constants * rate, rows)
        return np.concatenate([self.torque, forces, [force_all]])

    # --- the block interface --------------------------------------------------------------------
    def start(self, t0: float, u0: np.ndarray) -> np.ndarray:
        return self._outputs(t0, u0, advance=False)

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        if abs(h - self.step_size) > 1e-12:
            raise ValueError(f"block {self.name!r}: communication step {h!r} s differs from its step = "
                             f"{self.step_size!r} s (the filter is discretised for it)")
        return self._outputs(t + h, u, advance=True)
