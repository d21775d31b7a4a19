"""Path following with the identified wheel models (the paper's method extended to steering),
as an orchestrator block for the steerable rover.

1. Path tracking at the body, in the path's frame at the nearest point (arc length s,
   cross-track error e, left positive; heading psi_p and curvature kappa there):
   - along the path: a_t = sat(kv (v_t - v_s) + kp (v_t t - s), ±a_max), v_t the target speed;
   - across it: a_n = v_s² kappa - k_e e - k_de de/dt, saturated at ±a_n_max (the centripetal
     acceleration of the path as feed-forward, a critically damped PD on the cross-track error:
     k_e = 0.25 1/s², k_de = 1.0 1/s, natural frequency 0.5 rad/s: the error decays over ~6 s,
     ~3 m at 0.5 m/s, slower than the heading loop and far slower than the wheels);
   - heading: the body keeps the path's heading, yaw acceleration
     k_psi (psi_p - psi) + k_r (v_s kappa - r) with k_psi = 1.0 1/s², k_r = 2.0 1/s (critically
     damped at 1 rad/s), yaw moment M_z = Izz times that, saturated at Izz alpha_max.
   The body's force demand M (a_t, a_n) turned into the heading frame, and M_z.
2. Allocation (``allocation``): each wheel's (f_x, f_y) in the heading frame, least squares
   weighted by the measured loads.
3. Per wheel, the identified models at its measured load W_i: the steering angle delta and the
   wheel-frame demand (Fx_des, Fy_des) = R(-delta) (f_x, f_y) such that the identified lateral
   model gives Fy_des at the slip angle beta = gamma - delta (gamma: the hub's velocity
   direction in the heading frame, measured as the wheel's slip angle plus the steering it
   had) and at the slip the inverse longitudinal model gives for Fx_des (Newton on delta, from
   the last step's); the torque for Fx_des by the paper's inverse longitudinal model
   (``longitudinal``). ``steering = "kinematic"`` is the ablation: each wheel pointed along the
   velocity its hub would have if the body moved as commanded (no slip-angle compensation),
   yaw rate v_s kappa + k_psi/k_r-style corrections, Fx_des from the along-path demand alone.
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Callable, Iterable
from pathlib import Path as FilePath

import numpy as np

from rover_cosim.identification.model_set import ModelSet
from rover_cosim.orchestrator import native as native_code
from rover_cosim.orchestrator.native import doubles

from .allocation import allocation_matrix, share
from .longitudinal import LongitudinalInverse, read_model
from .path import Path, lane_change_path, turn_path

PATHS = {"turn": turn_path, "lane_change": lane_change_path}
MAX_STEER = math.radians(45.0)    # rad: steering range
MAX_SLIP_ANGLE = math.radians(30.0)  # rad: the lateral model's identified range
NEWTON_STEPS = 2
WINDOW = 2.0  # m of arc length around the last nearest point searched for the next (Path.locate's default)
#: The block's C twin (same arithmetic, same results), for the native stepper.
C_SOURCE = FilePath(__file__).with_name("path_controller.c")


def _clip(value: float, low: float, high: float) -> float:
    """np.clip of one value: min(max(value, low), high), NaN kept (as the C twin's)."""
    value = low if low > value else value
    return high if value > high else value


def _names(stem: str, wheels: int) -> list[str]:
    return [f"{stem}[{i}]" for i in range(1, wheels + 1)]


class PathFollowingController:
    """Orchestrator block. Inputs: x, y, yaw, v, vy, yawRate (body), W[1..N], slipAngle[1..N]
    (wheels). Outputs: tau[1..N], steer[1..N], Fx_des[1..N], Fy_des[1..N], s, s_ref,
    cross_track, heading_error. N = 2 len(x_limb): the hubs of the left side at (x_limb, y_limb)
    [m] from front to rear, the right side mirrors them (six on the paper's rover)."""

    def __init__(self, name: str, model: ModelSet | str, path: str | Path = "turn", v_target: float = 0.5,
                 steering: str = "inverse", mass: float = 1570.0, yaw_inertia: float = 1980.0,
                 x_limb: tuple[float, ...] = (1.5, 0.0, -1.5), y_limb: float = 1.5,
                 kv: float = 1.0, kp: float = 0.01, a_max: float = 0.1,
                 k_e: float = 0.25, k_de: float = 1.0, a_n_max: float = 0.3,
                 k_psi: float = 1.0, k_r: float = 2.0, alpha_max: float = 0.5,
                 wn: float = 342.0, step: float = 1e-3):
        models, longitudinal, _ = read_model(model, name)
        if models.lateral is None:
            raise ValueError(f"block {name!r}: {models.source} has no lateral model (run `make identify`)")
        if not isinstance(path, Path) and path not in PATHS:
            raise ValueError(f"block {name!r}: path = {path!r}: expected one of {sorted(PATHS)} or a Path")
        if steering not in ("inverse", "kinematic"):
            raise ValueError(f"block {name!r}: steering = {steering!r}: expected 'inverse' or 'kinematic'")
        for key, value in (("v_target", v_target), ("mass", mass), ("yaw_inertia", yaw_inertia), ("y_limb", y_limb),
                           ("a_max", a_max), ("a_n_max", a_n_max), ("alpha_max", alpha_max), ("step", step)):
            if not value > 0:
                raise ValueError(f"block {name!r}: {key} = {value!r}: expected > 0")
        self.name, self.steering, self.step_size = name, steering, step
        self.path: Path = path if isinstance(path, Path) else PATHS[path]()
        self.lateral = models.lateral
        if not 1 <= len(x_limb) <= 8:
            raise ValueError(f"block {name!r}: x_limb = {x_limb!r}: expected 1 to 8 hub positions per side [m]")
        self.wheels = wheels = 2 * len(x_limb)
        self.inverse = LongitudinalInverse(longitudinal, wheels, wn, step, name)
        self.v_target, self.mass, self.yaw_inertia = v_target, mass, yaw_inertia
        self.gains = dict(kv=kv, kp=kp, a_max=a_max, k_e=k_e, k_de=k_de, a_n_max=a_n_max, k_psi=k_psi, k_r=k_r,
                          alpha_max=alpha_max)
        self.x_hub = np.array([*x_limb, *x_limb], float)
        self.y_hub = np.array([y_limb] * len(x_limb) + [-y_limb] * len(x_limb), float)
        self.matrix = allocation_matrix(self.x_hub, self.y_hub)
        self._rows = self.matrix.tolist()
        self.steer = np.zeros(wheels)
        self.hint: int | None = None
        self.inputs = ("x", "y", "yaw", "v", "vy", "yawRate", *_names("W", wheels), *_names("slipAngle", wheels))
        self.outputs = (*_names("tau", wheels), *_names("steer", wheels), *_names("Fx_des", wheels),
                        *_names("Fy_des", wheels),
                        "s", "s_ref", "cross_track", "heading_error")
        self.units = {"x": "m", "y": "m", "yaw": "rad", "v": "m/s", "vy": "m/s", "yawRate": "rad/s", "s": "m",
                      "s_ref": "m", "cross_track": "m", "heading_error": "rad",
                      **{n: "N" for n in (*_names("W", wheels), *_names("Fx_des", wheels), *_names("Fy_des", wheels))},
                      **{n: "rad" for n in (*_names("slipAngle", wheels), *_names("steer", wheels))},
                      **{n: "N.m" for n in _names("tau", wheels)}}

    # --- 1. tracking ----------------------------------------------------------------------------
    def _tracking(self, t: float, u: list[float]) -> tuple[list[float], float, list[float], tuple[float, float]]:
        """(force demand (F_x, F_y, M_z) in the heading frame, path speed, signals (s, s_ref,
        cross_track, heading_error), (kappa, error of heading))."""
        x, y, yaw, v, vy, r = u[:6]
        where = self.path.locate(x, y, self.hint, WINDOW)
        self.hint = where.index
        offset = yaw - where.heading
        cos, sin = math.cos(offset), math.sin(offset)
        along, across = v * cos - vy * sin, v * sin + vy * cos
        g = self.gains
        s_ref = self.v_target * t
        a_t = _clip(g["kv"] * (self.v_target - along) + g["kp"] * (s_ref - where.s), -g["a_max"], g["a_max"])
        a_n = _clip(along * along * where.curvature - g["k_e"] * where.cross_track - g["k_de"] * across,
                    -g["a_n_max"], g["a_n_max"])
        alpha = _clip(g["k_psi"] * -offset + g["k_r"] * (along * where.curvature - r), -g["alpha_max"],
                      g["alpha_max"])
        demand = [self.mass * (a_t * cos + a_n * sin), self.mass * (-a_t * sin + a_n * cos), self.yaw_inertia * alpha]
        return demand, along, [where.s, s_ref, where.cross_track, offset], (where.curvature, offset)

    # --- 3. per wheel -----------------------------------------------------------------------------
    def _inverse_steering(self, loads: Iterable[float], gamma: Iterable[float], fx: Iterable[float],
                          fy: Iterable[float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(steer, Fx_des, Fy_des): Newton on delta for Fy_model(W, gamma - delta, slip) = Fy_des(delta),
        from the last step's delta (two steps reach the solve's tolerance: delta changes by
        micro-radians per step); the slip is the one for Fx_des at the last step's delta."""
        steer, fx_des, fy_des = [], [], []
        for wheel, (load, angle, f_x, f_y, delta) in enumerate(zip(map(float, loads), map(float, gamma), map(float, fx),
                                                                   map(float, fy), map(float, self.steer))):
            lateral = self._lateral_law(wheel, load, f_x * math.cos(delta) + f_y * math.sin(delta))
            low, high = _clip(angle - MAX_SLIP_ANGLE, -MAX_STEER, math.inf), _clip(angle + MAX_SLIP_ANGLE, -math.inf,
                                                                                   MAX_STEER)
            for _ in range(NEWTON_STEPS):
                cos, sin = math.cos(delta), math.sin(delta)
                model_fy, slope = lateral(angle - delta)
                residual = model_fy - (f_y * cos - f_x * sin)
                derivative = -slope + f_x * cos + f_y * sin  # d/d delta of the residual
                delta = _clip(delta - residual / (derivative if abs(derivative) > 1e-9 else 1e-9), low, high)
            cos, sin = math.cos(delta), math.sin(delta)
            steer.append(delta)
            fx_des.append(f_x * cos + f_y * sin)
            fy_des.append(f_y * cos - f_x * sin)
        return np.array(steer), np.array(fx_des), np.array(fy_des)

    def _lateral_law(self, wheel: int, load: float, force: float) -> Callable[[float], tuple[float, float]]:
        """Wheel ``wheel``'s (0-5) lateral model at ``load`` [N] and at the slip the inverse
        longitudinal model gives for ``force`` [N]: slip angle [rad] -> (Fy [N], dFy/dbeta [N/rad])."""
        coefficients = self.lateral.angle_coefficients_at(load, self.inverse.slip_for_force(load, force))
        return lambda beta: self.lateral.fy_and_slope_at(coefficients, beta)

    def _torques(self, loads: np.ndarray, forces: np.ndarray, advance: bool, step: float | None) -> np.ndarray:
        """The wheels' torques [N·m] for ``forces`` [N] at ``loads`` [N] (``LongitudinalInverse.torques``)."""
        return self.inverse.torques(loads, forces, advance, step)

    def _kinematic_steering(self, v: float, curvature: float, offset: float, cross_track: float,
                            loads: list[float], force_t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The ablation: wheels along the hub velocities of the commanded motion; Fy_des = 0."""
        g = self.gains
        rate = v * curvature - g["k_psi"] / g["k_r"] * offset - g["k_e"] / g["k_de"] * cross_track
        speed = 1e-3 if 1e-3 > v else v
        steer = [_clip(math.atan2(rate * x, speed - rate * y), -MAX_STEER, MAX_STEER)
                 for x, y in zip(self.x_hub.tolist(), self.y_hub.tolist())]
        total = 0.0
        for load in loads:
            total += load
        return np.array(steer), np.array([force_t * load / total for load in loads]), np.zeros(self.wheels)

    # --- the block interface ----------------------------------------------------------------------
    def _outputs(self, t: float, u: np.ndarray, advance: bool, step: float | None = None) -> np.ndarray:
        values = np.asarray(u, float).tolist()
        n = self.wheels
        loads = [1.0 if 1.0 > w else w for w in values[6:6 + n]]  # np.clip(W, 1, None), NaN kept
        slip_angles = values[6 + n:6 + 2 * n]
        demand, along, signals, (curvature, offset) = self._tracking(t, values)
        if self.steering == "kinematic":
            steer, fx_des, fy_des = self._kinematic_steering(along, curvature, offset, signals[2], loads, demand[0])
        else:
            fx, fy = share(demand, self._rows, loads)
            gamma = [a + d for a, d in zip(slip_angles, self.steer.tolist())]
            steer, fx_des, fy_des = self._inverse_steering(loads, gamma, fx, fy)
        self.steer = steer
        torque = self._torques(np.array(loads), fx_des, advance, step)
        return np.concatenate([torque, steer, fx_des, fy_des, signals])

    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        """The outputs at the start; ``h`` [s]: the run's communication step (the law's filter is
        discretised at it; None: at the ``step`` it was made with)."""
        if h is not None:
            self.use_step(h)
        return self._outputs(t0, u0, advance=False)

    def use_step(self, h: float) -> None:
        """Step at the communication step ``h`` [s]: the law's filter discretised at it."""
        self.step_size = self.inverse.set_step(h)

    def get_state(self) -> tuple[np.ndarray, np.ndarray, int | None]:
        """The filter's state, the last steering and the path index (for masters that repeat a step)."""
        return self.inverse.filter_state.copy(), self.steer.copy(), self.hint

    def set_state(self, state: tuple[np.ndarray, np.ndarray, int | None]) -> None:
        self.inverse.filter_state, self.steer, self.hint = state[0].copy(), state[1].copy(), state[2]

    def native(self) -> native_code.NativeBlock | None:
        """The block's C twin (path_controller.c) from its state now, for the native stepper; None
        where it cannot be compiled or does not cover the models (the block then steps in Python).
        The twin keeps its own state: a run stepped by it leaves this block's state as it was."""
        library = native_code.load_library(C_SOURCE)
        if isinstance(library, str) or self.inverse.model.degree not in (1, 2):
            return None
        terms, slips, loads_ = self.lateral.form.shape()
        if terms > 16:
            return None
        pointer = ctypes.c_void_p


        library.path_new.restype = pointer
        library.path_new.argtypes = ([pointer] + [ctypes.c_int] * 3 + [pointer] * 6 + [ctypes.c_int, pointer]
                                     + [ctypes.c_int] * 2 + [pointer] * 5 + [ctypes.c_int])
        g = self.gains
        settings = [self.mass, self.yaw_inertia, self.v_target, g["kv"], g["kp"], g["a_max"], g["k_e"], g["k_de"],
                    g["a_n_max"], g["k_psi"], g["k_r"], g["alpha_max"], self.step_size, self.inverse.wn,
                    1.0 if self.steering == "kinematic" else 0.0, MAX_STEER, MAX_SLIP_ANGLE, self.path.spacing,
                    self.path.length, WINDOW, *self._pull_settings()]
        table_loads, torques, settled, log_t, coefficients = self.inverse.tables()
        path = self.path
        bases = {"rational": 0, "exponential": 1, "polynomial": 2}
        component = library.path_new(
            doubles(settings), len(table_loads), len(torques), self.inverse.model.degree, doubles(table_loads),
            doubles(torques), doubles(settled), doubles(log_t), doubles(coefficients),
            doubles(self.inverse.filter_state), len(path.s),
            doubles([path.s, path.x, path.y, path.heading, path.curvature]), -1 if self.hint is None else self.hint,
            bases[self.lateral.form.basis], (ctypes.c_int * 3)(terms, slips, loads_),
            doubles(self.lateral.form.scales_rad), doubles(self.lateral.coefficients),
            doubles([self.x_hub, self.y_hub]), doubles(self.steer), self.wheels)
        if not component:
            raise MemoryError(f"block {self.name!r}: its C twin could not be made (tables of {len(table_loads)} loads "
                              f"x {len(torques)} torques: expected >= 2 each; or out of memory)")
        return native_code.NativeBlock(library, component, "path")

    def _pull_settings(self) -> list[float]:
        """The twin's ground pull: (on, slope [rad], downhill [rad], gravity [m/s²]); none here."""
        return [0.0, 0.0, 0.0, 0.0]

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        if not 0 < h <= self.step_size * (1 + 1e-9):
            raise ValueError(f"block {self.name!r}: communication step {h!r} s: expected at most its step = "
                             f"{self.step_size!r} s (a shorter last step is fine)")
        return self._outputs(t + h, u, advance=True, step=h)
