"""The inverse of the identified longitudinal model (paper Sec. 4.1, steps 3-4), per wheel:
Fx_des -> slip by the Fx(W, slip) block, the filter of Eq. (17) on that slip, and the inverse
of the first-order tau -> slip block at the wheel's load, tau = (slip_f + T slip_f') / K."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from scipy.linalg import expm

from rover_cosim.identification.fits import IdentifiedModel


def read_model(model: str | Path, name: str, label: str | None = None) -> tuple[dict[str, Any], IdentifiedModel, str]:
    """(model.json's content, the identified longitudinal model ``label`` (default: the
    recommended one), its label), with errors that name the block and the file."""
    path = Path(model)
    if not path.is_file():
        raise ValueError(f"block {name!r}: identified model {path} not found (run `make identify`)")
    data = json.loads(path.read_text())
    label = label or data["recommended"]
    if label not in data["models"]:
        raise ValueError(f"block {name!r}: model {label!r} not in {path} (has {sorted(data['models'])})")
    return data, IdentifiedModel.from_dict(data["models"][label]), label


class LongitudinalInverse:
    """Torques [N·m] for desired longitudinal forces [N] of ``wheels`` wheels at their loads [N],
    through the identified ``model``; the filter of Eq. (17) (``wn`` [rad/s]) is discretised
    exactly for the held step ``step`` [s]."""

    def __init__(self, model: IdentifiedModel, wheels: int, wn: float, step: float, name: str = "controller"):
        self.model, self.name, self.wn, self.step = model, name, wn, step
        self.ad, self.bd = self.discretised(step)
        self.filter_state = np.zeros((wheels, 2))

    def discretised(self, step: float) -> tuple[np.ndarray, np.ndarray]:
        """Eq. (17) as x' = A x + B u, x = (slip_f, slip_f'), discretised exactly for an input
        held over ``step`` [s]."""
        wn = self.wn
        a = np.array([[0.0, 1.0], [-wn**2, -2.0 * wn]])
        b = np.array([0.0, wn**2])
        ad = expm(a * step)
        return ad, np.linalg.solve(a, (ad - np.eye(2)) @ b)

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

    def torques(self, loads: np.ndarray, forces: np.ndarray, advance: bool, step: float | None = None) -> np.ndarray:
        """The torques for ``forces`` at ``loads``; ``advance`` moves the filter one step on (else
        it starts settled at the targets); ``step`` [s]: a step other than the one it was made for
        (the shorter last step of a run)."""
        targets = self.slips_for_forces(loads, forces)
        if advance:
            ad, bd = (self.ad, self.bd) if step is None or abs(step - self.step) <= 1e-12 else self.discretised(step)
            self.filter_state = self.filter_state @ ad.T + np.outer(targets, bd)
        else:
            self.filter_state = np.column_stack([targets, np.zeros(len(targets))])
        slip, rate = self.filter_state[:, 0], self.filter_state[:, 1]
        # The inverse of K/(T s + 1): tau = (slip + T slip') / K, with T at the torque for slip.
        rows = self.model.rows_at(loads)
        _, constants = self.torques_for_slips(loads, slip, rows)
        torque, _ = self.torques_for_slips(loads, slip + constants * rate, rows)
        return torque
