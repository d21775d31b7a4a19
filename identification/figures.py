"""Figures like the paper's Figs. 5-8, as PNG bytes (computation stays in fits/validate)."""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from .fits import FIT_TORQUE_MAX, SLIP_FIT_RANGE, IdentifiedModel


def png_bytes(fig) -> bytes:
    buffer = io.BytesIO()
    fig.tight_layout()
    fig.savefig(buffer, format="png", dpi=110)
    plt.close(fig)
    return buffer.getvalue()


def fig5_fx_vs_slip(table: pd.DataFrame, per_load: pd.DataFrame) -> bytes:
    """Settled (slip, Fx) of every run and the per-load line Fx = a slip + b (Eq. 14)."""
    fig, ax = plt.subplots(figsize=(7, 5))
    colors = plt.cm.viridis(np.linspace(0, 0.9, len(per_load)))
    for color, (_, row) in zip(colors, per_load.iterrows()):
        part = table[table["load_N"] == row["load_N"]]
        used = (part["torque_N_m"] <= FIT_TORQUE_MAX) & part["slip"].between(*SLIP_FIT_RANGE)
        ax.plot(part["slip"][used], part["Fx_N"][used], "o", color=color, label=f"{row['load_N']:.0f} N")
        ax.plot(part["slip"][~used], part["Fx_N"][~used], "x", color=color)
        s = np.linspace(part["slip"][used].min(), part["slip"][used].max(), 20)
        ax.plot(s, row["c1"] * s + row["c0"], "-", color=color)
    ax.set_xlabel("slip ratio [-]")
    ax.set_ylabel("Fx [N]")
    ax.set_title("Fig. 5: settled Fx against slip (x: not fitted) and Fx = a(W) slip + b(W)")
    ax.legend(ncol=2, fontsize=8)
    ax.grid(alpha=0.3)
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


def fig8_validation(run: pd.DataFrame, load: float, labels: list[str]) -> bytes:
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    axes[0].plot(run["time"], run["Fx"], "k-", label="SingleWheel.fmu (terramechanics)")
    axes[1].plot(run["time"], run["slip"], "k-", label="SingleWheel.fmu")
    for label, style in zip(labels, ("--", ":")):
        axes[0].plot(run["time"], run[f"Fx_{label}"], style, label=f"identified model ({label})")
        axes[1].plot(run["time"], run[f"slip_{label}"], style, label=f"identified model ({label})")
    axes[0].set_ylabel("Fx [N]")
    axes[1].set_ylabel("slip [-]")
    axes[1].set_xlabel("time [s]")
    axes[0].set_title(f"Fig. 8: torque staircase 5-40 N·m at W = {load:.0f} N")
    for ax in axes:
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    return png_bytes(fig)
