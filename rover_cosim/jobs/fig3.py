"""Paper Fig. 3: longitudinal force against slip ratio for wheel loads 100 ... 800 N.

Computation (``fig3_table``), drawing (``fig3_figure``) and writing (``write_fig3``) are kept
apart; only ``write_fig3`` touches the file system, and it writes all of its files or none.
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from rover_cosim.common.figures import render
from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.common.paper import LOADS as PAPER_LOADS
from rover_cosim.terramechanics import Soil, Wheel, wheel_state
from rover_cosim.terramechanics.library import Choice, as_choice, describe, soil_label

CSV_NAME = "fig3_fx_vs_slip.csv"
PNG_NAME = "fig3_fx_vs_slip.png"
RECORD_NAME = "fig3_fx_vs_slip.json"
COLUMNS = ["load_N", "slip", "sinkage_m", "Fx_N", "Fz_N", "Tx_Nm"]
STEM = "fig3_fx_vs_slip"
#: Most (load, slip) points Fig. 3 computes (a grid beyond it is refused before any memory is taken).
MAX_POINTS = 1_000_000


def file_names(choice: Choice) -> dict[str, str]:
    """The names of Fig. 3's files for ``choice``: fig3_fx_vs_slip.* on the paper's soil and wheel,
    fig3_fx_vs_slip_<soil>[_<wheel>][_set-<digest>].* otherwise, so that several soils share a folder."""
    suffix = ""
    if choice.soil_name != "paper":
        suffix += f"_{_safe(choice.soil_name)}"
    if choice.wheel_name != "paper":
        suffix += f"_{_safe(choice.wheel_name)}"
    if choice.overrides:
        import hashlib

        suffix += "_set-" + hashlib.sha256("\n".join(choice.overrides).encode()).hexdigest()[:8]
    return {kind: f"{STEM}{suffix}.{kind}" for kind in ("csv", "png", "json")}


def _safe(name: str) -> str:
    import re

    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)


def slip_grid(step: float, last: float = 0.9, first: float = 0.0) -> tuple[float, ...]:
    """Slip ratios first, first + step, ..., last [-] (both ends included, the spacing adjusted;
    rounded to 10 decimals). Negative slip: braking."""
    if step > last - first:
        raise ValueError(f"slip step={step!r}: expected at most the range's width {last - first:g}")
    count = int(round((last - first) / step)) + 1
    if count > MAX_POINTS:
        raise ValueError(f"slip step {step!r} makes {count:,} slips from {first:g} to {last:g}: more than the "
                         f"{MAX_POINTS:,} points Fig. 3 computes (a larger --slip-step)")
    return tuple(float(k) for k in np.round(np.linspace(first, last, count), 10))


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


def fig3_figure(table: pd.DataFrame, soil: str = "the paper's soil and wheel") -> Figure:
    """Fx against slip ratio, one curve per load, labelled as the paper's Fig. 3; ``soil`` names
    the soil and wheel in the title."""
    figure = Figure(figsize=(7.2, 4.8), dpi=150)
    axes = figure.add_subplot()
    loads = sorted(table["load_N"].unique())
    for load in loads:
        curve = table[table["load_N"] == load].sort_values("slip")
        axes.plot(curve["slip"], curve["Fx_N"], label=f"W = {load:g} N")
    axes.set_xlabel("Slip ratio κ [-]")
    axes.set_ylabel("Longitudinal force $F_x$ [N]")
    axes.set_title("Slip ratio and longitudinal force for wheel loads "
                   f"{loads[0]:g}–{loads[-1]:g} N\n{soil}", fontsize=10)
    if table["slip"].min() < 0:
        axes.axvline(0.0, color="0.5", lw=0.8)
        axes.text(0.02, 0.95, "braking ← | → driving", transform=axes.transAxes, fontsize=8, color="0.3", va="top")
    axes.grid(True, alpha=0.3)
    handles, labels = axes.get_legend_handles_labels()
    axes.legend(handles[::-1], labels[::-1], loc="center left", bbox_to_anchor=(1.01, 0.5),
                fontsize=8, title="Wheel load", title_fontsize=8)
    figure.tight_layout()
    return figure


def write_fig3(out_dir: Path, loads: tuple[float, ...] = PAPER_LOADS,
               slips: tuple[float, ...] = PAPER_SLIPS, choice: Choice | Soil | Wheel | None = None) -> list[Path]:
    """Compute, draw and write Fig. 3 (CSV, PNG and a JSON run record) into ``out_dir``, on the
    soil and wheel of ``choice`` (default: the paper's)."""
    choice = as_choice(choice)
    if len(loads) * len(slips) > MAX_POINTS:
        raise ValueError(f"{len(loads)} loads x {len(slips)} slips = {len(loads) * len(slips):,} wheel states: more "
                         f"than the {MAX_POINTS:,} Fig. 3 computes (fewer loads, or a larger --slip-step)")
    wheel, soil = choice.wheel, choice.soil
    table = fig3_table(loads, slips, wheel, soil)
    png = render(fig3_figure(table, soil_label(choice)), 150)
    parameters = {"loads_N": list(loads), "slips": list(slips), "wheel": asdict(wheel), "soil": asdict(soil),
                  "choice": describe(choice)}
    names = file_names(choice)
    files = {
        out_dir / names["csv"]: table.to_csv(index=False, float_format="%.10g").encode(),
        out_dir / names["png"]: png,
        out_dir / names["json"]: json_bytes(run_record("rover-cosim fig3", parameters)),
    }
    write_all(files, folder=out_dir)  # results/ itself is shared: renamed file by file there
    return list(files)
