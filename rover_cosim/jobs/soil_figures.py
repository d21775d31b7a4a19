"""Figures of a soil estimate: the data as markers and the fitted wheel as lines, per channel
against slip, one colour per load and one marker per slip angle (:func:`fit_figure`); the residuals
against slip with the ±2σ noise band (:func:`residual_figure`). Sized for a screen 1024 px wide."""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from numpy.typing import NDArray

from rover_cosim.identification.soil_estimation import SoilEstimate
from rover_cosim.identification.testbed_data import LABELS, FloatArray

Color = tuple[float, float, float, float]
MARKERS = ("o", "s", "^", "D", "v", "P")
#: Most curves per figure: more distinct loads (or slip angles) are grouped into this many bins.
MOST_LOADS, MOST_ANGLES = 8, len(MARKERS)


class Groups(NamedTuple):
    """Rows grouped by a value: the groups' values, the group of every row, whether they are bins."""

    values: FloatArray
    of_row: NDArray[np.intp]
    binned: bool


def groups(values: FloatArray, most: int) -> Groups:
    """The distinct values (rounded), or at most ``most`` bins of them (each represented by its
    median), and the group of every row."""
    distinct = np.unique(np.round(values, 6))
    if len(distinct) <= most:
        return Groups(distinct, np.searchsorted(distinct, np.round(values, 6)), False)
    edges = np.quantile(values, np.linspace(0, 1, most + 1))
    index = np.clip(np.searchsorted(edges, values, side="right") - 1, 0, most - 1)
    used = np.unique(index)
    medians = np.array([np.median(values[index == k]) for k in used])
    return Groups(medians, np.searchsorted(used, index), True)


def _layout(panels: int, height: float) -> tuple[Figure, list[Axes], Axes]:
    """A figure 1024 px wide at 100 dpi with ``panels`` axes in two columns and one more cell
    for the legend and notes."""
    rows = (panels + 2) // 2
    ratios = [1.0] * (rows - 1) + [0.7 if panels % 2 == 0 else 1.0]
    figure = Figure(figsize=(10.24, height * sum(ratios) + 0.9), dpi=100)
    grid = figure.add_gridspec(rows, 2, height_ratios=ratios)
    axes = [figure.add_subplot(grid[k // 2, k % 2]) for k in range(panels)]
    info = figure.add_subplot(grid[panels // 2, panels % 2:])
    info.axis("off")
    return figure, axes, info


def _legend(info: Axes, loads: Groups, angles: Groups, colors: Sequence[Color],
            extra: list[tuple[Line2D, str]], lines: bool = True) -> None:
    """The legend: a colour per load, a marker per slip angle (≈: the median of a bin of them)."""
    handles = [Line2D([], [], color=color, marker="o", ls="-" if lines else "") for color in colors]
    labels = [f"W {'≈' if loads.binned else '='} {w:.0f} N" for w in loads.values]
    if len(angles.values) > 1:
        handles += [Line2D([], [], color="0.3", marker=MARKERS[k], ls="", mfc="none" if lines else None)
                    for k in range(len(angles.values))]
        labels += [f"β {'≈' if angles.binned else '='} {b:.3g}°" for b in angles.values]
    for handle, label in extra:
        handles.append(handle)
        labels.append(label)
    info.legend(handles, labels, loc="upper left", fontsize=10, ncol=2 if len(labels) > 8 else 1, frameon=False)


def _colors(count: int) -> list[Color]:
    import matplotlib

    return [tuple(float(v) for v in matplotlib.colormaps["viridis"](float(x)))  # type: ignore[misc]
            for x in np.linspace(0.0, 0.85, count)]


def estimates_text(estimate: SoilEstimate) -> str:
    """The estimates with their intervals, one short line each (φ in degrees), and what was kept."""
    lines = [f"Estimates ({100 * estimate.confidence:g} % intervals):"]
    for e in estimate.parameters.values():
        scale, unit = (180 / np.pi, "deg") if e.name == "phi" else (1.0, "" if e.unit == "1" else e.unit)
        interval = "not determined" if np.isnan(e.low) else f"[{e.low * scale:.3g}, {e.high * scale:.3g}]"
        note = {"well": "", "poorly": " poorly"}.get(e.determined, f" {e.determined}") + (" at bound" * e.at_bound)
        lines.append(f"{e.name:<7s} {e.value * scale:<9.4g} {interval}{note}")
    units: dict[str, list[str]] = {}
    for e in estimate.parameters.values():
        if e.unit != "1" and e.name != "phi":
            units.setdefault(e.unit, []).append(e.name)
    lines.append("units: " + "; ".join(f"{', '.join(names)} {unit}" for unit, names in units.items()))
    kept = list(estimate.fixed)
    lines += ["kept at the prior:", *(" " + ", ".join(kept[k:k + 4]) for k in range(0, len(kept), 4))]
    return "\n".join(lines)


def fit_figure(estimate: SoilEstimate, title: str) -> Figure:
    """Each measured channel against slip: data as markers, the estimated soil's wheel as lines
    (at each load and slip angle of the data, over the data's slips there); the estimates with
    their intervals beside the legend."""
    data = estimate.data
    beta = np.zeros(data.rows) if data.slip_angle_deg is None else data.slip_angle_deg
    load_groups, angle_groups = groups(data.load_N, MOST_LOADS), groups(beta, MOST_ANGLES)
    (loads, load_of, _), (angles, angle_of, _) = load_groups, angle_groups
    colors = _colors(len(loads))
    figure, axes, info = _layout(len(data.channels), 3.4)
    curves: dict[tuple[int, int], tuple[FloatArray, dict[str, FloatArray]]] = {}
    for i, load in enumerate(loads):
        for j, angle in enumerate(angles):
            rows = (load_of == i) & (angle_of == j)
            if rows.any():
                slips = np.linspace(data.slip[rows].min(), data.slip[rows].max(), 61)
                prediction = estimate.predict(np.full(slips.shape, load), slips, angle)
                curves[i, j] = slips, {name: prediction.channel(name) for name in data.channels}
    for ax, name in zip(axes, data.channels):
        for (i, j), (slips, values) in curves.items():
            rows = (load_of == i) & (angle_of == j)
            ax.plot(slips, values[name], "-", color=colors[i], lw=1.4)
            ax.plot(data.slip[rows], data.channel(name)[rows], MARKERS[j], color=colors[i], ms=5, mfc="none")
        ax.set_xlabel("slip ratio κ [-]")
        ax.set_ylabel(LABELS[name])
        ax.grid(alpha=0.3)
    measured = Line2D([], [], color="0.3", marker="o", mfc="none", ls="")
    _legend(info, load_groups, angle_groups, colors, [(measured, "measured"),
                                                      (Line2D([], [], color="0.3", ls="-"), "estimated soil")])
    few = len(loads) + len(angles) <= 10
    info.text(0.45 if few else 1.0, 1.0, estimates_text(estimate), transform=info.transAxes, va="top",
              ha="left" if few else "right", fontsize=8.5, family="monospace")
    figure.suptitle(title, fontsize=11)
    figure.tight_layout()
    return figure


def residual_figure(estimate: SoilEstimate, title: str) -> Figure:
    """Residuals (model - data) of each channel against slip, coloured by load, with the band of
    ±2 noise scales (given, or estimated from the residuals)."""
    data = estimate.data
    beta = np.zeros(data.rows) if data.slip_angle_deg is None else data.slip_angle_deg
    load_groups, angle_groups = groups(data.load_N, MOST_LOADS), groups(beta, MOST_ANGLES)
    (loads, load_of, _), (angles, angle_of, _) = load_groups, angle_groups
    colors = _colors(len(loads))
    figure, axes, info = _layout(len(data.channels), 3.0)
    for ax, name in zip(axes, data.channels):
        channel = estimate.residuals[name]
        sigma = channel.noise_scale
        ax.axhspan(-2 * sigma, 2 * sigma, color="0.85", zorder=0)
        ax.axhline(0.0, color="0.4", lw=0.8)
        for i in range(len(loads)):
            for j in range(len(angles)):
                rows = (load_of == i) & (angle_of == j)
                ax.plot(data.slip[rows], channel.residuals[rows], MARKERS[j], color=colors[i], ms=5)
        unit = LABELS[name].rsplit("[", 1)[1].rstrip("]")
        ax.set_xlabel("slip ratio κ [-]")
        ax.set_ylabel(f"{LABELS[name].split(' [')[0]}: model − data [{unit}]")
        ax.set_title(f"RMS {channel.rms:.3g} {unit}; σ = {sigma:.3g} {unit} "
                     f"({'given' if channel.noise_given else 'estimated'})", fontsize=9)
        ax.grid(alpha=0.3)
    _legend(info, load_groups, angle_groups, colors, [(Line2D([], [], color="0.85", lw=8), "±2σ (noise scale)")],
            lines=False)
    figure.suptitle(title, fontsize=11)
    figure.tight_layout()
    return figure
