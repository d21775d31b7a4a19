"""The rut participant (multi-pass, issue 48): a block that remembers where each wheel went and how
deep it sank (``terramechanics.multipass.RutMap``) and gives each wheel the rut another wheel left
under it (the ``rutDepth`` inputs of Rover, SteerableRover, LegWheelRover or of each Wheel).

Inputs: the body's pose (``x`` for the pitch-plane rover; ``x``, ``y``, ``yaw`` for a rover free in
the plane) and ``sinkage[i]`` of each wheel. Outputs: ``rutDepth[i]`` [m]. The wheels' sinkage
depends on their rut, so the block has no direct feedthrough (``feedthrough = False``): a step
marks the ruts with the sinkages and poses it receives and gives the ruts under the hubs there,
one communication step late (1 mm at 1 m/s and 1 ms), which closes no algebraic loop.

C twin: ``rut_block.c`` (the same stamps and depths, bit for bit; its map in a hash table), so that a
run with ruts steps natively; it starts from the block's map at the hand-over and keeps its own from
then on (the block's map stays as it was then, as the controllers' twins leave their blocks).
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.orchestrator import native as native_code
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.terramechanics.library import Choice
from rover_cosim.terramechanics.multipass import RutMap
from rover_cosim.terramechanics.terrain import hub_positions

RUT_C_SOURCE = Path(__file__).with_name("rut_block.c")
#: The most wheels the C twin takes (a rover with more steps its rut block in Python).
TWIN_WHEELS = 64


class RutBlock:
    """Orchestrator block: the ruts under the wheels of a rover whose hubs sit at ``x_limb`` [m]
    (one side, front to rear; the other side mirrors it) and ±``y_limb`` [m] in the body frame, each
    wheel ``width`` [m] wide; ``planar``: inputs x, y, yaw (a rover free in the plane), else x alone
    (the pitch-plane rover, on the line y = 0 heading along x)."""

    feedthrough = False

    def __init__(self, name: str, x_limb: tuple[float, ...], y_limb: float, width: float, *,
                 planar: bool = False, cell: float = 0.02):
        if not (len(x_limb) >= 1 and y_limb > 0 and width > 0):
            raise ValueError(f"block {name!r}: x_limb = {x_limb!r}, y_limb = {y_limb!r} m, width = {width!r} m: "
                             "expected hubs, y_limb > 0 m and a wheel width > 0 m")
        self.name = name
        self.x_hub = np.array([*x_limb, *x_limb], float)
        self.y_hub = np.array([y_limb] * len(x_limb) + [-y_limb] * len(x_limb), float)
        self.wheels = self.x_hub.size
        self.half_width = 0.5 * float(width)
        self.planar = planar
        self.map = RutMap(self.wheels, cell)
        self.last: np.ndarray | None = None  # the outputs of the last start or step
        numbers = range(1, self.wheels + 1)
        pose = ("x", "y", "yaw") if planar else ("x",)
        self.inputs: tuple[str, ...] = (*pose, *[f"sinkage[{i}]" for i in numbers])
        self.outputs: tuple[str, ...] = tuple(f"rutDepth[{i}]" for i in numbers)
        self.units = {"x": "m", "y": "m", "yaw": "rad", **{n: "m" for n in self.inputs if n.startswith("sinkage")},
                      **{n: "m" for n in self.outputs}}

    def _hubs(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.planar:
            return hub_positions(float(u[0]), float(u[1]), float(u[2]), self.x_hub, self.y_hub)
        return float(u[0]) + self.x_hub, self.y_hub.copy()

    def _advance(self, u: np.ndarray) -> np.ndarray:
        pose = 3 if self.planar else 1
        x, y = self._hubs(u)
        self.map.stamp(x, y, np.asarray(u[pose:pose + self.wheels], float), self.half_width)
        return self.map.depths(x, y)

    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        """A run starts on virgin soil (a system run again does not meet the ruts of its last run)."""
        self.map = RutMap(self.wheels, self.map.cell)
        self.last = self._advance(u0)
        return self.last

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        self.last = self._advance(u)
        return self.last

    def native(self) -> native_code.NativeBlock | None:
        """The block's C twin (rut_block.c) from its map and outputs now, for the native stepper;
        None where it cannot be compiled or the rover has more than TWIN_WHEELS wheels (the block
        then steps in Python)."""
        if self.wheels > TWIN_WHEELS:
            return None
        library = native_code.load_library(RUT_C_SOURCE)
        if isinstance(library, str):
            return None
        pointer = ctypes.c_void_p
        library.rut_new.restype = pointer
        library.rut_new.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_double, ctypes.c_double, pointer,
                                    ctypes.c_int, pointer, pointer, pointer]
        cells = self.map.get_state()
        keys = (ctypes.c_longlong * max(1, 2 * len(cells)))(*[k for key in cells for k in key])
        depths = native_code.doubles([cells[key] for key in cells] if cells else [0.0])
        now = self.last if self.last is not None else np.zeros(self.wheels)
        component = library.rut_new(self.wheels, int(self.planar), self.map.cell, self.half_width,
                                    native_code.doubles([self.x_hub, self.y_hub]), len(cells), keys, depths,
                                    native_code.doubles(now))
        if not component:
            raise MemoryError(f"block {self.name!r}: its C twin could not be made ({len(cells)} cells: out of memory)")
        return native_code.NativeBlock(library, component, "rut")

    def get_state(self) -> Any:
        return self.map.get_state()

    def set_state(self, state: Any) -> None:
        self.map.set_state(state)


def add_ruts(builder: SystemBuilder, choice: Choice, body: str, wheel: Callable[[int, str], str], *,
             planar: bool = False) -> RutBlock:
    """A rut block ``ruts`` for the rover and wheel of ``choice`` in ``builder``, wired to the pose of the
    participant ``body`` (x; with ``planar`` x, y, yaw) and to each wheel's ``sinkage`` output and
    ``rutDepth`` input (``wheel(i, name)``: the variable of wheel i, 1-based)."""
    rover = choice.rover
    block = RutBlock("ruts", rover.x_limb, rover.y_limb, choice.wheel.b, planar=planar)
    builder.add_block("ruts", block)
    for name in ("x", "y", "yaw") if planar else ("x",):
        builder.connect(f"{body}.{name}", f"ruts.{name}")
    for i in range(1, block.wheels + 1):
        builder.connect(wheel(i, "sinkage"), f"ruts.sinkage[{i}]").connect(f"ruts.rutDepth[{i}]", wheel(i, "rutDepth"))
    return block
