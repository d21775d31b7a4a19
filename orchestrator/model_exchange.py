"""Model Exchange FMUs (FMI 2.0 and 3.0) in a co-simulation: the engine integrates them.

:class:`ModelExchangeParticipant` is a participant like a Co-Simulation FMU: over each
communication step it holds the inputs (continuous ones set in Continuous-Time Mode, discrete
ones that changed set in Event Mode with an event iteration), integrates the states with
SUNDIALS CVode (BDF, FMPy's wrapper ``fmpy.sundials.CVodeSolver``; it goes on across
communication points and restarts where the inputs jump, after an event and after a restored
state), and handles the events on the way:

- state events: a sign change of an event indicator, located by CVode's root finding;
- time events: the next event time the FMU announced (the integration stops exactly there);
- step events: fmi2CompletedIntegratorStep asking for Event Mode.

At each event it enters Event Mode and iterates fmi2NewDiscreteStates (fmi3UpdateDiscreteStates)
until no new discrete states are needed (at most :data:`MAX_EVENT_ITERATIONS` passes), then
goes on in Continuous-Time Mode with the integrator restarted. An FMU asking to terminate ends
the run cleanly there (:class:`~rover_cosim.orchestrator.participants.Terminated`).

Tolerances: CVode's relative tolerance is the system's ``relative_tolerance`` (default 1e-6), its
absolute tolerance that times each state's nominal value, as FMPy does.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from fmpy.sundials import CVodeSolver

from .fmi_access import Exchange, StringTable
from .model import FmuEntry
from .participants import FmuParticipant, RunError

#: Passes of the event iteration at one event before the FMU is said not to settle.
MAX_EVENT_ITERATIONS = 100
#: Events within one communication step before the FMU is said to chatter.
MAX_EVENTS_PER_STEP = 10_000
#: CVode steps within one communication step (between two events).
MAX_SOLVER_STEPS = 100_000


class _Held:
    """The inputs as CVode sees them: held by the participant over the step (nothing to apply)."""

    def apply(self, *args: Any, **kwargs: Any) -> None:
        """Nothing to do: the participant sets the inputs before integrating."""


class _Solver(CVodeSolver):
    """FMPy's CVode wrapper whose right-hand side and root functions turn a failed FMU call into
    a CVode failure (kept in ``failure``) instead of an exception inside a C callback."""

    failure: str | None = None

    def f(self, t, y, ydot, user_data):  # noqa: ANN001, ANN201 - CVode's callback signature
        try:
            return super().f(t, y, ydot, user_data)
        except Exception as error:  # noqa: BLE001 - reported through step()
            self.failure = self.failure or f"the derivatives at t = {t:.6g} s: {error}"
            return -1

    def g(self, t, y, gout, user_data):  # noqa: ANN001, ANN201
        try:
            return super().g(t, y, gout, user_data)
        except Exception as error:  # noqa: BLE001
            self.failure = self.failure or f"the event indicators at t = {t:.6g} s: {error}"
            return -1


class ModelExchangeParticipant(FmuParticipant):
    """An FMU run through its Model Exchange interface, integrated by CVode over each step."""

    #: Takes an input signal's jump at a communication point (``take_signals``; ``execution``).
    takes_signals = True

    def __init__(self, entry: FmuEntry, folder: Path, strings: StringTable | None = None,
                 relative_tolerance: float = 1e-6):
        super().__init__(entry, folder, strings)
        md = entry.description
        self.nx = int(md.numberOfContinuousStates or 0)
        self.nz = int(md.numberOfEventIndicators or 0)
        self.tolerance = relative_tolerance
        self.needs_completed_step = bool(getattr(md.modelExchange, "needsCompletedIntegratorStep", False))
        self.can_interpolate = False
        self.solver: _Solver | None = None
        self.next_event = math.inf   # s, the next time event the FMU announced
        self._discrete = np.zeros(0, dtype=bool)
        #: Whether CVode may go on from where it stopped (nothing changed since: no restart needed).
        self._fresh = False
        self._step_start = 0.0  # s, where the step under way began (an end inside it is reported from there)

    def configure(self, inputs: list[str], reads: list[str]) -> None:
        super().configure(inputs, reads)
        self._discrete = self.discrete_inputs
        # the continuous inputs alone: what may be set in Continuous-Time Mode
        self._continuous_positions = np.flatnonzero(~self._discrete)
        self._continuous = Exchange(self.version, [self.inputs[k] for k in self._continuous_positions], self.types,
                                    self.refs, self.strings, self.elements)

    # --- FMI calls that differ between the versions ----------------------------------------------
    def _mode(self, what: str, t: float) -> None:
        """Enter Event Mode (``what`` = "event") or Continuous-Time Mode ("continuous")."""
        if what == "event":
            self._call(f"fmi{self.version}EnterEventMode", self.fmu.enterEventMode, t)
        else:
            self._call(f"fmi{self.version}EnterContinuousTimeMode", self.fmu.enterContinuousTimeMode, t)

    def _event_iteration(self, t: float) -> None:
        """New discrete states until none are needed; the next time event; Terminated where the
        FMU asks to end the simulation."""
        update = self.fmu.newDiscreteStates if self.version == 2 else self.fmu.updateDiscreteStates
        name = "fmi2NewDiscreteStates" if self.version == 2 else "fmi3UpdateDiscreteStates"
        for _ in range(MAX_EVENT_ITERATIONS):
            needed, terminate, _nominals, _values, defined, next_time = self._call(name, update, t)
            if terminate:  # the run ends in the step from its start, having got to t
                self.end(min(self._step_start, t), t)
            if not needed:
                self.next_event = float(next_time) if defined else math.inf
                return
        raise RunError(f"{self.name} ({self.entry.path.name}): the event iteration at t = {t:.6g} s did not settle "
                       f"in {MAX_EVENT_ITERATIONS} passes")

    def _event(self, t: float) -> None:
        """An event at ``t``: Event Mode, the event iteration, Continuous-Time Mode, a fresh integrator."""
        self._mode("event", t)
        self._event_iteration(t)
        self._mode("continuous", t)

    def _make_solver(self, t0: float) -> None:
        fmu = self.fmu
        get_dx = fmu.getDerivatives if self.version == 2 else fmu.getContinuousStateDerivatives
        self.solver = self._call("CVode (start)", lambda: _Solver(
            nx=self.nx, nz=self.nz, get_x=fmu.getContinuousStates, set_x=fmu.setContinuousStates, get_dx=get_dx,
            get_z=fmu.getEventIndicators, get_nominals=fmu.getNominalsOfContinuousStates, set_time=fmu.setTime,
            input=_Held(), startTime=t0, relativeTolerance=self.tolerance, maxNumSteps=MAX_SOLVER_STEPS), t0)

    # --- the participant ------------------------------------------------------------------------
    def exit_initialization(self, t0: float, u: np.ndarray) -> np.ndarray:
        """Exit Initialization Mode, the initial event iteration, Continuous-Time Mode, the integrator."""
        self._step_start = t0
        self.set_inputs(u, t0)
        self._call(f"fmi{self.version}ExitInitializationMode", self.fmu.exitInitializationMode, t0)
        self._event_iteration(t0)
        self._mode("continuous", t0)
        self._make_solver(t0)
        self._fresh = True
        return self.get_outputs(t0)

    def do_step(self, t: float, h: float, u: np.ndarray, slopes: np.ndarray | None = None) -> None:
        """Integrate from ``t`` to ``t + h`` with the inputs ``u`` held (``slopes`` are not used:
        a held input is what an ME FMU is given between events)."""
        self._step_start = t
        self._take_inputs(np.asarray(u, dtype=float), t)
        if not self._fresh:  # the inputs, or the state (an event, a restored state), changed: restart at t
            self._restart(t)
        end = t + h
        now = t
        for _ in range(MAX_EVENTS_PER_STEP):
            if not now < end - 1e-12 * max(1.0, abs(end)):
                break
            now = self._advance(t, now, end)
        else:
            raise RunError(f"{self.name} ({self.entry.path.name}): more than {MAX_EVENTS_PER_STEP} events in the step "
                           f"from t = {t:.6g} s (the FMU chatters)")
        if now != end:
            self._call(f"fmi{self.version}SetTime", lambda: self.fmu.setTime(end), end)

    def take_signals(self, u: np.ndarray, fed: np.ndarray, t: float, jump: bool = False) -> bool:
        """At the end of a step (``t``): the inputs ``fed`` by input signals take their values in
        ``u`` there (an event where a discrete one changes, or where a signal ``jump``s: FMPy's
        input event, which a continuous input's jump may trigger through the FMU's event
        indicators); whether any changed."""
        new = self.input_values.copy()
        new[fed] = np.asarray(u, dtype=float)[fed]
        if np.array_equal(new, self.input_values, equal_nan=True):
            return False
        self._step_start = t
        self._take_inputs(new, t, jump)
        return True

    def _take_inputs(self, u: np.ndarray, t: float, jump: bool = False) -> None:
        """Set the inputs that changed: in Event Mode (with an event iteration) where a discrete one did
        or a signal jumps."""
        moved = u != self.input_values
        if not self.inputs or not bool(np.any(moved)):
            return
        if jump or bool(np.any(self._discrete & moved)):  # an input event at t
            self._mode("event", t)
            self.set_inputs(u, t)
            self._event_iteration(t)
            self._mode("continuous", t)
        else:  # continuous inputs only, in Continuous-Time Mode
            chosen = self._continuous_positions
            self.input_values[chosen] = u[chosen]
            self._continuous.set(self.fmu, self.input_values[chosen], self._exchange("set", t))
        self._fresh = False

    def _advance(self, t: float, now: float, end: float) -> float:
        """Integrate from ``now`` towards ``end`` up to the first event (handled); the time reached [s]."""
        target = max(now, min(end, self.next_event))
        if target - now > 1e-13 * max(1.0, abs(now)):
            state_event, _roots, now = self._integrate(now, target)
        else:
            state_event, now = False, target
        reached = now
        self._call(f"fmi{self.version}SetTime", lambda: self.fmu.setTime(reached), reached)
        step_event = False
        if self.needs_completed_step:
            step_event, terminate = self._call(f"fmi{self.version}CompletedIntegratorStep",
                                               self.fmu.completedIntegratorStep, reached)
            if terminate:
                self.end(t, reached)
        time_event = not state_event and self.next_event <= reached + 1e-12 * max(1.0, abs(reached))
        if state_event or time_event or step_event:
            self._event(reached)
            self._restart(reached)
        return reached

    def _restart(self, t: float) -> None:
        solver = self.solver
        assert solver is not None
        self._call("CVode (restart)", lambda: solver.reset(t), t)
        self._fresh = True

    def _integrate(self, now: float, target: float) -> tuple[bool, Any, float]:
        assert self.solver is not None
        solver = self.solver
        solver.failure = None
        try:
            return solver.step(now, target)
        except Exception as error:  # noqa: BLE001 - CVode's failure, or the FMU's within it
            detail = "; ".join(self.messages[-3:]) or solver.failure or str(error)
            raise RunError(f"{self.name} ({self.entry.path.name}): integrating from t = {now:.6g} s failed: "
                           f"{detail}") from None

    def get_state(self, t: float) -> Any:
        """The FMU's state and its next time event (the integrator restarts from any restored state)."""
        return super().get_state(t), self.next_event

    def set_state(self, state: Any, t: float) -> None:
        fmu_state, self.next_event = state
        super().set_state(fmu_state, t)
        self._fresh = False
        self.input_values[:] = np.nan  # the restored FMU holds the inputs of its time: set them all anew

    def free_state(self, state: Any) -> None:
        super().free_state(state[0])

    def reset(self) -> None:
        """Back to the state after instantiation; the integrator is made anew at the next start."""
        super().reset()
        self.solver, self.next_event, self._fresh = None, math.inf, False


def make_fmu_participant(entry: FmuEntry, folder: Path, strings: StringTable,
                         relative_tolerance: float = 1e-6) -> FmuParticipant:
    """The participant running ``entry`` (unpacked in ``folder``) through the interface it names
    (Co-Simulation or Model Exchange)."""
    if entry.interface == "model-exchange":
        return ModelExchangeParticipant(entry, folder, strings, relative_tolerance)
    return FmuParticipant(entry, folder, strings)
