"""The ground participants of the steerable rover (issue 35): Python blocks that give each hub
the ground under it (``GroundBlock``: ``Interfaces.GroundContacts`` of SteerableRover and
SteerableRoverBody, from the body's pose and velocity) and each wheel the soil under it
(``SoilBlock``: the ``soilShare`` inputs of SteerableRover or of each Wheel, from the pose).

Why a participant and not a table inside the FMU: our exporter (rumoca -> CasADi -> C) has no
table functions reading files, and a participant serves the monolithic FMU and the co-simulated
body alike, with any map; the body's pose and velocity are states, so the block (direct
feedthrough from them) closes no algebraic loop. The hub positions are the limbs' (pitch and
roll of a few degrees neglected): hub i at (x, y) + R(yaw) (x_i, y_i), its velocity
R(yaw) (v - r y_i, v_y + r x_i); then h_i, dh_i/dt = grad h . velocity, and the gradient turned
into the heading frame.
"""

from __future__ import annotations

import ctypes
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.orchestrator import native as native_code
from rover_cosim.orchestrator.native import doubles
from rover_cosim.terramechanics.terrain import HeightMap, SoilMap, hub_positions

#: The participants' C twins (the laws of terramechanics/height_map.h, soil_map.h), for the native stepper.
GROUND_C_SOURCE = Path(__file__).with_name("ground_block.c")
SOIL_C_SOURCE = Path(__file__).with_name("soil_block.c")
BODY = ("x", "y", "yaw", "v", "vy", "yawRate")
#: The hubs the C twins (ground_block.c, soil_block.c) are made for.
TWIN_HUBS = 6
SIGNALS = ("groundHeight", "groundHeightRate", "groundGradientAlong", "groundGradientLateral")


class _HubBlock:
    """What both blocks share: a map (of the class ``map_type``, given as ``map_argument``), the
    hubs in the body frame (the left side's limbs from front to rear at ``y_limb`` [m], 1-3 of six;
    the right side mirrors them; ``x_limb`` [m] ahead of the centre of gravity), and outputs that
    are a function of the inputs now (``values``). The C twins are made for six hubs: a rover with
    another number of wheels steps these blocks in Python."""

    map_type: type = object
    map_argument = "map"
    outputs: tuple[str, ...] = ()

    def __init__(self, name: str, the_map: object, x_limb: tuple[float, ...], y_limb: float):
        if not isinstance(the_map, self.map_type):
            raise TypeError(f"block {name!r}: {self.map_argument} = {the_map!r}: expected a {self.map_type.__name__}")
        if not y_limb > 0:
            raise ValueError(f"block {name!r}: y_limb = {y_limb!r} m: expected > 0")
        self.name, self.map = name, the_map
        self.x_hub = np.array([*x_limb, *x_limb], float)
        self.y_hub = np.array([y_limb] * len(x_limb) + [-y_limb] * len(x_limb), float)

    def values(self, u: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _twin(self, source: Path, prefix: str, map_types: list[Any],
              *map_arguments: Any) -> native_code.NativeBlock | None:
        """The C twin ``<prefix>_new(map_arguments..., hubs, outputs now)`` of ``source``; None where
        it cannot be compiled."""
        if len(self.x_hub) != TWIN_HUBS:
            return None
        now = getattr(self, "last", None)
        return _twin(self.name, source, prefix, f"{prefix}_new", map_types, map_arguments,
                     np.concatenate([self.x_hub, self.y_hub]), now if now is not None else np.zeros(len(self.outputs)))

    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        self.last = self.values(u0)
        return self.last

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        self.last = self.values(u)
        return self.last


class GroundBlock(_HubBlock):
    """Orchestrator block. Inputs: x, y, yaw, v, vy, yawRate of the body. Outputs per hub i:
    groundHeight[i] [m], groundHeightRate[i] [m/s], groundGradientAlong[i], groundGradientLateral[i] [1]."""

    map_type, map_argument = HeightMap, "height_map"

    def __init__(self, name: str, height_map: HeightMap, x_limb: tuple[float, ...] = (1.5, 0.0, -1.5),
                 y_limb: float = 1.5):
        super().__init__(name, height_map, x_limb, y_limb)
        self.map: HeightMap
        self.inputs: tuple[str, ...] = BODY
        self.outputs: tuple[str, ...] = tuple(f"{s}[{i}]" for s in SIGNALS for i in range(1, len(self.x_hub) + 1))
        units = {"groundHeight": "m", "groundHeightRate": "m/s", "groundGradientAlong": "1",
                 "groundGradientLateral": "1"}
        self.units = {"x": "m", "y": "m", "yaw": "rad", "v": "m/s", "vy": "m/s", "yawRate": "rad/s",
                      **{f"{s}[{i}]": units[s] for s in SIGNALS for i in range(1, len(self.x_hub) + 1)}}

    def ground(self, u: np.ndarray) -> np.ndarray:
        """The outputs for the body state ``u`` (the inputs)."""
        x, y, yaw, v, vy, r = (float(value) for value in u[:6])
        cos, sin = math.cos(yaw), math.sin(yaw)
        hx, hy = hub_positions(x, y, yaw, self.x_hub, self.y_hub)
        ux, uy = v - r * self.y_hub, vy + r * self.x_hub          # hub velocities, heading frame
        gx, gy = self.map.gradient(hx, hy)
        along, lateral = gx * cos + gy * sin, -gx * sin + gy * cos
        return np.concatenate([self.map.height(hx, hy), along * ux + lateral * uy, along, lateral])

    values = ground

    def native(self) -> native_code.NativeBlock | None:
        """The block's C twin (ground_block.c: the same outputs, bit for bit) with its outputs now,
        for the native stepper; None where it cannot be compiled (the block then steps in Python)."""
        spline = self.map
        extent = [spline.x[0], spline.x[-1], spline.y[0], spline.y[-1]]
        return self._twin(GROUND_C_SOURCE, "ground", [ctypes.c_int, ctypes.c_void_p] * 2 + [ctypes.c_void_p] * 2,
                          spline.knots_x.size, doubles(spline.knots_x), spline.knots_y.size,
                          doubles(spline.knots_y), doubles(spline.coefficients), doubles(extent))


class SoilBlock(_HubBlock):
    """Orchestrator block: the soil under each wheel from a soil map. Inputs: x, y, yaw of the
    body. Outputs: soilShare[i] [1], the share of the map's second soil under hub i (the input
    ``soilShare`` of SteerableRover, per wheel, or of Wheel i)."""

    map_type, map_argument = SoilMap, "soil_map"

    def __init__(self, name: str, soil_map: SoilMap, x_limb: tuple[float, ...] = (1.5, 0.0, -1.5),
                 y_limb: float = 1.5):
        super().__init__(name, soil_map, x_limb, y_limb)
        self.map: SoilMap
        self.inputs: tuple[str, ...] = BODY[:3]
        self.outputs: tuple[str, ...] = tuple(f"soilShare[{i}]" for i in range(1, len(self.x_hub) + 1))
        self.units = {"x": "m", "y": "m", "yaw": "rad", **{name: "1" for name in self.outputs}}

    def shares(self, u: np.ndarray) -> np.ndarray:
        """The outputs for the body pose ``u`` (the inputs)."""
        return self.map.hub_shares(float(u[0]), float(u[1]), float(u[2]), self.x_hub, self.y_hub)

    values = shares

    def native(self) -> native_code.NativeBlock | None:
        """The block's C twin (soil_block.c: the same shares, bit for bit) with its outputs now, for
        the native stepper; None where it cannot be compiled (the block then steps in Python)."""
        grid = self.map.grid
        return self._twin(SOIL_C_SOURCE, "soil", [ctypes.c_int] * 2 + [ctypes.c_void_p] * 3, grid.x.size,
                          grid.y.size, doubles(grid.x), doubles(grid.y), doubles(grid.heights))


class LimbSoilBlock:
    """Orchestrator block: the soil under each wheel of a rover whose hubs move on its body (the
    leg-wheel rover): ``SoilBlock``'s shares, the hubs where the rover says they are. Inputs: x, y,
    yaw of the body, hubX[i], hubY[i] [m] (body frame; pitch and roll neglected as ``SoilBlock``
    does). Outputs: soilShare[i] [1]. A C twin (soil_block.c) for six hubs."""

    def __init__(self, name: str, soil_map: SoilMap, hubs: int = 6):
        if not isinstance(soil_map, SoilMap):
            raise TypeError(f"block {name!r}: soil_map = {soil_map!r}: expected a SoilMap")
        if isinstance(hubs, bool) or not isinstance(hubs, int) or hubs < 1:
            raise ValueError(f"block {name!r}: hubs = {hubs!r}: expected a number of wheels >= 1")
        self.name, self.map, self.hubs = name, soil_map, hubs
        numbers = range(1, hubs + 1)
        self.inputs: tuple[str, ...] = (*BODY[:3], *[f"hubX[{i}]" for i in numbers], *[f"hubY[{i}]" for i in numbers])
        self.outputs: tuple[str, ...] = tuple(f"soilShare[{i}]" for i in numbers)
        self.units = {"x": "m", "y": "m", "yaw": "rad", **{name: "m" for name in self.inputs[3:]},
                      **{name: "1" for name in self.outputs}}

    def shares(self, u: np.ndarray) -> np.ndarray:
        """The outputs for the inputs ``u``."""
        n = self.hubs
        return self.map.hub_shares(float(u[0]), float(u[1]), float(u[2]), np.asarray(u[3:3 + n], float),
                                   np.asarray(u[3 + n:3 + 2 * n], float))

    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        self.start_hubs = np.array(u0[3:3 + 2 * self.hubs], float)  # the twin starts from them
        self.last = self.shares(u0)
        return self.last

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        return self.shares(u)

    def native(self) -> native_code.NativeBlock | None:
        """The block's C twin (soil_block.c: the same shares, bit for bit) with its hubs and outputs
        at the start, for the native stepper; None for other than six hubs or where it cannot be
        compiled (the block then steps in Python)."""
        if self.hubs != TWIN_HUBS:
            return None
        grid = self.map.grid
        return _twin(self.name, SOIL_C_SOURCE, "soil", "soil_new_limbs", [ctypes.c_int] * 2 + [ctypes.c_void_p] * 3,
                     (grid.x.size, grid.y.size, doubles(grid.x), doubles(grid.y), doubles(grid.heights)),
                     getattr(self, "start_hubs", np.zeros(2 * self.hubs)), getattr(self, "last", np.zeros(self.hubs)))


def _twin(name: str, source: Path, prefix: str, constructor: str, map_types: list[Any], map_arguments: Sequence[Any],
          hubs: np.ndarray, now: np.ndarray) -> native_code.NativeBlock | None:
    """The C twin made by ``constructor(map_arguments..., hubs, outputs now)`` of ``source``
    (functions ``<prefix>_...``) for block ``name``; None where it cannot be compiled."""
    library = native_code.load_library(source)
    if isinstance(library, str):
        return None
    new = getattr(library, constructor)
    new.restype = ctypes.c_void_p
    new.argtypes = [*map_types, ctypes.c_void_p, ctypes.c_void_p]
    component = new(*map_arguments, doubles(hubs), doubles(now))
    if not component:
        raise MemoryError(f"block {name!r}: its C twin could not be made (bad sizes or out of memory)")
    return native_code.NativeBlock(library, component, prefix)
