"""Figures of the leg-wheel scenarios (issue 47), as PNG bytes (computation stays in ``legwheel``)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from rover_cosim.common.figures import thinned
from rover_cosim.control.posture import JOINT_INPUTS
from rover_cosim.identification.figures import png_bytes
from rover_cosim.limbs import athlete_limbs, attitude, forward

#: Points per line of a panel of :func:`limbs` (thinned: each of its six columns is about 330 pixels
#: wide at 110 dpi, so 1000 points keep every pixel's extremes; the default 4000 cost a sixth of the
#: figure's drawing more).
PANEL_POINTS = 1000
JOINT_LABELS = ("hip yaw", "hip pitch", "knee pitch", "ankle pitch", "ankle steer", "ankle roll")
LIMB_NAMES = ("front left", "middle left", "rear left", "front right", "middle right", "rear right")


def _chains(joints: dict[str, float], roll: float, pitch: float, ground: tuple[float, float]) -> list[np.ndarray]:
    """Per limb, the points mount, knee, ankle pitch joint, ankle joint, hub in the world [m] (origin
    at the centre of gravity, x along the heading) for the set-points ``joints``, the body turned by
    ``roll``, ``pitch`` [rad] against the ground and the ground by ``ground`` (roll, pitch) [rad]."""
    rotation = attitude(ground[0], ground[1], 0.0) @ attitude(roll, pitch, 0.0)
    chains = []
    for i, limb in enumerate(athlete_limbs()):
        pose = forward(limb, [joints[f"{name}[{i + 1}]"] for name in JOINT_INPUTS])
        points = np.vstack([pose.origins[[0, 2, 3, 4]], pose.hub])
        chains.append(points @ rotation.T)
    return chains


def stance(stances: dict[str, tuple[dict[str, float], float, float, tuple[float, float]]]) -> bytes:
    """Side, front and top views (left limbs solid, right dashed) of each stance in the world: the
    body's hexagonal frame, each limb's links from hip to hub, the ground through the hubs.
    ``stances``: label -> (set-points, roll, pitch [rad] of the body against the ground, the ground's
    (roll, pitch) [rad]: a side slope with the valley to the right rolls it by the slope, a slope
    climbed along the heading pitches it)."""
    fig, axes = plt.subplots(len(stances), 3, figsize=(16, 4.8 * len(stances)), squeeze=False)
    for row, (label, (joints, roll, pitch, ground)) in enumerate(stances.items()):
        chains = _chains(joints, roll, pitch, ground)
        mounts = np.array([c[0] for c in chains])
        frame = mounts[[0, 1, 2, 5, 4, 3, 0]]
        for column, (a, b, title) in enumerate(((0, 2, "side view (from the left)"), (1, 2, "front view"),
                                                (0, 1, "top view"))):
            ax = axes[row][column]
            ax.plot(frame[:, a], frame[:, b], color="0.3", lw=2.5, label="body frame")
            for i, chain in enumerate(chains):
                style = "-" if i < 3 else "--"
                ax.plot(chain[:, a], chain[:, b], style, marker="o", ms=3, lw=1.5, color=f"C{i % 3}",
                        label=LIMB_NAMES[i] if column == 0 else None)
            ax.plot(0, 0, "k+", ms=12, mew=2, label="centre of gravity" if column == 0 else None)
            hubs = np.array([c[-1] for c in chains])
            if b == 2:  # the ground's line through the hubs (side view: its pitch; front view: its roll)
                along = np.linspace(hubs[:, a].min() - 0.3, hubs[:, a].max() + 0.3, 2)
                middle = hubs.mean(axis=0)
                gradient = np.tan(ground[1]) if a == 0 else np.tan(ground[0])
                ax.plot(along, middle[2] + gradient * (along - middle[a]), color="saddlebrown", lw=1,
                        alpha=0.6, label="ground (through the hubs)" if column == 0 else None)
            names = "xyz"
            ax.set_xlabel(f"{names[a]} [m] (world, x along the heading)")
            ax.set_ylabel(f"{names[b]} [m]")
            ax.set_aspect("equal")
            ax.grid(alpha=0.3)
            ax.set_title(f"{label}: {title}", fontsize=10)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=9)
    fig.suptitle("Leg-wheel rover stances (side slopes: the valley to the right; climbs: uphill ahead)")
    fig.tight_layout(rect=(0, 0.08, 1, 0.97))
    return png_bytes(fig)


def limbs(tables: dict[str, pd.DataFrame], title: str) -> bytes:
    """Per limb (a column): its joints' torques, the wheel's load, sinkage and slip against time, one
    line style per run (``tables``: label -> the run's table with ``<joint>Torque_i``, ``Fz_i``,
    ``sinkage_i``, ``slip_i``)."""
    fig, axes = plt.subplots(4, 6, figsize=(22, 12), sharex=True)
    styles = ("-", "--", ":", "-.")
    for column in range(6):
        i = column + 1
        for run, (label, table) in enumerate(tables.items()):
            style, t = styles[run % 4], table["time"]
            for k, name in enumerate(JOINT_INPUTS):
                axes[0][column].plot(*thinned(t, table[f"{name}Torque_{i}"], PANEL_POINTS), style, color=f"C{k}",
                                     lw=1, label=f"{JOINT_LABELS[k]}" if run == 0 else None)
            for row, values, color in ((1, table[f"Fz_{i}"], "C0"), (2, 1e3 * table[f"sinkage_{i}"], "C1"),
                                       (3, table[f"slip_{i}"], "C2")):
                axes[row][column].plot(*thinned(t, values, PANEL_POINTS), style, color=color, lw=1.2, label=label)
        axes[0][column].set_title(f"limb {i} ({LIMB_NAMES[column]})")
        axes[3][column].set_xlabel("time [s]")
    for ax, label in zip(axes[:, 0], ("joint torque [N·m]", "load Fz [N]", "sinkage [mm]", "slip ratio [-]")):
        ax.set_ylabel(label)
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
        ax.locator_params(nbins=4)  # four or five ticks a panel: enough for 24 panels, and a third of the drawing
    axes[0][0].legend(fontsize=7, loc="best")
    axes[1][0].legend(fontsize=7, loc="best")
    fig.suptitle(f"Leg-wheel rover, {title}: per limb (line style: run)")
    fig.subplots_adjust(left=0.045, right=0.99, bottom=0.05, top=0.93, wspace=0.28, hspace=0.12)  # the grid's
    return png_bytes(fig, tight=False)  # layout by hand: matplotlib's tight layout took a third of the figure's time

