"""An algorithm carried out by executors: :class:`Execution` takes the participants of a run,
asks the algorithm for its stages and hands each stage to the executor that steps it (the
native C stepper for the stages it can take, else threads or plain Python)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from . import native
from .algorithms import Algorithm, algorithm_of
from .executors import NativeExecutor, PythonExecutor, ThreadExecutor
from .model import System
from .observers import check_finite
from .participants import BlockParticipant, FmuParticipant, Participant, RunError
from .wiring import Wiring


class Execution:
    """``algorithm`` over ``participants`` (in the system's order), with ``threads`` threads and
    the native stepper where ``use_native`` and it builds; :meth:`step` advances one
    communication step in place on the value vector."""

    def __init__(self, algorithm: Algorithm, participants: Sequence[Participant], wiring: Wiring, threads: int = 1,
                 use_native: bool = True):
        self.algorithm = algorithm
        self.participants = list(participants)
        self.inputs = [wiring.participants[p.name].input_slots for p in participants]
        self.outputs = [wiring.participants[p.name].output_slots for p in participants]
        self.step_seconds = {p.name: 0.0 for p in participants}
        names = {int(slot): f"{p}.{v}" for p, ports in wiring.participants.items()
                 for v, slot in zip(ports.outputs, ports.output_slots)}
        self.slot_names = [names.get(slot, f"slot {slot}") for slot in range(wiring.size)]
        self.output_names = {p.name: wiring.participants[p.name].outputs for p in participants}
        self.stages = algorithm.stages(self.participants, self.inputs, self.outputs, threads)
        #: Whether participants may be stepped from C at all (explicit algorithm, native stepping on).
        self.native_enabled = algorithm.explicit and use_native
        for participant in self.participants:  # blocks that step C of their own from Python learn it too
            told = getattr(getattr(participant, "block", None), "use_native", None)
            if isinstance(participant, BlockParticipant) and callable(told):
                told(self.native_enabled)
        self.native = self._native(threads) if self.native_enabled else None
        self.natively: frozenset[int] = self.native.members if self.native is not None else frozenset()
        self.python: PythonExecutor
        if algorithm.explicit and threads > 1 and self.native is None:
            self.python = ThreadExecutor(self.participants, self.outputs, self.step_seconds, threads)
        else:
            self.python = PythonExecutor(self.participants, self.outputs, self.step_seconds)
        #: Per stage (by identity): its participants stepped natively and the others, split once.
        self._splits: dict[int, tuple[list[int], list[int]]] = {}
        self.signal_inputs = self._signal_inputs()
        algorithm.prepare(self)

    def _signal_inputs(self) -> list[tuple[int, np.ndarray, np.ndarray]]:
        """The Model Exchange FMUs fed by a source (a block without inputs: an input signal), with
        which of their inputs it feeds and the times [s] where those sources jump (a csv input's
        repeated time, a step): at a communication point they take the signals' new values at once,
        in Event Mode (with an event iteration) where a discrete input changes or a signal jumps,
        so that the row there shows them, as FMPy records an input event."""
        from .algorithms import sources

        found = []
        feeding = sources(self.participants, self.inputs)
        fed = np.concatenate([self.outputs[i] for i in feeding] or [np.zeros(0, int)])
        for i, p in enumerate(self.participants):
            mine = np.isin(self.inputs[i], fed)
            if not (getattr(p, "takes_signals", False) and mine.any()):
                continue
            jumps = [np.asarray(getattr(getattr(self.participants[k], "block", None), "jump_times", ()), float)
                     for k in feeding if np.isin(self.outputs[k], self.inputs[i]).any()]
            found.append((i, mine, np.unique(np.concatenate(jumps or [np.zeros(0)]))))
        return found

    def _steppable(self, i: int) -> bool:
        """Whether participant ``i`` can be stepped natively: an FMU whose exchanged variables are
        all Real, or a block that has a C twin."""
        participant = self.participants[i]
        if isinstance(participant, FmuParticipant):
            return participant.real_only  # the stepper calls fmi2SetReal and fmi2GetReal only
        return isinstance(participant, BlockParticipant) and participant.make_native()

    def _native(self, threads: int) -> NativeExecutor | None:
        """The native executor of the stages whose participants can all be stepped natively
        (Jacobi: the participants of its one stage that can), when the stepper is available."""
        if native.unavailable_reason() is not None:
            return None
        if self.algorithm.gathers_first:
            chosen = [[i for i in g if self._steppable(i)] for g in self.stages]
        else:
            chosen = [g for g in self.stages if all(self._steppable(i) for i in g)]
        chosen = [g for g in chosen if g]
        if not any(not isinstance(self.participants[i], BlockParticipant) for g in chosen for i in g):
            return None  # blocks alone: nothing to gain
        return NativeExecutor(self.participants, self.inputs, self.outputs, chosen, self.algorithm.gathers_first,
                              threads)

    # --- what the run loop and the tests look at ----------------------------------------------
    @property
    def stepper(self) -> native.NativeStepper | None:
        return self.native.stepper if self.native is not None else None

    @property
    def pool(self):  # noqa: ANN201 - executors.Crew | None
        return self.python.pool

    @property
    def all_native(self) -> bool:
        return len(self.natively) == len(self.participants)

    @property
    def checked_in_python(self) -> list[int]:
        """Participants whose outputs the run loop checks (the native stepper checks its own)."""
        return [i for i in range(len(self.participants)) if i not in self.natively]

    # --- stepping -----------------------------------------------------------------------------
    def step(self, values: np.ndarray, t: float, h: float) -> None:
        """Advance every participant from ``t`` to ``t + h``; ``values`` then holds the outputs at ``t + h``."""
        self.algorithm.step(self, values, t, h)
        end = t + h
        for i, fed, jumps in self.signal_inputs:  # the input signals' values at t + h, taken there
            participant = self.participants[i]
            # a jump in (t, t + h], to the rounding of the communication points
            slack = 1e-9 * h
            jump = bool(jumps.size) and bool(np.any((jumps > t + slack) & (jumps <= end + slack)))
            if participant.take_signals(values[self.inputs[i]], fed, end, jump):  # type: ignore[attr-defined]
                values[self.outputs[i]] = participant.get_outputs(end)

    def run_stage(self, stage: Sequence[int], values: np.ndarray, t: float, h: float) -> None:
        """Step the participants of ``stage`` from the values as they are now."""
        split = self._splits.get(id(stage))
        if split is None:
            split = self._splits[id(stage)] = ([i for i in stage if i in self.natively],
                                               [i for i in stage if i not in self.natively])
        natively, rest = split
        if not natively:
            self.python.run(stage, [values[self.inputs[i]] for i in stage], values, t, h)
            return
        assert self.native is not None
        gathered = [values[self.inputs[i]] for i in rest]
        self.check_native(self.native.run_group(values, natively[0], t, h), values, t + h)
        self.python.run(rest, gathered, values, t, h)

    def run_stretch(self, values: np.ndarray, times: np.ndarray, first: int, last: int, record: np.ndarray,
                    rows: np.ndarray) -> tuple[int, int]:
        """Steps ``first`` .. ``last`` - 1 from C (every participant stepped natively), recording
        ``values[record]`` in ``rows[k + 1]``; returns (the steps completed, -1 or the unit whose
        output was not finite: pass it to :meth:`check_native`). Other failures are RunErrors."""
        assert self.native is not None
        failed = self.native.run_stretch(values, times, first, last, record, rows)
        return self.native.reached, failed

    def check_native(self, failed: int, values: np.ndarray, t: float) -> None:
        """A non-finite output from the native stepper, named as check_finite names it."""
        if failed >= 0:
            check_finite(self, values, t, sorted(self.natively))
            raise RunError(f"native stepper: a non-finite output at t = {t:.6g} s")

    def close(self) -> None:
        """End the executors' threads and free the native stepper."""
        self.python.close()
        if self.native is not None:
            self.native.close(self.step_seconds)


def make_execution(system: System, participants: Sequence[Participant], wiring: Wiring) -> Execution:
    """The system's algorithm over its participants, with the system's threads and native setting."""
    algorithm = algorithm_of(system.algorithm, system.iteration)
    return Execution(algorithm, participants, wiring, threads=system.threads, use_native=system.native)
