"""Master algorithms at a fixed communication step, and :func:`run`.

Every value exchanged or recorded has a slot in one vector ``values`` (``wiring``); each
participant reads its inputs from the slots of their sources and writes its outputs into its own
slots. :class:`JacobiMaster` steps all participants from the values at ``t`` and then exchanges;
:class:`GaussSeidelMaster` steps them in order, each seeing the outputs at ``t + h`` of those
before it. Recorded values go into a preallocated array (``recorder``).
"""

from __future__ import annotations

import os
import shutil
import tempfile
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from . import native
from .participants import BlockParticipant, FmuParticipant, Participant, RunError
from .recorder import Recorder, communication_points
from .system import Iteration, System
from .wiring import Wiring, wire

#: Passes of the initial-output exchange among participants with an iterative start (FMUs in
#: Initialization Mode), so that a chain of direct feedthrough two deep settles.
INITIAL_PASSES = 2
#: Pieces of the iterative master's first communication step (see IterativeMaster.step).
START_SUBSTEPS = 10


@dataclass
class RunResult:
    data: pd.DataFrame  # time [s] and one column per recorded "instance.variable"
    wall_seconds: float
    steps: int
    step_seconds: dict[str, float] = field(default_factory=dict)  # time inside each participant's step

    @property
    def master_overhead_seconds(self) -> float:
        return self.wall_seconds - sum(self.step_seconds.values())


class Master(ABC):
    """Steps the participants (in the system's order) over one communication step, in place on
    the value vector, and keeps the time spent inside each participant."""

    def __init__(self, participants: list[Participant], wiring: Wiring):
        self.participants = participants
        self.inputs = [wiring.participants[p.name].input_slots for p in participants]
        self.outputs = [wiring.participants[p.name].output_slots for p in participants]
        self.step_seconds = {p.name: 0.0 for p in participants}

    pool: Crew | None = None
    stepper: native.NativeStepper | None = None
    #: Participants stepped by the native stepper (FMUs, and blocks with a C twin).
    natively: frozenset[int] = frozenset()

    @abstractmethod
    def step(self, values: np.ndarray, t: float, h: float) -> None:
        """Advance every participant from ``t`` to ``t + h``; ``values`` then holds the outputs at ``t + h``."""

    def close(self) -> None:
        """End the master's threads (if any)."""
        if self.pool is not None:
            self.pool.shutdown()
        if self.stepper is not None:
            self.step_seconds.update(self.stepper.seconds())
            self.stepper.close()
            self.stepper = None

    def _steppable(self, i: int) -> bool:
        """Whether participant ``i`` can be stepped natively: an FMU, or a block that has a C twin."""
        participant = self.participants[i]
        return not isinstance(participant, BlockParticipant) or participant.make_native()

    def _native(self, groups: list[list[int]], jacobi: bool, threads: int, enabled: bool) -> list[list[int]]:
        """Hand the groups whose participants can all be stepped natively to a native stepper,
        when enabled and available (Jacobi: the participants of its one group that can); returns
        those groups."""
        if not enabled or native.unavailable_reason() is not None:
            return []
        if jacobi:
            chosen = [[i for i in g if self._steppable(i)] for g in groups]
        else:
            chosen = [g for g in groups if all(self._steppable(i) for i in g)]
        chosen = [g for g in chosen if g]
        if not any(not isinstance(self.participants[i], BlockParticipant) for g in chosen for i in g):
            return []  # blocks alone: nothing to gain
        self.stepper = native.NativeStepper(self.participants, self.inputs, self.outputs, chosen, jacobi, threads)
        self.natively = frozenset(i for g in chosen for i in g)
        if self.pool is not None:  # the stepper has its own threads
            self.pool.shutdown()
            self.pool = None
        return chosen

    @property
    def checked_in_python(self) -> list[int]:
        """Participants whose outputs the run loop checks (the native stepper checks its own)."""
        return [i for i in range(len(self.participants)) if i not in self.natively]

    @property
    def all_native(self) -> bool:
        return len(self.natively) == len(self.participants)

    def _check_native(self, failed: int, values: np.ndarray, t: float) -> None:
        """A non-finite output from the native stepper, named as check_finite names it."""
        if failed >= 0:
            check_finite({p.name: p.outputs for p in self.participants}, self, values, t, sorted(self.natively))
            raise RunError(f"native stepper: a non-finite output at t = {t:.6g} s")

    def _advance(self, i: int, u: np.ndarray, t: float, h: float) -> np.ndarray:
        """Step participant ``i`` with ``u`` and return a copy of its outputs at ``t + h``."""
        participant = self.participants[i]
        begin = time.perf_counter()
        participant.do_step(t, h, u)
        produced = np.array(participant.get_outputs(t + h))
        self.step_seconds[participant.name] += time.perf_counter() - begin
        return produced

    def _step_one(self, i: int, values: np.ndarray, u: np.ndarray, t: float, h: float) -> None:
        values[self.outputs[i]] = self._advance(i, u, t, h)

    def _step_together(self, group: list[int], values: np.ndarray, inputs: list[np.ndarray], t: float,
                       h: float) -> None:
        assert self.pool is not None
        produced: dict[int, np.ndarray] = {}

        def task(i: int, u: np.ndarray) -> Callable[[], None]:
            return lambda: produced.__setitem__(i, self._advance(i, u, t, h))

        self.pool.run([task(i, u) for i, u in zip(group, inputs)])
        for i in group:
            values[self.outputs[i]] = produced[i]


class GaussSeidelMaster(Master):
    """Participant after participant, each with the newest values of those before it. FMUs in a
    row of the order that read none of each other's outputs (the six wheels after the body) step
    at the same time in threads: the same values as one after the other."""

    def __init__(self, participants: list[Participant], wiring: Wiring, threads: int = 1, use_native: bool = True):
        super().__init__(participants, wiring)
        self.pool = _pool(threads)
        self.groups = _independent_runs(participants, self.inputs, self.outputs) if threads > 1 else [
            [i] for i in range(len(participants))]
        self._native(self.groups, False, threads, use_native)

    def step(self, values: np.ndarray, t: float, h: float) -> None:
        for group in self.groups:
            if group[0] in self.natively:
                assert self.stepper is not None
                self._check_native(self.stepper.step_group(values, group[0], t, h), values, t + h)
            elif len(group) == 1:
                self._step_one(group[0], values, values[self.inputs[group[0]]], t, h)
            else:
                self._step_together(group, values, [values[self.inputs[i]] for i in group], t, h)


class JacobiMaster(Master):
    """Every participant from the values at ``t``; outputs exchanged after all have stepped. With
    threads, the FMUs step at the same time (blocks, Python, in the calling thread)."""

    def __init__(self, participants: list[Participant], wiring: Wiring, threads: int = 1, use_native: bool = True):
        super().__init__(participants, wiring)
        self.pool = _pool(threads)
        every = list(range(len(participants)))
        native_units = self._native([every], True, threads, use_native)
        self.fmus = [i for i, p in enumerate(participants) if not isinstance(p, BlockParticipant)]
        self.blocks = [i for i, p in enumerate(participants) if isinstance(p, BlockParticipant)]
        if native_units:  # the blocks left for Python
            self.blocks = [i for i in every if i not in self.natively]

    def step(self, values: np.ndarray, t: float, h: float) -> None:
        if self.stepper is not None:
            gathered_blocks = [values[self.inputs[i]] for i in self.blocks]
            self._check_native(self.stepper.step(values, t, h), values, t + h)
            for i, u in zip(self.blocks, gathered_blocks):
                values[self.outputs[i]] = self._advance(i, u, t, h)
            return
        gathered = [values[inputs] for inputs in self.inputs]
        if self.pool is None or len(self.fmus) < 2:
            for i in range(len(self.participants)):
                values[self.outputs[i]] = self._advance(i, gathered[i], t, h)
            return
        for i in self.blocks:
            values[self.outputs[i]] = self._advance(i, gathered[i], t, h)
        self._step_together(self.fmus, values, [gathered[i] for i in self.fmus], t, h)


class IterativeMaster(Master):
    """Each step repeated from the participants' saved states (fmi2GetFMUstate / the blocks'
    get_state) until the exchanged values converge. Each pass steps the participants in order
    (Gauss-Seidel within the pass: a participant sees the outputs at ``t + h`` of those before it
    in this pass, of the others from the last pass); every FMU steps with its inputs interpolated
    linearly from their values at ``t`` to those at ``t + h``
    (fmi2SetRealInputDerivatives; an FMU that cannot interpolate holds their mean), an implicit,
    second-order coupling; blocks get the guess at ``t + h``. The guess moves ``relaxation`` of the way to the new
    outputs, and the step is accepted when no exchanged value changed by more than
    ``tolerance`` x (1 + |value|). Non-convergence within ``max_iterations`` passes is a
    RunError naming the step and the signals still moving."""

    def __init__(self, participants: list[Participant], wiring: Wiring, iteration: Iteration | None = None,
                 names: list[str] | None = None):
        super().__init__(participants, wiring)
        self.iteration = iteration or Iteration()
        exchanged = np.unique(np.concatenate([slots for slots in self.inputs if len(slots)] or [np.zeros(0, int)]))
        self.exchanged = exchanged.astype(int)
        self.names = names or [str(slot) for slot in range(wiring.size)]
        # FMUs that can interpolate inputs get them linearly from t to the guess at t + h; other
        # FMUs hold the mean of the two (trapezoidal); blocks compute their outputs at t + h from
        # the inputs there (the guess).
        self.holds = ["end" if isinstance(p, BlockParticipant)
                      else "interpolate" if getattr(p, "can_interpolate", False) else "mean" for p in participants]
        self.passes = 0       # total passes, for the statistics
        self.steps = 0

    def step(self, values: np.ndarray, t: float, h: float) -> None:
        # The first step of a run is taken in START_SUBSTEPS pieces: inputs switched on at the
        # start (a torque step from rest) make the exchanged values jump within it, which no
        # interpolation over the whole step follows.
        pieces = START_SUBSTEPS if self.steps == 0 else 1
        for piece in range(pieces):
            self._iterate(values, t + piece * h / pieces, h / pieces)
        self.steps += 1

    def _iterate(self, values: np.ndarray, t: float, h: float) -> None:
        clock = time.perf_counter
        settings = self.iteration
        start = values.copy()
        guess = values.copy()
        states = [p.get_state(t) for p in self.participants]
        try:
            for attempt in range(1, settings.max_iterations + 1):
                new = guess.copy()  # filled in order: later participants see this pass's outputs
                for participant, inputs, outputs, hold in zip(self.participants, self.inputs, self.outputs, self.holds):
                    begin = clock()
                    if hold == "interpolate":
                        participant.do_step(t, h, start[inputs], (new[inputs] - start[inputs]) / h)
                    elif hold == "mean":
                        participant.do_step(t, h, 0.5 * (start[inputs] + new[inputs]))
                    else:
                        participant.do_step(t, h, new[inputs])
                    new[outputs] = participant.get_outputs(t + h)
                    self.step_seconds[participant.name] += clock() - begin
                change = np.abs(new[self.exchanged] - guess[self.exchanged])
                scale = settings.tolerance * (1.0 + np.abs(new[self.exchanged]))
                self.passes += 1
                if np.all(change <= scale) and attempt > 1:
                    values[:] = new
                    return
                guess += settings.relaxation * (new - guess)
                if attempt < settings.max_iterations:
                    for participant, state in zip(self.participants, states):
                        participant.set_state(state, t)
            worst = np.argsort(-(change / scale))[:3]
            signals = ", ".join(f"{self.names[self.exchanged[i]]} (changed {change[i]:.3g})" for i in worst
                                if change[i] > scale[i])
            raise RunError(f"iterative master: the step from t = {t:.6g} s did not converge in "
                           f"{settings.max_iterations} passes (tolerance {settings.tolerance:g}); still moving: "
                           f"{signals}")
        finally:
            for participant, state in zip(self.participants, states):
                participant.free_state(state)


class Crew:
    """``threads`` - 1 helper threads that, with the calling thread, share out a list of tasks:
    one hand-off per list (cheaper than a pool's submit per task, which at ~50 us per FMU step
    would eat the gain). ctypes releases the GIL during FMU calls, so FMUs step at the same time.
    The first error of any task is raised in the calling thread."""

    def __init__(self, threads: int):
        self.size = threads
        self._work: list[list[Callable[[], None]]] = [[] for _ in range(threads)]
        self._start = [threading.Event() for _ in range(threads - 1)]
        self._done = [threading.Event() for _ in range(threads - 1)]
        self._errors: list[BaseException] = []
        self._stop = False
        self._helpers = [threading.Thread(target=self._serve, args=(k,), name=f"fmu-{k + 1}", daemon=True)
                         for k in range(threads - 1)]
        for helper in self._helpers:
            helper.start()

    def _serve(self, k: int) -> None:
        while True:
            self._start[k].wait()
            self._start[k].clear()
            if self._stop:
                return
            self._perform(self._work[k + 1])
            self._done[k].set()

    def _perform(self, tasks: list[Callable[[], None]]) -> None:
        try:
            for task in tasks:
                task()
        except BaseException as error:  # noqa: BLE001 - handed to the calling thread
            self._errors.append(error)

    def run(self, tasks: list[Callable[[], None]]) -> None:
        for k in range(self.size):
            self._work[k] = tasks[k::self.size]
        for k in range(self.size - 1):
            self._done[k].clear()
            self._start[k].set()
        self._perform(self._work[0])
        for k in range(self.size - 1):
            self._done[k].wait()
        if self._errors:
            error, self._errors = self._errors[0], []
            raise error

    def shutdown(self) -> None:
        self._stop = True
        for event in self._start:
            event.set()
        for helper in self._helpers:
            helper.join(timeout=5)


def _pool(threads: int) -> Crew | None:
    """Threads for stepping FMUs at the same time, or None for one thread."""
    return Crew(threads) if threads > 1 else None


def _independent_runs(participants: list[Participant], inputs: list[np.ndarray],
                      outputs: list[np.ndarray]) -> list[list[int]]:
    """The order cut into runs of FMUs that read none of each other's outputs (blocks alone)."""
    groups: list[list[int]] = []
    written: set[int] = set()
    for i, participant in enumerate(participants):
        reads = set(inputs[i].tolist())
        if (groups and not isinstance(participant, BlockParticipant) and len(groups[-1]) >= 1
                and not isinstance(participants[groups[-1][0]], BlockParticipant) and not reads & written):
            groups[-1].append(i)
        else:
            groups.append([i])
            written = set()
        written |= set(outputs[i].tolist())
    return groups


MASTERS: dict[str, type[Master]] = {"jacobi": JacobiMaster, "gauss-seidel": GaussSeidelMaster,
                                    "iterative": IterativeMaster}


def initialize(participants: list[Participant], wiring: Wiring, values: np.ndarray, t0: float,
               stop_time: float) -> None:
    """FMI 2.0 initialization of every participant; ``values`` then holds the outputs at ``t0``."""
    slots = {p.name: wiring.participants[p.name] for p in participants}

    def initial(participant: Participant) -> None:
        ports = slots[participant.name]
        values[ports.output_slots] = participant.initial_outputs(t0, values[ports.input_slots])

    for participant in participants:
        participant.enter_initialization(t0, stop_time)
    direct = [p for p in participants if not p.iterative_start]
    iterative = [p for p in participants if p.iterative_start]
    for participant in direct:  # sources first: their outputs do not depend on anyone
        if not participant.inputs:
            initial(participant)
    for _ in range(INITIAL_PASSES):
        for participant in iterative:
            initial(participant)
    for participant in direct:
        if participant.inputs:
            initial(participant)
    for participant in participants:
        ports = slots[participant.name]
        values[ports.output_slots] = participant.exit_initialization(t0, values[ports.input_slots])


#: The temporary folder of a run's unpacked FMUs: ``<tmp>/rover-cosim-run-<pid>-<random>``.
UNZIP_PREFIX = "rover-cosim-run-"


def remove_stale_folders() -> list[Path]:
    """Remove the unpacked FMUs of runs whose process is gone (killed with SIGKILL, where no
    clean-up can run); returns what was removed."""
    removed = []
    for folder in Path(tempfile.gettempdir()).glob(f"{UNZIP_PREFIX}*-*"):
        pid = folder.name[len(UNZIP_PREFIX):].split("-", 1)[0]
        if not pid.isdigit() or int(pid) == os.getpid() or _alive(int(pid)):
            continue
        shutil.rmtree(folder, ignore_errors=True)
        removed.append(folder)
    return removed


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


@contextmanager
def participants_of(system: System, wiring: Wiring) -> Iterator[list[Participant]]:
    """The participants of ``system`` in its order, FMUs extracted into a temporary folder;
    every FMU is terminated and freed on leaving, whatever happened."""
    remove_stale_folders()
    with ExitStack() as stack:
        unzip_root = Path(stack.enter_context(tempfile.TemporaryDirectory(prefix=f"{UNZIP_PREFIX}{os.getpid()}-")))
        by_name: dict[str, Participant] = {}
        for entry in system.fmus:
            fmu = FmuParticipant(entry, unzip_root)
            stack.callback(fmu.close)
            ports = wiring.participants[entry.name]
            fmu.configure(ports.inputs, ports.outputs)
            by_name[entry.name] = fmu
        for block in system.blocks:
            participant = BlockParticipant(block.name, block.block)
            stack.callback(participant.close)
            by_name[block.name] = participant
        yield [by_name[name] for name in system.order]


def make_master(system: System, participants: list[Participant], wiring: Wiring) -> Master:
    """The system's master algorithm over its participants."""
    if system.algorithm == "iterative":
        names = {int(slot): f"{p}.{v}" for p, ports in wiring.participants.items()
                 for v, slot in zip(ports.outputs, ports.output_slots)}
        return IterativeMaster(participants, wiring, system.iteration,
                               [names.get(slot, f"slot {slot}") for slot in range(wiring.size)])
    master_class = GaussSeidelMaster if system.algorithm == "gauss-seidel" else JacobiMaster
    return master_class(participants, wiring, threads=system.threads, use_native=system.native)


def run(system: System, *, progress: Callable[[float], None] | None = None) -> RunResult:
    """Run ``system``; raises :class:`RunError` naming the participant, call and time on failure,
    with the rows recorded up to the failure in its ``partial``."""
    started = time.perf_counter()
    wiring = wire(system)
    times = communication_points(system.start_time, system.stop_time, system.step)
    n_steps = len(times) - 1
    with participants_of(system, wiring) as participants, ExitStack() as stack:
        values = wiring.initial_values()
        initialize(participants, wiring, values, system.start_time, system.stop_time)
        master = make_master(system, participants, wiring)
        stack.callback(master.close)
        recorder = Recorder(system.record, wiring.record_slots, times)
        names = {p.name: wiring.participants[p.name].outputs for p in participants}
        check_finite(names, master, values, system.start_time)
        recorder.sample(0, values)
        try:
            if master.stepper is not None and master.all_native:
                _run_native(master, values, times, recorder, progress)
            else:
                checked = master.checked_in_python
                for k in range(n_steps):
                    master.step(values, float(times[k]), float(times[k + 1] - times[k]))
                    check_finite(names, master, values, float(times[k + 1]), checked)
                    recorder.sample(k + 1, values)
                    if progress is not None:
                        progress((k + 1) / n_steps)
        except RunError as error:
            error.partial = recorder.frame()
            raise
        master.close()
        return RunResult(recorder.frame(), time.perf_counter() - started, n_steps, master.step_seconds)


#: Steps per call of the native stepper in a system stepped natively throughout (between progress reports).
NATIVE_STRETCH = 500


def _run_native(master: Master, values: np.ndarray, times: np.ndarray, recorder: Recorder,
                progress: Callable[[float], None] | None) -> None:
    """A system stepped natively throughout: stretches of steps in one native call each, recorded in place."""
    assert master.stepper is not None
    n_steps = len(times) - 1
    record = np.ascontiguousarray(recorder.slots, dtype=np.int64)
    for first in range(0, n_steps, NATIVE_STRETCH):
        last = min(first + NATIVE_STRETCH, n_steps)
        failed = master.stepper.run(values, times, first, last, record, recorder.rows)
        recorder.filled = master.stepper.reached + 1
        if failed >= 0:
            master._check_native(failed, values, float(times[master.stepper.reached + 1]))
        if progress is not None:
            progress(last / n_steps)


def check_finite(names: dict[str, list[str]], master: Master, values: np.ndarray, t: float,
                 which: list[int] | None = None) -> None:
    """A RunError naming the participant, the signal and the time of the first non-finite output
    (of the participants ``which``, default all)."""
    for i in range(len(master.participants)) if which is None else which:
        participant, outputs = master.participants[i], master.outputs[i]
        produced = values[outputs]
        if not np.all(np.isfinite(produced)):
            bad = int(np.nonzero(~np.isfinite(produced))[0][0])
            raise RunError(f"{participant.name}: output {names[participant.name][bad]} = {produced[bad]} at "
                           f"t = {t:.6g} s: expected a finite value")


__all__ = ["GaussSeidelMaster", "IterativeMaster", "JacobiMaster", "Master", "RunError", "RunResult", "initialize",
           "make_master", "run"]
