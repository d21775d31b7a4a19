"""Many independent calls of one function, on a Dask cluster, local processes or serially,
with the results in the order they complete (the identification sweep and the Monte Carlo study).

The function must be importable by name (the workers import it) and should not raise: it reports
its own failures in what it returns, so that one failing call does not stop the others. What it
cannot report, the local pool does through the caller's ``lost``: a worker that crashes (SIGSEGV
inside an FMU), calls exit() or overruns the time limit is replaced, the call reported as lost
with the reason, and the other calls go on. The local worker processes end with the caller: on
an error, Ctrl-C or SIGTERM (raised as KeyboardInterrupt by the CLI) or the consumer closing the
generator, idle workers are told to end and busy ones killed; and each worker asks Linux to kill
it when its parent dies (PR_SET_PDEATHSIG, SIGKILL) and takes the default signal handlers back,
so a caller killed in any way (kill -9 included) leaves no workers behind.
"""

from __future__ import annotations

import math
import os
import signal
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any, TypeVar

from . import handoff
from .heap import freeze_imports
from .scratch import remove_stale_folders

Result = TypeVar("Result")
#: s, how long a Dask scheduler may take to answer (ROVER_COSIM_SCHEDULER_TIMEOUT sets another).
SCHEDULER_TIMEOUT = 30.0


def parallel_map(function: Callable[..., Result], arguments: Sequence[tuple[Any, ...]], workers: int | None = None,
                 scheduler: str | None = None, lost: Callable[[tuple[Any, ...], str], Result] | None = None,
                 timeout: float | None = None) -> Iterator[Result]:
    """``function(*a)`` for every ``a`` of ``arguments``: on the Dask cluster at ``scheduler``
    (``tcp://host:port``) when given, else on ``workers`` local processes (default and at most:
    the cores; 1 with ``lost`` given runs in a worker process too, so that a crash cannot end the
    caller, except inside a pool's worker, whose own pool survives it; without, serially here).
    Results in the order they complete. A call whose worker dies (a crash inside an FMU, exit())
    or that runs longer than ``timeout`` seconds (None: 20 x the slowest call so far once three
    completed, at least 120 s) gives ``lost(a, reason)``
    instead (the worker is replaced; without ``lost``, RuntimeError)."""
    if scheduler is not None:
        from dask.distributed import Client
        from dask.distributed import as_completed as dask_completed

        timeout = scheduler_timeout()
        try:
            client = Client(scheduler, timeout=timeout)
        except Exception as error:  # noqa: BLE001 - no answer, a refusal, or something else answering there
            raise RuntimeError(f"Dask scheduler {scheduler}: no Dask scheduler answered within {timeout:g} s "
                               f"({type(error).__name__}: {str(error)[:200]}); is it running, and is the address "
                               "right?") from None
        with client:
            for future in dask_completed([client.submit(function, *a, pure=False) for a in arguments]):
                yield future.result()
        return
    workers = workers or os.cpu_count() or 1
    if workers < 1:
        raise ValueError(f"workers = {workers!r}: expected >= 1")
    if (lost is None or _in_a_worker()) and (workers == 1 or len(arguments) <= 1):
        # nothing to survive, or already in a worker of a pool (whose pool reports the call lost if
        # this one crashes): serially, here, without a process of its own
        yield from (function(*a) for a in arguments)
        return
    workers = min(workers, len(arguments), cores())
    if not arguments:
        return
    freeze_imports()  # the workers are forked from this heap: they share it unwritten
    pool = _Pool(function, workers)
    try:
        yield from pool.results(list(arguments), lost or _raise_lost, timeout)
    finally:  # done, or Ctrl-C, SIGTERM (raised as KeyboardInterrupt by the CLI), the consumer closing
        pool.stop()
        remove_stale_folders()  # the workers' temporary folders (they exit without clean-ups)


def _in_a_worker() -> bool:
    """Whether this process is a worker of a pool: a local pool's, or a daemonic one (a Dask
    worker's, which may not start processes of its own)."""
    import multiprocessing

    return _IN_WORKER or bool(multiprocessing.current_process().daemon)


def scheduler_timeout() -> float:
    """s, how long a Dask scheduler may take to answer: ROVER_COSIM_SCHEDULER_TIMEOUT, else
    SCHEDULER_TIMEOUT; ValueError naming the variable for a value that is not a number of
    seconds in (0, 3600]."""
    text = os.environ.get("ROVER_COSIM_SCHEDULER_TIMEOUT")
    if text is None:
        return SCHEDULER_TIMEOUT
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 < value <= 3600:
        raise ValueError(f"ROVER_COSIM_SCHEDULER_TIMEOUT = {text!r}: expected a number of seconds > 0 and at most 3600")
    return value


def cores() -> int:
    """The cores this process may use (the affinity mask where the system has one)."""
    try:
        return len(os.sched_getaffinity(0)) or 1
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _raise_lost(arguments: tuple[Any, ...], reason: str) -> Any:
    raise RuntimeError(f"a worker process was lost: {reason}")


#: True in a worker process of a local pool: a map of one worker nested in its call (an adaptive
#: run's identification sweep inside a Monte Carlo run) runs serially in it, not in a process of
#: its own; a crash there ends the worker's call, which its pool reports as lost.
_IN_WORKER = False

#: s, the time limit of a call when none is given, once some calls have completed: so many times the
#: slowest of them, and at least RUN_TIMEOUT_FLOOR.
RUN_TIMEOUT_FACTOR, RUN_TIMEOUT_FLOOR = 20.0, 120.0
#: Completed calls before the automatic time limit applies.
RUN_TIMEOUT_AFTER = 3


class _Worker:
    """One local worker process and the call it is running (None: idle)."""

    def __init__(self, context: Any, function: Callable[..., Any]):
        self.conn, child = context.Pipe()
        # not a daemon: a run in it may start processes of its own (an isolated FMU, a nested sweep); it
        # ends with the pool (stop) or its parent (PR_SET_PDEATHSIG)
        self.process = context.Process(target=_work, args=(child, function, os.getpid()), daemon=False)
        self.process.start()
        child.close()
        self.task: int | None = None
        self.started = 0.0

    def give(self, task: int, arguments: tuple[Any, ...]) -> None:
        self.task, self.started = task, time.monotonic()
        self.conn.send((task, arguments))

    def end(self, kill: bool = False) -> None:
        if kill or self.task is not None:
            self.process.kill()
        else:
            try:
                self.conn.send(None)
            except OSError:
                self.process.kill()
        self.process.join(5)
        if self.process.is_alive():
            self.process.kill()
            self.process.join(5)
        self.conn.close()

    def death(self) -> str:
        """Why the worker is gone."""
        self.process.join(2)
        code = self.process.exitcode
        if code is None:
            return "its worker process stopped answering"
        if code < 0:
            try:
                name = signal.Signals(-code).name
            except ValueError:
                name = f"signal {-code}"
            return f"its worker process ended with {name} (a crash, e.g. inside an FMU)"
        return f"its worker process ended with exit status {code} (something in it called exit())"


class _Pool:
    """Local worker processes that outlive what goes wrong in one call: a worker that dies (a
    crash inside an FMU, exit()) or overruns the time limit is replaced, and its call reported
    through ``lost`` (the others go on)."""

    def __init__(self, function: Callable[..., Any], workers: int):
        import multiprocessing

        methods = multiprocessing.get_all_start_methods()
        self.context = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
        self.function = function
        self.size = workers
        self.workers: list[_Worker] = []

    def results(self, arguments: list[tuple[Any, ...]], lost: Callable[[tuple[Any, ...], str], Any],
                timeout: float | None) -> Iterator[Any]:
        from multiprocessing.connection import wait

        pending = list(range(len(arguments)))[::-1]
        durations: list[float] = []
        self.workers = [_Worker(self.context, self.function) for _ in range(self.size)]
        while pending or any(w.task is not None for w in self.workers):
            for worker in self.workers:
                if worker.task is None and pending:
                    task = pending.pop()
                    worker.give(task, arguments[task])
            busy = [w for w in self.workers if w.task is not None]
            limit = timeout if timeout is not None else (
                max(RUN_TIMEOUT_FLOOR, RUN_TIMEOUT_FACTOR * max(durations)) if len(durations) >= RUN_TIMEOUT_AFTER
                else None)
            now = time.monotonic()
            wake = None if limit is None else max(0.0, min(w.started + limit for w in busy) - now)
            ready = set(wait([w.conn for w in busy] + [w.process.sentinel for w in busy],
                             timeout=min(wake, 1.0) if wake is not None else 1.0))
            for worker in busy:
                running = worker.task
                assert running is not None
                if worker.conn in ready:
                    try:
                        kind, result = handoff.receive(worker.conn)
                    except (EOFError, OSError):
                        pass
                    else:
                        durations.append(time.monotonic() - worker.started)
                        worker.task = None
                        yield result if kind == "ok" else lost(arguments[running], f"it raised {result}")
                        continue
                if worker.conn in ready or worker.process.sentinel in ready:
                    reason = worker.death()
                elif limit is not None and time.monotonic() - worker.started > limit:
                    reason = (f"it ran longer than {limit:g} s (the time limit"
                              + (")" if timeout is not None else f": {RUN_TIMEOUT_FACTOR:g} x the slowest run "
                                 f"so far, at least {RUN_TIMEOUT_FLOOR:g} s; --run-timeout sets another)") + "; ended")
                else:
                    continue
                worker.end(kill=True)
                self.workers[self.workers.index(worker)] = _Worker(self.context, self.function)
                yield lost(arguments[running], reason)

    def stop(self) -> None:
        """End every worker: idle ones asked, busy ones killed."""
        for worker in self.workers:
            worker.end()
        self.workers = []


def _work(conn: Any, function: Callable[..., Any], parent: int) -> None:
    """A worker's loop: call ``function`` with each task's arguments until told to end."""
    global _IN_WORKER
    _IN_WORKER = True
    _end_with_parent(parent)
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            break
        if message is None:
            break
        task, arguments = message
        try:
            handoff.send(conn, ("ok", function(*arguments)))  # large arrays through shared memory
        except Exception as error:  # noqa: BLE001 - the function should not raise: said, not a dead worker
            conn.send(("raised", f"{type(error).__name__}: {error}"))
    conn.close()
    os._exit(0)  # the parent does the clean-ups


def _end_with_parent(parent: int | None = None) -> None:
    """In a worker: die with the parent. The kernel sends SIGKILL when the parent dies (Linux,
    PR_SET_PDEATHSIG; nothing in the worker can turn it into something else); the handlers
    inherited from the command (SIGTERM raised as KeyboardInterrupt) are put back to the
    defaults, so a SIGTERM ends the worker instead of failing its task; a parent already gone
    before this ran ends it at once. Ctrl-C is left to the parent, which stops the pool; a crash
    is said by the parent (no Python fault report of the worker's own)."""
    import faulthandler

    faulthandler.disable()
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        pass
    if parent is not None and os.getppid() != parent:
        os._exit(1)
