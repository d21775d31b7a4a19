"""Paper Fig. 3: longitudinal force against slip ratio for wheel loads 100 ... 800 N.

Computation (``fig3_table``), drawing (``fig3_figure``) and writing (``write_fig3``) are kept
apart; only ``write_fig3`` touches the file system, and it writes all of its files or none.
"""

from __future__ import annotations

import io
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.common.paper import LOADS as PAPER_LOADS
from rover_cosim.terramechanics import Soil, Wheel, wheel_state
from rover_cosim.terramechanics.library import Choice, choose, describe

CSV_NAME = "fig3_fx_vs_slip.csv"
PNG_NAME = "fig3_fx_vs_slip.png"
RECORD_NAME = "fig3_fx_vs_slip.json"
COLUMNS = ["load_N", "slip", "sinkage_m", "Fx_N", "Fz_N", "Tx_Nm"]


def slip_grid(step: float, last: float = 0.9) -> tuple[float, ...]:
    """Slip ratios 0, step, ..., last [-] (``last`` included, rounded to 10 decimals)."""
    count = int(round(last / step)) + 1
    return tuple(float(k) for k in np.round(np.linspace(0.0, last, count), 10))


PAPER_SLIPS = slip_grid(0.01)  # [-]


def fig3_table(loads: tuple[float, ...] = PAPER_LOADS, slips: tuple[float, ...] = PAPER_SLIPS,
               wheel: Wheel = Wheel(), soil: Soil = Soil()) -> pd.DataFrame:
    """Wheel state at every (load [N], slip [-]) pair, one row each, columns ``COLUMNS``."""
    state = wheel_state(np.asarray(loads, dtype=float)[:, None], np.asarray(slips, dtype=float)[None, :],
                        wheel, soil)
    return pd.DataFrame({
        "load_N": state.load.ravel(), "slip": state.slip.ravel(), "sinkage_m": state.sinkage.ravel(),
        "Fx_N": state.Fx.ravel(), "Fz_N": state.Fz.ravel(), "Tx_Nm": state.Tx.ravel(),
    }, columns=COLUMNS)


def fig3_figure(table: pd.DataFrame) -> Figure:
    """Fx against slip ratio, one curve per load, labelled as the paper's Fig. 3."""
    figure = Figure(figsize=(7.2, 4.8), dpi=150)
    axes = figure.add_subplot()
    loads = sorted(table["load_N"].unique())
    for load in loads:
        curve = table[table["load_N"] == load].sort_values("slip")
        axes.plot(curve["slip"], curve["Fx_N"], label=f"W = {load:g} N")
    axes.set_xlabel("Slip ratio κ [-]")
    axes.set_ylabel("Longitudinal force $F_x$ [N]")
    axes.set_title("Slip ratio and longitudinal force for wheel loads "
                   f"{loads[0]:g}–{loads[-1]:g} N", fontsize=10)
    axes.grid(True, alpha=0.3)
    handles, labels = axes.get_legend_handles_labels()
    axes.legend(handles[::-1], labels[::-1], loc="center left", bbox_to_anchor=(1.01, 0.5),
                fontsize=8, title="Wheel load", title_fontsize=8)
    figure.tight_layout()
    return figure


def write_fig3(out_dir: Path, loads: tuple[float, ...] = PAPER_LOADS,
               slips: tuple[float, ...] = PAPER_SLIPS, choice: Choice | None = None) -> list[Path]:
    """Compute, draw and write Fig. 3 (CSV, PNG and a JSON run record) into ``out_dir``, on the
    soil and wheel of ``choice`` (default: the paper's)."""
    choice = choice or choose()
    wheel, soil = choice.wheel, choice.soil
    table = fig3_table(loads, slips, wheel, soil)
    png = io.BytesIO()
    fig3_figure(table).savefig(png, format="png")
    parameters = {"loads_N": list(loads), "slips": list(slips), "wheel": asdict(wheel), "soil": asdict(soil),
                  "choice": describe(choice)}
    files = {
        out_dir / CSV_NAME: table.to_csv(index=False, float_format="%.10g").encode(),
        out_dir / PNG_NAME: png.getvalue(),
        out_dir / RECORD_NAME: json_bytes(run_record("rover-cosim fig3", parameters)),
    }
    write_all(files)
    return list(files)
