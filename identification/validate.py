"""Validation of the identified model at loads off the LUT grid (275, 575, 875 N, Table 1).

Per load, the FMU runs a torque staircase, starting rolling at 1.0 m/s, through the rover's torque range
(5, 10, 15, 20, 30, 40 N·m, each held 0.1 s); the identified model gets the same torque. The
Fit of Eq. (15) on Fx(t) over the whole staircase is the load's figure (one step alone barely
varies after its first millisecond, which would make Eq. (15) measure the settled error only).
Per torque level: the settled Fx and slip of plant and model.
"""

from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from rover_cosim.common.paper import TABLE_1_FIT, TARGET_VELOCITY

from .fits import IdentifiedModel, fit_percent
from .testbed import TorqueProfile, WheelTestBed

VALIDATION_LOADS = (275.0, 575.0, 875.0)
VALIDATION_TORQUES = (5.0, 10.0, 15.0, 20.0, 30.0, 40.0)
HOLD = 0.1          # s per torque level
SAMPLE_TIME = 1e-3  # s
PAPER_FIT = TABLE_1_FIT  # Table 1 [%]
#: m/s: the staircase starts rolling at the rover's target speed, as the identification runs do
#: (identification.sweep.SweepPlan.start_speed), where the paper's model applies.
START_SPEED = TARGET_VELOCITY


@dataclass
class Validation:
    runs: dict[float, pd.DataFrame]   # per load: time, tau, plant columns, slip_model, Fx_model
    fit: pd.DataFrame                 # load_N, fit_percent, ...
    detail: pd.DataFrame              # per load and torque level


def staircase(torques: tuple[float, ...] = VALIDATION_TORQUES) -> TorqueProfile:
    """The validation staircase through ``torques`` [N·m], each held HOLD."""
    return TorqueProfile.staircase(tuple(torques), HOLD)


def validate(bed: WheelTestBed, models: dict[str, IdentifiedModel],
             loads: tuple[float, ...] = VALIDATION_LOADS,
             torques: tuple[float, ...] = VALIDATION_TORQUES) -> Validation:
    """``models`` by label (e.g. "linear", "quadratic"); the first is the one reported as
    ``fit_percent``, each also gets its own column. ``loads`` [N] and ``torques`` [N·m]: the
    plan's (the paper's Table 1 by default)."""
    profile = staircase(torques)
    stop = HOLD * len(torques) - SAMPLE_TIME
    runs, fits, detail = {}, [], []
    for load in loads:
        run = bed.run(load, profile, stop, SAMPLE_TIME, start_speed=START_SPEED)
        time, torque = run["time"].to_numpy(), run["tau"].to_numpy()
        row: dict[str, float | str] = {"load_N": load}
        for i, (label, model) in enumerate(models.items()):
            slip = model.slip_response(load, time, torque)
            fx = model.fx(load, slip)
            run[f"slip_{label}"] = slip
            run[f"Fx_{label}"] = fx
            value = fit_percent(fx, run["Fx"].to_numpy())
            if i == 0:
                row["fit_percent"] = value
            row[f"fit_percent_{label}"] = value
            row[f"slip_fit_percent_{label}"] = fit_percent(slip, run["slip"].to_numpy())
        row["paper_fit_percent"] = PAPER_FIT.get(load, float("nan"))
        fits.append(row)
        for level_index, level in enumerate(torques):
            segment = (time >= level_index * HOLD + HOLD / 2) & (time < (level_index + 1) * HOLD)
            entry = {"load_N": load, "torque_N_m": level, "Fx_plant_N": float(run["Fx"][segment].mean()),
                     "slip_plant": float(run["slip"][segment].mean())}
            for label in models:
                entry[f"Fx_{label}_N"] = float(run[f"Fx_{label}"][segment].mean())
                entry[f"slip_{label}"] = float(run[f"slip_{label}"][segment].mean())
            detail.append(entry)
        runs[load] = run
    return Validation(runs, pd.DataFrame(fits), pd.DataFrame(detail))
