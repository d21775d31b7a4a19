"""The identification cache cannot be poisoned, and a sweep's workers end with it: damaged cache
files are found, named and computed again; partial files are removed; killing the sweep (SIGKILL
or SIGTERM) leaves no worker running."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pandas as pd
import psutil
import pytest

from rover_cosim.identification.cache import checksum_file
from rover_cosim.identification.sweep import Case, SweepPlan, run_file, run_sweep

SMALL = SweepPlan(loads=(300.0, 600.0), torques=(10.0, 30.0), stop_time=0.02, sample_time=1e-3)


@pytest.fixture
def cached(fmus, tmp_path):
    first = run_sweep(fmus["SingleWheel"], SMALL, tmp_path, workers=1)
    assert not first.failures and not first.rejected
    return first


def test_the_sweeps_cache_files_are_compressed_and_read_back_exactly(cached):
    """A sweep's cache files are gzip-compressed CSV: smaller than the CSV they hold, and read back
    equal to the runs the sweep returned."""
    import gzip

    from rover_cosim.identification.cache import read_run

    path = run_file(cached.cache_folder, 600.0, 30.0)
    assert path.name.endswith(".csv.gz") and path.read_bytes()[:2] == b"\x1f\x8b"
    assert path.stat().st_size < len(gzip.decompress(path.read_bytes()))
    run = cached.runs[Case(600.0, 30.0)]
    data, problem = read_run(path, len(run), list(run.columns))
    assert problem is None and data is not None
    pd.testing.assert_frame_equal(data, run)


@pytest.mark.parametrize("damage", ["cut mid-line", "empty", "garbage", "no checksum", "other rows"])
def test_a_damaged_cache_file_is_named_and_computed_again(fmus, tmp_path, cached, damage):
    path = run_file(cached.cache_folder, 600.0, 30.0)
    payload = path.read_bytes()
    if damage == "cut mid-line":
        path.write_bytes(payload[: len(payload) // 2])
    elif damage == "empty":
        path.write_bytes(b"")
    elif damage == "garbage":
        path.write_bytes(os.urandom(300))
    elif damage == "no checksum":
        checksum_file(path).unlink()
    else:  # a whole, self-consistent file of another run length
        from rover_cosim.identification.cache import write_run

        write_run(path, cached.runs[Case(600.0, 30.0)].iloc[:5])
    with pytest.warns(UserWarning, match=f"{path.name}.*computing it again"):
        again = run_sweep(fmus["SingleWheel"], SMALL, tmp_path, workers=1)
    assert again.computed == 1 and path in again.rejected and not again.failures
    for case, run in cached.runs.items():
        pd.testing.assert_frame_equal(run, again.runs[case])


def test_stale_partial_files_are_removed(fmus, tmp_path, cached):
    stale = cached.cache_folder / ".W300_tau10.csv.abc.part"
    stale.write_text("half a run")
    again = run_sweep(fmus["SingleWheel"], SMALL, tmp_path, workers=1)
    assert not stale.exists() and again.computed == 0


SWEEP = textwrap.dedent("""
    import sys
    from pathlib import Path
    from rover_cosim.identification.sweep import SweepPlan, run_sweep
    plan = SweepPlan(loads=tuple(100.0 + i for i in range(200)), torques=(10.0, 20.0), stop_time=0.1,
                     sample_time=1e-4)
    print("started", flush=True)
    run_sweep(Path(sys.argv[1]), plan, Path(sys.argv[2]), workers=2)
""")


def _workers(parent: psutil.Process, deadline: float) -> list[psutil.Process]:
    while time.time() < deadline:
        children = parent.children(recursive=True)
        if len([c for c in children if "python" in c.name().lower()]) >= 2:
            return children
        time.sleep(0.1)
    return parent.children(recursive=True)


@pytest.mark.parametrize("sent", [signal.SIGKILL, signal.SIGTERM])
def test_the_workers_end_with_the_sweep(fmus, tmp_path, sent):
    process = subprocess.Popen([sys.executable, "-P", "-c", SWEEP, str(fmus["SingleWheel"]), str(tmp_path)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    parent = psutil.Process(process.pid)
    workers = _workers(parent, time.time() + 60)
    assert len(workers) >= 2, "the sweep never started its workers"
    time.sleep(1.0)
    process.send_signal(sent)
    process.wait(timeout=30)
    gone, alive = psutil.wait_procs(workers, timeout=15)
    assert not alive, f"workers still running after {sent!r}: {[p.pid for p in alive]}"


def test_a_cache_file_copied_over_another_case_with_its_checksum_is_refused(tmp_path):
    """Each checksum carries the case it was computed for: a run file and its checksum copied over
    another case's (the poisoning of issue 30) are named and computed again; a results folder moved
    as a whole keeps its cache."""
    import shutil

    import pandas as pd

    from rover_cosim.identification.cache import checksum_file, read_run, write_run

    folder = tmp_path / "results" / "identification" / "cache" / "fmu-digest" / "plan-digest"
    folder.mkdir(parents=True)
    a, b = folder / "W275_tau20.csv", folder / "W575_tau20.csv"
    write_run(a, pd.DataFrame({"time": [0.0, 1.0], "Fx": [1.0, 2.0]}))
    write_run(b, pd.DataFrame({"time": [0.0, 1.0], "Fx": [5.0, 6.0]}))
    shutil.copy(b, a)
    shutil.copy(checksum_file(b), checksum_file(a))
    data, problem = read_run(a, 2, ["time", "Fx"])
    assert data is None and "computed for 'fmu-digest/plan-digest/W575_tau20.csv'" in str(problem)
    assert read_run(b, 2, ["time", "Fx"])[0] is not None
    moved = tmp_path / "elsewhere"
    shutil.move(str(tmp_path / "results"), moved)
    assert read_run(moved / "identification" / "cache" / "fmu-digest" / "plan-digest" / "W575_tau20.csv", 2,
                    ["time", "Fx"])[0] is not None
