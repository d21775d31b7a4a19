"""The inverse of the identified longitudinal model (paper Sec. 4.1, steps 3-4), per wheel:
Fx_des -> slip by the Fx(W, slip) block, the filter of Eq. (17) on that slip, and the inverse
of the first-order tau -> slip block at the wheel's load, tau = (slip_f + T slip_f') / K.

One law, written once in Python wheel by wheel in plain floats, and its C twin
(``inverse_controller.c``, stepped by the native stepper) with the same arithmetic in the same
order, so that their torques agree to the last bit (tests); ``torques_for_slips`` applies the
same law to each wheel. Plain floats rather than numpy: on six wheels numpy's cost per call
dominates (a whole-array numpy version of this law, bit for bit the same, took 7.5x as long per
step: 405 against 54 us, measured side by side); where no C compiler works the blocks step this
law in Python (``make bench``: results/bench/controller.json has its cost per step).
"""

from __future__ import annotations

import bisect
import math
from pathlib import Path

import numpy as np

from rover_cosim.identification.fits import IdentifiedModel
from rover_cosim.identification.model_set import ModelFileError, ModelSet

#: N: a wheel under this load or less is off the ground (a leg-wheel rover's lifted wheel; the
#: wheel FMUs' own floor is 1 mN): the law gives it no torque and holds its filter at rest (the
#: inverse model there would ask for any torque at all). The C twins' LAW_NO_LOAD (inverse_law.h).
NO_LOAD = 1.0

# Below the lightest load of the identified tables (and above NO_LOAD: a wheel lifting off or set
# down) the law extrapolates neither its Fx model nor its torque tables, which turned the torque over
# (on the paper's model 26 N asked at 30 N gave -5.1 N·m, and a leg-wheel rover's unloading wheel
# spun up to -22,800 rad/s): the slip for a force is the model's at the lightest load, the torque
# for the filtered slip the tables' at the lightest load, scaled by W / W_lightest (the resistance a
# wheel's torque works against grows about as its load): continuous at W_lightest, 0 at no load.
# The C twins' slip_for_force and law_torque do the same.

def read_model(model: ModelSet | str | Path, name: str,
               label: str | None = None) -> tuple[ModelSet, IdentifiedModel, str]:
    """(the identified models, the longitudinal model ``label`` (default: the recommended one),
    its label) of ``model``: a ModelSet, or the model.json to read; errors name the block and the file."""
    try:
        models = model if isinstance(model, ModelSet) else ModelSet.read(model)
        chosen = models.model(label)
    except ModelFileError as error:
        raise ValueError(f"block {name!r}: {error}") from None
    return models, chosen, label or models.recommended


class LongitudinalInverse:
    """Torques [N·m] for desired longitudinal forces [N] of ``wheels`` wheels at their loads [N],
    through the identified ``model``; the filter of Eq. (17) (``wn`` [rad/s]) is discretised
    exactly for the held step ``step`` [s]."""

    def __init__(self, model: IdentifiedModel, wheels: int, wn: float, step: float, name: str = "controller"):
        self.model, self.name, self.wn = model, name, wn
        self.set_step(step)
        self.filter_state = np.zeros((wheels, 2))
        # The tables as plain Python floats (see the module docstring).
        self._inverse = [float(v) for v in 1.0 / np.asarray(model.loads, float)]   # decreasing
        self._negated_inverse = [-v for v in self._inverse]                          # increasing, for bisect
        self._lightest = 1.0 / self._inverse[0]  # N, the tables' lightest load (the light-load rule)
        self._torques = [float(v) for v in model.torques]
        self._settled = [[float(v) for v in row] for row in np.asarray(model.gain) * model.torques[None, :]]
        self._log_t = [[float(v) for v in row] for row in np.log(np.asarray(model.time_constant, float))]
        self._coefficients = [[float(v) for v in row] for row in model.fx_coefficients]

    def set_step(self, step: float) -> float:
        """Discretise the filter at the communication step ``step`` [s] (a block learns the run's
        step at its start); ``step``."""
        if not (math.isfinite(step) and step > 0):
            raise ValueError(f"{self.name}: step = {step!r} s: expected a finite step > 0")
        self.step = step
        self.ad, self.bd = self.discretised(step)
        return step

    def tables(self) -> tuple[list[float], list[float], list[list[float]], list[list[float]], list[list[float]]]:
        """The law's tables, for the controller's C twin: 1/W of the loads
        [1/N] (decreasing), the torques [N·m], per load the settled slips and log T [log s], and
        the Fx model's coefficient rows."""
        return self._inverse, self._torques, self._settled, self._log_t, self._coefficients

    def discretised(self, step: float) -> tuple[np.ndarray, np.ndarray]:
        """Eq. (17) as x' = A x + b u, x = (slip_f, slip_f'), A = [[0, 1], [-wn², -2 wn]],
        b = (0, wn²), discretised exactly for an input held over ``step`` [s]. The filter is
        critically damped, so exp(A h) = e^(-wn h) [[1 + wn h, h], [-wn² h, 1 - wn h]] and
        b_d = (1 - e^(-wn h) (1 + wn h), wn² h e^(-wn h)) (the C twin computes the same)."""
        wn = self.wn
        decay, wh, wn2 = math.exp(-wn * step), wn * step, wn * wn
        ad = np.array([[decay * (1.0 + wh), decay * step], [decay * (-wn2 * step), decay * (1.0 - wh)]])
        return ad, np.array([1.0 - decay * (1.0 + wh), wn2 * step * decay])

    def slips_for_forces(self, loads: np.ndarray, forces: np.ndarray) -> np.ndarray:
        """The slip at which the Fx(W, slip) block gives each force (for the quadratic model, the
        root nearest the linear solution; beyond its extremum, the extremum's slip), for whole
        arrays at once: the path controller's force allocation uses it. The same inverse as the
        law's first step up to round-off (the law evaluates c_k(W) term by term, this a matrix
        product); moving the path controller onto the law changes its results in the last printed
        digit, so that waits for its C twin."""
        lightest = self._lightest
        loads = np.where((loads > 0) & (loads < lightest), lightest, loads)  # the light-load rule
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
        # a force beyond the model's extremum: the extremum's slip (see _slip_for_force)
        vertex = -c[1] / np.where(c[2] != 0, 2.0 * c[2], 1.0)
        return np.where(safe, nearest, np.where(c[2] != 0, vertex, linear))

    def torques_for_slips(self, loads: np.ndarray, slips: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(torque whose settled slip K(W, tau) tau is each slip, T there [s]): the exact inverse
        of the tables as the law reads them (settled slip linear in tau between the table's
        torques, extended linearly beyond them; T linear between them, held beyond)."""
        torques, constants = [], []
        for load, slip in zip(np.asarray(loads, float).tolist(), np.asarray(slips, float).tolist()):
            share, load = self._light(load)
            settled, log_t = self._rows(load)
            torque = self._torque_for(settled, slip)
            torques.append(share * torque)
            constants.append(self._time_constant(torque, log_t))
        return np.array(torques), np.array(constants)

    def _light(self, load: float) -> tuple[float, float]:
        """(W / W_lightest, the load the tables are read at) of a wheel under the tables' lightest
        load (see the module's light-load rule); (1, load) for the others."""
        lightest = self._lightest
        if 0 < load < lightest:
            return load / lightest, lightest
        return 1.0, load

    def torques(self, loads: np.ndarray, forces: np.ndarray, advance: bool, step: float | None = None) -> np.ndarray:
        """The torques for ``forces`` at ``loads``; ``advance`` moves the filter one step on (else
        it starts settled at the targets); ``step`` [s]: a step other than the one it was made for
        (the shorter last step of a run)."""
        ad, bd = self.ad, self.bd
        if advance and step is not None and abs(step - self.step) > 1e-12:
            ad, bd = self.discretised(step)
        a00, a01, a10, a11 = float(ad[0, 0]), float(ad[0, 1]), float(ad[1, 0]), float(ad[1, 1])
        b0, b1 = float(bd[0]), float(bd[1])
        state = self.filter_state
        result = np.empty(len(loads))
        for i, (load, force) in enumerate(zip(loads.tolist(), forces.tolist())):
            if 0 < load <= NO_LOAD:  # off the ground (a leg-wheel rover's lifted wheel): no torque, the filter at rest
                state[i, 0], state[i, 1], result[i] = 0.0, 0.0, 0.0
                continue
            target = self._slip_for_force(load, force)
            if advance:
                slip_f, rate_f = float(state[i, 0]), float(state[i, 1])
                slip, rate = a00 * slip_f + a01 * rate_f + b0 * target, a10 * slip_f + a11 * rate_f + b1 * target
            else:
                slip, rate = target, 0.0
            state[i, 0], state[i, 1] = slip, rate
            # The inverse of K/(T s + 1): tau = (slip + T slip') / K, with T at the torque for slip; a
            # light wheel's read at the tables' lightest load and scaled (the light-load rule above).
            share, table_load = self._light(load)
            settled, log_t = self._rows(table_load)
            constant = self._time_constant(self._torque_for(settled, slip), log_t)
            result[i] = share * self._torque_for(settled, slip + constant * rate)
        return result

    def slip_for_force(self, load: float, force: float) -> float:
        """The slip at which the Fx(W, slip) model gives ``force`` [N] at ``load`` [N] (for the
        quadratic model, the root nearest the linear solution): the law's first step."""
        return self._slip_for_force(load, force)

    def _slip_for_force(self, load: float, force: float) -> float:
        """The slip at which the Fx(W, slip) model gives ``force`` at ``load``; a force beyond the
        quadratic model's extremum (more pull than its peak at that load: a steep climb on evenly
        loaded wheels) gets the slip of the extremum, the most the model knows to give (before: the
        linear model's slip, which on the paper's model at 400 N asks 0.175 for 171 N where the
        peak, 152 N, is at 0.31: a rover that could climb stalled)."""
        load = self._light(load)[1]  # a light wheel: the model at the lightest load (the light-load rule)
        c = [row[0] + row[1] * load + row[2] * load * load for row in self._coefficients]
        linear = (force - c[0]) / c[1]
        if self.model.degree == 1:
            return linear
        if self.model.degree != 2:
            raise ValueError(f"block {self.name!r}: inverse of a degree-{self.model.degree} Fx model not implemented")
        discriminant = c[1] * c[1] - 4.0 * c[2] * (c[0] - force)
        if c[2] == 0:
            return linear
        if discriminant < 0:
            return -c[1] / (2.0 * c[2])
        root = math.sqrt(discriminant)
        plus, minus = (-c[1] + root) / (2.0 * c[2]), (-c[1] - root) / (2.0 * c[2])
        return plus if abs(plus - linear) <= abs(minus - linear) else minus

    def _rows(self, load: float) -> tuple[list[float], list[float]]:
        """The settled-slip row and the log T row at ``load`` (interpolated linearly in 1/W)."""
        if not load > 0:
            raise ValueError(f"loads = {load!r} N: expected > 0")
        inverse, x = self._inverse, 1.0 / load
        j = min(max(bisect.bisect_left(self._negated_inverse, -x), 1), len(inverse) - 1)
        weight = (x - inverse[j - 1]) / (inverse[j] - inverse[j - 1])
        low, high = self._settled[j - 1], self._settled[j]
        settled = [(1 - weight) * a + weight * b for a, b in zip(low, high)]
        low_t, high_t = self._log_t[j - 1], self._log_t[j]
        return settled, [(1 - weight) * a + weight * b for a, b in zip(low_t, high_t)]

    def _torque_for(self, row: list[float], slip: float) -> float:
        """The torque whose settled slip (in ``row``) is ``slip``."""
        torques = self._torques
        j = min(max(bisect.bisect_left(row, slip), 1), len(torques) - 1)
        return torques[j - 1] + (slip - row[j - 1]) * (torques[j] - torques[j - 1]) / (row[j] - row[j - 1])

    def _time_constant(self, torque: float, log_t: list[float]) -> float:
        """T at ``torque`` (np.interp of the row's T over the torques, held beyond its ends)."""
        torques = self._torques
        if torque <= torques[0]:
            return math.exp(log_t[0])
        if torque >= torques[-1]:
            return math.exp(log_t[-1])
        j = bisect.bisect_right(torques, torque)
        low, high = math.exp(log_t[j - 1]), math.exp(log_t[j])
        return low + (torque - torques[j - 1]) * (high - low) / (torques[j] - torques[j - 1])
