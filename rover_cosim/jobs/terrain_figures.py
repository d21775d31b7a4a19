"""Figures of the terrain scenarios (issue 35), as PNG bytes (computation stays in ``terrain``)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from rover_cosim.control.path import Path
from rover_cosim.identification.figures import png_bytes

LABELS = {"inverse": "identified models, downhill pull compensated (SteerableRover.fmu)",
          "cosim": "identified models, compensated (co-simulated)",
          "kinematic": "kinematic steering (ablation)",
          "unaware": "identified models, the map unknown to the controller (ablation)"}
STYLES = {"inverse": "-", "cosim": "--", "kinematic": ":", "unaware": ":"}
COLORS = {"inverse": "tab:blue", "cosim": "tab:orange", "kinematic": "tab:red", "unaware": "tab:red"}


def paths_over_terrain(scenarios: dict[str, tuple[Path, Any]],
                       tables: dict[tuple[str, str], pd.DataFrame]) -> bytes:
    """Per scenario: the ground's height contours [m] (``terrain.height(x, y)``, ``terrain.label()``)
    with the reference path and the centre of gravity of each run (top), the cross-track error
    against arc length (bottom)."""
    fig, axes = plt.subplots(2, len(scenarios), figsize=(6.5 * len(scenarios), 9), squeeze=False)
    for column, (scenario, (path, terrain)) in enumerate(scenarios.items()):
        top, bottom = axes[0][column], axes[1][column]
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
        fig.colorbar(filled, ax=top, label="ground height z [m]", orientation="horizontal", pad=0.15)
        top.plot(path.x, path.y, color="0.3", lw=5, alpha=0.4, label="reference path")
        for label, table in runs.items():
            name = LABELS[label] if terrain.plane.slope else LABELS[label].replace("downhill pull", "map's pull")
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
            ax.legend(fontsize=8, loc="upper right" if ax is top else "lower left", framealpha=0.9)
    return png_bytes(fig)


def wheels(tables: dict[str, pd.DataFrame], scenario: str) -> bytes:
    """Per wheel against time: slip, slip angle, sinkage, load and lateral force, one colour per
    wheel, one line style per run (compensated solid, kinematic dotted)."""
    names = (("slip", "slip [-]", 1.0), ("slipAngle", "slip angle [deg]", 180 / np.pi),
             ("sinkage", "sinkage [mm]", 1000.0), ("Fz", "load Fz [N]", 1.0), ("Fy", "lateral force Fy [N]", 1.0))
    fig, axes = plt.subplots(len(names), 1, figsize=(10, 14), sharex=True)
    colors = plt.cm.tab10(np.arange(6))
    for label, table in tables.items():
        for ax, (name, _, scale) in zip(axes, names):
            for i, color in zip(range(1, 7), colors):
                ax.plot(table["time"], scale * table[f"{name}_{i}"], STYLES[label], color=color, lw=1,
                        label=f"wheel {i}" if label == next(iter(tables)) else None)
    for ax, (_, ylabel, _) in zip(axes, names):
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, ncol=6, loc="upper right")
    axes[-1].set_xlabel("time [s]")
    kinds = {"-": "solid", "--": "dashed", ":": "dotted"}
    crater = scenario == "crater"
    pull = "map's pull" if crater else "downhill pull"
    run_names = {label: LABELS[label].split(" (")[0].replace("downhill pull", pull) for label in tables}
    runs = ", ".join(f"{kinds[STYLES[label]]}: {run_names[label]}" for label in tables)
    title = "crater" if crater else f"{scenario.replace('_', ' ')} deg"
    sides = "1-3 left, 4-6 right (the bowl's side)" if crater else "1-3 left/uphill, 4-6 right/downhill"
    axes[0].set_title(f"{title}: wheels {sides}; front, middle, rear\n{runs}", fontsize=10)
    return png_bytes(fig)
