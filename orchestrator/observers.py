"""Observers: what watches a run without stepping it. ``master.run`` composes the engine's own
(the recorder, the finite-value check, progress) with any the caller passes; ``rover-cosim
run``'s result writer is one too (``runs.Publisher``).

A user observer subclasses :class:`Observer` and overrides what it needs:

```python
class StopWhenFast(Observer):
    ports = ("body.v",)                      # the signals observe() receives, in this order

    def observe(self, t, values):            # at t0 and after every communication step
        if values[0] >= 0.98:
            return f"body.v reached 0.98 m/s at t = {t:.3f} s"   # truthy: the run ends here

result = run(system, observers=[StopWhenFast()])   # result.stopped says why; rows up to t kept
```

An observer that overrides ``observe`` sees every communication point, so the run then steps one
communication step at a time (a system stepped natively throughout otherwise runs stretches of
steps in one C call). ``start`` gets a :class:`RunInfo`, ``finish`` the RunResult, ``fail`` the
RunError (its ``partial`` holds the rows recorded before the failure).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .algorithms import Stepping
from .model import System
from .participants import RunError
from .recorder import Recorder, RunResult


@dataclass(frozen=True)
class RunInfo:
    """What an observer is told at the start: the system, its communication points [s] and the
    ports its ``observe`` receives."""

    system: System
    times: np.ndarray
    ports: tuple[str, ...]


class Observer:
    """Watches a run; every method is optional (this base class does nothing)."""

    #: Ports ("instance.variable") whose values ``observe`` receives, in this order.
    ports: Sequence[str] = ()

    def start(self, info: RunInfo) -> None:
        """Before the first step (after initialization)."""

    def observe(self, t: float, values: np.ndarray) -> Any:
        """At the start time and after every communication step, with the values of ``ports`` at
        ``t``; a truthy return ends the run there (a string: the reason, in RunResult.stopped)."""
        return None

    def finish(self, result: RunResult) -> None:
        """The run ended (at its stop time, or where an observer stopped it)."""

    def fail(self, error: RunError) -> None:
        """The run failed; ``error.partial`` holds the rows recorded before the failure."""


def watches_every_step(observer: Observer) -> bool:
    return type(observer).observe is not Observer.observe


class StopWhen(Observer):
    """Ends the run at the first communication point where ``condition(value)`` holds for the
    value of ``port`` (e.g. ``StopWhen("body.x", lambda x: x >= 10.0)``: the rover drove 10 m)."""

    def __init__(self, port: str, condition: Callable[[float], bool], reason: str | None = None):
        self.ports = (port,)
        self.condition, self.reason = condition, reason

    def observe(self, t: float, values: np.ndarray) -> Any:
        if self.condition(float(values[0])):
            return self.reason or f"{self.ports[0]} = {float(values[0]):.6g} at t = {t:.6g} s"
        return None


def check_finite(execution: Stepping, values: np.ndarray, t: float, which: Sequence[int] | None = None) -> None:
    """A RunError naming the participant, the signal and the time of the first non-finite output
    (of the participants ``which``, default all)."""
    for i in range(len(execution.participants)) if which is None else which:
        participant, outputs = execution.participants[i], execution.outputs[i]
        produced = values[outputs]
        if not np.all(np.isfinite(produced)):
            bad = int(np.nonzero(~np.isfinite(produced))[0][0])
            raise RunError(f"{participant.name}: output {execution.output_names[participant.name][bad]} = "
                           f"{produced[bad]} at t = {t:.6g} s: expected a finite value")


class Watcher:
    """The engine's side of an observer: told of every communication point ``k`` (0: the
    start) with the whole value vector, or of a stretch of steps the native stepper ran."""

    def sampled(self, k: int, t: float, values: np.ndarray) -> Any:
        return None

    def stretched(self, reached: int) -> None:
        """Steps up to ``reached`` were run (and recorded) from C."""


class FiniteCheck(Watcher):
    """Outputs must be finite: every participant's at the start, then those of the participants
    stepped in Python (the native stepper checks its own)."""

    def __init__(self, execution: Stepping, checked: list[int]):
        self.execution = execution
        self.checked = checked

    def sampled(self, k: int, t: float, values: np.ndarray) -> Any:
        check_finite(self.execution, values, t, None if k == 0 else self.checked)


class Recording(Watcher):
    """Feeds the recorder (whose rows the native stepper fills in place in a stretch)."""

    def __init__(self, recorder: Recorder):
        self.recorder = recorder

    def sampled(self, k: int, t: float, values: np.ndarray) -> Any:
        self.recorder.sample(k, values)

    def stretched(self, reached: int) -> None:
        self.recorder.filled = reached + 1


class Progress(Watcher):
    """``report(fraction)`` after every step (or stretch) of a run of ``steps`` steps."""

    def __init__(self, report: Callable[[float], None], steps: int):
        self.report, self.steps = report, steps

    def sampled(self, k: int, t: float, values: np.ndarray) -> Any:
        if k:
            self.report(k / self.steps)

    def stretched(self, reached: int) -> None:
        self.report(reached / self.steps)


class Watch(Watcher):
    """A user observer, given the values of its ports (``slots`` in the value vector)."""

    def __init__(self, observer: Observer, slots: np.ndarray):
        self.observer, self.slots = observer, slots

    def sampled(self, k: int, t: float, values: np.ndarray) -> Any:
        return self.observer.observe(t, values[self.slots])
