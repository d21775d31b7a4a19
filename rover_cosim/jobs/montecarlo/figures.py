"""Figures of a Monte Carlo study as PNG bytes (computation stays in metrics and sensitivity):
the outputs' distributions, the sensitivity ranking, and the worst-limb force error against
each parameter."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

from rover_cosim.identification.figures import finish, png_bytes

from .metrics import RMS_FLOOR
from .sensitivity import OUTPUTS

DISTRIBUTIONS = ("rms_Fx_max_N", "time_to_98_s", "position_lag_m", "max_slip")


def _ecdf(ax, values: np.ndarray, label: str) -> None:  # noqa: ANN001 - matplotlib Axes
    """The share of ``values`` at or below x: 0 up to the smallest, a step of 1/n at each value
    (NaN, never, counts in n: the curve then ends below 1)."""
    finite = np.sort(values[np.isfinite(values)])
    share = np.arange(1, len(finite) + 1) / max(len(values), 1)
    if finite.size:  # the rise from 0 at the smallest value: the first run is a step, not the curve's start
        finite, share = np.r_[finite[0], finite], np.r_[0.0, share]
    ax.step(finite, share, where="post", lw=2, label=label)
    ax.margins(x=0.05)


def distributions(runs: pd.DataFrame, nominal: pd.Series | None) -> bytes:
    """ECDFs of the worst-limb RMS, time to 0.98 m/s, position lag and max slip over the
    completed straight runs, with the nominal run and the paper's 1 N floor marked."""
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    for ax, column in zip(axes.ravel(), DISTRIBUTIONS):
        values = runs[column].to_numpy(float)
        _ecdf(ax, values, f"{len(values)} runs")
        if nominal is not None and np.isfinite(nominal[column]):
            ax.axvline(nominal[column], color="k", ls="--", lw=1.3, label="nominal soil (sample 0)")
        if column == "rms_Fx_max_N":
            ax.axvline(RMS_FLOOR, color="tab:red", ls=":", lw=1.8, label="paper's floor, 1 N")
            if np.nanmax(values, initial=0) > 10 * max(np.nanmin(values, initial=1), 1e-3):
                ax.set_xscale("log")
        never = int(np.isnan(values).sum())
        if column == "time_to_98_s" and never:
            ax.set_title(f"{never} of {len(values)} runs never reach 0.98 m/s (the curve ends below 1)", fontsize=10)
        ax.set_xlabel(OUTPUTS[column])
        ax.set_ylabel("share of runs ≤ x [-]")
        ax.set_ylim(0, 1.02)
    finish(axes)
    fig.suptitle("Monte Carlo over the soil: distributions of the closed loop's outcomes (straight run)")
    return png_bytes(fig)


def ranking(table: pd.DataFrame, labels: dict[str, str]) -> bytes:
    """Horizontal bars per parameter: the PRCC (monotonic effect) and the rank correlation with the
    distance from the nominal value (V-shaped effect), for the worst-limb RMS and the position lag."""
    shown = [o for o in ("rms_Fx_max_N", "position_lag_m") if o in set(table["output"])]
    first = table[table["output"] == shown[0]].sort_values("rank", ascending=False) if shown else table
    parameters = list(first["parameter"])
    bars = [(o, m) for o in shown for m in ("prcc", "distance_spearman")]
    fig, ax = plt.subplots(figsize=(10, 1.5 + 0.32 * len(parameters) * max(len(bars), 1)))
    height = 0.84 / max(len(bars), 1)
    colours = {"rms_Fx_max_N": "tab:blue", "position_lag_m": "tab:orange"}
    for k, (output, measure) in enumerate(bars):
        values = table[table["output"] == output].set_index("parameter").loc[parameters, measure]
        what = "PRCC (monotonic)" if measure == "prcc" else "ρ with distance from nominal"
        ax.barh(np.arange(len(parameters)) - (k - (len(bars) - 1) / 2) * height, values, height=height,
                color=colours[output], alpha=1.0 if measure == "prcc" else 0.45,
                hatch="" if measure == "prcc" else "//", label=f"{OUTPUTS[output]}: {what}")
    ax.set_yticks(np.arange(len(parameters)), [labels.get(p, p) for p in parameters])
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_xlim(-1, 1)
    ax.set_xlabel("rank correlation [-]: > 0 the output grows with the parameter (or with its distance from nominal)")
    ax.set_title("Sensitivity ranking, most influential on the largest RMS at the top")
    finish(ax)
    ax.legend(fontsize=8, loc="lower left")
    return png_bytes(fig)


def scatter(runs: pd.DataFrame, parameters: list[str], labels: dict[str, str], nominal: pd.Series | None,
            logarithmic: set[str]) -> bytes:
    """The worst-limb RMS(Fx - Fx_des) against each parameter, stuck runs marked."""
    columns = min(3, len(parameters))
    rows = math.ceil(len(parameters) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.4 * rows), squeeze=False)
    stuck = runs["stuck"].astype(bool).to_numpy()
    errors = runs["rms_Fx_max_N"].to_numpy(float)
    spread = bool(np.nanmax(errors, initial=0) > 10 * max(np.nanmin(errors, initial=1), 1e-3))   # log y
    for ax, name in zip(axes.ravel(), parameters):
        ax.scatter(runs.loc[~stuck, name], runs.loc[~stuck, "rms_Fx_max_N"], s=14, alpha=0.7, label="runs")
        if stuck.any():
            ax.scatter(runs.loc[stuck, name], runs.loc[stuck, "rms_Fx_max_N"], s=22, marker="x", color="tab:red",
                       label="stuck")
        if nominal is not None:
            ax.scatter([nominal[name]], [nominal["rms_Fx_max_N"]], s=80, marker="*", color="k", zorder=5,
                       label="nominal")
        ax.axhline(RMS_FLOOR, color="tab:red", ls=":", lw=1.5, label="1 N")
        if name in logarithmic:
            ax.set_xscale("log")
            values = runs[name].to_numpy(float)
            ax.xaxis.set_minor_formatter(NullFormatter())  # the minor labels of a log axis overlap
            if np.nanmax(values) < 10 * np.nanmin(values):  # less than a decade: 1-2-5 steps, labelled, few
                ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0), numticks=6))
                ax.xaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:.2g}"))
        if spread:
            ax.set_yscale("log")
        ax.set_xlabel(labels.get(name, name))
        ax.set_ylabel("largest RMS(Fx - Fx_des) [N]")
    for ax in axes.ravel()[len(parameters):]:
        ax.set_visible(False)
    finish(axes.ravel()[:1])
    finish(axes.ravel()[1:len(parameters)], legend=False)
    fig.suptitle("Worst-limb force error against each uncertain parameter (straight run)")
    return png_bytes(fig)


def adaptation(plain: pd.DataFrame, adapted: pd.DataFrame, calibration: float) -> bytes:
    """ECDFs of the worst-limb RMS(Fx - Fx_des) after the calibration phase, with the controller
    identified on the nominal soil and with the adaptive one, over the same samples; and the
    whole-run RMS of both (the calibration's own cost)."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    panels = ((axes[0], "rms_Fx_max_after_calibration_N", f"after the calibration (t ≥ {calibration:g} s)"),
              (axes[1], "rms_Fx_max_N", "over the whole run (calibration included)"))
    for ax, column, title in panels:
        for runs, label in ((plain, "identified on the nominal soil"), (adapted, "adaptive (soil estimated)")):
            values = runs[column].to_numpy(float)
            share = float(np.mean(values <= RMS_FLOOR)) if len(values) else float("nan")
            _ecdf(ax, values, f"{label}: {100 * share:.0f} % ≤ 1 N ({len(values)} runs)")
        ax.axvline(RMS_FLOOR, color="tab:red", ls=":", lw=1.8, label="paper's floor, 1 N")
        ax.set_xscale("log")
        ax.set_xlabel("largest RMS(Fx - Fx_des) of the six limbs [N]")
        ax.set_ylabel("share of runs ≤ x [-]")
        ax.set_ylim(0, 1.02)
        ax.set_title(title, fontsize=11)
    finish(axes)
    return png_bytes(fig)
