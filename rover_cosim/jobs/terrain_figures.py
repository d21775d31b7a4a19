"""Figures of the terrain scenarios (issue 35), as PNG bytes (computation stays in ``terrain``)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from rover_cosim.common.figures import thinned
from rover_cosim.common.rows import indices
from rover_cosim.control.path import Path
from rover_cosim.identification.figures import png_bytes

LABELS = {"inverse": "identified models, downhill pull compensated (SteerableRover.fmu)",
          "cosim": "identified models, compensated (co-simulated)",
          "kinematic": "kinematic steering (ablation)",
          "unaware": "identified models, the map unknown to the controller (ablation)"}
#: The soil crossing's runs: what the controller believes of the soil, not of the ground's pull.
SOIL_LABELS = {"inverse": "both soils' models, the soil map believed (SteerableRover.fmu)",
               "cosim": "both soils' models, the soil map believed (co-simulated)",
               "unaware": "the first soil's models everywhere (ablation)"}
STYLES = {"inverse": "-", "cosim": "--", "kinematic": ":", "unaware": ":"}
COLORS = {"inverse": "tab:blue", "cosim": "tab:orange", "kinematic": "tab:red", "unaware": "tab:red"}


def run_label(scenario: str, label: str) -> str:
    """How the figures name run ``label`` of ``scenario``."""
    if scenario == "soil_crossing":
        return SOIL_LABELS[label]
    return LABELS[label] if scenario != "crater" else LABELS[label].replace("downhill pull", "map's pull")


def paths_over_terrain(scenarios: dict[str, tuple[Path, Any]],
                       tables: dict[tuple[str, str], pd.DataFrame]) -> bytes:
    """Per scenario (a row): the ground's height contours [m] (``terrain.height(x, y)``,
    ``terrain.label()``; hatched where a soil map has its second soil) with the reference path and
    the centre of gravity of each run (left), the cross-track error against arc length (right)."""
    fig, axes = plt.subplots(len(scenarios), 2, figsize=(13, 4.6 * len(scenarios)), squeeze=False)
    for row, (scenario, (path, terrain)) in enumerate(scenarios.items()):
        top, bottom = axes[row][0], axes[row][1]
        runs = {label: table for (name, label), table in tables.items() if name == scenario}
        ys = np.concatenate([path.y, *[t["y"].to_numpy() for t in runs.values()]])
        half = max(1.0, 1.5 * float(np.abs(ys).max()))
        if getattr(terrain, "map", None) is not None:  # a height map: show it around the path
            half = max(half, 6.0)
        x = np.linspace(float(path.x.min()) - 1.0, float(path.x.max()) + 1.0, 120)
        y = np.linspace(-half, half, 80)
        grid_x, grid_y = np.meshgrid(x, y)
        height = terrain.height(grid_x, grid_y)
        filled = top.contourf(grid_x, grid_y, height, levels=14, cmap="terrain", alpha=0.8)
        fig.colorbar(filled, ax=top, label="ground height z [m]", orientation="vertical", fraction=0.04)
        top.plot(path.x, path.y, color="0.3", lw=5, alpha=0.4, label="reference path")
        soil_map = getattr(terrain, "soil_map", None)
        if soil_map is not None:  # the second soil: hatched beyond the share's midpoint
            share = soil_map.share(grid_x, grid_y)
            top.contourf(grid_x, grid_y, share, levels=[0.5, 1.01], colors="none", hatches=["//"])
            top.contour(grid_x, grid_y, share, levels=[0.5], colors="k", linewidths=1.0)
            top.plot([], [], color="k", lw=1.0, label="soil boundary (hatched: the second soil)")
        for label, table in runs.items():
            name = run_label(scenario, label)
            top.plot(table["x"], table["y"], STYLES[label], color=COLORS[label], label=name)
            bottom.plot(table["s"], 100 * table["cross_track"], STYLES[label], color=COLORS[label], label=name)
        if getattr(terrain, "map", None) is not None:
            top.set_aspect("equal")
        top.set_xlabel("x along the ground [m]")
        top.set_ylabel("y along the ground [m]")
        top.set_title(f"{terrain.label()}: centre of gravity\n"
                      + ("(y stretched; the ground's x axis runs level across the slope)"
                         if getattr(terrain, "map", None) is None else "(to scale)"), fontsize=10)
        bottom.set_xlabel("arc length s [m]")
        bottom.set_ylabel("cross-track error [cm] (left/uphill +)")
        bottom.set_title("cross-track error along the path")
        for ax in (top, bottom):
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper right" if ax is top else "lower left", framealpha=0.9)
    return png_bytes(fig)


def wheels(tables: dict[str, pd.DataFrame], scenario: str) -> bytes:
    """Per wheel against time: slip, slip angle, sinkage, load and lateral force, one colour per
    wheel, one line style per run (compensated solid, kinematic dotted)."""
    names = (("slip", "slip [-]", 1.0), ("slipAngle", "slip angle [deg]", 180 / np.pi),
             ("sinkage", "sinkage [mm]", 1000.0), ("Fz", "load Fz [N]", 1.0), ("Fy", "lateral force Fy [N]", 1.0))
    fig, axes = plt.subplots(len(names), 1, figsize=(10, 14), sharex=True)
    for label, table in tables.items():
        numbers = indices(table.columns, "Fz")
        colors = plt.cm.tab10(np.arange(len(numbers)) % 10)
        for ax, (name, _, scale) in zip(axes, names):
            for i, color in zip(numbers, colors):
                ax.plot(*thinned(table["time"], scale * table[f"{name}_{i}"]), STYLES[label], color=color, lw=1,
                        label=f"wheel {i}" if label == next(iter(tables)) else None)
    for ax, (_, ylabel, _) in zip(axes, names):
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, ncol=6, loc="upper right")
    axes[-1].set_xlabel("time [s]")
    kinds = {"-": "solid", "--": "dashed", ":": "dotted"}
    crater = scenario == "crater"
    run_names = {label: run_label(scenario, label).split(" (")[0] for label in tables}
    runs = ", ".join(f"{kinds[STYLES[label]]}: {run_names[label]}" for label in tables)
    title = {"crater": "crater", "soil_crossing": "soil crossing on a side slope"}.get(
        scenario, f"{scenario.replace('_', ' ')} deg")
    sides = "1-3 left, 4-6 right (the bowl's side)" if crater else "1-3 left/uphill, 4-6 right/downhill"
    axes[0].set_title(f"{title}: wheels {sides}; front, middle, rear\n{runs}", fontsize=10)
    return png_bytes(fig)
