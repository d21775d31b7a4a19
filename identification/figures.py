"""Figures like the paper's Figs. 5-8, as PNG bytes (computation stays in fits/validate)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.lines import Line2D

from rover_cosim.common.figures import render

from .fits import FIT_TORQUE_MAX, SLIP_FIT_RANGE, IdentifiedModel


def finish(axes, legend: bool = True) -> None:  # noqa: ANN001 - matplotlib Axes
    """Grid (and legend) on every axis of a figure."""
    for ax in np.atleast_1d(axes).ravel():
        if legend:
            ax.legend(fontsize=8)
        ax.grid(alpha=0.3)


def png_bytes(fig, tight: bool = True) -> bytes:
    """The figure as PNG (110 dpi, or the --dpi asked for), with the other --figures formats attached;
    ``tight``: laid out by matplotlib's tight layout first (a figure laid out by hand skips its cost)."""
    if tight:
        fig.tight_layout()
    rendered = render(fig, 110)
    plt.close(fig)
    return rendered


def fig5_fx_vs_slip(table: pd.DataFrame, per_load: pd.DataFrame, soil: str = "") -> bytes:
    """Settled (slip, Fx) of the fitted runs and the per-load line Fx = a slip + b (Eq. 14), over
    the fitted range of slip (the runs left out, spun out or beyond the rover's torques, are
    counted in the title, not drawn: they would stretch the axis to slip 1)."""
    fig, ax = plt.subplots(figsize=(8, 5.5))
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(per_load)))
    fitted_slips, left_out = [], 0
    for color, (_, row) in zip(colors, per_load.iterrows()):
        part = table[table["load_N"] == row["load_N"]]
        used = (part["torque_N_m"] <= FIT_TORQUE_MAX) & part["slip"].between(*SLIP_FIT_RANGE)
        if "rolling" in part:
            used &= part["rolling"].astype(bool)
        left_out += int((~used).sum())
        fitted_slips += list(part["slip"][used])
        ax.plot(part["slip"][used], part["Fx_N"][used], "o", color=color, label=f"{row['load_N']:.0f} N")
        s = np.linspace(part["slip"][used].min(), part["slip"][used].max(), 20)
        ax.plot(s, row["c1"] * s + row["c0"], "-", color=color)
    span = max(fitted_slips) - min(fitted_slips)
    ax.set_xlim(min(fitted_slips) - 0.05 * span, max(fitted_slips) + 0.05 * span)
    handles, labels = ax.get_legend_handles_labels()
    handles += [Line2D([], [], marker="o", ls="", color="0.3"), Line2D([], [], ls="-", color="0.3")]
    labels += ["settled run (fitted)", "Fx = a(W) slip + b(W)"]
    ax.legend(handles, labels, ncol=2, fontsize=8, title="load W")
    ax.set_xlabel("slip ratio [-]")
    ax.set_ylabel("Fx [N]")
    ax.set_title(f"Fig. 5: settled Fx against slip over the fitted range ({left_out} runs outside it not drawn)"
                 + (f"\n{soil}" if soil else ""), fontsize=10)
    ax.grid(alpha=0.3)
    return png_bytes(fig)


def fig_model_coefficients(per_load: pd.DataFrame, model: IdentifiedModel) -> bytes:
    """The recommended model's c_k(W) (Fx = sum c_k(W) slip^k): per-load fits and the quadratics in W."""
    fig, axes = plt.subplots(1, model.degree + 1, figsize=(4.2 * (model.degree + 1), 3.8))
    w = np.linspace(per_load["load_N"].min(), per_load["load_N"].max(), 100)
    for k, ax in enumerate(np.atleast_1d(axes)):
        ax.plot(per_load["load_N"], per_load[f"c{k}"], "o", label="per-load fit")
        ax.plot(w, np.polyval(model.fx_coefficients[k][::-1], w), "-", label="quadratic in W (the model)")
        ax.set_xlabel("load W [N]")
        ax.set_ylabel(f"c{k} [N]")
        ax.set_title(f"c{k}(W): coefficient of slip^{k}", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Recommended model: Fx = sum c_k(W) slip^k, k = 0..{model.degree}")
    return png_bytes(fig)


def fig_coefficient(per_load: pd.DataFrame, model: IdentifiedModel, k: int, name: str, unit: str, title: str) -> bytes:
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(per_load["load_N"], per_load[f"c{k}"], "o", label="per-load fit")
    w = np.linspace(per_load["load_N"].min(), per_load["load_N"].max(), 100)
    ax.plot(w, np.polyval(model.fx_coefficients[k][::-1], w), "-", label="quadratic in W")
    ax.set_xlabel("load W [N]")
    ax.set_ylabel(f"{name} [{unit}]")
    ax.set_title(title)
    ax.legend()
    ax.grid(alpha=0.3)
    return png_bytes(fig)


def fig8_validation(run: pd.DataFrame, load: float, labels: list[str], soil: str = "") -> bytes:
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    axes[0].plot(run["time"], run["Fx"], "k-", label="SingleWheel.fmu (terramechanics)")
    axes[1].plot(run["time"], run["slip"], "k-", label="SingleWheel.fmu")
    for label, style in zip(labels, ("--", ":")):
        axes[0].plot(run["time"], run[f"Fx_{label}"], style, label=f"identified model ({label})")
        axes[1].plot(run["time"], run[f"slip_{label}"], style, label=f"identified model ({label})")
    axes[0].set_ylabel("Fx [N]")
    axes[1].set_ylabel("slip [-]")
    axes[1].set_xlabel("time [s]")
    axes[0].set_title(f"Fig. 8: torque staircase 5-40 N·m at W = {load:.0f} N" + (f", {soil}" if soil else ""))
    finish(axes)
    return png_bytes(fig)
