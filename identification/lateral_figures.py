"""Figures of the lateral identification, as PNG bytes (computation stays in lateral and
lateral_validation)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from .figures import finish, png_bytes
from .fits import FIT_TORQUE_MAX
from .lateral import LateralModel, fit_points

#: N·m: the torque level of the runs drawn against beta (inside the fits at every load).
SHOWN_TORQUE = 10.0
#: deg: the slip angle of the runs drawn against slip.
SHOWN_ANGLE = 10.0


def _colors(count: int) -> np.ndarray:
    return plt.cm.viridis(np.linspace(0, 0.9, count))


def shown_torque(table: pd.DataFrame, torque_max: float) -> float:
    """The torque level of panel (a): SHOWN_TORQUE where the sweep has it, else the middle of the
    sweep's levels up to ``torque_max`` [N·m] (a plan scaled to another wheel)."""
    torques = sorted(table["torque_N_m"].unique())
    if SHOWN_TORQUE in torques:
        return SHOWN_TORQUE
    fitted = [t for t in torques if t <= torque_max] or torques
    return float(fitted[len(fitted) // 2])


def fy_against_beta_and_slip(table: pd.DataFrame, model: LateralModel, torque_max: float = FIT_TORQUE_MAX) -> bytes:
    """(a) settled Fy against beta per load at SHOWN_TORQUE (:func:`shown_torque`), with the model
    at the runs' slips; (b) settled Fy against slip per load at SHOWN_ANGLE, with the model."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.8))
    loads = sorted(table["load_N"].unique())
    used = fit_points(table, torque_max)
    torque = shown_torque(table, torque_max)
    for color, load in zip(_colors(len(loads)), loads):
        part = table[(table["load_N"] == load) & (table["torque_N_m"] == torque)].sort_values("slip_angle_deg")
        if part.empty:
            continue
        fitted = part.index.isin(used.index)
        left.plot(part["slip_angle_deg"][fitted], part["Fy_N"][fitted], "o", color=color, label=f"{load:.0f} N")
        left.plot(part["slip_angle_deg"][~fitted], part["Fy_N"][~fitted], "x", color=color)
        beta = np.linspace(0.0, part["slip_angle_deg"].max(), 121)
        slip = np.interp(beta, part["slip_angle_deg"], part["slip"])
        left.plot(beta, model.fy(load, np.radians(beta), slip), "-", color=color, lw=1)
        at_angle = used[(used["load_N"] == load) & (used["slip_angle_deg"] == SHOWN_ANGLE)].sort_values("slip")
        if len(at_angle):
            right.plot(at_angle["slip"], at_angle["Fy_N"], "o", color=color, label=f"{load:.0f} N")
            s = np.linspace(at_angle["slip"].min(), at_angle["slip"].max(), 30)
            right.plot(s, model.fy(load, np.radians(SHOWN_ANGLE), s), "-", color=color, lw=1)
    left.set_xlabel("slip angle beta [deg]")
    left.set_ylabel("Fy [N]")
    left.set_title(f"(a) settled Fy against beta at {torque:.3g} N·m (x: not fitted); lines: model")
    right.set_xlabel("slip ratio [-]")
    right.set_ylabel("Fy [N]")
    right.set_title(f"(b) settled Fy against slip at beta = {SHOWN_ANGLE:g} deg; lines: model")
    for ax in (left, right):
        ax.grid(alpha=0.3)
        ax.legend(ncol=2, fontsize=8, title="load W")
    return png_bytes(fig)


def coefficient_curves(per_load: pd.DataFrame, model: LateralModel) -> bytes:
    """Each c_ik(W): the per-load fit (points) and the identified polynomial in W (line)."""
    terms, slips, _ = model.form.shape()
    fig, axes = plt.subplots(slips, terms, figsize=(3.6 * terms, 3.0 * slips), squeeze=False)
    w = np.linspace(per_load["load_N"].min(), per_load["load_N"].max(), 100)
    scales = model.form.scales_deg
    for i in range(terms):
        for k in range(slips):
            ax = axes[k][i]
            ax.plot(per_load["load_N"], per_load[f"c{i}{k}"], "o", label="per-load fit")
            ax.plot(w, model.coefficient_at(w, i, k), "-", label=f"degree {model.form.load_degree} in W")
            ax.set_title(f"c{i}{k}: phi{i} (beta_{i} = {scales[i]:g} deg) x slip^{k}", fontsize=9)
            ax.set_xlabel("load W [N]")
            ax.set_ylabel("coefficient [N]")
            ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(f"Lateral model {model.form.name}: Fy = sum c_ik(W) phi_i(beta) slip^k")
    return png_bytes(fig)


def validation_run(run: pd.DataFrame, load: float, angle: float, label: str) -> bytes:
    """Fy(t) and slip(t) of the plant and Fy of the model in one validation run."""
    fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    axes[0].plot(run["time"], run["Fy"], "k-", label="SingleWheel.fmu (terramechanics)")
    axes[0].plot(run["time"], run[f"Fy_{label}"], "--", label=f"identified model ({label})")
    axes[1].plot(run["time"], run["slip"], "k-", label="slip [-]")
    axes[1].plot(run["time"], np.degrees(run["beta"]) / 100, ":", label="slip angle [deg] / 100")
    axes[0].set_ylabel("Fy [N]")
    axes[1].set_ylabel("slip, slip angle / 100")
    axes[1].set_xlabel("time [s]")
    axes[0].set_title(f"Lateral validation at W = {load:.0f} N, beta = ±{angle:g} deg, torque 5-40 N·m")
    finish(axes)
    return png_bytes(fig)
