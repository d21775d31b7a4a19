"""What one closed-loop run of a Monte Carlo study measured, from its trajectories (pure).

Straight run (the paper's loop; columns of simulate.trajectories):
  rms_Fx_<i>_N         RMS(Fx_i - Fx_des_i) of limb i over the whole run [N] (Table 3's measure)
  rms_Fx_max_N         the largest of the six [N]; the paper's floor is 1 N
  rms_Fx_max_after_calibration_N
                       the same over the run after the calibration phase (t >= its duration, the
                       study's calibration, also for runs without adaptation; an adapted run's own
                       phase, which lasts longer on a rover that crawls: see control.adaptive) [N]
  time_to_98_s         first time v >= 0.98 m/s [s]; NaN if never (with the controller's
                       a_max = 0.1 m/s² the rover needs about 10 s: a shorter run never gets there)
  steady_v_error_m_s   mean of v - v_t over the final quarter of the run [m/s] (the final 5 s of
                       the paper's 20 s; negative: slower than the target)
  position_lag_m       x_t(t_end) - x(t_end) [m], x_t = v_t t: the target the controller tracks
                       (control.controller, v_t = 1.0 m/s) moves at v_t from t = 0
  max_slip             largest slip of any wheel at any time [-]
  stuck                the rover stalls: its mean velocity over the final quarter is below
                       STUCK_VELOCITY (0.1 m/s, a tenth of the target), or its wheels spin out
                       (mean slip of all wheels over that quarter above STUCK_SLIP = 0.9)
Adapted straight run (the adaptive controller; control.adaptive): the straight run's, and
  switched_at_s        when the model switched [s]; adapt_wall_s: the estimate and the sweep [s of wall time]
  estimate_rows        calibration samples the estimate used
  estimated_<name>     the estimated soil: c [Pa], phi_deg [deg], kphi [N/m^(n+2)], n [-], kx [m]
Path run (the lane change; path_following.metrics): cross-track RMS and max [m], largest speed
error [%], RMS(Fx - Fx_des) and RMS(Fy - Fy_des) per wheel [N], max slip and stuck as above.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from rover_cosim.common.paper import TARGET_VELOCITY, WHEELS

#: m/s: the velocity that counts as reached (the paper's Fig. 10 g; simulate's check)
REACHED_VELOCITY = 0.98
#: m/s: below this mean velocity over the final quarter the rover is stuck
STUCK_VELOCITY = 0.1
#: -: above this mean slip of all wheels over the final quarter the wheels spin out (stuck)
STUCK_SLIP = 0.9
#: the final part of a run over which steady values are taken
FINAL_FRACTION = 0.25
#: RMS(Fx - Fx_des) [N] the paper's controller stays under on every limb (Table 3: 0.4-0.7 N)
RMS_FLOOR = 1.0
LIMBS = range(1, WHEELS + 1)
STRAIGHT = (*(f"rms_Fx_{i}_N" for i in LIMBS), "rms_Fx_max_N", "rms_Fx_max_after_calibration_N", "time_to_98_s",
            "steady_v_error_m_s", "position_lag_m", "max_slip", "stuck")
ESTIMATED = ("c", "phi_deg", "kphi", "n", "kx")
ADAPTED = (*STRAIGHT, "switched_at_s", "adapt_wall_s", "estimate_rows", *(f"estimated_{n}" for n in ESTIMATED))
PATH = ("cross_track_rms_m", "cross_track_max_m", "speed_error_max_percent",
        *(f"rms_Fx_{i}_N" for i in LIMBS), *(f"rms_Fy_{i}_N" for i in LIMBS), "rms_Fx_max_N",
        "rms_Fx_max_after_calibration_N", "max_slip", "stuck")
ADAPTED_PATH = (*PATH, "switched_at_s", "adapt_wall_s", "estimate_rows", *(f"estimated_{n}" for n in ESTIMATED))


def _final(table: pd.DataFrame) -> pd.DataFrame:
    """The rows of the final quarter of the run (at least one)."""
    time = table["time"].to_numpy()
    start = time[-1] - FINAL_FRACTION * (time[-1] - time[0])
    return table[time >= start] if (time >= start).any() else table.iloc[-1:]


def _slip_and_stuck(table: pd.DataFrame, speed: pd.Series) -> dict[str, float | bool]:
    slips = table[[f"slip_{i}" for i in LIMBS]].to_numpy()
    final = _final(table)
    stalled = float(speed[final.index].mean()) < STUCK_VELOCITY
    spinning = float(final[[f"slip_{i}" for i in LIMBS]].to_numpy().mean()) > STUCK_SLIP
    return {"max_slip": float(np.nanmax(slips)), "stuck": bool(stalled or spinning)}


def _rms_max(table: pd.DataFrame) -> float:
    """The largest RMS(Fx_i - Fx_des_i) of the six limbs [N] (NaN for no rows)."""
    if not len(table):
        return float("nan")
    return max(float(np.sqrt(np.mean((table[f"Fx_{i}"] - table[f"Fx_des_{i}"]) ** 2))) for i in LIMBS)


def straight_metrics(table: pd.DataFrame, v_target: float = TARGET_VELOCITY,
                     calibration: float = 0.0) -> dict[str, float | bool]:
    """The straight run's metrics (see the module's docstring) from simulate.trajectories' table;
    ``calibration`` [s]: the length of the calibration phase (the window of the "after" RMS)."""
    row: dict[str, float | bool] = {
        f"rms_Fx_{i}_N": float(np.sqrt(np.mean((table[f"Fx_{i}"] - table[f"Fx_des_{i}"]) ** 2))) for i in LIMBS}
    row["rms_Fx_max_N"] = max(float(row[f"rms_Fx_{i}_N"]) for i in LIMBS)
    row["rms_Fx_max_after_calibration_N"] = _rms_max(table[table["time"] >= calibration])
    v, time = table["v"].to_numpy(), table["time"].to_numpy()
    reached = np.nonzero(v >= REACHED_VELOCITY)[0]
    row["time_to_98_s"] = float(time[reached[0]]) if reached.size else float("nan")
    row["steady_v_error_m_s"] = float(np.mean(_final(table)["v"] - v_target))
    row["position_lag_m"] = float(v_target * time[-1] - table["x"].iloc[-1])
    row.update(_slip_and_stuck(table, table["v"]))
    return row


def path_metrics(table: pd.DataFrame, basic: dict[str, float], calibration: float = 0.0) -> dict[str, float | bool]:
    """The path run's metrics: ``basic`` (path_following.metrics of the table) with the largest
    RMS(Fx - Fx_des) (over the run, and from ``calibration`` [s] on), the max slip and whether the
    rover got stuck."""
    row: dict[str, float | bool] = dict(basic)
    row["rms_Fx_max_N"] = max(float(basic[f"rms_Fx_{i}_N"]) for i in LIMBS)
    row["rms_Fx_max_after_calibration_N"] = _rms_max(table[table["time"] >= calibration])
    row.update(_slip_and_stuck(table, pd.Series(np.hypot(table["v"], table["vy"]), index=table.index)))
    return row
