"""The single-wheel test bed in Python on the numpy reference wheel: the same experiment as
SingleWheel.fmu, for the cross-check of the identification.

    J dω/dt = τ - Tx(W, κ),   (W/g) dv/dt = Fx(W, κ),   κ = slip_ratio(r ω, v, v_eps)

with the forces from :func:`terramechanics.wheel_state` (sinkage solving Fz = W), integrated by
SciPy's Radau method (the start from rest is stiff: dκ/dω = r/v_eps there).
"""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
from scipy.integrate import solve_ivp

from rover_cosim.terramechanics import Soil, Wheel, slip_ratio, wheel_state

from .testbed import RECORDED, TorqueProfile

G_MOON = 1.62   # m/s², as the SingleWheel model's default g
V_EPS = 1e-3    # m/s, as the SingleWheel model's default vEps


def run_reference_test_bed(load: float, torque: TorqueProfile, stop_time: float, sample_time: float, *,
                 wheel: Wheel | None = None, soil: Soil | None = None, g: float = G_MOON,
                 v_eps: float = V_EPS) -> pd.DataFrame:
    """Columns as :meth:`identification.testbed.WheelTestBed.run` (time, tau, RECORDED)."""
    wheel = wheel or Wheel()
    soil = soil or Soil()
    if not load > 0:
        raise ValueError(f"load = {load!r} N: expected > 0")
    mass = load / g
    n = round(stop_time / sample_time)
    times = sample_time * np.arange(n + 1)
    boundaries = sorted({0.0, *[t for t in torque.times if 0 < t < stop_time], stop_time})

    def forces(omega: float, v: float):
        slip = float(slip_ratio(wheel.r * omega, v, v_eps))
        return slip, wheel_state(load, slip, wheel, soil)

    def rhs(t: float, y: np.ndarray, tau: float) -> np.ndarray:
        _, state = forces(y[0], y[1])
        return np.array([(tau - float(state.Tx)) / wheel.J, float(state.Fx) / mass])

    states = np.zeros((n + 1, 2))
    y = np.zeros(2)
    for start, end in itertools.pairwise(boundaries):
        tau = float(torque(np.array([start]))[0])
        inside = (times > start + 1e-12) & (times <= end + 1e-12)
        solution = solve_ivp(rhs, (start, end), y, method="Radau", t_eval=times[inside], args=(tau,),
                             rtol=1e-7, atol=1e-10)
        if not solution.success:
            raise RuntimeError(f"reference test bed at W = {load} N, tau = {tau} N·m: {solution.message}")
        states[inside] = solution.y.T
        y = solution.y[:, -1] if solution.y.size else y
    rows = []
    for omega, v in states:
        slip, state = forces(omega, v)
        rows.append([slip, float(state.Fx), float(state.Fz), float(state.Tx), float(state.sinkage), omega, v])
    data = pd.DataFrame(rows, columns=list(RECORDED))
    data.insert(0, "tau", torque(times))
    data.insert(0, "time", times)
    return data
