"""Controllers that first learn the soil they drive on (issue 33): a calibration phase, the soil
estimated from the rover's own telemetry, the models identified again, then the law with the new
models. ``AdaptiveController``: the paper's straight-run controller (Rover.fmu);
``AdaptivePathController``: the path-following controller of the steerable rover, which also
identifies its lateral model again on the estimated soil (the soil's own lateral moduli k_y,
k_y,beta, k_x,beta cannot be seen without a lateral force, which a rover does not measure: they
keep the nominal values).

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

import ctypes
import math
import time
from collections.abc import Callable
from dataclasses import asdict
from typing import Any

import numpy as np

from rover_cosim.common.paper import WHEELS
from rover_cosim.identification.model_set import ModelSet
from rover_cosim.identification.online import Adaptation
from rover_cosim.identification.testbed_data import TestBedData
from rover_cosim.orchestrator import native as native_code

from .calibration import Calibration
from .controller import InverseModelController, LawTwin
from .longitudinal import LongitudinalInverse
from .path import Path as ReferencePath
from .path_controller import PathFollowingController

#: m/s: below this body speed no sample is kept (the slip ratio is ill-conditioned near rest).
MIN_SPEED = 0.05
#: Levels of samples the estimate wants: a rover still slower than MIN_SPEED at the phase's end
#: (a very soft soil) keeps calibrating until it has them, up to LONGEST x the phase's duration;
#: with fewer than FEWEST levels then it keeps the nominal model and its record says why.
ENOUGH_LEVELS = 4
FEWEST_LEVELS = 2
LONGEST = 3.0
class Calibrating:
    """The calibration phase of an adaptive block (see the module docstring): the samples, when the
    phase ends, the adaptation and its record. A block using it calls ``_calibrate`` at every step
    with the telemetry, and gives ``_apply`` (switch to the adapted models)."""

    name: str
    step_size: float

    def _setup_calibration(self, adapter: Callable[[TestBedData], Adaptation], radius: float, inertia: float,
                           calibration: Calibration) -> None:
        if not (radius > 0 and inertia > 0):
            raise ValueError(f"block {self.name!r}: radius = {radius!r} m, inertia = {inertia!r} kg·m²: "
                             "expected > 0")
        self.adapter, self.radius, self.inertia, self.calibration = adapter, float(radius), float(inertia), calibration
        self.samples: list[np.ndarray] = []     # per level, a row per wheel: t, W, slip, Tx, sinkage (NaN: no sensor)
        self.adaptation: Adaptation | None = None
        self.calibrated_until: float | None = None  # s, when the phase ended (None: still calibrating)
        self.switched_at: float | None = None       # s, when the model switched (None: not (yet) adapted)
        self.not_adapted: str | None = None         # why the phase ended without an adaptation
        self.adapt_wall_seconds: float | None = None
        self._spins: np.ndarray | None = None        # the wheel spins at the last call [rad/s]

    def native(self) -> native_code.NativeBlock | None:
        """None while calibrating (the calibration and the switch-over are Python); afterwards the
        C twin of the law the block then steps alone (``_law_twin``), made from its state now."""
        if self.calibrated_until is None:
            return None
        return self._law_twin()

    def native_ready(self) -> bool:
        """Whether the engine may ask again for a C twin: the calibration has ended (adapted or
        not, the block now steps its law alone, which its twin repeats bit for bit)."""
        return self.calibrated_until is not None

    def _law_twin(self) -> native_code.NativeBlock | None:
        raise NotImplementedError

    @staticmethod
    def _ignoring(twin: native_code.NativeBlock | None, function: str, count: int) -> native_code.NativeBlock | None:
        """``twin``, told to accept and ignore the ``count`` inputs after its law's (the telemetry)."""
        if twin is not None:
            ignore = getattr(twin.library, function)
            ignore.argtypes = [ctypes.c_void_p, ctypes.c_int]
            ignore.restype = None
            ignore(twin.component, count)
        return twin

    def _apply(self, adaptation: Adaptation) -> None:
        raise NotImplementedError

    def _calibrate(self, t: float, h: float | None, speed: float, loads: np.ndarray, hub_speeds: np.ndarray,
                   spins: np.ndarray, torques: np.ndarray, sinkages: np.ndarray) -> bool:
        """One step's telemetry at ``t`` [s] (``h`` [s]: the step that ended there; None at the start):
        the body's ``speed`` [m/s], the wheels' loads [N], hub speeds along the wheels [m/s], spins
        [rad/s], the torques held over the step [N·m] and sinkages [m] (NaN without a sensor). Keeps
        the sample that ends a level; True when the phase ends here (the law then restarts settled)."""
        before, self._spins = self._spins, spins
        if h is None or before is None:
            return False
        level = self.calibration.segment_index(t)
        ends_phase = t < self.calibration.duration <= t + h  # the last step of the planned phase
        if self.calibration.segment_index(t - h) == level and speed >= MIN_SPEED \
                and (self.calibration.segment_index(t + h) != level or ends_phase):
            r_omega = self.radius * spins
            # Eq. (4): (r omega - v) / max(r omega, v), signed as the FMUs' slip (driving > 0, skidding < 0)
            slip = (r_omega - hub_speeds) / np.maximum(np.maximum(np.abs(r_omega), np.abs(hub_speeds)), 1e-9)
            drive = torques - self.inertia * (spins - before) / h
            self.samples.append(np.column_stack([np.full(WHEELS, t), loads, slip, drive, sinkages]))
        return self._end_phase(t)

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
        self._apply(self.adaptation)
        self.switched_at, self.adapt_wall_seconds = t, time.perf_counter() - started
        return True

    def _calibration_state(self) -> tuple[int, np.ndarray | None]:
        return len(self.samples), self._spins

    def _restore_calibration(self, state: tuple[int, np.ndarray | None]) -> None:
        del self.samples[state[0]:]
        self._spins = state[1]

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
                           "sweep_runs_computed": self.adaptation.runs_computed,
                           "lateral_identified_again": self.adaptation.lateral is not None})
        return record


class _Rates:
    """Rates of body angles by differences between calls (an IMU's gyros)."""

    def __init__(self, count: int):
        self.last = np.zeros(count)

    def update(self, angles: np.ndarray, h: float | None) -> np.ndarray:
        rates = np.zeros_like(angles) if not h else (angles - self.last) / h
        self.last = angles.copy()
        return rates


class AdaptiveController(Calibrating, InverseModelController):
    """The paper's controller block (``InverseModelController``) with a calibration phase. Inputs:
    x, v, W[1..6] as the paper's, omega[1..6] (wheel spins [rad/s]) and pitch [rad] (the hubs'
    speed is the body's plus its pitch rate times the lever ``x_limb``, ``h_cog`` [m], the rover's
    geometry), plus sinkage[1..6] [m] with a sinkage sensor. The wheel's ``radius`` [m] gives the
    slip, its ``inertia`` [kg·m²] the torque the soil takes. ``adapter`` turns the calibration
    data into an :class:`Adaptation`."""

    def __init__(self, name: str, model: ModelSet | str, adapter: Callable[[TestBedData], Adaptation],
                 radius: float = 0.355, inertia: float = 0.5, calibration: Calibration = Calibration(),
                 x_limb: tuple[float, float, float] = (1.5, 0.0, -1.5), h_cog: float = 1.0, **options: Any):
        InverseModelController.__init__(self, name, model, **options)
        if options.get("fixed_load"):
            raise ValueError(f"block {name!r}: fixed_load: the adaptive controller uses the measured loads")
        if self.wheels != WHEELS:
            raise ValueError(f"block {name!r}: wheels = {self.wheels!r}: the adaptive controller drives the paper's "
                             f"rover ({WHEELS} limbs placed by x_limb)")
        self._setup_calibration(adapter, radius, inertia, calibration)
        spins = [f"omega[{i}]" for i in range(1, WHEELS + 1)]
        sinkages = [f"sinkage[{i}]" for i in range(1, WHEELS + 1)] if calibration.sinkage_sensor else []
        self.inputs = (*self.inputs, *spins, "pitch", *sinkages)
        self.units = {**self.units, **{s: "rad/s" for s in spins}, "pitch": "rad", **{s: "m" for s in sinkages}}
        if len(x_limb) != 3 or not h_cog >= 0:
            raise ValueError(f"block {name!r}: x_limb = {x_limb!r}, h_cog = {h_cog!r}: expected three limb "
                             "positions [m] and a height >= 0 m")
        self.x_hub = np.array([*x_limb, *x_limb], float)  # limbs 1-3 front to rear, 4-6 the same
        self.h_cog = float(h_cog)
        self._rates = _Rates(1)
        self._stepping: LawTwin | None = None  # the law's C twin while calibrating (made at the first step)
        self._stepping_tried = False
        self._native_allowed = True  # the run's native setting (use_native); True for a block stepped alone

    def _apply(self, adaptation: Adaptation) -> None:
        self.model = adaptation.model
        self.inverse = LongitudinalInverse(self.model, WHEELS, self.inverse.wn, self.step_size, self.name)

    def _law_twin(self) -> native_code.NativeBlock | None:
        return self._ignoring(InverseModelController.native(self), "controller_ignore_inputs",
                              len(self.inputs) - (2 + WHEELS))

    def _outputs(self, t: float, u: np.ndarray, advance: bool, step: float | None = None) -> np.ndarray:
        if self.calibrated_until is None:
            h = (step or self.step_size) if advance else None
            pitch = float(u[2 + 2 * WHEELS])
            pitch_rate = float(self._rates.update(np.array([pitch]), h)[0])
            # The hubs' speed from the body's speed and pitch rate, as the body model moves them.
            z_hub = self.x_hub * math.sin(pitch) - self.h_cog * math.cos(pitch)
            v = float(u[1])
            sinkages = (np.asarray(u[3 + 2 * WHEELS:3 + 3 * WHEELS], float) if self.calibration.sinkage_sensor
                        else np.full(WHEELS, np.nan))
            if self._calibrate(t, h, v, np.asarray(u[2:2 + WHEELS], float), v - pitch_rate * z_hub,
                               np.asarray(u[2 + WHEELS:2 + 2 * WHEELS], float), self.torque, sinkages):
                advance = False  # the law (re)starts settled at its targets, as it does at t = 0
        out = self._law(t, u, advance, step)
        if self.calibrated_until is None:
            self.torque = self.torque + self.calibration.excitation(t)
            out[:WHEELS] = self.torque
        return out

    def _law(self, t: float, u: np.ndarray, advance: bool, step: float | None) -> np.ndarray:
        """The paper's law at ``t``: while calibrating (this block steps in Python then) through its
        C twin, the same bits several times faster; at the start, the switch-over (where the
        filter restarts settled) and after it, the Python law."""
        stepping = self._stepping
        if advance and self.calibrated_until is None and self._native_allowed:
            if stepping is None and not self._stepping_tried:
                self._stepping_tried = True
                stepping = self._stepping = self.law_twin()
            if stepping is not None:
                out = stepping.step_at(t, step or self.step_size, u)
                self.torque = out[:WHEELS].copy()
                return out
        if stepping is not None:  # the phase is over: the twin is freed, its filter handed back
            self.inverse.filter_state = stepping.filter()
            stepping.close()
            self._stepping = None
        return InverseModelController._outputs(self, t, u, advance, step)

    def use_native(self, enabled: bool) -> None:
        """Whether the run lets C code step (the system's ``native`` setting under an explicit
        master): without, the law steps in Python while calibrating too."""
        self._native_allowed = bool(enabled)

    def get_state(self) -> tuple[Any, ...]:
        """The paper's block's state and the calibration's (for masters that repeat a step; a
        repeated step after the switch-over keeps the new model)."""
        if self._stepping is not None:  # the filter lives in the law's twin while calibrating
            self.inverse.filter_state = self._stepping.filter()
        return (*InverseModelController.get_state(self), self._calibration_state(), self._rates.last.copy())

    def set_state(self, state: tuple[Any, ...]) -> None:
        InverseModelController.set_state(self, (state[0], state[1]))
        if self._stepping is not None:
            self._stepping.set_filter(self.inverse.filter_state)
        self._restore_calibration(state[2])
        self._rates.last = state[3].copy()


class AdaptivePathController(Calibrating, PathFollowingController):
    """The path-following block (``PathFollowingController``) with a calibration phase on the
    path's first straight. Inputs: those of the path-following block, and omega[1..6] (wheel
    spins [rad/s]), pitch, roll [rad] (with the body's velocity, yaw rate and the wheels' steering,
    the hubs' velocities along the wheels, as the steerable body moves them), plus sinkage[1..6]
    [m] with a sinkage sensor. The adaptation replaces the longitudinal model and, where it
    brings one, the lateral model."""

    def __init__(self, name: str, model: ModelSet | str, adapter: Callable[[TestBedData], Adaptation],
                 radius: float = 0.355, inertia: float = 0.5, calibration: Calibration = Calibration(),
                 h_cog: float = 1.0, path: str | ReferencePath = "lane_change", **options: Any):
        PathFollowingController.__init__(self, name, model, path=path, **options)
        if options.get("steering", "inverse") != "inverse":
            raise ValueError(f"block {name!r}: steering: the adaptive path controller steers by the models")
        self._setup_calibration(adapter, radius, inertia, calibration)
        spins = [f"omega[{i}]" for i in range(1, WHEELS + 1)]
        sinkages = [f"sinkage[{i}]" for i in range(1, WHEELS + 1)] if calibration.sinkage_sensor else []
        self.inputs = (*self.inputs, *spins, "pitch", "roll", *sinkages)
        self.units = {**self.units, **{s: "rad/s" for s in spins}, "pitch": "rad", "roll": "rad",
                      **{s: "m" for s in sinkages}}
        if not h_cog >= 0:
            raise ValueError(f"block {name!r}: h_cog = {h_cog!r}: expected a height >= 0 m")
        self.h_cog = float(h_cog)
        self.torque = np.zeros(WHEELS)
        self._rates = _Rates(2)

    def _apply(self, adaptation: Adaptation) -> None:
        self.inverse = LongitudinalInverse(adaptation.model, WHEELS, self.inverse.wn, self.step_size, self.name)
        if adaptation.lateral is not None:
            self.lateral = adaptation.lateral

    def _law_twin(self) -> native_code.NativeBlock | None:
        return self._ignoring(PathFollowingController.native(self), "path_ignore_inputs",
                              len(self.inputs) - (6 + 2 * WHEELS))

    def _hub_speeds(self, u: np.ndarray, pitch: float, roll: float, pitch_rate: float, roll_rate: float) -> np.ndarray:
        """The hubs' velocities along the wheels [m/s] (SteerableChassis' kinematics)."""
        v, vy, yaw_rate = float(u[3]), float(u[4]), float(u[5])
        y_rolled = self.y_hub * math.cos(roll) + self.h_cog * math.sin(roll)
        z_rolled = self.y_hub * math.sin(roll) - self.h_cog * math.cos(roll)
        x_world = self.x_hub * math.cos(pitch) - z_rolled * math.sin(pitch)
        z_world = self.x_hub * math.sin(pitch) + z_rolled * math.cos(pitch)
        vx = v - pitch_rate * z_world - roll_rate * math.sin(pitch) * y_rolled - yaw_rate * y_rolled
        vy_hub = vy - roll_rate * z_rolled + yaw_rate * x_world
        return vx * np.cos(self.steer) + vy_hub * np.sin(self.steer)

    def _outputs(self, t: float, u: np.ndarray, advance: bool, step: float | None = None) -> np.ndarray:
        if self.calibrated_until is None:
            h = (step or self.step_size) if advance else None
            base = 6 + 2 * WHEELS
            pitch, roll = float(u[base + WHEELS]), float(u[base + WHEELS + 1])
            pitch_rate, roll_rate = (float(r) for r in self._rates.update(np.array([pitch, roll]), h))
            sinkages = (np.asarray(u[base + WHEELS + 2:base + 2 * WHEELS + 2], float)
                        if self.calibration.sinkage_sensor else np.full(WHEELS, np.nan))
            if self._calibrate(t, h, float(np.hypot(u[3], u[4])), np.asarray(u[6:6 + WHEELS], float),
                               self._hub_speeds(u, pitch, roll, pitch_rate, roll_rate),
                               np.asarray(u[base:base + WHEELS], float), self.torque, sinkages):
                advance = False  # the law (re)starts settled at its targets, as it does at t = 0
        out = PathFollowingController._outputs(self, t, u, advance, step)
        self.torque = out[:WHEELS].copy()
        if self.calibrated_until is None:
            self.torque = self.torque + self.calibration.excitation(t)
            out[:WHEELS] = self.torque
        return out

    def get_state(self) -> tuple[Any, ...]:
        return (*PathFollowingController.get_state(self), self._calibration_state(), self._rates.last.copy(),
                self.torque.copy())

    def set_state(self, state: tuple[Any, ...]) -> None:
        PathFollowingController.set_state(self, (state[0], state[1], state[2]))
        self._restore_calibration(state[3])
        self._rates.last, self.torque = state[4].copy(), state[5].copy()
