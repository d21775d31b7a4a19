"""Validation of the identified lateral model at loads and slip angles off the sweep's grid
(275, 575, 875 N; 7.5 and 12.5 deg), by Eq. (15) as Table 1.

Per (load, angle) the test bed runs, rolling from 1.0 m/s, the torque staircase of the
longitudinal validation (5-40 N·m, each held 0.1 s) while the carriage's track turns between
+angle and -angle every half level (SingleWheel's input ``trackAngle``). The model gets the
run's load, slip angle and slip (its inputs; the controller knows the slip it commands) and
Eq. (15) compares its Fy(t) with the plant's over the whole run. The sign changes make Fy(t)
swing by twice its size, so the Fit measures the model's error against the force itself (90 %:
an RMS error of about a tenth of |Fy|), not against the small changes of Fy with slip within
one angle. Per segment: the settled Fy of plant and model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .fits import fit_percent
from .lateral import LateralModel
from .testbed import Staircase, WheelTestBed
from .validate import HOLD, SAMPLE_TIME, START_SPEED, VALIDATION_LOADS, VALIDATION_TORQUES, staircase

LATERAL_VALIDATION_ANGLES_DEG = (7.5, 12.5)


@dataclass
class LateralValidation:
    runs: dict[tuple[float, float], pd.DataFrame]  # per (load, angle): the run and Fy_<model> columns
    fit: pd.DataFrame      # load_N, slip_angle_deg, fit_percent (first model), fit_percent_<label>
    detail: pd.DataFrame   # per (load, angle, segment): settled slip, beta, Fy of plant and models


def track_turns(angle: float, levels: int) -> Staircase:
    """+angle, -angle [rad], each for half a torque level, over ``levels`` levels."""
    return Staircase.staircase(tuple(angle * (1 if i % 2 == 0 else -1) for i in range(2 * levels)), HOLD / 2)


def validate_lateral(bed: WheelTestBed, models: dict[str, LateralModel], loads: tuple[float, ...] = VALIDATION_LOADS,
                     angles_deg: tuple[float, ...] = LATERAL_VALIDATION_ANGLES_DEG,
                     torques: tuple[float, ...] = VALIDATION_TORQUES) -> LateralValidation:
    """``models`` by label; the first is reported as ``fit_percent``. ``loads`` [N] and
    ``torques`` [N·m]: the plan's (the paper's by default)."""
    torque = staircase(torques)
    levels = len(torque.levels)
    stop = HOLD * levels - SAMPLE_TIME
    runs, fits, detail = {}, [], []
    for load in loads:
        for angle in angles_deg:
            run = bed.run(load, torque, stop, SAMPLE_TIME, start_speed=START_SPEED,
                          track_angle=track_turns(math.radians(angle), levels))
            row: dict[str, float] = {"load_N": load, "slip_angle_deg": angle}
            for i, (label, model) in enumerate(models.items()):
                run[f"Fy_{label}"] = model.fy(load, run["beta"].to_numpy(), run["slip"].to_numpy())
                value = fit_percent(run[f"Fy_{label}"].to_numpy(), run["Fy"].to_numpy())
                if i == 0:
                    row["fit_percent"] = value
                row[f"fit_percent_{label}"] = value
            fits.append(row)
            detail.extend(_segments(run, load, angle, list(models)))
            runs[load, angle] = run
    return LateralValidation(runs, pd.DataFrame(fits), pd.DataFrame(detail))


def _segments(run: pd.DataFrame, load: float, angle: float, labels: list[str]) -> list[dict[str, float]]:
    """Settled values (second half) of each constant-angle segment."""
    time = run["time"].to_numpy()
    half = HOLD / 2
    rows = []
    for index in range(int(round(time[-1] / half)) + 1):
        inside = (time >= index * half + half / 2) & (time < (index + 1) * half - 1e-12)
        if not inside.any():
            continue
        part = run[inside]
        entry = {"load_N": load, "slip_angle_deg": angle, "torque_N_m": float(part["tau"].iloc[0]),
                 "beta_deg": float(np.degrees(part["beta"].mean())), "slip": float(part["slip"].mean()),
                 "Fy_plant_N": float(part["Fy"].mean())}
        entry.update({f"Fy_{label}_N": float(part[f"Fy_{label}"].mean()) for label in labels})
        rows.append(entry)
    return rows
