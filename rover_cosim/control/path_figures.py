"""Figures of the path-following runs, as PNG bytes (computation stays in the job)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from rover_cosim.common.figures import thinned
from rover_cosim.common.rows import indices
from rover_cosim.identification.figures import png_bytes

from .path import Path

LABELS = {"inverse": "identified models (SteerableRover.fmu)", "cosim": "identified models (co-simulated)",
          "kinematic": "kinematic steering (ablation)"}
STYLES = {"inverse": "-", "cosim": "--", "kinematic": ":"}


def path_xy(paths: dict[str, Path], tables: dict[tuple[str, str], pd.DataFrame]) -> bytes:
    """Per scenario: the reference path and the centre of gravity of each run in x-y, and the
    cross-track error against arc length."""
    fig, axes = plt.subplots(2, len(paths), figsize=(6.5 * len(paths), 9), squeeze=False)
    for column, (scenario, path) in enumerate(paths.items()):
        top, bottom = axes[0][column], axes[1][column]
        top.plot(path.x, path.y, color="0.6", lw=6, alpha=0.5, label="reference path")
        for (name, label), table in tables.items():
            if name != scenario:
                continue
            top.plot(table["x"], table["y"], STYLES[label], label=LABELS[label])
            bottom.plot(table["s"], 100 * table["cross_track"], STYLES[label], label=LABELS[label])
        top.set_aspect("equal", adjustable="datalim")
        top.set_xlabel("x [m]")
        top.set_ylabel("y [m]")
        top.set_title(f"{scenario.replace('_', ' ')}: centre of gravity in the plane")
        bottom.set_xlabel("arc length s [m]")
        bottom.set_ylabel("cross-track error [cm] (left +)")
        bottom.set_title("cross-track error along the path")
        for ax in (top, bottom):
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
    return png_bytes(fig)


def wheels(table: pd.DataFrame, scenario: str) -> bytes:
    """Per wheel against time: Fx with Fx_des, Fy with Fy_des, slip angle and steering, load."""
    fig, axes = plt.subplots(4, 1, figsize=(10, 12), sharex=True)
    numbers = indices(table.columns, "Fz")
    colors = plt.cm.tab10(np.arange(len(numbers)) % 10)
    for i, color in zip(numbers, colors):
        axes[0].plot(*thinned(table["time"], table[f"Fx_{i}"]), color=color, lw=1, label=f"wheel {i}")
        axes[0].plot(*thinned(table["time"], table[f"Fx_des_{i}"]), color=color, lw=1, ls="--")
        axes[1].plot(*thinned(table["time"], table[f"Fy_{i}"]), color=color, lw=1, label=f"wheel {i}")
        axes[1].plot(*thinned(table["time"], table[f"Fy_des_{i}"]), color=color, lw=1, ls="--")
        axes[2].plot(*thinned(table["time"], np.degrees(table[f"slipAngle_{i}"])), color=color, lw=1,
                     label=f"wheel {i} slip angle")
        axes[2].plot(*thinned(table["time"], np.degrees(table[f"steer_{i}"])), color=color, lw=1, ls=":")
        axes[3].plot(*thinned(table["time"], table[f"Fz_{i}"]), color=color, lw=1, label=f"wheel {i}")
    axes[0].set_ylabel("Fx [N] (dashed: Fx_des)")
    axes[1].set_ylabel("Fy [N] (dashed: Fy_des)")
    axes[2].set_ylabel("slip angle, steering (dotted) [deg]")
    axes[3].set_ylabel("load Fz [N]")
    axes[3].set_xlabel("time [s]")
    axes[0].set_title(f"{scenario.replace('_', ' ')}: wheels 1-3 left (front, middle, rear), 4-6 right")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=3)
    return png_bytes(fig)
