"""The ground under the steerable rover: a plane of any inclination (issue 35).

The same law as the Modelica record ``Parameters.TerrainParameters`` (and the chassis that uses
it): a plane of inclination ``slope`` θ [rad] whose direction of steepest descent makes the angle
``downhill`` ψd [rad] with the ground's x axis (positive to the left). Positions (x, y) [m] and
headings ψ [rad] are measured in the plane. Then

    z_ground(x, y) = -sin θ (x cos ψd + y sin ψd)                [m, world height]
    g_along   = g sin θ cos(ψd - ψ)                              [m/s², along the heading]
    g_lateral = g sin θ sin(ψd - ψ)                              [m/s², to the left]
    g_normal  = g cos θ                                          [m/s², into the ground]

A plane of world gradients G_x = dz/dx, G_y = dz/dy is θ = atan(hypot(G_x, G_y)),
ψd = atan2(-G_y, -G_x) (``PlaneTerrain.from_gradients``). Source of the setting: Ishigami, Miwa,
Nagatani, Yoshida, J. Field Robotics 24(3), 2007 (steering on slopes of loose soil).

``HeightMap`` (a grid file, bicubic spline) and ``crater``: a height map over the plane, given to
the rover hub by hub (``Interfaces.GroundContacts``). ``SoilMap`` and ``soil_boundary``: where a
second soil lies (its share in [0, 1], a grid file like the height map's), given to the wheels one
by one (their ``soilShare``); ``hub_positions``: where the hubs are. ``static_hold`` and ``critical_slope``: a
rover at rest on the plane by the reference wheel's static regime (``regimes``): whether the soil
holds it, the holding torques, the creep.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .parameters import Soil, Wheel

FloatArray = NDArray[np.float64]


def _angle(name: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(float(value)):
        raise ValueError(f"{name} = {value!r}: expected a finite angle in rad")
    return float(value)


@dataclass(frozen=True)
class PlaneTerrain:
    """A ground plane: ``slope`` θ [rad], 0 <= θ < π/2, and ``downhill`` ψd [rad], the direction of
    steepest descent against the ground's x axis, positive to the left (-π/2: the valley to the
    right of a path along x). ``PlaneTerrain()`` is level ground."""

    slope: float = 0.0
    downhill: float = 0.0

    def __post_init__(self) -> None:
        slope, downhill = _angle("slope", self.slope), _angle("downhill", self.downhill)
        if not 0.0 <= slope < math.pi / 2:
            raise ValueError(f"slope = {self.slope!r} rad ({math.degrees(slope):.4g} deg): expected an inclination "
                             "0 <= slope < pi/2 rad (0 to 90 deg, 90 excluded)")
        object.__setattr__(self, "slope", slope)
        object.__setattr__(self, "downhill", downhill)

    @classmethod
    def side_slope(cls, degrees: float, valley: str = "right") -> PlaneTerrain:
        """A side slope of ``degrees`` [deg] for a path along +x, the valley to its ``valley``."""
        if valley not in ("right", "left"):
            raise ValueError(f"valley = {valley!r}: expected 'right' or 'left'")
        angle = _angle("degrees", degrees)
        if not 0.0 <= angle < 90.0:
            raise ValueError(f"side slope = {degrees!r} deg: expected 0 <= slope < 90 deg")
        return cls(math.radians(angle), -math.pi / 2 if valley == "right" else math.pi / 2)

    @classmethod
    def from_gradients(cls, gx: float, gy: float) -> PlaneTerrain:
        """The plane z = gx x + gy y of world gradients ``gx`` = dz/dx, ``gy`` = dz/dy [m/m]."""
        gx, gy = _angle("gx", gx), _angle("gy", gy)
        return cls(math.atan(math.hypot(gx, gy)), math.atan2(-gy, -gx) if (gx or gy) else 0.0)

    @property
    def level(self) -> bool:
        return self.slope == 0.0

    def height(self, x: ArrayLike, y: ArrayLike) -> FloatArray:
        """World height z_ground [m] of the ground point (x, y) [m] (0 at the origin)."""
        x, y = np.asarray(x, float), np.asarray(y, float)
        return -math.sin(self.slope) * (x * math.cos(self.downhill) + y * math.sin(self.downhill))

    def gravity(self, heading: ArrayLike, g: float) -> tuple[FloatArray, FloatArray, float]:
        """Gravity ``g`` [m/s²] in the heading frame of a body with heading ``heading`` [rad]:
        (along the heading, to its left, into the ground) [m/s²]."""
        heading = np.asarray(heading, float)
        tangential = g * math.sin(self.slope)
        return (tangential * np.cos(self.downhill - heading), tangential * np.sin(self.downhill - heading),
                g * math.cos(self.slope))

    def fmu_parameters(self) -> dict[str, float]:
        """The plane as the steerable rover FMUs' parameters (``terrain.slope``, ``terrain.downhill``)."""
        return {"terrain.slope": self.slope, "terrain.downhill": self.downhill}

    def label(self) -> str:
        if self.level:
            return "level ground"
        return f"{math.degrees(self.slope):.3g}° slope, downhill at {math.degrees(self.downhill):.3g}°"


@dataclass(frozen=True)
class StaticHold:
    """A rover at rest on a ``PlaneTerrain``, by the reference wheel (``regimes``' static regime).

    Attributes:
        pull: gravity's pull in the ground plane, M g sin θ [N].
        strength: what the soils under the wheels hold at most, sum of the patches' Mohr-Coulomb
            strength c b L + W tan φ [N] at the static loads (equal shares of M g cos θ).
        holding_torque: the drive torque of each wheel [N·m] that holds the component of the pull
            along the heading (r M g_along / n, against it); the lateral component is held by the
            wheels' lateral shear alone.
        creep_speed: the speed [m/s] at which the static regime's regularised shear
            F_max tanh(v / v_stick) carries the pull: a rover that holds creeps at it.
    """

    pull: float
    strength: float
    holding_torque: float
    creep_speed: float

    @property
    def holds(self) -> bool:
        return self.pull < self.strength


def static_hold(terrain: PlaneTerrain, heading: float, mass: float, g: float, wheel: Wheel | None = None,
                soil: Soil | None = None, wheels: int = 6, v_stick: float = 1e-4) -> StaticHold:
    """The rover of ``mass`` [kg] at rest with heading ``heading`` [rad] on ``terrain`` under gravity
    ``g`` [m/s²] on ``wheels`` wheels (see ``StaticHold``)."""
    from .regimes import shear_strength
    from .sinkage import wheel_state

    wheel, soil = wheel or Wheel(), soil or Soil()
    if not (mass > 0 and g > 0 and wheels >= 1 and v_stick > 0):
        raise ValueError(f"mass = {mass!r} kg, g = {g!r} m/s², wheels = {wheels!r}, v_stick = {v_stick!r} m/s: "
                         "expected mass > 0, g > 0, wheels >= 1, v_stick > 0")
    along, _, normal = terrain.gravity(heading, g)
    load = mass * normal / wheels
    sinkage = float(wheel_state(load, 0.0, wheel, soil).sinkage)
    strength = wheels * float(shear_strength(load, sinkage, wheel, soil))
    pull = mass * g * math.sin(terrain.slope)
    creep = v_stick * math.atanh(pull / strength) if pull < strength else math.inf
    return StaticHold(pull, strength, -wheel.r * mass * float(along) / wheels, creep)


def critical_slope(mass: float, g: float, wheel: Wheel | None = None, soil: Soil | None = None,
                   wheels: int = 6) -> float:
    """The steepest slope [rad] the soil holds the rover at rest on (``static_hold``'s pull equal to
    its strength), by bisection to 1e-6 rad."""
    low, high = 0.0, math.pi / 2 - 1e-6
    while high - low > 1e-6:
        middle = (low + high) / 2
        if static_hold(PlaneTerrain(middle), 0.0, mass, g, wheel, soil, wheels).holds:
            low = middle
        else:
            high = middle
    return low


class HeightMap:
    """A height map over the ground plane: heights ``heights[j, i]`` [m] above the plane at the grid
    points (``x[i]``, ``y[j]``) [m] (strictly increasing, at least 4 each), interpolated by a bicubic
    spline (continuous height, gradient and curvature: smooth for the integrator). Outside the grid
    the edge's height continues flat (gradient 0): give a grid whose edges are level.

    The file (``read``, ``write``): CSV, the first row ``y\\x`` and the x values, then one row per y:
    the y value and the heights along x."""

    def __init__(self, x: ArrayLike, y: ArrayLike, heights: ArrayLike, source: str = "height map"):
        from scipy.interpolate import RectBivariateSpline

        self.x, self.y = np.asarray(x, float), np.asarray(y, float)
        self.heights = np.asarray(heights, float)
        self.source = source
        for name, axis in (("x", self.x), ("y", self.y)):
            if axis.ndim != 1 or axis.size < 4 or not np.isfinite(axis).all() or not (np.diff(axis) > 0).all():
                shown = ", ".join(f"{v:g}" for v in axis.ravel()[:6]) + (", ..." if axis.size > 6 else "")
                raise ValueError(f"{source}: the grid's {name} = [{shown}] m: expected at least 4 finite, "
                                 "strictly increasing values")
        if self.heights.shape != (self.y.size, self.x.size):
            raise ValueError(f"{source}: heights of shape {self.heights.shape}: expected (len(y), len(x)) = "
                             f"({self.y.size}, {self.x.size})")
        bad = np.argwhere(~np.isfinite(self.heights))
        if bad.size:
            j, i = bad[0]
            raise ValueError(f"{source}: height at x = {self.x[i]:g} m, y = {self.y[j]:g} m is "
                             f"{float(self.heights[j, i])!r}: expected a finite height in m")
        spline = RectBivariateSpline(self.y, self.x, self.heights, kx=3, ky=3)
        #: The interpolating spline's knots along y and x and its coefficients c[row along y, column
        #: along x] (FITPACK's fit, evaluated by ``_evaluate`` and by the C twins' height_map.h).
        self.knots_y, self.knots_x, flat = (np.asarray(a, float) for a in spline.tck)
        self.coefficients = flat.reshape(self.knots_y.size - 4, self.knots_x.size - 4)

    def _clamped(self, x: ArrayLike, y: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        cx, cy = np.clip(x, self.x[0], self.x[-1]), np.clip(y, self.y[0], self.y[-1])
        inside = ((cx == x) & (cy == y)).astype(float)
        return cx, cy, inside

    def _evaluate(self, cx: FloatArray, cy: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(h, dh/dx, dh/dy) of the spline at the points (cx, cy) inside the grid: the cubic
        B-spline bases by de Boor's recursion, summed over the 4 x 4 coefficients, row by row, in
        the order of the C twins (height_map.h), each operation elementwise."""
        by, dby = _cubic_basis(self.knots_y, cy)
        bx, dbx = _cubic_basis(self.knots_x, cx)
        ly = _interval(self.knots_y, cy) - 3
        lx = _interval(self.knots_x, cx) - 3
        value = np.zeros(cx.shape)
        along_x = np.zeros(cx.shape)
        along_y = np.zeros(cx.shape)
        for a in range(4):
            row = np.zeros(cx.shape)
            row_dx = np.zeros(cx.shape)
            for b in range(4):
                c = self.coefficients[ly + a, lx + b]
                row = row + c * bx[b]
                row_dx = row_dx + c * dbx[b]
            value = value + by[a] * row
            along_x = along_x + by[a] * row_dx
            along_y = along_y + dby[a] * row
        return value, along_x, along_y

    def height(self, x: ArrayLike, y: ArrayLike) -> FloatArray:
        """Height [m] of the ground above the plane at (x, y) [m]."""
        cx, cy, _ = self._clamped(x, y)
        return self._evaluate(cx, cy)[0]

    def gradient(self, x: ArrayLike, y: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """(dh/dx, dh/dy) [1] at (x, y) [m] (0 outside the grid)."""
        cx, cy, inside = self._clamped(x, y)
        _, along_x, along_y = self._evaluate(cx, cy)
        return along_x * inside, along_y * inside

    @classmethod
    def read(cls, path: str | Path) -> HeightMap:
        """The height map of the CSV file ``path`` (see the class); ValueError naming the file."""
        path = Path(path)
        try:
            rows = np.loadtxt(path, delimiter=",", skiprows=0, dtype=str)
            x = rows[0, 1:].astype(float)
            y = rows[1:, 0].astype(float)
            heights = rows[1:, 1:].astype(float)
        except (OSError, ValueError, IndexError) as error:
            raise ValueError(f"height map {path}: {error} (expected CSV: a row 'y\\\\x' and the x values, "
                             "then rows of y and the heights)") from error
        return cls(x, y, heights, source=f"height map {path}")

    def write(self, path: str | Path) -> bytes:
        """The CSV text of the map (written to ``path`` unless it is empty)."""
        lines = ["y\\x," + ",".join(f"{v:.10g}" for v in self.x)]
        lines += [f"{yj:.10g}," + ",".join(f"{h:.10g}" for h in row) for yj, row in zip(self.y, self.heights)]
        text = ("\n".join(lines) + "\n").encode()
        if str(path):
            Path(path).write_bytes(text)
        return text


def _interval(knots: FloatArray, u: FloatArray) -> NDArray[np.intp]:
    """l with knots[l] <= u < knots[l + 1] among the spline's intervals (3 .. len - 5; the last
    closed on the right)."""
    return np.clip(np.searchsorted(knots, u, side="right") - 1, 3, knots.size - 5)


def _cubic_basis(knots: FloatArray, u: FloatArray) -> tuple[list[FloatArray], list[FloatArray]]:
    """The four cubic B-splines nonzero at ``u`` (those of indices l - 3 .. l) and their
    derivatives, by de Boor's recursion from degree 0 (height_map.h computes the same)."""
    interval = _interval(knots, u)
    previous = [np.ones(u.shape)]
    quadratic: list[FloatArray] = previous
    for degree in (1, 2, 3):
        current = []
        for r in range(degree + 1):
            j = interval - degree + r
            term = np.zeros(u.shape)
            if r > 0:
                term = term + (u - knots[j]) / (knots[j + degree] - knots[j]) * previous[r - 1]
            if r < degree:
                term = term + (knots[j + degree + 1] - u) / (knots[j + degree + 1] - knots[j + 1]) * previous[r]
            current.append(term)
        if degree == 2:
            quadratic = current
        previous = current
    slopes = []
    for r in range(4):
        j = interval - 3 + r
        slope = np.zeros(u.shape)
        if r > 0:
            slope = slope + 3.0 * quadratic[r - 1] / (knots[j + 3] - knots[j])
        if r < 3:
            slope = slope - 3.0 * quadratic[r] / (knots[j + 4] - knots[j + 1])
        slopes.append(slope)
    return previous, slopes


def crater(centre: tuple[float, float] = (6.0, -2.0), depth: float = 0.2, radius: float = 3.0,
           rim: float = 0.1, spacing: float = 0.25, margin: float = 4.0) -> HeightMap:
    """A crater-like depression [m]: a Gaussian bowl of ``depth`` and ``radius`` (its standard
    deviation) with a raised ``rim`` of height ``rim`` at 1.5 ``radius``, centred at ``centre``,
    sampled every ``spacing`` [m] over a square reaching ``margin`` radii from the centre (its edges
    level to within micrometres)."""
    for name, value in (("depth", depth), ("radius", radius), ("spacing", spacing), ("margin", margin)):
        if not (math.isfinite(value) and value > 0):
            raise ValueError(f"crater {name} = {value!r} m: expected > 0")
    if not (math.isfinite(rim) and rim >= 0):
        raise ValueError(f"crater rim = {rim!r} m: expected >= 0")
    reach = margin * radius
    x = np.arange(centre[0] - reach, centre[0] + reach + spacing / 2, spacing)
    y = np.arange(centre[1] - reach, centre[1] + reach + spacing / 2, spacing)
    gx, gy = np.meshgrid(x, y)
    r = np.hypot(gx - centre[0], gy - centre[1])
    bowl = -depth * np.exp(-0.5 * (r / radius) ** 2)
    heights = bowl + rim * np.exp(-0.5 * ((r - 1.5 * radius) / (0.4 * radius)) ** 2)
    return HeightMap(x, y, heights, source="crater")


def hub_positions(x: float, y: float, yaw: float, x_hub: FloatArray,
                  y_hub: FloatArray) -> tuple[FloatArray, FloatArray]:
    """(x, y) [m] of the hubs in the ground plane for the body at (``x``, ``y``) [m] with heading
    ``yaw`` [rad], the hubs at (``x_hub``, ``y_hub``) [m] in the body frame (pitch and roll of a few
    degrees neglected)."""
    cos, sin = math.cos(yaw), math.sin(yaw)
    return x + cos * x_hub - sin * y_hub, y + sin * x_hub + cos * y_hub


#: A share within this of 0 or 1 is 0 or 1 (``SoilMap.share``).
SNAP = 1e-12


class SoilMap:
    """Where a second soil lies over the ground: the share s [1] of ``soil_b`` in the soil under a
    wheel at (x, y) [m], 0 on ``soil``, 1 on ``soil_b``, in between a blend of their parameters
    (``Soil.blend``, ``Components.RigidWheel``'s ``soilShare``). The shares ``shares[j, i]`` at the
    grid points (``x[i]``, ``y[j]``) (at least 4 each, strictly increasing) are interpolated
    bilinearly: a share stays in [0, 1] and a region of one soil is that soil exactly (a bicubic
    spline, as for heights, rings across a boundary and leaves traces of the other soil metres
    away). The kinks at the grid lines are no events: each wheel's FMU holds its share, an input,
    over a communication step. Outside the grid the edge's share continues. The C twins' law:
    ``soil_map.h`` (the same arithmetic). The file
    (``read``, ``write``): the CSV of ``HeightMap`` with shares for heights; the soils are not in
    it (they are the FMUs' parameters ``soil`` and ``soilB``)."""

    def __init__(self, x: ArrayLike, y: ArrayLike, shares: ArrayLike, soil: Soil, soil_b: Soil,
                 source: str = "soil map"):
        for name, value in (("soil", soil), ("soil_b", soil_b)):
            if not isinstance(value, Soil):
                raise TypeError(f"{source}: {name} = {value!r}: expected a Soil")
        values = np.asarray(shares, float)
        bad = np.argwhere(~(np.isfinite(values) & (values >= 0.0) & (values <= 1.0)))
        if values.ndim == 2 and bad.size:
            j, i = bad[0]
            raise ValueError(f"{source}: share at grid point (row {j + 1}, column {i + 1}) is "
                             f"{float(values[j, i])!r}: expected a share of the second soil in [0, 1]")
        self.grid = HeightMap(x, y, values, source=source)  # its checks of the grid, and its file
        self.soil, self.soil_b, self.source = soil, soil_b, source

    def share(self, x: ArrayLike, y: ArrayLike) -> FloatArray:
        """The share [1] of ``soil_b`` under the points (x, y) [m]; within 1e-12 of 0 or 1 it is 0 or 1
        (the weights' round-off over a region of one soil: a wheel there is on that soil exactly)."""
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        gx, gy, v = self.grid.x, self.grid.y, self.grid.heights
        cx, cy = np.clip(x, gx[0], gx[-1]), np.clip(y, gy[0], gy[-1])
        i = np.clip(np.searchsorted(gx, cx, side="right") - 1, 0, gx.size - 2)
        j = np.clip(np.searchsorted(gy, cy, side="right") - 1, 0, gy.size - 2)
        tx, ty = (cx - gx[i]) / (gx[i + 1] - gx[i]), (cy - gy[j]) / (gy[j + 1] - gy[j])
        share = (1.0 - ty) * ((1.0 - tx) * v[j, i] + tx * v[j, i + 1]) + ty * ((1.0 - tx) * v[j + 1, i]
                                                                             + tx * v[j + 1, i + 1])
        share = np.clip(share, 0.0, 1.0)
        return np.where(share < SNAP, 0.0, np.where(share > 1.0 - SNAP, 1.0, share))

    def hub_shares(self, x: float, y: float, yaw: float, x_hub: FloatArray, y_hub: FloatArray) -> FloatArray:
        """The share [1] under each hub (``hub_positions``) of the body at (x, y) [m] heading
        ``yaw`` [rad] (the soil participant's outputs; what a controller that believes the map uses)."""
        return self.share(*hub_positions(x, y, yaw, x_hub, y_hub))

    def soil_at(self, x: float, y: float) -> Soil:
        """The soil under the point (x, y) [m]."""
        return self.soil.blend(self.soil_b, float(self.share(x, y)))

    @classmethod
    def read(cls, path: str | Path, soil: Soil, soil_b: Soil) -> SoilMap:
        """The soil map of the CSV file ``path`` between ``soil`` and ``soil_b``; ValueError naming the file."""
        grid = HeightMap.read(path)
        return cls(grid.x, grid.y, grid.heights, soil, soil_b, source=f"soil map {path}")

    def write(self, path: str | Path) -> bytes:
        """The CSV text of the map (written to ``path`` unless it is empty)."""
        return self.grid.write(path)


def soil_boundary(x_boundary: float, soil: Soil, soil_b: Soil, width: float = 0.5,
                  x_span: tuple[float, float] = (-5.0, 15.0), y_span: tuple[float, float] = (-5.0, 5.0),
                  spacing: float = 0.1) -> SoilMap:
    """``soil`` up to a straight boundary across the x axis at ``x_boundary`` [m], ``soil_b`` beyond
    it, the share rising over ``width`` [m] centred on the boundary as 3t² - 2t³ (t from 0 to 1:
    continuous with its slope), sampled every ``spacing`` [m] over ``x_span`` x ``y_span`` [m]."""
    for name, value in (("width", width), ("spacing", spacing)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"soil boundary {name} = {value!r} m: expected > 0")
    if not (isinstance(x_boundary, (int, float)) and math.isfinite(x_boundary)):
        raise ValueError(f"soil boundary x_boundary = {x_boundary!r} m: expected a finite position")
    x = np.arange(x_span[0], x_span[1] + spacing / 2, spacing)
    y = np.arange(y_span[0], y_span[1] + spacing / 2, spacing)
    t = np.clip((x - x_boundary) / width + 0.5, 0.0, 1.0)
    ramp = t * t * (3.0 - 2.0 * t)
    return SoilMap(x, y, np.tile(ramp, (y.size, 1)), soil, soil_b, source=f"soil boundary at x = {x_boundary:g} m")


def soil_patch(centre: tuple[float, float], radius: float, soil: Soil, soil_b: Soil, width: float = 0.2,
               x_span: tuple[float, float] = (-5.0, 15.0), y_span: tuple[float, float] = (-5.0, 5.0),
               spacing: float = 0.05) -> SoilMap:
    """``soil_b`` in a round patch of ``radius`` [m] about ``centre`` (x, y) [m] in ``soil``, the share
    falling from 1 to 0 over ``width`` [m] across the patch's edge (centred on it) as 3t² - 2t³,
    sampled every ``spacing`` [m] over ``x_span`` x ``y_span`` [m]."""
    for name, value in (("radius", radius), ("width", width), ("spacing", spacing)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise ValueError(f"soil patch {name} = {value!r} m: expected > 0")
    x = np.arange(x_span[0], x_span[1] + spacing / 2, spacing)
    y = np.arange(y_span[0], y_span[1] + spacing / 2, spacing)
    distance = np.hypot(*np.meshgrid(x - centre[0], y - centre[1]))
    t = np.clip((radius - distance) / width + 0.5, 0.0, 1.0)
    return SoilMap(x, y, t * t * (3.0 - 2.0 * t), soil, soil_b,
                   source=f"soil patch of radius {radius:g} m at ({centre[0]:g}, {centre[1]:g}) m")
