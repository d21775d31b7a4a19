"""The local worker pool of identify and montecarlo (common.parallel) survives a bad call (issue
45): a worker that crashes (SIGSEGV, as an FMU does), calls exit(), hangs past the time limit or
raises is replaced, its call reported through ``lost`` with the reason, every other call
completes, and no worker outlives the pool. One worker too: the caller survives its crash."""

from __future__ import annotations

import os
import signal
import time
from typing import Any

import pytest
from processes import children

from rover_cosim.common.parallel import cores, parallel_map
from rover_cosim.identification.sweep import Case
from rover_cosim.identification.sweep import _lost as sweep_lost
from rover_cosim.jobs.montecarlo.job import _lost as study_lost


def _call(k: int) -> int:
    """k squared, except: 2 segfaults, 3 calls exit(0), 4 hangs, 5 raises."""
    if k == 2:
        os.kill(os.getpid(), signal.SIGSEGV)
    if k == 3:
        os._exit(0)
    if k == 4:
        time.sleep(600)
    if k == 5:
        raise ValueError("five")
    return k * k


def _lost(arguments: tuple[int], reason: str) -> tuple[int, str]:
    return arguments[0], reason


@pytest.mark.parametrize("workers", [1, 2])
def test_a_crash_an_exit_a_hang_and_an_exception_each_lose_one_call_only(workers):
    before = set(children())
    results = list(parallel_map(_call, [(k,) for k in range(8)], workers=workers, lost=_lost, timeout=1.0))
    done = sorted(r for r in results if isinstance(r, int))
    lost: dict[int, str] = dict(r for r in results if isinstance(r, tuple))
    assert done == [0, 1, 36, 49] and sorted(lost) == [2, 3, 4, 5]
    assert "SIGSEGV" in lost[2] and "exit status 0" in lost[3]
    assert "longer than 1 s" in lost[4] and lost[5] == "it raised ValueError: five"
    time.sleep(0.2)
    assert not set(children()) - before, "no worker outlives the pool"


def test_without_lost_one_worker_runs_here_and_a_lost_call_is_an_error():
    assert list(parallel_map(_call, [(0,), (1,)], workers=1)) == [0, 1]  # serially, in this process
    with pytest.raises(RuntimeError, match="a worker process was lost: .*SIGSEGV"):
        list(parallel_map(_call, [(1,), (2,)], workers=2))


def test_the_jobs_record_a_lost_run_as_a_failed_one():
    case = Case(100.0, 10.0, 0.0)
    assert sweep_lost((None, case, 1.0, 0.01, 1e-6, 0.0, "x", None, None), "why") == (case, "lost: why", 0.0, None)

    class Spec:
        sample, scenario = 7, "straight"

    said = study_lost((Spec(),), "its worker process ended with SIGSEGV")  # type: ignore[arg-type]  # a RunSpec's keys
    assert said == (
        7, "straight", "lost: its worker process ended with SIGSEGV", 0.0)


def test_more_workers_than_cores_are_said_and_capped(capsys, tmp_path):
    from rover_cosim.cli import main

    code = main(["montecarlo", "--workers", str(cores() + 98), "--runs", "1", "--out", str(tmp_path / "mc"),
                 "--model", str(tmp_path / "missing.json"), "-q"])
    assert code == 2  # the missing model: nothing run
    assert f"--workers {cores() + 98}: more than the {cores()} cores of this machine; {cores()} used" in \
        capsys.readouterr().err
    assert main(["identify", "--run-timeout", "nan", "--out", str(tmp_path / "id")]) == 2
    assert "--run-timeout nan: expected a time limit > 0 s" in capsys.readouterr().err


def _pid(_k: int) -> int:
    return os.getpid()


def _no_pid(_arguments: tuple[int], _reason: str) -> int:
    return -1


def _nested(k: int) -> tuple[int, list[int]]:
    """In a pool's worker: its pid and the pids of a one-worker map with ``lost`` nested in it (an
    adaptive run's identification sweep inside a Monte Carlo run)."""
    return os.getpid(), list(parallel_map(_pid, [(k,), (k + 1,)], workers=1, lost=_no_pid))


def test_a_one_worker_map_nested_in_a_worker_runs_in_that_worker_and_elsewhere_in_a_process_of_its_own():
    """Nested in a pool's worker, a one-worker map with ``lost`` needs no process of its own (the
    outer pool already survives its crash); called from a command it still gets one."""
    outer = list(parallel_map(_nested, [(1,), (5,)], workers=2, lost=_lost))
    assert len(outer) == 2
    for worker, inner in outer:
        assert worker != os.getpid() and inner == [worker, worker]
    assert set(parallel_map(_pid, [(0,), (1,)], workers=1, lost=_no_pid)) - {os.getpid()}


def _nested_in_a_daemon(conn: Any) -> None:
    conn.send((os.getpid(), list(parallel_map(_pid, [(0,), (1,)], workers=1, lost=_no_pid))))
    conn.close()


def test_a_daemonic_worker_like_dasks_runs_a_nested_one_worker_map_in_itself():
    """A Dask worker is a daemonic process, which may not start processes of its own: a nested
    one-worker map with ``lost`` runs in it (before: the pool's Process.start failed there)."""
    import multiprocessing

    context = multiprocessing.get_context("fork")
    mine, theirs = context.Pipe()
    daemon = context.Process(target=_nested_in_a_daemon, args=(theirs,), daemon=True)
    daemon.start()
    assert mine.poll(30), "the daemonic process did not answer"
    pid, inner = mine.recv()
    daemon.join(10)
    assert pid == daemon.pid and inner == [pid, pid]
