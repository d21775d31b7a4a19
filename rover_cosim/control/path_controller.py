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

import math

import numpy as np

from rover_cosim.identification.model_set import ModelSet

from .allocation import allocate, allocation_matrix
from .longitudinal import LongitudinalInverse, read_model
from .path import Path, lane_change_path, turn_path

WHEELS = 6
PATHS = {"turn": turn_path, "lane_change": lane_change_path}
MAX_STEER = math.radians(45.0)    # rad: steering range
MAX_SLIP_ANGLE = math.radians(30.0)  # rad: the lateral model's identified range
NEWTON_STEPS = 2


def _names(stem: str) -> list[str]:
    return [f"{stem}[{i}]" for i in range(1, WHEELS + 1)]


class PathFollowingController:
    """Orchestrator block. Inputs: x, y, yaw, v, vy, yawRate (body), W[1..6], slipAngle[1..6]
    (wheels). Outputs: tau[1..6], steer[1..6], Fx_des[1..6], Fy_des[1..6], s, s_ref,
    cross_track, heading_error."""

    def __init__(self, name: str, model: ModelSet | str, path: str | Path = "turn", v_target: float = 0.5,
                 steering: str = "inverse", mass: float = 1570.0, yaw_inertia: float = 1980.0,
                 x_limb: tuple[float, float, float] = (1.5, 0.0, -1.5), y_limb: float = 1.5,
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
        self.inverse = LongitudinalInverse(longitudinal, WHEELS, wn, step, name)
        self.v_target, self.mass, self.yaw_inertia = v_target, mass, yaw_inertia
        self.gains = dict(kv=kv, kp=kp, a_max=a_max, k_e=k_e, k_de=k_de, a_n_max=a_n_max, k_psi=k_psi, k_r=k_r,
                          alpha_max=alpha_max)
        self.x_hub = np.array([*x_limb, *x_limb], float)
        self.y_hub = np.array([y_limb] * 3 + [-y_limb] * 3, float)
        self.matrix = allocation_matrix(self.x_hub, self.y_hub)
        self.steer = np.zeros(WHEELS)
        self.hint: int | None = None
        self.inputs = ("x", "y", "yaw", "v", "vy", "yawRate", *_names("W"), *_names("slipAngle"))
        self.outputs = (*_names("tau"), *_names("steer"), *_names("Fx_des"), *_names("Fy_des"),
                        "s", "s_ref", "cross_track", "heading_error")
        self.units = {"x": "m", "y": "m", "yaw": "rad", "v": "m/s", "vy": "m/s", "yawRate": "rad/s", "s": "m",
                      "s_ref": "m", "cross_track": "m", "heading_error": "rad",
                      **{n: "N" for n in (*_names("W"), *_names("Fx_des"), *_names("Fy_des"))},
                      **{n: "rad" for n in (*_names("slipAngle"), *_names("steer"))},
                      **{n: "N.m" for n in _names("tau")}}

    # --- 1. tracking ----------------------------------------------------------------------------
    def _tracking(self, t: float, u: np.ndarray) -> tuple[np.ndarray, float, dict[str, float], tuple[float, float]]:
        """(force demand (F_x, F_y, M_z) in the heading frame, path speed, signals, (kappa, error
        of heading))."""
        x, y, yaw, v, vy, r = (float(value) for value in u[:6])
        where = self.path.locate(x, y, self.hint)
        self.hint = where.index
        offset = yaw - where.heading
        along, across = v * math.cos(offset) - vy * math.sin(offset), v * math.sin(offset) + vy * math.cos(offset)
        g = self.gains
        s_ref = self.v_target * t
        a_t = float(np.clip(g["kv"] * (self.v_target - along) + g["kp"] * (s_ref - where.s), -g["a_max"], g["a_max"]))
        a_n = float(np.clip(along**2 * where.curvature - g["k_e"] * where.cross_track - g["k_de"] * across,
                            -g["a_n_max"], g["a_n_max"]))
        alpha = float(np.clip(g["k_psi"] * -offset + g["k_r"] * (along * where.curvature - r),
                              -g["alpha_max"], g["alpha_max"]))
        demand = np.array([self.mass * (a_t * math.cos(offset) + a_n * math.sin(offset)),
                           self.mass * (-a_t * math.sin(offset) + a_n * math.cos(offset)),
                           self.yaw_inertia * alpha])
        signals = {"s": where.s, "s_ref": s_ref, "cross_track": where.cross_track, "heading_error": offset}
        return demand, along, signals, (where.curvature, offset)

    # --- 3. per wheel -----------------------------------------------------------------------------
    def _inverse_steering(self, loads: np.ndarray, gamma: np.ndarray, fx: np.ndarray,
                          fy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(steer, Fx_des, Fy_des): Newton on delta for Fy_model(W, gamma - delta, slip) = Fy_des(delta),
        from the last step's delta (two steps reach the solve's tolerance: delta changes by
        micro-radians per step); the slip is the one for Fx_des at the last step's delta."""
        delta = self.steer.copy()
        slips = self.inverse.slips_for_forces(loads, fx * np.cos(delta) + fy * np.sin(delta))
        coefficients = self.lateral.angle_coefficients(loads, slips)
        low = np.maximum(gamma - MAX_SLIP_ANGLE, -MAX_STEER)
        high = np.minimum(gamma + MAX_SLIP_ANGLE, MAX_STEER)
        for _ in range(NEWTON_STEPS):
            cos, sin = np.cos(delta), np.sin(delta)
            model_fy, slope = self.lateral.fy_and_slope(coefficients, gamma - delta)
            residual = model_fy - (fy * cos - fx * sin)
            derivative = -slope + fx * cos + fy * sin  # d/d delta of the residual
            delta = np.clip(delta - residual / np.where(np.abs(derivative) > 1e-9, derivative, 1e-9), low, high)
        return delta, fx * np.cos(delta) + fy * np.sin(delta), fy * np.cos(delta) - fx * np.sin(delta)

    def _kinematic_steering(self, v: float, curvature: float, offset: float, cross_track: float,
                            loads: np.ndarray, force_t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The ablation: wheels along the hub velocities of the commanded motion; Fy_des = 0."""
        g = self.gains
        rate = v * curvature - g["k_psi"] / g["k_r"] * offset - g["k_e"] / g["k_de"] * cross_track
        speed = max(v, 1e-3)
        delta = np.clip(np.arctan2(rate * self.x_hub, speed - rate * self.y_hub), -MAX_STEER, MAX_STEER)
        share = force_t * loads / loads.sum()
        return delta, share, np.zeros(WHEELS)

    # --- the block interface ----------------------------------------------------------------------
    def _outputs(self, t: float, u: np.ndarray, advance: bool, step: float | None = None) -> np.ndarray:
        loads = np.clip(np.asarray(u[6:6 + WHEELS], float), 1.0, None)
        slip_angles = np.asarray(u[6 + WHEELS:6 + 2 * WHEELS], float)
        demand, along, signals, (curvature, offset) = self._tracking(t, u)
        if self.steering == "kinematic":
            steer, fx_des, fy_des = self._kinematic_steering(along, curvature, offset, signals["cross_track"], loads,
                                                             demand[0])
        else:
            fx, fy = allocate(demand, self.matrix, loads)
            steer, fx_des, fy_des = self._inverse_steering(loads, slip_angles + self.steer, fx, fy)
        self.steer = steer
        torque = self.inverse.torques(loads, fx_des, advance, step)
        return np.concatenate([torque, steer, fx_des, fy_des,
                               [signals["s"], signals["s_ref"], signals["cross_track"], signals["heading_error"]]])

    def start(self, t0: float, u0: np.ndarray) -> np.ndarray:
        return self._outputs(t0, u0, advance=False)

    def get_state(self) -> tuple[np.ndarray, np.ndarray, int | None]:
        """The filter's state, the last steering and the path index (for masters that repeat a step)."""
        return self.inverse.filter_state.copy(), self.steer.copy(), self.hint

    def set_state(self, state: tuple[np.ndarray, np.ndarray, int | None]) -> None:
        self.inverse.filter_state, self.steer, self.hint = state[0].copy(), state[1].copy(), state[2]

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        if not 0 < h <= self.step_size * (1 + 1e-9):
            raise ValueError(f"block {self.name!r}: communication step {h!r} s: expected at most its step = "
                             f"{self.step_size!r} s (a shorter last step is fine)")
        return self._outputs(t + h, u, advance=True, step=h)
