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

import ctypes
from pathlib import Path

import numpy as np

from rover_cosim.common.paper import WHEELS
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.orchestrator import native as native_code
from rover_cosim.orchestrator.native import doubles

from .longitudinal import LongitudinalInverse, read_model

#: The block's C twin (same arithmetic, same results), for the native stepper.
C_SOURCE = Path(__file__).with_name("inverse_controller.c")


class InverseModelController:
    """Orchestrator block: inputs x, v, W[1..N]; outputs tau[1..N], Fx_des[1..N], F_all, for a rover of
    N = ``wheels`` wheels (the job reads N from the plant; the paper's rover has six), each asked
    for F_all / N (Eq. 16). ``model``: the identified models (a ModelSet, or the model.json to read)."""

    def __init__(self, name: str, model: ModelSet | str, mass: float = 1570.0, v_target: float = 1.0, kv: float = 1.0,
                 kp: float = 0.001, a_max: float = 0.1, wn: float = 342.0, step: float = 1e-3,
                 fixed_load: float | None = None, model_label: str | None = None, wheels: int = WHEELS):
        _, self.model, self.model_label = read_model(model, name, model_label)
        for key, value in (("mass", mass), ("a_max", a_max), ("wn", wn), ("step", step), ("wheels", wheels)):
            if not value > 0:
                raise ValueError(f"block {name!r}: {key} = {value!r}: expected > 0")
        self.name, self.wheels = name, int(wheels)
        self.mass, self.v_target, self.kv, self.kp, self.a_max = mass, v_target, kv, kp, a_max
        self.fixed_load = fixed_load
        limbs = range(1, self.wheels + 1)
        self.inputs = ("x", "v", *[f"W[{i}]" for i in limbs])
        self.outputs = (*[f"tau[{i}]" for i in limbs], *[f"Fx_des[{i}]" for i in limbs], "F_all")
        self.units = {"x": "m", "v": "m/s", "F_all": "N", **{f"W[{i}]": "N" for i in limbs},
                      **{f"tau[{i}]": "N.m" for i in limbs}, **{f"Fx_des[{i}]": "N" for i in limbs}}
        self.step_size = step
        self.inverse = LongitudinalInverse(self.model, self.wheels, wn, step, name)
        self.torque = np.zeros(self.wheels)

    # --- the inverse model ----------------------------------------------------------------------
    def slips_for_forces(self, loads: np.ndarray, forces: np.ndarray) -> np.ndarray:
        """See LongitudinalInverse.slips_for_forces."""
        return self.inverse.slips_for_forces(loads, forces)

    def torques_for_slips(self, loads: np.ndarray, slips: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """See LongitudinalInverse.torques_for_slips."""
        return self.inverse.torques_for_slips(loads, slips)

    def _demand(self, t: float, x: float, v: float) -> float:
        acceleration = self.kv * (self.v_target - v) + self.kp * (self.v_target * t - x)
        return self.mass * float(np.clip(acceleration, -self.a_max, self.a_max))

    def _outputs(self, t: float, u: np.ndarray, advance: bool, step: float | None = None) -> np.ndarray:
        x, v = u[0], u[1]
        n = self.wheels
        loads = np.full(n, float(self.fixed_load)) if self.fixed_load else np.asarray(u[2:2 + n], float)
        force_all = self._demand(t, x, v)
        forces = np.full(self.wheels, force_all / self.wheels)  # Eq. (16)
        self.torque = self.inverse.torques(loads, forces, advance, step)
        return np.concatenate([self.torque, forces, [force_all]])

    # --- the block interface --------------------------------------------------------------------
    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        """The outputs at the start; ``h`` [s]: the run's communication step (the law's filter is
        discretised at it; None: at the ``step`` it was made with)."""
        if h is not None:
            self.use_step(h)
        return self._outputs(t0, u0, advance=False)

    def use_step(self, h: float) -> None:
        """Step at the communication step ``h`` [s]: the law's filter discretised at it."""
        self.step_size = self.inverse.set_step(h)

    def get_state(self) -> tuple[np.ndarray, np.ndarray]:
        """The filter's state and the last torques (for masters that repeat a step)."""
        return self.inverse.filter_state.copy(), self.torque.copy()

    def set_state(self, state: tuple[np.ndarray, np.ndarray]) -> None:
        self.inverse.filter_state, self.torque = state[0].copy(), state[1].copy()

    def native(self) -> native_code.NativeBlock | None:
        """The block's C twin (inverse_controller.c) from its state now, for the native stepper;
        None where it cannot be compiled (the block then steps in Python). The twin keeps its own
        state: a run stepped by it leaves this block's state as it was after ``start``."""
        library = native_code.load_library(C_SOURCE)
        if isinstance(library, str):
            return None
        inverse, model = self.inverse, self.model
        if model.degree not in (1, 2):
            return None  # the Python block reports it
        pointer = ctypes.c_void_p


        library.controller_new.restype = pointer
        library.controller_new.argtypes = [ctypes.c_int] * 4 + [pointer] * 7
        settings = [self.mass, self.v_target, self.kv, self.kp, self.a_max, inverse.wn, self.step_size,
                    float(self.fixed_load) if self.fixed_load else 0.0]
        loads, torques, settled, log_t, coefficients = inverse.tables()
        component = library.controller_new(
            self.wheels, len(loads), len(torques), model.degree, doubles(settings), doubles(loads), doubles(torques),
            doubles(settled), doubles(log_t), doubles(coefficients), doubles(inverse.filter_state))
        if not component:
            sizes = f"{len(loads)} loads x {len(torques)} torques"
            raise MemoryError(f"block {self.name!r}: its C twin could not be made (tables of {sizes}: expected >= 2 "
                              "each; or out of memory)")
        return native_code.NativeBlock(library, component, "controller")

    def law_twin(self) -> LawTwin | None:
        """The law alone stepped through the C twin from this block's state now (None where the
        twin cannot be compiled): for a block built on this one that steps the law from its own
        Python step, bit for bit and several times faster than the Python law."""
        try:
            made = InverseModelController.native(self)  # the law's own twin, whatever a subclass steps natively
        except MemoryError:  # tables it cannot take: the Python law steps (and says what is wrong, if anything)
            return None
        return None if made is None else LawTwin(made, self.wheels)

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        if not 0 < h <= self.step_size * (1 + 1e-9):
            raise ValueError(f"block {self.name!r}: communication step {h!r} s: expected at most its step = "
                             f"{self.step_size!r} s (a shorter last step is fine)")
        return self._outputs(t + h, u, advance=True, step=h)


class LawTwin:
    """An InverseModelController's law stepped through its C twin (inverse_controller.c) from
    Python: the inputs x, v, W[1..n] of ``u``, the outputs of the Python block's ``_outputs`` at
    ``t`` with the filter moved on by ``h``, bit for bit. The filter's state stays in the twin
    (``filter``, ``set_filter``: for masters that repeat a step)."""

    def __init__(self, made: native_code.NativeBlock, wheels: int):
        self.made: native_code.NativeBlock | None = made
        self.wheels = wheels
        library, pointer = made.library, ctypes.c_void_p
        for name in ("controller_set_real", "controller_get_real"):
            getattr(library, name).argtypes = [pointer, pointer, ctypes.c_size_t, pointer]
        library.controller_step_at.argtypes = [pointer, ctypes.c_double, ctypes.c_double]
        for name in ("controller_get_filter", "controller_set_filter"):
            getattr(library, name).argtypes = [pointer, pointer]
            getattr(library, name).restype = None
        self._inputs = (ctypes.c_uint * (2 + wheels))(*range(2 + wheels))
        self._outputs = (ctypes.c_uint * (2 * wheels + 1))(*range(2 * wheels + 1))
        self._values = np.zeros(2 * wheels + 1)

    def _twin(self) -> native_code.NativeBlock:
        if self.made is None:
            raise RuntimeError("the law's C twin was freed")
        return self.made

    def step_at(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        """The law's outputs (tau[1..n], Fx_des[1..n], F_all) at ``t`` [s], the filter moved on by ``h`` [s]."""
        made = self._twin()
        library, component = made.library, made.component
        inputs = np.ascontiguousarray(u[:2 + self.wheels], dtype=float)
        library.controller_set_real(component, self._inputs, inputs.size, inputs.ctypes.data)
        if library.controller_step_at(component, t, h) != 0:
            raise ValueError(made.message())
        library.controller_get_real(component, self._outputs, self._values.size, self._values.ctypes.data)
        return self._values.copy()

    def filter(self) -> np.ndarray:
        """The filter's state, (wheels, 2): slip_f, slip_f' [1/s]."""
        made = self._twin()
        state = np.zeros((self.wheels, 2))
        made.library.controller_get_filter(made.component, state.ctypes.data)
        return state

    def set_filter(self, state: np.ndarray) -> None:
        made = self._twin()
        values = np.ascontiguousarray(state, dtype=float).reshape(self.wheels, 2)
        made.library.controller_set_filter(made.component, values.ctypes.data)

    def close(self) -> None:
        """Free the twin (once; later calls do nothing, using it raises)."""
        made = getattr(self, "made", None)  # None: __init__ did not get that far, or freed
        if made is not None:
            made.close()
            self.made = None

    def __del__(self) -> None:
        self.close()
