"""Executors: how the participants of one stage are stepped, given the inputs gathered for them.

- :class:`PythonExecutor`: one after the other in the calling thread;
- :class:`ThreadExecutor`: the stage's FMUs at the same time on a :class:`Crew` of threads (ctypes
  releases the GIL during FMU calls), its blocks in the calling thread;
- :class:`NativeExecutor`: the stages it was given stepped from C (``native.NativeStepper``),
  FMUs and blocks with a C twin; whole stretches of steps in one call where every participant is
  stepped natively.

Every executor keeps the time spent inside each participant (``step_seconds``, by name).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence

import numpy as np

from . import native
from .participants import BlockParticipant, Participant


class PythonExecutor:
    """Steps participants one after the other in the calling thread."""

    pool: Crew | None = None

    def __init__(self, participants: Sequence[Participant], outputs: Sequence[np.ndarray],
                 step_seconds: dict[str, float]):
        self.participants, self.outputs, self.step_seconds = participants, outputs, step_seconds

    def advance(self, i: int, u: np.ndarray, t: float, h: float) -> np.ndarray:
        """Step participant ``i`` with ``u`` and return a copy of its outputs at ``t + h``."""
        participant = self.participants[i]
        begin = time.perf_counter()
        participant.do_step(t, h, u)
        produced = np.array(participant.get_outputs(t + h))
        self.step_seconds[participant.name] += time.perf_counter() - begin
        return produced

    def run(self, members: Sequence[int], gathered: Sequence[np.ndarray], values: np.ndarray, t: float,
            h: float) -> None:
        """Step ``members`` from ``t`` to ``t + h`` with their ``gathered`` inputs; write their outputs."""
        for i, u in zip(members, gathered):
            values[self.outputs[i]] = self.advance(i, u, t, h)

    def close(self) -> None:
        """Nothing to end."""


class ThreadExecutor(PythonExecutor):
    """A stage's FMUs at the same time on ``threads`` threads (its blocks, Python, first in the
    calling thread); a stage with fewer than two FMUs one after the other."""

    def __init__(self, participants: Sequence[Participant], outputs: Sequence[np.ndarray],
                 step_seconds: dict[str, float], threads: int):
        super().__init__(participants, outputs, step_seconds)
        self.pool = Crew(threads)

    def run(self, members: Sequence[int], gathered: Sequence[np.ndarray], values: np.ndarray, t: float,
            h: float) -> None:
        fmus = [k for k, i in enumerate(members) if not isinstance(self.participants[i], BlockParticipant)]
        if len(fmus) < 2:
            super().run(members, gathered, values, t, h)
            return
        assert self.pool is not None
        blocks = [k for k in range(len(members)) if k not in fmus]
        super().run([members[k] for k in blocks], [gathered[k] for k in blocks], values, t, h)
        produced: dict[int, np.ndarray] = {}

        def task(i: int, u: np.ndarray) -> Callable[[], None]:
            return lambda: produced.__setitem__(i, self.advance(i, u, t, h))

        self.pool.run([task(members[k], gathered[k]) for k in fmus])
        for k in fmus:
            values[self.outputs[members[k]]] = produced[members[k]]

    def close(self) -> None:
        if self.pool is not None:
            self.pool.shutdown()
            self.pool = None


class NativeExecutor:
    """The ``groups`` (lists of participant positions, FMUs and blocks with a C twin) stepped from
    C; ``jacobi``: every input of a group gathered before any of its units steps."""

    def __init__(self, participants: Sequence[Participant], inputs: Sequence[np.ndarray],
                 outputs: Sequence[np.ndarray], groups: list[list[int]], jacobi: bool, threads: int):
        self.stepper: native.NativeStepper | None = native.NativeStepper(participants, inputs, outputs, groups,
                                                                          jacobi, threads)
        self.jacobi = jacobi
        self.members = frozenset(i for g in groups for i in g)

    def run_group(self, values: np.ndarray, first: int, t: float, h: float) -> int:
        """Step the group holding participant ``first``; -1, or the unit whose output is not finite."""
        assert self.stepper is not None
        if self.jacobi:
            return self.stepper.step(values, t, h)
        return self.stepper.step_group(values, first, t, h)

    def run_stretch(self, values: np.ndarray, times: np.ndarray, first: int, last: int, record: np.ndarray,
                    rows: np.ndarray) -> int:
        """Steps ``first`` .. ``last`` - 1 in one call, ``values[record]`` into ``rows[k + 1]``."""
        assert self.stepper is not None
        return self.stepper.run(values, times, first, last, record, rows)

    @property
    def reached(self) -> int:
        assert self.stepper is not None
        return self.stepper.reached

    def close(self, step_seconds: dict[str, float]) -> None:
        """Free the stepper, adding the time inside each unit to ``step_seconds``."""
        if self.stepper is not None:
            for name, seconds in self.stepper.seconds().items():
                step_seconds[name] = step_seconds.get(name, 0.0) + seconds
            self.stepper.close()
            self.stepper = None


class Crew:
    """``threads`` - 1 helper threads that, with the calling thread, share out a list of tasks:
    one hand-off per list (cheaper than a pool's submit per task, which at ~50 us per FMU step
    would eat the gain). The first error of any task is raised in the calling thread."""

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
