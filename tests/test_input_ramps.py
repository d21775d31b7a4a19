"""Inputs ramped over a Co-Simulation step (fmi2SetRealInputDerivatives), as the interpolating
master hands set-points over: the FMUs keep the integrator's derivatives from one ramped step to
the next (the inputs end a step at u + u_der h, the bits the master sets next) and take the
affine inputs' gain again where the set-points moved. Checked on LegWheelRover.fmu with its knee
set-points swinging: a run at 1 ms follows the same run at 0.1 ms, at one internal step per
communication step; a restored FMU state repeats a ramped run exactly."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from cs_slave import Slave

SWING, FREQUENCY = 0.02, 0.5  # knee set-points' amplitude [rad] and frequency [Hz]
SETTLE, DURATION = 1.0, 1.0  # the rover settles on its wheels, then its knees swing [s]


class _Legs(Slave):
    """LegWheelRover.fmu (Co-Simulation) with its knee set-points swinging, handed as ramps."""

    def __init__(self, fmu: Path, tmp: Path):
        super().__init__(fmu, tmp, "legs")
        self.start = {v.name: float(v.start) for v in self.description.modelVariables
                      if v.causality == "input" and v.name.startswith("kneePitch[")}
        self.knees = [self.refs[name] for name in self.start]
        self.watched = [self.refs[n] for n in ("z", "kneePitchAngle[1]", "kneePitchAngle[5]", "Fz[1]", "Fz[2]")]

    def set_points(self, t: float) -> list[float]:
        swing = SWING * math.sin(2 * math.pi * FREQUENCY * (t - SETTLE)) if t > SETTLE else 0.0
        return [q0 + swing for q0 in self.start.values()]

    def run(self, step: float, first: int, last: int) -> np.ndarray:
        """Steps ``first`` to ``last`` of size ``step`` [s]; the watched values after each."""
        rows = []
        for k in range(first, last):
            t, end = k * step, (k + 1) * step
            now, then = self.set_points(t), self.set_points(end)
            self.slave.setReal(self.knees, now)
            self.slave.setRealInputDerivatives(self.knees, [1] * len(now), [(b - a) / step for a, b in zip(now, then)])
            self.slave.doStep(t, step)
            rows.append(self.slave.getReal(self.watched))
        return np.array(rows)



def test_a_ramped_run_follows_a_ten_times_finer_one(fmus, tmp_path):
    legs = _Legs(fmus["LegWheelRover"], tmp_path)
    try:
        legs.run(1e-3, 0, round(SETTLE / 1e-3))
        settled = legs.slave.getFMUstate()
        steps, before = round(DURATION / 1e-3), legs.statistic("steps")
        ran = legs.run(1e-3, round(SETTLE / 1e-3), round((SETTLE + DURATION) / 1e-3))
        taken = legs.statistic("steps") - before
        legs.slave.setFMUstate(settled)
        reference = legs.run(1e-4, round(SETTLE / 1e-4), round((SETTLE + DURATION) / 1e-4))[9::10]
        legs.slave.freeFMUstate(settled)
        assert np.ptp(ran[:, 1]) > SWING / 2  # the knees swung
        scale = np.abs(reference).max(axis=0)
        error = np.abs(ran - reference).max(axis=0) / scale
        assert np.all(error < 1e-6), error
        assert taken <= 1.02 * steps, (taken, steps)
    finally:
        legs.close()


def test_a_restored_state_repeats_a_ramped_run_exactly(fmus, tmp_path):
    legs = _Legs(fmus["LegWheelRover"], tmp_path)
    try:
        legs.run(1e-3, 0, 150)
        state = legs.slave.getFMUstate()
        first = legs.run(1e-3, 150, 300)
        legs.slave.setFMUstate(state)
        again = legs.run(1e-3, 150, 300)
        np.testing.assert_array_equal(first, again)
        legs.slave.freeFMUstate(state)
    finally:
        legs.close()
