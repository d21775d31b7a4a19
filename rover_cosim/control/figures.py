"""Fig. 10 (a)-(h) of the paper as PNG bytes: the limbs of one side (1-3 on the paper's rover) of a
closed-loop run; the other side mirrors them."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pandas as pd

from rover_cosim.common.figures import render, thinned
from rover_cosim.common.rows import indices

#: Line styles of limbs 1-3: curves that coincide (the limbs share one Fx_des, and their forces
#: follow it closely) stay visible as dashes and dots over the solid line.
STYLES = {1: dict(ls="-", lw=2.2), 2: dict(ls="--", lw=1.6), 3: dict(ls=":", lw=1.6)}


def _style(i: int) -> dict:
    """The line style of limb ``i`` (limbs past 3: dash-dot)."""
    return STYLES.get(i, dict(ls="-.", lw=1.4))


def one_side(table: pd.DataFrame) -> list[int]:
    """The limbs of the left side of a run's table: the first half of its ``tau_i`` (1-3 of six)."""
    limbs = list(indices(table.columns, "tau"))
    return limbs[:max(1, len(limbs) // 2)]


def _side_label(table: pd.DataFrame) -> str:
    side, limbs = one_side(table), list(indices(table.columns, "tau"))
    first = f"{side[0]}-{side[-1]}" if len(side) > 1 else f"{side[0]}"
    rest = limbs[len(side):]
    other = (f"{rest[0]}-{rest[-1]}" if len(rest) > 1 else f"{rest[0]}") if rest else ""
    return f"limbs {first}" + (f"; {other} mirror them" if other else "")
#: (column, panel title, y-axis label with its unit)
PANELS = (("tau", "(a) wheel torque", "τ [N·m]"), ("Tx", "(b) resistance torque", "T_x [N·m]"),
          ("Fz", "(c) vertical force", "F_z [N]"), ("sinkage", "(d) sinkage", "h [m]"),
          ("slip", "(e) slip ratio", "κ [-]"), ("Fx", "(f) longitudinal force", "F_x [N]"))


def fig10(table: pd.DataFrame, plant: str) -> bytes:
    fig, axes = plt.subplots(4, 2, figsize=(11, 12), sharex=True, layout="constrained")
    flat = axes.ravel()
    for ax, (name, title, label) in zip(flat, PANELS):
        for i in one_side(table):
            ax.plot(*thinned(table["time"], table[f"{name}_{i}"]), label=f"limb {i}", **_style(i))
        ax.set_title(title)
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
    flat[6].plot(*thinned(table["time"], table["v"]), "k-", label="v")
    flat[6].axhline(1.0, color="gray", ls=":", label="target 1.0 m/s")
    flat[6].set_title("(g) rover velocity")
    flat[6].set_ylabel("v [m/s]")
    flat[6].legend(fontsize=8)
    flat[7].plot(*thinned(table["time"], table["Fx_1"]), label="Fx limb 1")
    flat[7].plot(*thinned(table["time"], table["Fx_des_1"]), "--", label="Fx_des limb 1")
    flat[7].set_title("(h) actual and desired Fx, limb 1")
    flat[7].set_ylabel("F_x [N]")
    flat[7].legend(fontsize=8)
    for ax in flat:
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    fig.suptitle(f"Fig. 10: closed-loop rover ({plant}), inverse identified model per wheel "
                 f"({_side_label(table)})")
    return _png(fig)


def tracking(mono: pd.DataFrame, cosim: pd.DataFrame, mono_label: str = "Rover.fmu",
             cosim_label: str = "RoverBody + 6 Wheel") -> bytes:
    """(a) position x against the target x_t = t; (b) x - x_t; (c) Fx - Fx_des per limb;
    (d) the co-simulated plant minus the monolithic one (velocity and loads)."""
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), sharex=True)
    time = mono["time"]
    axes[0][0].plot(*thinned(time, mono["x"]), label=f"x, {mono_label}", lw=2)
    axes[0][0].plot(*thinned(time, cosim["x"]), "--", label=f"x, {cosim_label}")
    axes[0][0].plot(*thinned(time, time * 1.0), ":", color="k", label="target x_t = 1.0 m/s · t")
    axes[0][0].set_title("(a) position [m]")
    axes[0][1].plot(*thinned(time, mono["x"] - time), label=mono_label, lw=2)
    axes[0][1].plot(*thinned(time, cosim["x"] - time), "--", label=cosim_label)
    axes[0][1].set_title("(b) position lag x - x_t [m]")
    side = one_side(mono)
    for i in side:
        axes[1][0].plot(*thinned(time, mono[f"Fx_{i}"] - mono[f"Fx_des_{i}"]), label=f"limb {i}", **_style(i))
    axes[1][0].set_title(f"(c) force error Fx - Fx_des, {mono_label} [N]")
    axes[1][1].plot(*thinned(time, 1000 * (cosim["v"] - mono["v"])), label="velocity [mm/s]", lw=2)
    for i in sorted({side[0], side[-1]}):
        axes[1][1].plot(*thinned(time, cosim[f"Fz_{i}"] - mono[f"Fz_{i}"]), label=f"load, limb {i} [N]", **_style(i))
    axes[1][1].set_title("(d) co-simulated minus monolithic")
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    fig.suptitle("Closed loop: position tracking, force error, and the two plants against each other")
    return _png(fig)


def _png(fig) -> bytes:  # noqa: ANN001 - a matplotlib Figure
    if fig.get_layout_engine() is None:  # a figure laid out as it was made keeps its layout
        fig.tight_layout()
    rendered = render(fig, 100)
    plt.close(fig)
    return rendered
