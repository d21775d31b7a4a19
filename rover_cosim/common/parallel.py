"""Many independent calls of one function, on a Dask cluster, local processes or serially,
with the results in the order they complete (the identification sweep and the Monte Carlo study).

The function must be importable by name (the workers import it) and should not raise: it reports
its own failures in what it returns, so that one failing call does not stop the others. The
local worker processes end with the caller: on an error, Ctrl-C or SIGTERM (raised as
KeyboardInterrupt by the CLI) or the consumer closing the generator, the pool is cancelled and
its workers terminated; and each worker asks Linux to kill it when its parent dies
(PR_SET_PDEATHSIG, SIGKILL) and takes the default signal handlers back, so a caller killed in
any way (kill -9 included) leaves no workers behind.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any, TypeVar

from .scratch import remove_stale_folders

Result = TypeVar("Result")
#: s, how long a Dask scheduler may take to answer (ROVER_COSIM_SCHEDULER_TIMEOUT sets another).
SCHEDULER_TIMEOUT = 30.0


def parallel_map(function: Callable[..., Result], arguments: Sequence[tuple[Any, ...]], workers: int | None = None,
                 scheduler: str | None = None) -> Iterator[Result]:
    """``function(*a)`` for every ``a`` of ``arguments``: on the Dask cluster at ``scheduler``
    (``tcp://host:port``) when given, else on ``workers`` local processes (default: all cores;
    1: serially in this process). Results in the order they complete."""
    if scheduler is not None:
        from dask.distributed import Client
        from dask.distributed import as_completed as dask_completed

        timeout = float(os.environ.get("ROVER_COSIM_SCHEDULER_TIMEOUT", SCHEDULER_TIMEOUT))
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
    if workers == 1 or len(arguments) <= 1:
        yield from (function(*a) for a in arguments)
        return
    pool = ProcessPoolExecutor(max_workers=workers, initializer=_end_with_parent, initargs=(os.getpid(),))
    try:
        for future in as_completed([pool.submit(function, *a) for a in arguments]):
            yield future.result()
    except BaseException:  # Ctrl-C, SIGTERM (raised as KeyboardInterrupt by the CLI), the consumer closing
        _stop(pool)
        remove_stale_folders()
        raise
    pool.shutdown()
    remove_stale_folders()  # the workers' temporary folders (they exit without clean-ups)


def _stop(pool: ProcessPoolExecutor) -> None:
    """Cancel what has not started and end the workers now."""
    processes = list(getattr(pool, "_processes", {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()
    for process in processes:
        process.join(timeout=5)


def _end_with_parent(parent: int | None = None) -> None:
    """In a worker: die with the parent. The kernel sends SIGKILL when the parent dies (Linux,
    PR_SET_PDEATHSIG; nothing in the worker can turn it into something else); the handlers
    inherited from the command (SIGTERM raised as KeyboardInterrupt) are put back to the
    defaults, so a SIGTERM ends the worker instead of failing its task; a parent already gone
    before this ran ends it at once. Ctrl-C is left to the parent, which stops the pool."""
    import signal

    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        pass
    if parent is not None and os.getppid() != parent:
        os._exit(1)
