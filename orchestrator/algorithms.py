"""Master algorithms at a fixed communication step: which participants step in which order, and
which values each one sees. How a stage of steps is carried out (in Python, on threads, from C)
is the executors' business (``executors``); ``execution`` puts the two together.

- :class:`Jacobi`: every participant from the values at ``t``; outputs exchanged after all have
  stepped (one stage);
- :class:`GaussSeidel`: participant after participant, each with the newest values of those
  before it (a stage each; with threads, FMUs in a row of the order that read none of each
  other's outputs form one stage: the same values as one after the other);
- :class:`GaussSeidelInterpolated`: Gauss-Seidel where an FMU that can interpolate its inputs gets
  those from participants before it (FMUs, and blocks' declared ``ramped_outputs``) as the line
  from their value at ``t`` to the one at ``t + h`` (fmi2SetRealInputDerivatives) instead of the
  value at ``t + h`` held over the step;
- :class:`Iterative`: each step repeated from the participants' saved states until the exchanged
  values converge.

Participants are numbered by their position in the system's order; ``inputs[i]`` and
``outputs[i]`` are participant ``i``'s slots in the value vector (``wiring``).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from .model import Iteration
from .native import NativeStepper
from .participants import BlockParticipant, Participant, RunError


class Stepping(Protocol):
    """What an algorithm (and an observer) sees of the execution carrying it out
    (``execution.Execution``): the participants in order, their slots, the time inside each."""

    participants: list[Participant]
    inputs: list[np.ndarray]
    outputs: list[np.ndarray]
    stages: list[list[int]]
    step_seconds: dict[str, float]
    slot_names: list[str]                 # "instance.variable" of each slot of the value vector
    output_names: dict[str, list[str]]    # per participant, its outputs in the order of its slots
    natively: frozenset[int]              # the participants the native stepper steps

    @property
    def stepper(self) -> NativeStepper | None: ...

    def run_stage(self, stage: Sequence[int], values: np.ndarray, t: float, h: float) -> None: ...

#: Pieces of the iterative master's first communication step (see Iterative.step).
START_SUBSTEPS = 10


def sources(participants: Sequence[Participant], inputs: Sequence[np.ndarray]) -> list[int]:
    """The positions of the sources: blocks without inputs (functions of time: a csv input, a step,
    a ramp). Every participant sees a source's value at the communication point it steps from, as
    FMPy gives an FMU its inputs, under every master: the masters step the sources after the others."""
    return [i for i, (p, slots) in enumerate(zip(participants, inputs)) if isinstance(p, BlockParticipant)
            and not len(slots)]


class Algorithm:
    """An explicit algorithm is a list of stages stepped one after the other each communication
    step; the participants of a stage see the values as they were when the stage began."""

    name = "algorithm"
    #: Every input of the (one) stage is gathered at t before any participant steps (Jacobi).
    gathers_first = False
    #: The executors may step its stages on threads or from C (explicit algorithms).
    explicit = True

    @classmethod
    def of(cls, iteration: Iteration | None = None) -> Algorithm:
        """The algorithm of a system whose iteration settings are ``iteration`` (only the
        iterative master has any)."""
        return cls()

    def stages(self, participants: Sequence[Participant], inputs: Sequence[np.ndarray],
               outputs: Sequence[np.ndarray], threads: int) -> list[list[int]]:
        """The stages of one communication step, as lists of participant positions."""
        return [[i] for i in range(len(participants))]

    def prepare(self, execution: Stepping) -> None:
        """Called once the execution is set up (before the first step)."""

    def step(self, execution: Stepping, values: np.ndarray, t: float, h: float) -> None:
        """Advance every participant from ``t`` to ``t + h``; ``values`` then holds the outputs at ``t + h``."""
        for stage in execution.stages:
            execution.run_stage(stage, values, t, h)


class Jacobi(Algorithm):
    """Every participant from the values at ``t`` (one stage)."""

    name = "jacobi"
    gathers_first = True

    def stages(self, participants: Sequence[Participant], inputs: Sequence[np.ndarray],
               outputs: Sequence[np.ndarray], threads: int) -> list[list[int]]:
        return [list(range(len(participants)))]


class GaussSeidel(Algorithm):
    """Participant after participant in the system's order; with threads, runs of FMUs that read
    none of each other's outputs (the six wheels after the body) form one stage."""

    name = "gauss-seidel"

    def stages(self, participants: Sequence[Participant], inputs: Sequence[np.ndarray],
               outputs: Sequence[np.ndarray], threads: int) -> list[list[int]]:
        last = sources(participants, inputs)  # stepped after the others: they see their value at t
        order = [i for i in range(len(participants)) if i not in last] + last
        if threads > 1:
            return independent_runs(participants, inputs, outputs, order)
        return [[i] for i in order]


class GaussSeidelInterpolated(Algorithm):
    """Gauss-Seidel in the system's order, and an FMU that can interpolate its inputs (FMI 2.0
    Co-Simulation, canInterpolateInputs) takes those another FMU before it has already moved to
    ``t + h`` as the line from their value at ``t`` to that one (a first-order hold of what its
    source did over the step, fmi2SetRealInputDerivatives), not the value at ``t + h`` held over
    the whole step: a wheel fed the hub's speed of an accelerating body sees it rise through the
    step, as in the monolithic model, not half a step ahead. A block's outputs are held (a
    controller's output is a sample and hold), except those it declares ``ramped_outputs`` (a
    first-order hold of its own: a set-point moving linearly between updates), which are ramped
    as an FMU's. Inputs from participants after it (the values at ``t``), discrete inputs and
    every input of a block or of an FMU that cannot interpolate are as in Gauss-Seidel. The
    native stepper ramps as the Python master does (the same calls, the same results); an FMU it
    cannot step (other than FMI 2.0 Co-Simulation exchanging Reals) steps in Python."""

    name = "gauss-seidel-interpolated"

    def __init__(self) -> None:
        self.ramped: list[np.ndarray] = []  # per participant, which of its inputs ramp (bool per input)
        self._marks: NativeStepper | None = None  # the native stepper whose ramped units need the start values

    def stages(self, participants: Sequence[Participant], inputs: Sequence[np.ndarray],
               outputs: Sequence[np.ndarray], threads: int) -> list[list[int]]:
        last = sources(participants, inputs)
        return [[i] for i in range(len(participants)) if i not in last] + [[i] for i in last]

    def _ramps(self, participants: Sequence[Participant], inputs: Sequence[np.ndarray],
               outputs: Sequence[np.ndarray]) -> list[np.ndarray]:
        """Per participant, which of its inputs ramp."""
        last = sources(participants, inputs)
        ramped = [np.zeros(len(slots), bool) for slots in inputs]
        moved: list[np.ndarray] = []
        for [i] in self.stages(participants, inputs, outputs, 1):
            participant = participants[i]
            if getattr(participant, "can_interpolate", False) and moved and i not in last:
                discrete = getattr(participant, "discrete_inputs", np.zeros(len(inputs[i]), dtype=bool))
                ramped[i] = np.isin(inputs[i], np.concatenate(moved)) & ~discrete
            if not isinstance(participant, BlockParticipant):
                moved.append(np.asarray(outputs[i]))
            else:
                declared = set(getattr(participant.block, "ramped_outputs", ()))
                moved.append(np.asarray(outputs[i])[[name in declared for name in participant.outputs]])
        return ramped

    def prepare(self, execution: Stepping) -> None:
        self.ramped = self._ramps(execution.participants, execution.inputs, execution.outputs)
        stepper, self._marks = execution.stepper, None
        for i, ramped in enumerate(self.ramped):
            if stepper is not None and i in execution.natively and ramped.any():
                stepper.ramp(i, ramped)
                self._marks = stepper

    def step(self, execution: Stepping, values: np.ndarray, t: float, h: float) -> None:
        clock = time.perf_counter
        start = values.copy()
        if self._marks is not None:
            self._marks.mark(values)
        for stage in execution.stages:
            i = stage[0]
            ramped = self.ramped[i]
            if not ramped.any() or i in execution.natively:
                execution.run_stage(stage, values, t, h)
                continue
            participant, slots = execution.participants[i], execution.inputs[i]
            begin = clock()
            participant.do_step(t, h, np.where(ramped, start[slots], values[slots]),
                                np.where(ramped, (values[slots] - start[slots]) / h, 0.0))
            values[execution.outputs[i]] = participant.get_outputs(t + h)
            execution.step_seconds[participant.name] += clock() - begin


def independent_runs(participants: Sequence[Participant], inputs: Sequence[np.ndarray],
                     outputs: Sequence[np.ndarray], order: Sequence[int] | None = None) -> list[list[int]]:
    """``order`` (default: the participants' own) cut into runs of FMUs that read none of each
    other's outputs (blocks alone)."""
    groups: list[list[int]] = []
    written: set[int] = set()
    for i in (range(len(participants)) if order is None else order):
        participant = participants[i]
        reads = set(inputs[i].tolist())
        if (groups and not isinstance(participant, BlockParticipant) and len(groups[-1]) >= 1
                and not isinstance(participants[groups[-1][0]], BlockParticipant) and not reads & written):
            groups[-1].append(i)
        else:
            groups.append([i])
            written = set()
        written |= set(outputs[i].tolist())
    return groups


class Iterative(Algorithm):
    """Each step repeated from the participants' saved states (fmi2GetFMUstate / the blocks'
    get_state) until the exchanged values converge. Each pass steps the participants in order
    (Gauss-Seidel within the pass: a participant sees the outputs at ``t + h`` of those before it
    in this pass, of the others from the last pass); every FMU steps with its inputs interpolated
    linearly from their values at ``t`` to those at ``t + h`` (fmi2SetRealInputDerivatives; an
    FMU that cannot interpolate holds their mean), an implicit, second-order coupling; blocks get
    the guess at ``t + h``. The guess moves ``relaxation`` of the way to the new outputs, and the
    step is accepted when no exchanged value changed by more than ``tolerance`` x (1 + |value|).
    Non-convergence within ``max_iterations`` passes is a RunError naming the step and the
    signals still moving. Steps in Python (it saves and restores states between passes)."""

    name = "iterative"
    explicit = False

    @classmethod
    def of(cls, iteration: Iteration | None = None) -> Algorithm:
        return cls(iteration)

    def __init__(self, iteration: Iteration | None = None):
        self.iteration = iteration or Iteration()
        self.passes = 0       # total passes, for the statistics
        self.steps = 0
        self.exchanged = np.zeros(0, int)
        self.holds: list[str] = []
        self.sources: list[int] = []

    def prepare(self, execution: Stepping) -> None:
        inputs = execution.inputs
        # The sources step once, after the iteration: within it every participant sees their
        # value at t, held over the step (slope 0), as FMPy gives an FMU its inputs.
        self.sources = sources(execution.participants, inputs)
        exchanged = np.unique(np.concatenate([slots for slots in inputs if len(slots)] or [np.zeros(0, int)]))
        self.exchanged = exchanged.astype(int)
        # FMUs that can interpolate inputs get them linearly from t to the guess at t + h; other
        # FMUs hold the mean of the two (trapezoidal); blocks compute their outputs at t + h from
        # the inputs there (the guess).
        self.holds = ["end" if isinstance(p, BlockParticipant)
                      else "interpolate" if getattr(p, "can_interpolate", False) else "mean"
                      for p in execution.participants]
        # Discrete inputs (Integer, Boolean, discrete Reals) are never interpolated nor averaged:
        # they take the guess at t + h, as a participant after their source sees them.
        self.discrete = [getattr(p, "discrete_inputs", np.zeros(len(p.inputs), dtype=bool))
                         for p in execution.participants]

    def step(self, execution: Stepping, values: np.ndarray, t: float, h: float) -> None:
        # The first step of a run is taken in START_SUBSTEPS pieces: inputs switched on at the
        # start (a torque step from rest) make the exchanged values jump within it, which no
        # interpolation over the whole step follows.
        pieces = START_SUBSTEPS if self.steps == 0 else 1
        for piece in range(pieces):
            self._iterate(execution, values, t + piece * h / pieces, h / pieces)
        for i in self.sources:
            participant = execution.participants[i]
            participant.do_step(t, h, values[execution.inputs[i]])
            values[execution.outputs[i]] = participant.get_outputs(t + h)
        self.steps += 1

    def _pass(self, execution: Stepping, start: np.ndarray, guess: np.ndarray, t: float, h: float) -> np.ndarray:
        """One pass over the participants in order; returns the new values."""
        clock = time.perf_counter
        new = guess.copy()  # filled in order: later participants see this pass's outputs
        for k, (participant, inputs, outputs, hold, discrete) in enumerate(zip(
                execution.participants, execution.inputs, execution.outputs, self.holds, self.discrete)):
            if k in self.sources:
                continue
            begin = clock()
            if hold == "interpolate":
                held = np.where(discrete, new[inputs], start[inputs])
                participant.do_step(t, h, held, np.where(discrete, 0.0, (new[inputs] - start[inputs]) / h))
            elif hold == "mean":
                participant.do_step(t, h, np.where(discrete, new[inputs], 0.5 * (start[inputs] + new[inputs])))
            else:
                participant.do_step(t, h, new[inputs])
            new[outputs] = participant.get_outputs(t + h)
            execution.step_seconds[participant.name] += clock() - begin
        return new

    def _iterate(self, execution: Stepping, values: np.ndarray, t: float, h: float) -> None:
        settings, participants = self.iteration, execution.participants
        start = values.copy()
        guess = values.copy()
        states = [p.get_state(t) for p in participants]
        try:
            for attempt in range(1, settings.max_iterations + 1):
                new = self._pass(execution, start, guess, t, h)
                change = np.abs(new[self.exchanged] - guess[self.exchanged])
                scale = settings.tolerance * (1.0 + np.abs(new[self.exchanged]))
                self.passes += 1
                if np.all(change <= scale) and attempt > 1:
                    values[:] = new
                    return
                guess += settings.relaxation * (new - guess)
                if attempt < settings.max_iterations:
                    for participant, state in zip(participants, states):
                        participant.set_state(state, t)
            worst = np.argsort(-(change / scale))[:3]
            signals = ", ".join(f"{execution.slot_names[self.exchanged[i]]} (changed {change[i]:.3g})" for i in worst
                                if change[i] > scale[i])
            raise RunError(f"iterative master: the step from t = {t:.6g} s did not converge in "
                           f"{settings.max_iterations} passes (tolerance {settings.tolerance:g}); still moving: "
                           f"{signals}")
        finally:
            for participant, state in zip(participants, states):
                participant.free_state(state)


#: The master algorithms by their name (a system's ``algorithm``; the command line's choices): a
#: new algorithm is a class above and its entry here.
ALGORITHMS: dict[str, type[Algorithm]] = {cls.name: cls for cls in (Jacobi, GaussSeidel, GaussSeidelInterpolated,
                                                                    Iterative)}


def algorithm_of(name: str, iteration: Iteration | None = None) -> Algorithm:
    """The algorithm called ``name`` (a system's ``algorithm``)."""
    if not isinstance(name, str) or name not in ALGORITHMS:
        raise ValueError(f"algorithm {name!r}: expected one of {', '.join(ALGORITHMS)}")
    return ALGORITHMS[name].of(iteration)
