"""A co-simulation run: :func:`run` initializes the participants of a checked System, steps them
with its algorithm through the executors (``execution``) and lets the observers watch
(``observers``: the recorder, the finite-value check, progress, and any the caller adds).

Every value exchanged or recorded has a slot in one vector ``values`` (``wiring``); each
participant reads its inputs from the slots of their sources and writes its outputs into its own
slots.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager
from pathlib import Path

import numpy as np

from .archives import UnpackError
from .builder import block_port_type
from .execution import Execution, make_execution
from .fmi_access import StringTable
from .isolation import IsolatedFmu, isolated
from .model import FmuEntry, Port, System, declared_start
from .model_exchange import make_fmu_participant
from .native import unavailable_reason
from .observers import (
    FiniteCheck,
    Observer,
    Progress,
    Recording,
    RunInfo,
    Watch,
    Watcher,
    check_finite,
    watches_every_step,
)
from .participants import BlockParticipant, FmuParticipant, Participant, RunError, Terminated
from .recorder import Recorder, RunResult, Table, communication_points
from .unpacking import UNZIP_PREFIX, once_per_process, remove_stale_folders, run_folder, unpack
from .wiring import Wiring, wire

#: Passes of the initial-output exchange among participants with an iterative start (FMUs in
#: Initialization Mode), so that a chain of direct feedthrough two deep settles.
INITIAL_PASSES = 2
#: Steps per call of the native stepper in a system stepped natively throughout (between progress reports).
NATIVE_STRETCH = 500


def input_starts(participant: Participant) -> list[float] | None:
    """The start values of an FMU participant's connected inputs, as its system sets them (its
    ``start``) or its model description declares them (0 where neither gives a number); None for a
    block."""
    entry = getattr(participant, "entry", None)
    if not isinstance(entry, FmuEntry):
        return None
    variables = entry.variables()
    starts = []
    for name in participant.inputs:
        value = entry.start[name] if name in entry.start else (
            declared_start(variables[name]) if name in variables else None)
        starts.append(float(value) if isinstance(value, (int, float)) else 0.0)
    return starts


def _hold_start_values(participants: list[Participant], slots: dict, values: np.ndarray) -> None:
    """Each FMU input whose source is a block with inputs (started after the FMUs) at the input's
    start value (``input_starts``)."""
    later = {int(slot) for p in participants if not p.iterative_start and p.inputs
             for slot in slots[p.name].output_slots}
    for participant in participants:
        starts = input_starts(participant) if participant.iterative_start else None
        for slot, start in zip(slots[participant.name].input_slots, starts or []):
            if int(slot) in later:
                values[slot] = start


def initialize(participants: list[Participant], wiring: Wiring, values: np.ndarray, t0: float,
               stop_time: float) -> None:
    """FMI 2.0 initialization of every participant; ``values`` then holds the outputs at ``t0``.
    An FMU input whose source is a block with inputs (started after the FMUs) holds the input's
    start value until that block has started, as an unconnected input would."""
    slots = {p.name: wiring.participants[p.name] for p in participants}
    _hold_start_values(participants, slots, values)

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


@contextmanager
def participants_of(system: System, wiring: Wiring,
                    strings: StringTable | None = None) -> Iterator[list[Participant]]:
    """The participants of ``system`` in its order, FMUs unpacked once per process (``unpacking``);
    every FMU is terminated and freed on leaving, whatever happened.
    ``strings``: the run's String table (the recorder reads the recorded Strings from it)."""
    strings = strings if strings is not None else StringTable()
    with ExitStack() as stack:
        own = any(map(once_per_process, system.fmus))  # FMUs that need a copy per instance
        unzip_root = stack.enter_context(run_folder()) if own else None
        by_name: dict[str, Participant] = {}
        for entry in system.fmus:
            try:
                folder = unpack(entry, unzip_root)
            except UnpackError as error:
                raise RunError(f"{entry.name} ({Path(entry.path).name}): {error}") from None
            fmu: FmuParticipant | IsolatedFmu
            if isolated(entry, system.fmu_timeout):
                fmu = IsolatedFmu(entry, folder, strings, system.relative_tolerance, system.fmu_timeout)
            else:
                fmu = make_fmu_participant(entry, folder, strings, system.relative_tolerance)
            stack.callback(fmu.close)
            ports = wiring.participants[entry.name]
            fmu.configure(ports.inputs, ports.outputs)
            by_name[entry.name] = fmu
        for block in system.blocks:
            participant = BlockParticipant(block.name, block.block, system.step)
            stack.callback(participant.close)
            by_name[block.name] = participant
        yield [by_name[name] for name in system.order]


def make_master(system: System, participants: list[Participant], wiring: Wiring) -> Execution:
    """The system's algorithm over its participants (see ``execution.make_execution``)."""
    return make_execution(system, participants, wiring)


def _observed_ports(system: System, observers: Sequence[Observer]) -> list[Port]:
    """The ports the observers watch; ValueError naming an observer's unknown port."""
    entries = system.participants()
    ports = []
    for observer in observers:
        for text in observer.ports:
            port = Port.parse(str(text))
            entry = entries.get(port.instance)
            if isinstance(entry, FmuEntry):
                known = port.variable in entry.variables()
            else:
                known = entry is not None and port.variable in (*entry.block.inputs, *entry.block.outputs)
            if not known:
                raise ValueError(f"observer {type(observer).__name__}: port {text!r}: expected \"instance.variable\" "
                                 f"of this system's participants ({', '.join(entries)})")
            ports.append(port)
    return ports


def _types(system: System, ports: Sequence[Port]) -> list[str]:
    """The FMI type of each port (a block's ports are Real unless it says otherwise)."""
    entries = system.participants()
    return [entry.variable_type(port.variable) if isinstance(entry := entries[port.instance], FmuEntry)
            else block_port_type(entry.block, port.variable) for port in ports]


def run(system: System, *, progress: Callable[[float], None] | None = None,
        observers: Sequence[Observer] = (), sink: Callable[[Table], None] | None = None) -> RunResult:
    """Run ``system``; raises :class:`RunError` naming the participant, call and time on failure,
    with the rows recorded up to the failure in its ``partial``. ``progress(fraction)`` is told
    how far the run is; ``observers`` watch it (and may end it early: ``observers``). ``sink``:
    the recorded rows are handed to it in chunks as the run goes (``recorder``), the result's and
    a failure's tables holding only what was not handed over; without it they hold every row."""
    started = time.perf_counter()
    watched = _observed_ports(system, observers)
    wiring = wire(system, watched)
    times = communication_points(system.start_time, system.stop_time, system.step)
    strings = StringTable()
    closed: list[Participant] = []
    try:
        result = _run(system, progress, observers, sink, watched, wiring, times, strings, closed, started)
    except RunError as error:
        error.fmu_log = fmu_log(closed)
        raise
    result.notes.extend(problem for p in closed for problem in getattr(p, "problems", ()))
    result.fmu_log = fmu_log(closed)
    return result


def fmu_log(participants: Sequence[Participant]) -> dict[str, list[str]]:
    """Per FMU, its error messages too long to print, whole (``long_messages``; after closing)."""
    found = {p.name: getattr(p, "long_messages", None) for p in participants}
    return {name: list(messages) for name, messages in found.items() if messages}


def _run(system: System, progress: Callable[[float], None] | None, observers: Sequence[Observer],
         sink: Callable[[Table], None] | None, watched: list[Port], wiring: Wiring, times: np.ndarray,
         strings: StringTable, closed: list[Participant], started: float) -> RunResult:
    """The run of :func:`run`; ``closed``: filled with the participants (looked at after they closed)."""
    n_steps = len(times) - 1
    with participants_of(system, wiring, strings) as participants, ExitStack() as stack:
        closed.extend(participants)
        values = wiring.initial_values(strings)
        initialize(participants, wiring, values, system.start_time, system.stop_time)
        execution = make_execution(system, participants, wiring)
        stack.callback(execution.close)
        recorder = Recorder(system.record, wiring.record_slots, times, _types(system, system.record), strings,
                            system.record_every, sink)
        watchers: list[Watcher] = [FiniteCheck(execution, execution.checked_in_python), Recording(recorder)]
        offset = 0
        for observer in observers:
            count = len(observer.ports)
            watchers.append(Watch(observer, wiring.extra_slots[offset:offset + count]))
            observer.start(RunInfo(system, times, tuple(map(str, observer.ports))))
            offset += count
        if progress is not None:
            watchers.append(Progress(progress, n_steps))
        try:
            stopped = _sample(watchers, 0, system.start_time, values)
            steps, every_step = 0, any(map(watches_every_step, observers))
            while stopped is None and steps < n_steps:
                if execution.all_native and not every_step:
                    steps = _run_stretches(execution, values, times, recorder, watchers, steps)
                    break
                steps, stopped, late = _run_steps(execution, values, times, watchers, steps)
                if late:  # a block now offers its C twin: the run goes on with a new execution
                    execution = _handed_over(system, participants, wiring, execution, watchers)
                    stack.callback(execution.close)
        except Terminated as end:  # an FMU ended the simulation: a clean end at the start of that step
            _last_row(participants, execution, values, times, recorder, end)
            steps, stopped = recorder.filled - 1, str(end)
        except RunError as error:
            error.partial = recorder.frame() if sink is None else _handed(recorder)
            for observer in observers:
                observer.fail(error)
            raise
        execution.close()
        table = recorder.table() if sink is None else _handed(recorder)
        result = RunResult(table, time.perf_counter() - started, steps, execution.step_seconds, stopped)
        for observer in observers:  # before the FMUs are freed: an observer may write the results now
            observer.finish(result)
    return result


def _handed(recorder: Recorder) -> Table:
    """The rest of a sink's rows handed over (finish); what is left: a table of no rows."""
    recorder.finish()
    return recorder.table()


def _last_row(participants: list[Participant], execution: Execution, values: np.ndarray, times: np.ndarray,
              recorder: Recorder, end: Terminated) -> None:
    """A system of one FMU that ended the simulation within a step: a last row at the time it
    got to (fmi2LastSuccessfulTime), as FMPy records it. With other participants the run ends at
    the start of the step, where they all agree."""
    k = recorder.filled
    if len(participants) != 1 or end.last is None or not end.last > end.t or k >= len(times):
        return
    values[execution.outputs[0]] = participants[0].get_outputs(end.last)
    times[k] = min(end.last, times[k])
    recorder.sample(k, values)


def _sample(watchers: list[Watcher], k: int, t: float, values: np.ndarray) -> str | None:
    """Tell every watcher of communication point ``k``; why an observer stopped the run, or None."""
    stop = None
    for watcher in watchers:
        said = watcher.sampled(k, t, values)
        if said and stop is None:
            observer = getattr(watcher, "observer", watcher)
            stop = said if isinstance(said, str) else f"{type(observer).__name__} at t = {t:.6g} s"
    return stop


def _native_stepping_available() -> bool:
    """Whether the native stepper builds here (a block's late C twin needs it)."""
    return unavailable_reason() is None


def _run_steps(execution: Execution, values: np.ndarray, times: np.ndarray, watchers: list[Watcher],
               first: int = 0) -> tuple[int, str | None, bool]:
    """Step by step from step ``first`` to the end, until an observer stops the run, or until a
    block stepped in Python offers its C twin: (steps run in all, why it stopped, handed over)."""
    n_steps = len(times) - 1
    python_stepped = (execution.participants[i] for i in execution.checked_in_python)
    late = [p for p in python_stepped if isinstance(p, BlockParticipant) and hasattr(p.block, "native_ready")
            and execution.native_enabled and _native_stepping_available()]
    for k in range(first, n_steps):
        execution.step(values, float(times[k]), float(times[k + 1] - times[k]))
        reason = _sample(watchers, k + 1, float(times[k + 1]), values)
        if reason is not None:
            return k + 1, reason, False
        if late and any(block.ready_for_native() for block in late):
            return k + 1, None, True
    return n_steps, None, False


def _handed_over(system: System, participants: list[Participant], wiring: Wiring, execution: Execution,
                 watchers: list[Watcher]) -> Execution:
    """A new execution of the same participants, now that a block offers its C twin (made from
    the block's state at this step); the time inside each participant carries over."""
    seconds = execution.step_seconds
    execution.close()
    after = make_execution(system, participants, wiring)
    for name, spent in seconds.items():
        after.step_seconds[name] += spent
    for watcher in watchers:
        if isinstance(watcher, FiniteCheck):
            watcher.execution, watcher.checked = after, after.checked_in_python
    return after


def _run_stretches(execution: Execution, values: np.ndarray, times: np.ndarray, recorder: Recorder,
                   watchers: list[Watcher], start: int = 0) -> int:
    """A system stepped natively throughout: from step ``start``, stretches of steps in one native
    call each, recorded in place."""
    n_steps = len(times) - 1
    record = np.ascontiguousarray(recorder.slots, dtype=np.int64)
    for first in range(start, n_steps, NATIVE_STRETCH):
        last = min(first + NATIVE_STRETCH, n_steps)
        recorder.room(last - first)  # a recorder with a sink hands its rows over first
        base = recorder.base  # rows[i] is point base + i: the stepper counts from there
        try:
            reached, failed = execution.run_stretch(values, times[base:], first - base, last - base, record,
                                                    recorder.rows)
        except RunError:
            assert execution.native is not None
            recorder.filled = base + execution.native.reached + 1  # the rows before the failed step
            raise
        reached += base
        recorder.filled = reached + 1
        execution.check_native(failed, values, float(times[reached + 1]) if failed >= 0 else 0.0)
        for watcher in watchers:
            watcher.stretched(reached)
    return n_steps


__all__ = ["UNZIP_PREFIX", "Execution", "RunError", "RunResult", "check_finite", "initialize", "make_master",
           "participants_of", "remove_stale_folders", "run"]
