"""The paper's controller that first learns the soil it drives on (issue 33): a calibration phase,
the soil estimated from the rover's own telemetry, the model identified again, then the paper's
law with the new model.

Calibration (``Calibration``, documented choices):

- length ``duration`` (3 s by default): long enough for a dozen steady levels per wheel, short
  against the paper's 20 s run; the rover keeps accelerating under the paper's law meanwhile;
- excitation: on top of the law's torques, each side's three wheels get +A, 0 and -A in turn
  (every order of the three, ``segment`` = 0.25 s each; the right side shifted by three orders;
  A = ``amplitude``, halved in every second round), so each wheel drives and brakes at a spread of
  slips and loads while the sum of the torques, and so the body's acceleration and pitch, is the
  law's;
- samples: each wheel at the end of each level, where its slip has settled (it settles within
  milliseconds): load W [N] (the body model's, as the law itself uses), slip ratio (Eq. 4) from
  the wheel's spin and the body's speed, torque Tx = tau - J domega/dt [N·m], and sinkage [m] only
  with ``sinkage_sensor``;
- a rover still crawling at the end (slower than MIN_SPEED, no sample: a very soft soil) calibrates
  on until it has ENOUGH_LEVELS levels, at most LONGEST x ``duration``; with fewer than
  FEWEST_LEVELS it keeps the nominal model, and its record says so;
- switch-over: at the first step at or after ``duration`` the block calls its ``adapter`` (the
  estimate and the sweep, :func:`rover_cosim.identification.online.adapt_model`, seconds of wall
  time while the simulated time waits), replaces the law's model and starts its slip filter
  settled at the new model's targets, as the law starts at t = 0 (carrying the old filter's state
  over gave a 10 ms spike of 40-50 N in Fx - Fx_des: that state belongs to the old model's slips).

A run's record takes ``report()``: what was estimated, from how many samples, when the model
switched and what it cost.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from rover_cosim.identification.model_set import ModelSet
from rover_cosim.identification.online import Adaptation
from rover_cosim.identification.testbed_data import TestBedData
from rover_cosim.orchestrator import native as native_code

from .controller import WHEELS, InverseModelController
from .longitudinal import LongitudinalInverse

#: m/s: below this body speed no sample is kept (the slip ratio is ill-conditioned near rest).
MIN_SPEED = 0.05
#: Levels of samples the estimate wants: a rover still slower than MIN_SPEED at the phase's end
#: (a very soft soil) keeps calibrating until it has them, up to LONGEST x the phase's duration;
#: with fewer than FEWEST levels then it keeps the nominal model and its record says why.
ENOUGH_LEVELS = 4
FEWEST_LEVELS = 2
LONGEST = 3.0
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
    """

    duration: float = 3.0
    segment: float = 0.25
    amplitude: float = 20.0
    sinkage_sensor: bool = False

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


class AdaptiveController(InverseModelController):
    """The paper's controller block (``InverseModelController``) with a calibration phase. Inputs:
    x, v, W[1..6] as the paper's, omega[1..6] (wheel spins [rad/s]) and pitch [rad] (the hubs'
    speed is the body's plus its pitch rate times the lever ``x_limb``, ``h_cog`` [m], the rover's
    geometry), plus sinkage[1..6] [m] with a sinkage sensor. The wheel's ``radius`` [m] gives the
    slip, its ``inertia`` [kg·m²] the torque the soil takes. ``adapter`` turns the calibration
    data into an :class:`Adaptation`."""

    def __init__(self, name: str, model: ModelSet | str, adapter: Callable[[TestBedData], Adaptation],
                 radius: float = 0.355, inertia: float = 0.5, calibration: Calibration = Calibration(),
                 x_limb: tuple[float, float, float] = (1.5, 0.0, -1.5), h_cog: float = 1.0, **options: Any):
        super().__init__(name, model, **options)
        if options.get("fixed_load"):
            raise ValueError(f"block {name!r}: fixed_load: the adaptive controller uses the measured loads")
        if not (radius > 0 and inertia > 0):
            raise ValueError(f"block {name!r}: radius = {radius!r} m, inertia = {inertia!r} kg·m²: expected > 0")
        self.adapter, self.radius, self.inertia, self.calibration = adapter, float(radius), float(inertia), calibration
        spins = [f"omega[{i}]" for i in range(1, WHEELS + 1)]
        sinkages = [f"sinkage[{i}]" for i in range(1, WHEELS + 1)] if calibration.sinkage_sensor else []
        self.inputs = (*self.inputs, *spins, "pitch", *sinkages)
        self.units = {**self.units, **{s: "rad/s" for s in spins}, "pitch": "rad", **{s: "m" for s in sinkages}}
        if len(x_limb) != 3 or not h_cog >= 0:
            raise ValueError(f"block {name!r}: x_limb = {x_limb!r}, h_cog = {h_cog!r}: expected three limb "
                             "positions [m] and a height >= 0 m")
        self.x_hub = np.array([*x_limb, *x_limb], float)  # limbs 1-3 front to rear, 4-6 the same
        self.h_cog = float(h_cog)
        self.samples: list[np.ndarray] = []     # per level, a row per wheel: t, W, slip, Tx, sinkage (NaN: no sensor)
        self.adaptation: Adaptation | None = None
        self.calibrated_until: float | None = None  # s, when the phase ended (None: still calibrating)
        self.switched_at: float | None = None       # s, when the model switched (None: not (yet) adapted)
        self.not_adapted: str | None = None         # why the phase ended without an adaptation
        self.adapt_wall_seconds: float | None = None
        self._previous: tuple[np.ndarray, float] = (np.zeros(WHEELS), 0.0)  # spins, pitch at the last call

    def native(self) -> native_code.NativeBlock | None:
        return None  # the calibration and the switch-over are Python: the block steps in Python

    def _telemetry(self, u: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
        """(wheel spins [rad/s], body pitch [rad], sinkages [m] or NaN) from the block's inputs."""
        omega = np.asarray(u[2 + WHEELS:2 + 2 * WHEELS], float)
        pitch = float(u[2 + 2 * WHEELS])
        sinkage = (np.asarray(u[3 + 2 * WHEELS:3 + 3 * WHEELS], float) if self.calibration.sinkage_sensor
                   else np.full(WHEELS, np.nan))
        return omega, pitch, sinkage

    def _measure(self, t: float, u: np.ndarray, h: float) -> None:
        """Keep each wheel's sample at ``t`` [s] if the step of ``h`` [s] that ended there is the last
        of its level (``self.torque``: the torques held over it)."""
        omega, pitch, sinkage = self._telemetry(u)
        (before, pitch_before), self._previous = self._previous, (omega, pitch)
        level = self.calibration.segment_index(t)
        v = float(u[1])
        ends_phase = t < self.calibration.duration <= t + h  # the last step of the planned phase
        if self.calibration.segment_index(t - h) != level or v < MIN_SPEED \
                or (self.calibration.segment_index(t + h) == level and not ends_phase):
            return
        # The hubs' speed from the body's speed and pitch rate (an IMU's), as the body model moves them.
        z_hub = self.x_hub * math.sin(pitch) - self.h_cog * math.cos(pitch)
        v_hub = v - (pitch - pitch_before) / h * z_hub
        r_omega = self.radius * omega
        # Eq. (4): (r omega - v) / max(r omega, v), signed as the FMUs' slip (driving > 0, skidding < 0)
        slip = (r_omega - v_hub) / np.maximum(np.maximum(np.abs(r_omega), np.abs(v_hub)), 1e-9)
        drive = self.torque - self.inertia * (omega - before) / h
        loads = np.asarray(u[2:2 + WHEELS], float)
        self.samples.append(np.column_stack([np.full(WHEELS, t), loads, slip, drive, sinkage]))

    def calibration_data(self) -> TestBedData:
        """The samples so far as single-wheel data (one row per wheel and level)."""
        if not self.samples:
            raise ValueError(f"block {self.name!r}: no calibration samples (the phase is shorter than a level)")
        rows = np.vstack(self.samples)
        return TestBedData(load_N=rows[:, 1], slip=rows[:, 2], Tx_Nm=rows[:, 3],
                           sinkage_m=rows[:, 4] if self.calibration.sinkage_sensor else None,
                           source=f"calibration of block {self.name!r}")

    def _end_phase(self, t: float) -> bool:
        """Whether the calibration ends at ``t`` [s], and if so: the adaptation done (or why not)."""
        levels = len(self.samples)
        longest = LONGEST * self.calibration.duration
        if t < self.calibration.duration - 1e-12 or (levels < ENOUGH_LEVELS and t < longest - 1e-12):
            return False
        self.calibrated_until = t
        if levels < FEWEST_LEVELS:
            self.not_adapted = (f"{levels} levels sampled by t = {t:g} s (the rover stayed below {MIN_SPEED} m/s): "
                                "the nominal model is kept")
            return True
        started = time.perf_counter()
        self.adaptation = self.adapter(self.calibration_data())
        self.model = self.adaptation.model
        self.inverse = LongitudinalInverse(self.model, WHEELS, self.inverse.wn, self.step_size, self.name)
        self.switched_at, self.adapt_wall_seconds = t, time.perf_counter() - started
        return True

    def _outputs(self, t: float, u: np.ndarray, advance: bool, step: float | None = None) -> np.ndarray:
        if self.calibrated_until is None:
            if advance:
                self._measure(t, u, step or self.step_size)
                if self._end_phase(t):
                    advance = False  # the law (re)starts settled at its targets, as it does at t = 0
            else:
                omega, pitch, _ = self._telemetry(u)
                self._previous = (omega, pitch)
        out = super()._outputs(t, u, advance, step)
        if self.calibrated_until is None:
            self.torque = self.torque + self.calibration.excitation(t)
            out[:WHEELS] = self.torque
        return out

    def get_state(self) -> tuple[Any, ...]:
        """The paper's block's state, the samples kept so far and the last spins (for masters
        that repeat a step; a repeated step after the switch-over keeps the new model)."""
        return (*super().get_state(), len(self.samples), self._previous)

    def set_state(self, state: tuple[Any, ...]) -> None:
        super().set_state((state[0], state[1]))
        del self.samples[state[2]:]
        self._previous = state[3]

    def report(self) -> dict[str, Any]:
        """What the adaptation did, for the run's record."""
        record: dict[str, Any] = {"calibration": asdict(self.calibration), "samples": sum(len(s) for s in self.samples),
                                  "calibrated_until_s": self.calibrated_until, "switched_at_s": self.switched_at,
                                  "adapt_wall_s": self.adapt_wall_seconds, "not_adapted": self.not_adapted}
        if self.adaptation is not None:
            estimate = self.adaptation.estimate
            record.update({"estimated_soil": asdict(estimate.soil), "estimate": estimate.to_dict(),
                           "estimate_wall_s": self.adaptation.estimate_seconds,
                           "identify_wall_s": self.adaptation.identify_seconds,
                           "sweep_runs_computed": self.adaptation.runs_computed})
        return record
