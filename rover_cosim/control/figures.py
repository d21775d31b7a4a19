"""Fig. 10 (a)-(h) of the paper as PNG bytes: limbs 1-3 of a closed-loop run."""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pandas as pd

PANELS = (("tau", "(a) wheel torque [N·m]"), ("Tx", "(b) resistance torque [N·m]"), ("Fz", "(c) vertical force [N]"),
          ("sinkage", "(d) sinkage [m]"), ("slip", "(e) slip ratio [-]"), ("Fx", "(f) longitudinal force [N]"))


def fig10(table: pd.DataFrame, plant: str) -> bytes:
    fig, axes = plt.subplots(4, 2, figsize=(11, 12), sharex=True)
    flat = axes.ravel()
    for ax, (name, title) in zip(flat, PANELS):
        for i in (1, 2, 3):
            ax.plot(table["time"], table[f"{name}_{i}"], label=f"limb {i}")
        ax.set_title(title)
        ax.legend(fontsize=8)
    flat[6].plot(table["time"], table["v"], "k-")
    flat[6].axhline(1.0, color="gray", ls=":")
    flat[6].set_title("(g) rover velocity [m/s]")
    flat[7].plot(table["time"], table["Fx_1"], label="Fx limb 1")
    flat[7].plot(table["time"], table["Fx_des_1"], "--", label="Fx_des limb 1")
    flat[7].set_title("(h) actual and desired Fx, limb 1 [N]")
    flat[7].legend(fontsize=8)
    for ax in flat:
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    fig.suptitle(f"Fig. 10: closed-loop rover ({plant}), inverse identified model per wheel")
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    plt.close(fig)
    return buffer.getvalue()
