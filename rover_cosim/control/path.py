"""Reference paths in the plane and the rover's position against them (pure geometry).

A :class:`Path` is sampled densely (``spacing`` [m]) by arc length s [m]: position (x, y) [m],
heading [rad] (against world x, positive to the left) and curvature [1/m] (positive turning
left). :meth:`Path.locate` projects a point onto it: the arc length of the nearest point, the
signed cross-track error (positive: the point lies to the left of the path) and the path's
heading and curvature there.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np

SPACING = 0.01  # m between samples


@dataclass(frozen=True)
class Line:
    """A straight of ``length`` [m]."""

    length: float


@dataclass(frozen=True)
class Arc:
    """An arc of ``radius`` [m] through ``angle`` [rad] (positive: turning left)."""

    radius: float
    angle: float


@dataclass(frozen=True)
class LaneChange:
    """A sideways shift of ``offset`` [m] (positive: to the left) over ``length`` [m] along the
    heading, y = offset (1 - cos(pi x / length)) / 2: heading and curvature are continuous."""

    length: float
    offset: float


@dataclass(frozen=True)
class Location:
    """The nearest point of a path: arc length s [m], cross-track error [m] (left positive),
    heading [rad] and curvature [1/m] there, and its sample index."""

    s: float
    cross_track: float
    heading: float
    curvature: float
    index: int


class Path:
    """A path of segments from (0, 0) heading along world x."""

    def __init__(self, segments: tuple[Line | Arc | LaneChange, ...], spacing: float = SPACING):
        if not segments:
            raise ValueError("a path needs at least one segment")
        if not spacing > 0:
            raise ValueError(f"spacing = {spacing!r} m: expected > 0")
        self.segments, self.spacing = segments, spacing
        pieces = [np.array([[0.0, 0.0, 0.0, 0.0]])]  # s, x, y, heading
        curvatures = [np.array([0.0])]
        for segment in segments:
            start = pieces[-1][-1]
            piece, curvature = _sample(segment, start, spacing)
            pieces.append(piece)
            curvatures.append(curvature)
        table = np.vstack(pieces)
        self.s, self.x, self.y, self.heading = table.T
        self.curvature = np.concatenate(curvatures)
        self.curvature[0] = self.curvature[1] if len(self.curvature) > 1 else 0.0
        self.length = float(self.s[-1])
        # Plain floats for locate (one point at a time; its C twin reads the same tables).
        self._tables = [column.tolist() for column in (self.s, self.x, self.y, self.heading, self.curvature)]

    def at(self, s: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(x, y, heading, curvature) at arc length s, interpolated between samples."""
        s = np.clip(np.asarray(s, float), 0.0, self.length)
        heading = np.interp(s, self.s, self.heading)  # continuous: the segments never wrap it
        return (np.interp(s, self.s, self.x), np.interp(s, self.s, self.y), heading,
                np.interp(s, self.s, self.curvature))

    def locate(self, x: float, y: float, hint: int | None = None, window: float = 2.0) -> Location:
        """The nearest point of the path to (x, y); with ``hint`` (the last index) only within
        ``window`` [m] of arc length around it, so a path that comes back near itself is followed
        in order. Plain floats after the search, in the order its C twin (``path_controller.c``)
        repeats."""
        if hint is None:
            low, high = 0, len(self.s)
        else:
            reach = int(window / self.spacing) + 1
            low, high = max(hint - reach, 0), min(hint + reach + 1, len(self.s))
        distance = (self.x[low:high] - x) ** 2 + (self.y[low:high] - y) ** 2
        i = low + int(np.argmin(distance))
        # Refine on the segment to the better neighbour: the foot of the perpendicular.
        j = i + 1 if i + 1 < len(self.s) else i - 1
        arc, xs, ys = self._tables[0], self._tables[1], self._tables[2]
        dx, dy = xs[j] - xs[i], ys[j] - ys[i]
        norm = math.sqrt(dx * dx + dy * dy)
        along = ((x - xs[i]) * (dx / norm) + (y - ys[i]) * (dy / norm)) * (1.0 if j > i else -1.0)
        reach_s = self.spacing
        s = arc[i] + min(max(along, -reach_s), reach_s)
        s = min(max(s, 0.0), self.length)
        px, py, heading, curvature = (interpolate(arc, table, s) for table in self._tables[1:])
        cross = -math.sin(heading) * (x - px) + math.cos(heading) * (y - py)
        return Location(s, cross, heading, curvature, i)


def interpolate(xp: list[float], fp: list[float], x: float) -> float:
    """np.interp at one point, in plain floats: fp linear in x between the samples xp
    (increasing), held beyond them."""
    if not x > xp[0]:
        return fp[0] if x == x else x
    if x >= xp[-1]:
        return fp[-1]
    j = bisect.bisect_right(xp, x) - 1
    if xp[j] == x:
        return fp[j]
    return (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]) * (x - xp[j]) + fp[j]


def _sample(segment: Line | Arc | LaneChange, start: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """Rows (s, x, y, heading) of one segment after ``start`` (excluded), and the curvatures."""
    s0, x0, y0, h0 = start
    if isinstance(segment, Line):
        if not segment.length > 0:
            raise ValueError(f"Line length = {segment.length!r} m: expected > 0")
        d = _steps(segment.length, spacing)
        return np.column_stack([s0 + d, x0 + d * math.cos(h0), y0 + d * math.sin(h0), np.full_like(d, h0)]), 0 * d
    if isinstance(segment, Arc):
        if not segment.radius > 0 or segment.angle == 0:
            raise ValueError(f"Arc radius = {segment.radius!r} m, angle = {segment.angle!r} rad: expected radius > 0 "
                             "and angle != 0")
        d = _steps(segment.radius * abs(segment.angle), spacing)
        turn = math.copysign(1.0, segment.angle)
        heading = h0 + turn * d / segment.radius
        cx, cy = x0 - turn * segment.radius * math.sin(h0), y0 + turn * segment.radius * math.cos(h0)
        x = cx + turn * segment.radius * np.sin(heading)
        y = cy - turn * segment.radius * np.cos(heading)
        return np.column_stack([s0 + d, x, y, heading]), np.full_like(d, turn / segment.radius)
    if not segment.length > 0:
        raise ValueError(f"LaneChange length = {segment.length!r} m: expected > 0")
    # Sampled finely along the heading, then resampled by arc length.
    u = np.linspace(0.0, segment.length, int(segment.length / spacing) * 10 + 1)
    k = math.pi / segment.length
    lateral = segment.offset * (1 - np.cos(k * u)) / 2
    slope = segment.offset * k * np.sin(k * u) / 2
    bend = segment.offset * k**2 * np.cos(k * u) / 2
    arc = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(u), np.diff(lateral)))])
    d = _steps(float(arc[-1]), spacing)
    ux, uy = np.interp(d, arc, u), np.interp(d, arc, lateral)
    local_heading = np.arctan(np.interp(d, arc, slope))
    curvature = np.interp(d, arc, bend / (1 + slope**2) ** 1.5)
    x = x0 + ux * math.cos(h0) - uy * math.sin(h0)
    y = y0 + ux * math.sin(h0) + uy * math.cos(h0)
    return np.column_stack([s0 + d, x, y, h0 + local_heading]), curvature


def _steps(length: float, spacing: float) -> np.ndarray:
    count = max(int(math.ceil(length / spacing)), 1)
    return np.linspace(length / count, length, count)


def turn_path(straight: float = 10.0) -> Path:
    """The issue's first scenario: ``straight`` [m] (10 m) straight, a 90 deg left turn of radius
    10 m, ``straight`` straight (the tests shorten the straights, the turn stays)."""
    return Path((Line(straight), Arc(10.0, math.pi / 2), Line(straight)))


def lane_change_path(straight: float = 10.0) -> Path:
    """The second: ``straight`` [m] (10 m) straight, 3 m to the left over 15 m, ``straight`` straight."""
    return Path((Line(straight), LaneChange(15.0, 3.0), Line(straight)))
