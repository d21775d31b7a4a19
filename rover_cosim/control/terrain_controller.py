"""The path-following controller on sloped ground and over a height map (issue 35).

``PathFollowingController`` tracks the path with a force and yaw-moment demand at the body that
the wheels must produce (``path_controller``, step 1). On sloped ground they must also hold the
body against gravity's pull in the ground plane, and over a height map against the loads' pull on
the local slopes. ``TerrainPathController`` adds both to the demand as a feed-forward, then
allocates and inverts the identified models exactly as the path controller does:

- the plane (``terrain``, a ``rover_cosim.terramechanics.PlaneTerrain``): with gravity's
  components in the heading frame g_along, g_lateral (``terrain.gravity(heading, g)``), the demand
  is M (a_t, a_n) - M (g_along, g_lateral);
- a height map (``ground_map``, a ``terramechanics.terrain.HeightMap``): the load W_i, normal to
  the local ground of gradient s_i under hub i (the map's at the hub's position), pushes the body
  by -W_i s_i along and across the heading; the demand subtracts sum -W_i s_i and its yaw moment
  sum (x_i f_y,i - y_i f_x,i), with the measured loads (as the controller clips them, >= 1 N).

Soil that varies (``soil_map``, a ``terramechanics.terrain.SoilMap``, and ``model_b``, the models
identified on its second soil): the soil the controller believes in under each wheel is the map's
at the hub, a share s_i of the second soil. Each wheel's models are then the two soils' blended by
s_i: the lateral force and its slope at a slip angle (1 - s_i) of the first model's + s_i of the
second's (each at the slip its own inverse longitudinal model gives for the demand), and the
torque (1 - s_i) tau_a + s_i tau_b, both inverse longitudinal laws (each with its filter) run on
the same demands. Where the map believes the first soil (s_i = 0) a wheel's outputs are those of
the controller without the map, bit for bit.

Without a slope, a height map and a soil map the demand, and every output, is the path
controller's (bit for bit). The path controller's C twin takes the plane's pull, the height map's
pull and the belief in a soil map too (the same arithmetic).
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np

from rover_cosim.orchestrator.native import doubles

from .longitudinal import LongitudinalInverse, read_model
from .path_controller import PathFollowingController


class Ground(Protocol):
    """What the controller needs of the ground plane (``rover_cosim.terramechanics.PlaneTerrain``)."""

    @property
    def slope(self) -> float:
        """Inclination [rad]."""
        ...

    @property
    def downhill(self) -> float:
        """Direction of steepest descent [rad]."""
        ...

    @property
    def level(self) -> bool: ...

    def gravity(self, heading: float, g: float) -> tuple[Any, Any, float]:
        """Gravity [m/s²] along the heading, to its left, into the ground (heading [rad])."""
        ...


class GroundMap(Protocol):
    """A height map over the ground plane (``rover_cosim.terramechanics.terrain.HeightMap``)."""

    def gradient(self, x: Any, y: Any) -> tuple[Any, Any]:
        """(dh/dx, dh/dy) [1] at the points (x, y) [m]."""
        ...


class SoilBelief(Protocol):
    """Where the controller believes the second soil lies (``rover_cosim.terramechanics.terrain.SoilMap``)."""

    def hub_shares(self, x: float, y: float, yaw: float, x_hub: Any, y_hub: Any) -> Any:
        """The share [1] of the second soil under each hub (body frame ``x_hub``, ``y_hub`` [m]) of the
        body at (x, y) [m] heading ``yaw`` [rad]."""
        ...


class TerrainPathController(PathFollowingController):
    """``PathFollowingController`` (same inputs, outputs and options) with the ground's pull fed
    forward: ``terrain`` (None: level), ``g`` [m/s²] the gravity it believes in, ``ground_map``
    (None: no map); and with the soil it believes in under each wheel: ``soil_map`` (None: the
    soil ``model`` was identified on, everywhere) with ``model_b``, the models identified on the
    map's second soil."""

    def __init__(self, name: str, model: Any, *, terrain: Ground | None = None, g: float = 1.62,
                 ground_map: GroundMap | None = None, soil_map: SoilBelief | None = None, model_b: Any = None,
                 **options: Any):
        super().__init__(name, model, **options)
        if (soil_map is None) != (model_b is None):
            raise ValueError(f"block {name!r}: soil_map = {soil_map!r}, model_b = {model_b!r}: expected both (a "
                             "SoilMap and the models identified on its second soil) or neither")
        if soil_map is not None and not hasattr(soil_map, "hub_shares"):
            raise TypeError(f"block {name!r}: soil_map = {soil_map!r}: expected a SoilMap or None")
        self.soil_map = soil_map
        self.shares = [0.0] * self.wheels
        if model_b is not None:
            models_b, longitudinal_b, _ = read_model(model_b, name)
            if models_b.lateral is None:
                raise ValueError(f"block {name!r}: model_b {models_b.source} has no lateral model")
            self.lateral_b = models_b.lateral
            self.inverse_b = LongitudinalInverse(longitudinal_b, self.wheels, self.inverse.wn, self.step_size, name)
        if not (isinstance(g, (int, float)) and math.isfinite(g) and g > 0):
            raise ValueError(f"block {name!r}: g = {g!r} m/s²: expected a gravity > 0")
        if terrain is not None and not (hasattr(terrain, "gravity") and hasattr(terrain, "level")):
            raise TypeError(f"block {name!r}: terrain = {terrain!r}: expected a PlaneTerrain or None (level)")
        if ground_map is not None and not hasattr(ground_map, "gradient"):
            raise TypeError(f"block {name!r}: ground_map = {ground_map!r}: expected a HeightMap or None")
        self.terrain, self.g, self.ground_map = terrain, float(g), ground_map

    def use_step(self, h: float) -> None:
        """Step at ``h`` [s]: both soils' filters discretised at it."""
        super().use_step(h)
        if self.soil_map is not None:
            self.inverse_b.set_step(h)

    @property
    def plain(self) -> bool:
        """Level ground without a map: nothing to feed forward."""
        return (self.terrain is None or self.terrain.level) and self.ground_map is None

    def ground_pull(self, u: Any) -> tuple[float, float, float]:
        """(F_x, F_y, M_z) [N, N, N·m]: gravity's and the map's pull on the body in the heading frame,
        for the inputs ``u`` (x, y, yaw, v, vy, yawRate, W[1..6], ...)."""
        x, y, yaw = float(u[0]), float(u[1]), float(u[2])
        fx = fy = mz = 0.0
        if self.terrain is not None and not self.terrain.level:
            g_along, g_lateral, _ = self.terrain.gravity(yaw, self.g)
            fx, fy = self.mass * float(g_along), self.mass * float(g_lateral)
        if self.ground_map is not None:  # in plain floats, in the order of the C twin
            cos, sin = math.cos(yaw), math.sin(yaw)
            gx, gy = self.ground_map.gradient(x + cos * self.x_hub - sin * self.y_hub,
                                              y + sin * self.x_hub + cos * self.y_hub)
            sum_x = sum_y = 0.0
            for w, slope_x, slope_y, x_hub, y_hub in zip(u[6:6 + self.wheels], np.asarray(gx).tolist(),
                                                         np.asarray(gy).tolist(), self.x_hub.tolist(),
                                                         self.y_hub.tolist()):
                load = max(1.0, float(w))
                hub_x = -load * (slope_x * cos + slope_y * sin)
                hub_y = -load * (-slope_x * sin + slope_y * cos)
                sum_x += hub_x
                sum_y += hub_y
                mz += x_hub * hub_y - y_hub * hub_x
            fx, fy = fx + sum_x, fy + sum_y
        return fx, fy, mz

    def _tracking(self, t: float, u: Any) -> Any:
        if self.soil_map is not None:  # the soil believed in under each wheel, for this step's laws
            shares = self.soil_map.hub_shares(float(u[0]), float(u[1]), float(u[2]), self.x_hub, self.y_hub)
            self.shares = [float(s) for s in shares]
        demand, along, signals, path = super()._tracking(t, u)
        if self.plain:
            return demand, along, signals, path
        fx, fy, mz = self.ground_pull(u)
        held = [demand[0] - fx, demand[1] - fy, demand[2] - mz]
        return (held if isinstance(demand, list) else np.array(held)), along, signals, path

    def _lateral_law(self, wheel: int, load: float, force: float) -> Callable[[float], tuple[float, float]]:
        law = super()._lateral_law(wheel, load, force)
        share = self.shares[wheel]
        if share == 0.0:
            return law
        coefficients = self.lateral_b.angle_coefficients_at(load, self.inverse_b.slip_for_force(load, force))

        def blended(beta: float) -> tuple[float, float]:
            fy_a, slope_a = law(beta)
            fy_b, slope_b = self.lateral_b.fy_and_slope_at(coefficients, beta)
            return (1.0 - share) * fy_a + share * fy_b, (1.0 - share) * slope_a + share * slope_b
        return blended

    def _torques(self, loads: np.ndarray, forces: np.ndarray, advance: bool, step: float | None) -> np.ndarray:
        torque = super()._torques(loads, forces, advance, step)
        if self.soil_map is None:
            return torque
        torque_b = self.inverse_b.torques(loads, forces, advance, step)
        shares = np.array(self.shares)
        return np.where(shares == 0.0, torque, (1.0 - shares) * torque + shares * torque_b)

    def get_state(self) -> Any:
        state = super().get_state()
        return state if self.soil_map is None else (*state, self.inverse_b.filter_state.copy(), list(self.shares))

    def set_state(self, state: Any) -> None:
        super().set_state(state[:3])
        if self.soil_map is not None:
            self.inverse_b.filter_state, self.shares = state[3].copy(), list(state[4])

    def native(self) -> Any:
        """The path controller's C twin, with the plane's pull where the ground is sloped, the pull
        of a height map (a ``HeightMap``'s spline) and the belief in a soil map (a ``SoilMap``'s
        grid); None for maps of other kinds (the block then steps in Python)."""
        if (self.ground_map is not None and not hasattr(self.ground_map, "knots_x")) or (
                self.soil_map is not None and not hasattr(self.soil_map, "grid")):
            return None
        twin = super().native()
        if twin is not None and self.ground_map is not None:
            self._give_map(twin)
        if twin is None or self.soil_map is None:
            return twin
        if self.inverse_b.model.degree not in (1, 2) or self.lateral_b.form.shape()[0] > 16:
            twin.close()
            return None
        library, pointer = twin.library, ctypes.c_void_p


        library.path_believe.restype = ctypes.c_int
        library.path_believe.argtypes = ([pointer] + [ctypes.c_int] * 3 + [pointer] * 6 + [ctypes.c_int, pointer]
                                         + [pointer] * 2 + [ctypes.c_int] * 2 + [pointer] * 3)
        table_loads, torques, settled, log_t, coefficients = self.inverse_b.tables()
        terms, slips, loads_ = self.lateral_b.form.shape()
        grid = self.soil_map.grid  # a SoilMap (checked above)
        bases = {"rational": 0, "exponential": 1, "polynomial": 2}
        status = library.path_believe(
            twin.component, len(table_loads), len(torques), self.inverse_b.model.degree, doubles(table_loads),
            doubles(torques), doubles(settled), doubles(log_t), doubles(coefficients),
            doubles(self.inverse_b.filter_state), bases[self.lateral_b.form.basis],
            (ctypes.c_int * 3)(terms, slips, loads_), doubles(self.lateral_b.form.scales_rad),
            doubles(self.lateral_b.coefficients), grid.x.size, grid.y.size, doubles(grid.x), doubles(grid.y),
            doubles(grid.heights))
        if status != 0:
            message = twin.message()
            twin.close()
            raise MemoryError(f"block {self.name!r}: its C twin could not take the soil map: {message}")
        return twin

    def _give_map(self, twin: Any) -> None:
        """The height map's spline to the twin (``path_ground_map``)."""
        spline: Any = self.ground_map  # a HeightMap (native() checked it)
        pointer = ctypes.c_void_p


        function = twin.library.path_ground_map
        function.restype = ctypes.c_int
        function.argtypes = [pointer, ctypes.c_int, pointer, ctypes.c_int, pointer, pointer, pointer]
        extent = [spline.x[0], spline.x[-1], spline.y[0], spline.y[-1]]
        status = function(twin.component, spline.knots_x.size, doubles(spline.knots_x), spline.knots_y.size,
                          doubles(spline.knots_y), doubles(spline.coefficients), doubles(extent))
        if status != 0:
            message = twin.message()
            twin.close()
            raise MemoryError(f"block {self.name!r}: its C twin could not take the height map: {message}")

    def _pull_settings(self) -> list[float]:
        if self.terrain is None or self.terrain.level:
            return [0.0, 0.0, 0.0, 0.0]
        return [1.0, float(self.terrain.slope), float(self.terrain.downhill), self.g]
