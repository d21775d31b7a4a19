"""The masters' native inner loop (orchestrator.native, issue 18): the FMUs stepped from C give
the Python master's results bit for bit, with and without blocks, on one thread or several;
failures are named as from Python; it can be switched off, and a machine without a C compiler
falls back to Python with the reason."""

from __future__ import annotations

import threading
import tomllib

import numpy as np
import pandas as pd
import pytest

from rover_cosim.cli import EXAMPLES
from rover_cosim.orchestrator import native
from rover_cosim.orchestrator.algorithms import Jacobi
from rover_cosim.orchestrator.execution import Execution
from rover_cosim.orchestrator.master import RunError, participants_of, run
from rover_cosim.orchestrator.system import SystemFileError, system_from_dict
from rover_cosim.orchestrator.wiring import wire

pytestmark = pytest.mark.skipif(native.unavailable_reason() is not None,
                                reason=str(native.unavailable_reason()))


def rover(blocks: bool = True, **simulation: object) -> dict:
    """The co-simulated rover of the examples, 0.3 s; without blocks the torques are start values."""
    data = tomllib.loads(EXAMPLES["rover_cosim"].read_text())
    data["simulation"].update(stop_time=0.3, **simulation)
    if not blocks:
        data.pop("block")
        data["connection"] = [c for c in data["connection"] if not c["from"].startswith("torque.")]
        data["simulation"]["order"] = [n for n in data["simulation"]["order"] if n != "torque"]
        for fmu in data["fmu"]:
            fmu["start"] = {"tau": 20.0} if fmu["name"].startswith("wheel") else {
                f"tau[{i}]": 20.0 for i in range(1, 7)}
    return data


@pytest.mark.parametrize("blocks", [True, False], ids=["with a block", "FMUs only"])
@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi", "gauss-seidel-interpolated"])
@pytest.mark.parametrize("threads", [1, 2])
def test_native_stepping_gives_the_python_masters_results_exactly(fmu_dir, fmus, algorithm, threads, blocks):
    python = run(system_from_dict(rover(blocks, algorithm=algorithm, native=False, threads=1), name="p",
                                  base=fmu_dir))
    ours = run(system_from_dict(rover(blocks, algorithm=algorithm, threads=threads), name="n", base=fmu_dir))
    pd.testing.assert_frame_equal(python.data, ours.data, check_exact=True)
    assert len(ours.data) == 301 and np.isfinite(ours.data.to_numpy()).all()
    # The time inside the FMUs is measured by the stepper and reported per participant.
    assert all(ours.step_seconds[f"wheel{i}"] > 0 for i in range(1, 7))


def test_the_masters_use_the_native_stepper_unless_switched_off(fmu_dir, fmus):
    threads_before = threading.active_count()
    for switch, expected in ((True, True), (False, False)):
        system = system_from_dict(rover(native=switch), name="s", base=fmu_dir)
        wiring = wire(system)
        with participants_of(system, wiring) as participants:
            master = Execution(Jacobi(), participants, wiring, threads=2, use_native=system.native)
            assert (master.stepper is not None) is expected
            assert (master.pool is None) is expected  # the stepper has its own threads
            master.close()
    assert threading.active_count() == threads_before  # no Python helper thread left behind


@pytest.mark.parametrize("blocks", [True, False], ids=["with a block", "FMUs only"])
def test_a_failing_fmu_is_named_and_the_rows_before_kept(fmu_dir, fmus, blocks):
    data = rover(blocks, threads=2)
    data["fmu"][3]["parameters"] = {"solver.maxStep": 1e-12}  # wheel3 cannot integrate a step
    with pytest.raises(RunError, match=r"wheel3 \(Wheel.fmu\): fmi2DoStep at t = 0 s failed: .*step") as info:
        run(system_from_dict(data, name="t", base=fmu_dir))
    assert len(info.value.partial) == 1  # the start only


def test_native_must_be_true_or_false(fmu_dir, fmus):
    with pytest.raises(SystemFileError, match=r"native: 'yes': expected true or false"):
        system_from_dict(rover(native="yes"), name="t", base=fmu_dir)


def test_without_a_compiler_the_masters_stay_in_python_and_say_why(fmu_dir, fmus, tmp_path, monkeypatch):
    monkeypatch.setenv("ROVER_COSIM_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    native._library.cache_clear()
    native.load_library.cache_clear()
    try:
        reason = native.unavailable_reason()
        assert reason is not None and "no-such-compiler" in reason
        result = run(system_from_dict(rover(), name="t", base=fmu_dir))
        assert len(result.data) == 301
    finally:
        monkeypatch.undo()
        native._library.cache_clear()
        native.load_library.cache_clear()
    assert native.unavailable_reason() is None


@pytest.mark.parametrize("damage", ["truncated", "foreign"])
def test_a_damaged_library_in_the_native_cache_is_compiled_again(fmu_dir, fmus, tmp_path, damage):
    """A stepper library cut short (it crashed every run with SIGBUS) or another library under its
    name: the next run names it in one line, compiles it again and runs natively, exit 0."""
    import os
    import subprocess
    import sys

    cache = tmp_path / "cache"
    env = {**os.environ, "ROVER_COSIM_CACHE": str(cache)}
    command = [sys.executable, "-m", "rover_cosim", "run", "single_wheel_step", "--fmu-dir", str(fmu_dir),
               "--stop-time", "0.05", "-o", str(tmp_path / "run.csv"), "-q"]
    first = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
    assert first.returncode == 0, first.stderr
    library = next(cache.glob("stepper-*.so"))
    if damage == "truncated":
        library.write_bytes(library.read_bytes()[:4096])
    else:
        library.write_bytes(library.read_bytes()[::-1])  # not the library compiled here
    again = subprocess.run(command, env=env, capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr
    assert f"native cache {library}: its content does not match its checksum" in again.stderr
    assert again.stderr.count("native cache") == 1
