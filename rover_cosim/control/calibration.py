"""The calibration phase of an adaptive run (issue 33; the choices are documented in
:mod:`rover_cosim.control.adaptive`): its length, excitation and sensors, checked. A module of its
own, with numpy only, so that the command line refuses a bad ``--calibration`` before it imports
the adaptive controller and the identification."""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

#: Each side's excitation levels in turn: every order of (+1, 0, -1).
ORDERS = tuple(itertools.permutations((1.0, 0.0, -1.0)))


@dataclass(frozen=True)
class Calibration:
    """The calibration phase of an adaptive run (see the module docstring).

    Attributes:
        duration: length of the phase [s]; the model switches at its end.
        segment: how long each excitation level is held [s].
        amplitude: the excitation torque A [N·m] added to and taken from the law's.
        sinkage_sensor: the rover measures each wheel's sinkage (else the estimate uses the torques only).
        optional_parameters: the soil estimate also tries the stress distribution's a1, a0, λ in
            turn, as ``estimate-soil`` does (else they keep the prior's values: several times
            faster; see :mod:`rover_cosim.identification.online`).
    """

    duration: float = 3.0
    segment: float = 0.25
    amplitude: float = 20.0
    sinkage_sensor: bool = False
    optional_parameters: bool = False

    def __post_init__(self) -> None:
        for key in ("duration", "segment", "amplitude"):
            value = getattr(self, key)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"calibration {key} = {value!r}: expected a finite number > 0")
        if self.segment > self.duration:
            raise ValueError(f"calibration segment = {self.segment!r} s: expected at most its duration "
                             f"{self.duration!r} s")

    def segment_index(self, t: float) -> int:
        """The excitation level's number at time ``t`` [s] (0 from the start)."""
        return int(math.floor(t / self.segment + 1e-9))

    def excitation(self, t: float) -> np.ndarray:
        """The torques [N·m] added to the law's at time ``t`` [s] while the phase lasts: zero-sum
        on each side."""
        k = self.segment_index(t)
        scale = self.amplitude * (1.0 if (k // len(ORDERS)) % 2 == 0 else 0.5)
        left, right = ORDERS[k % len(ORDERS)], ORDERS[(k + 3) % len(ORDERS)]
        return scale * np.array([*left, *right])
