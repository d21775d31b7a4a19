"""The single-wheel test bed in Python on the numpy reference wheel: the same experiment as
SingleWheel.fmu, for the cross-check of the identification and of the motion regimes.

    J dω/dt = τ - Tx,   (W/g) dv/dt = Fx cos β + Fy sin β - W sin(slope),   dx/dt = v

with Fx, Fy, Tx from :func:`terramechanics.wheel_forces` under the load W cos(slope) normal to the
slope (positive slope: uphill) and the hub velocity (v cos β, v sin β) in the wheel frame (β: the
slip angle of the carriage's track to the wheel plane), integrated by SciPy's Radau method (the start from rest and the
static regime are stiff).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from rover_cosim.terramechanics import Regimes, Soil, Wheel, wheel_forces

from .testbed import RECORDED, TorqueProfile

G_MOON = 1.62   # m/s², as the SingleWheel model's default g


@dataclass(frozen=True)
class StartState:
    """Initial state of the carriage and wheel: position x [m], speed v [m/s], spin omega [rad/s]."""

    x: float = 0.0
    v: float = 0.0
    omega: float = 0.0


def run_reference_test_bed(load: float, torque: TorqueProfile, stop_time: float, sample_time: float, *,
                           wheel: Wheel | None = None, soil: Soil | None = None, g: float = G_MOON,
                           regimes: Regimes | None = None, slope: float = 0.0,
                           start: StartState | None = None, slip_angle: float = 0.0,
                           rtol: float = 1e-7) -> pd.DataFrame:
    """Columns as :meth:`identification.testbed.WheelTestBed.run` (time, tau, RECORDED), then x [m];
    ``rtol`` the integrator's relative tolerance (its absolute one a thousandth of it): 1e-7, the
    reference's, by default; a looser one for a property that does not need it (a wheel held at
    rest on a slope: its stiff stick regime costs Radau 9x as much at 1e-7 as at 1e-4)."""
    wheel, soil, regimes, start = wheel or Wheel(), soil or Soil(), regimes or Regimes(), start or StartState()
    if not load > 0:
        raise ValueError(f"load = {load!r} N: expected > 0")
    if not abs(slope) < math.pi / 2:
        raise ValueError(f"slope = {slope!r} rad: expected -pi/2 < slope < pi/2")
    if not 0 < rtol < 1:
        raise ValueError(f"rtol = {rtol!r}: expected 0 < rtol < 1")
    if not abs(slip_angle) < math.pi / 2:
        raise ValueError(f"slip_angle = {slip_angle!r} rad: expected -pi/2 < slip_angle < pi/2")
    along, across = math.cos(slip_angle), math.sin(slip_angle)
    mass, normal_load, downhill = load / g, load * math.cos(slope), load * math.sin(slope)
    n = round(stop_time / sample_time)
    times = sample_time * np.arange(n + 1)
    boundaries = sorted({0.0, *[t for t in torque.times if 0 < t < stop_time], stop_time})

    def rhs(t: float, y: np.ndarray, tau: float) -> np.ndarray:
        contact = wheel_forces(normal_load, y[2], y[1] * along, wheel, soil, regimes, v_lateral=y[1] * across)
        push = float(contact.Fx) * along + float(contact.Fy) * across
        return np.array([y[1], (push - downhill) / mass, (tau - float(contact.Tx)) / wheel.J])

    states = np.zeros((n + 1, 3))
    y = np.array([start.x, start.v, start.omega], dtype=float)
    states[0] = y
    for begin, end in itertools.pairwise(boundaries):
        tau = float(torque(np.array([begin]))[0])
        inside = (times > begin + 1e-12) & (times <= end + 1e-12)
        solution = solve_ivp(rhs, (begin, end), y, method="Radau", t_eval=times[inside], args=(tau,),
                             rtol=rtol, atol=rtol * 1e-3)
        if not solution.success:
            raise RuntimeError(f"reference test bed at W = {load} N, tau = {tau} N·m: {solution.message}")
        states[inside] = solution.y.T
        y = solution.y[:, -1] if solution.y.size else y
    contact = wheel_forces(normal_load, states[:, 2], states[:, 1] * along, wheel, soil, regimes,
                           v_lateral=states[:, 1] * across)
    data = pd.DataFrame({"time": times, "tau": torque(times), "slip": contact.slip, "Fx": contact.Fx,
                         "Fz": contact.Fz, "Tx": contact.Tx, "sinkage": contact.sinkage,
                         "omega": states[:, 2], "v": states[:, 1], "Fy": contact.Fy,
                         "beta": np.full(n + 1, slip_angle), "x": states[:, 0]})
    return data[["time", "tau", *RECORDED, "x"]]
