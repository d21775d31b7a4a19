"""The single-wheel test bed as an experiment: SingleWheel.fmu (Co-Simulation) driven by a
piecewise-constant torque from rest or rolling (``start_speed``), with the carriage's track at a
slip angle to the wheel plane (``slip_angle``, Ishigami's test bed), recorded at a fixed sample
time (= communication step).

One FMU instance per process is kept and reset between runs (:func:`shared_test_bed`), so a sweep
pays for unpacking and loading the FMU once per worker. The FMU is driven through the engine's FMU
participant (``orchestrator.participants.FmuParticipant``: the one FMU driver, with its logger
and its error messages naming the call and the time); the bed only decides the calls: inputs set
when their level changes, one fmi2DoStep per sample. The samples between level changes are
stepped by the engine's native stepper (the same calls from C, so the same bits) where a C
compiler is available: a sweep run is overhead-bound in Python (1,000 samples of 0.1 ms).
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import fmpy
import numpy as np
import pandas as pd

from rover_cosim.common.scratch import scratch_prefix
from rover_cosim.orchestrator import native
from rover_cosim.orchestrator.model import FmuEntry, Value
from rover_cosim.orchestrator.participants import FmuParticipant
from rover_cosim.orchestrator.unpacking import unpack

#: What every run records besides time and torque (SingleWheel outputs, SI units).
RECORDED = ("slip", "Fx", "Fz", "Tx", "sinkage", "omega", "v", "Fy", "beta")


#: The variables a single-wheel test bed FMU has (SingleWheel.fmu's interface).
TEST_BED_VARIABLES = ("W", "tau", "slipAngle", "trackAngle", *RECORDED)


def not_a_test_bed(description: Any) -> str | None:
    """Why an FMU (its FMPy model description) is not a single-wheel test bed, or None."""
    names = {v.name for v in description.modelVariables}
    missing = [n for n in TEST_BED_VARIABLES if n not in names]
    return f"not a SingleWheel FMU (no variables {missing})" if missing else None


@dataclass(frozen=True)
class Staircase:
    """Piecewise-constant levels (of a torque [N·m] or an angle [rad]) held from the given times
    [s] on (the first from t = 0)."""

    times: tuple[float, ...]
    levels: tuple[float, ...]

    @staticmethod
    def step(level: float) -> Staircase:
        return Staircase((0.0,), (float(level),))

    @staticmethod
    def staircase(levels: tuple[float, ...], hold: float) -> Staircase:
        return Staircase(tuple(i * hold for i in range(len(levels))), tuple(float(x) for x in levels))

    def __call__(self, t: np.ndarray) -> np.ndarray:
        index = np.searchsorted(np.asarray(self.times), t + 1e-12, side="right") - 1
        return np.asarray(self.levels)[np.clip(index, 0, None)]


#: The drive torque of a run [N·m].
TorqueProfile = Staircase


class WheelTestBed:
    """SingleWheel.fmu loaded once; :meth:`run` resets and runs it."""

    def __init__(self, fmu_path: Path):
        self.path = Path(fmu_path)
        self._folder = tempfile.TemporaryDirectory(prefix=scratch_prefix("testbed"))
        self.description = fmpy.read_model_description(str(self.path))
        self.radius = float(next((v.start for v in self.description.modelVariables if v.name == "wheel.r"), 0.355))
        problem = not_a_test_bed(self.description)
        if problem:
            raise ValueError(f"{self.path}: {problem}")
        self.names = {v.name for v in self.description.modelVariables}
        entry = FmuEntry("testbed", self.path, {}, {}, self.description)
        self.fmu = FmuParticipant(entry, unpack(entry, Path(self._folder.name)))
        self.fmu.configure([], list(RECORDED))  # inputs are set by name when they change; RECORDED read each step
        self._fresh = True
        #: FMU parameters set before every run (e.g. a soil and wheel: terramechanics.library.fmu_parameters)
        self.parameters: dict[str, float] = {}

    def _start(self, load: float, tau: float, turn: float, tolerance: float, start_speed: float, slip_angle: float,
               parameters: dict[str, float], stop_time: float) -> np.ndarray:
        """Reset (after the first run), set up and initialize the FMU for a run; the recorded
        variables at the start."""
        fmu = self.fmu
        if not self._fresh:
            fmu.reset()
        self._fresh = False
        unknown = sorted(set(parameters) - self.names)
        if unknown:
            raise ValueError(f"{self.path}: no parameters {unknown}")
        start: dict[str, Value] = {"W": load, "tau": tau, "solver.tolerance": tolerance, "slipAngle": slip_angle,
                                   "trackAngle": turn}
        if start_speed:
            radius = float(parameters.get("wheel.r", self.radius))
            start.update(v=start_speed, omega=start_speed * math.cos(slip_angle + turn) / radius)
        fmu.entry = FmuEntry(fmu.name, self.path, {k: float(v) for k, v in parameters.items()}, start,
                             self.description)
        fmu.enter_initialization(0.0, stop_time)
        return fmu.exit_initialization(0.0, np.zeros(0))

    def run(self, load: float, torque: TorqueProfile, stop_time: float, sample_time: float,
            tolerance: float = 1e-8, *, start_speed: float = 0.0, slip_angle: float = 0.0,
            track_angle: Staircase | None = None, parameters: dict[str, float] | None = None) -> pd.DataFrame:
        """Columns time, tau, then :data:`RECORDED`; rows at 0, sample_time, ..., stop_time. The
        carriage starts at ``start_speed`` [m/s] along its track, which runs at ``slip_angle``
        [rad] to the wheel plane, with the wheel rolling without slip (omega = v cos(slip_angle)/r).
        ``track_angle`` [rad] turns the track during the run (the slip angle is recorded as beta).
        ``parameters``: FMU parameters for this run (default: the bed's ``parameters``)."""
        if not load > 0:
            raise ValueError(f"load = {load!r} N: expected > 0")
        if not abs(slip_angle) < math.pi / 2:
            raise ValueError(f"slip_angle = {slip_angle!r} rad: expected -pi/2 < slip_angle < pi/2")
        if not 0 < sample_time <= stop_time:
            raise ValueError(f"sample_time = {sample_time!r} s: "
                             f"expected 0 < sample_time <= stop_time = {stop_time!r} s")
        n = round(stop_time / sample_time)
        times = sample_time * np.arange(n + 1)
        taus = torque(times)
        turns = track_angle(times) if track_angle is not None else np.zeros(n + 1)
        if not np.all(np.abs(slip_angle + turns) < math.pi / 2):
            raise ValueError(f"track_angle = {track_angle!r}: the slip angle must stay in (-pi/2, pi/2) rad")
        rows = np.empty((n + 1, len(RECORDED)))
        rows[0] = self._start(load, float(taus[0]), float(turns[0]), tolerance, start_speed, slip_angle,
                              self.parameters if parameters is None else parameters, float(times[-1]))
        fmu = self.fmu
        changes = (np.flatnonzero((taus[1:n] != taus[:n - 1]) | (turns[1:n] != turns[:n - 1])) + 1).tolist()
        stepper = self._stepper()
        try:
            for first, last in zip([0, *changes], [*changes, n]):
                if first and taus[first] != taus[first - 1]:
                    fmu.set_values({"tau": float(taus[first])})
                if first and turns[first] != turns[first - 1]:
                    fmu.set_values({"trackAngle": float(turns[first])})
                self._steps(stepper, times, first, last, sample_time, rows)
        finally:
            if stepper is not None:
                stepper.close()
        fmu.terminate()
        return pd.DataFrame(np.column_stack([times, taus, rows]), columns=["time", "tau", *RECORDED])


    def _stepper(self) -> native.NativeStepper | None:
        """The native stepper for this run's stretches (the FMU's calls in C: the same calls as
        from Python, the same bits), or None where it is unavailable (no C compiler)."""
        if native.unavailable_reason() is not None or not self.fmu.real_only:
            return None
        slots = np.arange(len(RECORDED), dtype=np.int64)
        return native.NativeStepper([self.fmu], [np.zeros(0, dtype=np.int64)], [slots], [[0]], False, 1)

    def _steps(self, stepper: native.NativeStepper | None, times: np.ndarray, first: int, last: int, h: float,
               rows: np.ndarray) -> None:
        """Samples ``first`` .. ``last`` - 1 (one fmi2DoStep of ``h`` [s] each, the recorded
        variables after it into ``rows[k + 1]``), with the levels held."""
        if stepper is None:
            nothing = np.zeros(0)
            for k in range(first, last):
                self.fmu.do_step(float(times[k]), h, nothing)
                rows[k + 1] = self.fmu.get_outputs(float(times[k + 1]))
            return
        values, record = np.zeros(len(RECORDED)), np.arange(len(RECORDED), dtype=np.int64)
        while first < last:  # a non-finite output stops the stepper: recorded as read, the run goes on
            stepped = stepper.run(values, times, first, last, record, rows, h)
            if stepped < 0:
                return
            rows[stepper.reached + 1] = values
            first = stepper.reached + 1


_BEDS: dict[Path, WheelTestBed] = {}


def shared_test_bed(fmu_path: Path) -> WheelTestBed:
    """This process's test bed for ``fmu_path`` (created on first use)."""
    key = Path(fmu_path).resolve()
    if key not in _BEDS:
        _BEDS[key] = WheelTestBed(key)
    return _BEDS[key]
