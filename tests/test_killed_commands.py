"""identify and montecarlo killed (SIGKILL, SIGTERM) while they work. On local worker processes
(--workers 2): no worker is alive a few seconds later. On a Dask cluster (--scheduler; here a
LocalCluster with worker processes, standing for a user's cluster): the cluster lets go of every
task of the killed command (none left queued or running a few seconds later, once the run under
way ends), its worker processes stay the cluster's (alive, and take new work), and the command
leaves no process of its own behind."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

psutil = pytest.importorskip("psutil", reason="psutil not installed")


@pytest.fixture(scope="module")
def cluster() -> Iterator[Any]:
    # imported here, not at collection: dask.distributed takes a third of a second to import, in
    # every test worker that collects this module (make test-fast collects it without running it)
    distributed = pytest.importorskip("distributed", reason="dask.distributed not installed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
                                  processes=True) as local, distributed.Client(local) as client:
        yield client


def _tasks(client: Any) -> int:
    """Tasks the scheduler holds (queued, running or kept in memory) for any client."""
    return int(client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks)))


def _busy(client: Any) -> int:
    """Tasks the cluster's workers run or have ready to run."""
    states = client.run(lambda dask_worker: len(dask_worker.state.executing) + len(dask_worker.state.ready))
    return sum(states.values())


def _wait(condition: Any, seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.2)
    return condition()


def _command(name: str, tmp_path: Path, where: list[str], fmus: dict[str, Path], identified: Any) -> list[str]:
    base = [sys.executable, "-P", "-m", "rover_cosim", name, "--out", str(tmp_path / name), *where, "--quiet"]
    if name == "identify":
        return [*base, "--fmu", str(fmus["SingleWheel"])]
    return [*base, "--runs", "20", "--fmu-dir", str(fmus["Rover"].parent),
            "--model", str(identified.files[0].parent / "model.json")]


@pytest.mark.parametrize("signal_name", ["SIGKILL", "SIGTERM"])
@pytest.mark.parametrize("name", ["identify", "montecarlo"])
def test_a_killed_command_leaves_nothing_running_on_the_cluster(cluster, fmus, request, tmp_path, name, signal_name):
    identified = request.getfixturevalue("identified") if name == "montecarlo" else None
    workers = {w["id"]: w for w in cluster.scheduler_info()["workers"].values()}
    assert _wait(lambda: _tasks(cluster) == 0, 60), "the cluster is not idle before the test"
    command = subprocess.Popen(_command(name, tmp_path, ["--scheduler", cluster.scheduler.address], fmus, identified),
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        assert _wait(lambda: _busy(cluster) > 0 or command.poll() is not None, 120), "no task reached the cluster"
        assert command.poll() is None, f"{name} ended before it could be killed: {command.stderr.read()}"  # type: ignore[union-attr]
        own = psutil.Process(command.pid).children(recursive=True)
        assert _tasks(cluster) > 1, "the command should have more tasks queued than the cluster runs"
        os.kill(command.pid, getattr(signal, signal_name))
        command.wait(timeout=60)
    finally:
        if command.poll() is None:
            command.kill()
    assert command.returncode == (-9 if signal_name == "SIGKILL" else 130), command.stderr.read()  # type: ignore[union-attr]
    assert _wait(lambda: _tasks(cluster) == 0 and _busy(cluster) == 0, 120), (
        f"{_tasks(cluster)} tasks still on the cluster, {_busy(cluster)} running or ready, after {name} was killed")
    gone, alive = psutil.wait_procs(own, timeout=10)
    assert not alive, f"{len(alive)} processes of the killed {name} outlived it"
    assert {w["id"] for w in cluster.scheduler_info()["workers"].values()} == set(workers)  # the cluster's own
    assert cluster.submit(pow, 2, 10, pure=False).result(timeout=60) == 1024


@pytest.mark.parametrize("signal_name", ["SIGKILL", "SIGTERM"])
@pytest.mark.parametrize("name", ["identify", "montecarlo"])
def test_a_killed_command_leaves_no_local_worker_alive(fmus, request, tmp_path, name, signal_name):
    identified = request.getfixturevalue("identified") if name == "montecarlo" else None
    command = subprocess.Popen(_command(name, tmp_path, ["--workers", "2"], fmus, identified),
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        assert _wait(lambda: len(_workers(command.pid)) >= 2 or command.poll() is not None, 120), "no workers"
        assert command.poll() is None, f"{name} ended before it could be killed: {command.stderr.read()}"  # type: ignore[union-attr]
        workers = _workers(command.pid)
        os.kill(command.pid, getattr(signal, signal_name))
        command.wait(timeout=60)
    finally:
        if command.poll() is None:
            command.kill()
    gone, alive = psutil.wait_procs(workers, timeout=10)
    for process in alive:
        process.kill()
    assert not alive, f"{len(alive)} workers of {name} outlived it ({signal_name})"


def _workers(pid: int) -> list[Any]:
    """The Python processes below ``pid`` (its pool's workers)."""
    try:
        return [c for c in psutil.Process(pid).children(recursive=True) if "python" in c.name().lower()]
    except psutil.NoSuchProcess:
        return []
