"""One process at a time builds a given FMU into a given folder (fmubuild.build._one_build_at_a_time):
a second `make fmus` or a parallel test worker waits for the first instead of writing the same
partial file."""

from __future__ import annotations

import multiprocessing
import time
from pathlib import Path

import pytest

from rover_cosim.fmubuild.build import _one_build_at_a_time


def _hold(lock: Path, log: Path, started: object) -> None:
    with _one_build_at_a_time(lock):
        started.set()  # type: ignore[attr-defined]
        with open(log, "a") as out:
            out.write("first in\n")
        time.sleep(0.5)
        with open(log, "a") as out:
            out.write("first out\n")


def test_a_second_build_of_the_same_fmu_waits_for_the_first(tmp_path: Path):
    lock, log = tmp_path / "locks" / "Wheel.lock", tmp_path / "log"
    context = multiprocessing.get_context("spawn")
    started = context.Event()
    first = context.Process(target=_hold, args=(lock, log, started))
    first.start()
    assert started.wait(30)
    with _one_build_at_a_time(lock):
        with open(log, "a") as out:
            out.write("second in\n")
    first.join(30)
    assert first.exitcode == 0
    assert log.read_text().splitlines() == ["first in", "first out", "second in"]


@pytest.mark.fmu  # it builds two FMUs
def test_the_longest_builds_of_the_last_time_start_first(tmp_path: Path, monkeypatch):
    """build_all starts the FMUs that took longest here the last time first (those without a time
    before them, as given), reports them in the order asked, and remembers what it built."""
    import json

    from rover_cosim.fmubuild import build

    assert build.build_order(["A", "B", "C", "D"], {"A": 1.0, "C": 9.0, "D": 4.0}) == ["B", "C", "D", "A"]
    monkeypatch.setenv("ROVER_COSIM_CACHE", str(tmp_path / "cache"))
    (tmp_path / "cache").mkdir()
    (tmp_path / "cache" / build.BUILD_SECONDS).write_text(json.dumps({"SteerableRoverBody": 0.01, "Other": 3.0}))
    names = ["RoverBody", "SteerableRoverBody"]  # the two quickest to build
    results = build.build_all(names, tmp_path / "fmus", jobs=2)
    assert [r.name for r in results] == names and all(r.rebuilt for r in results)
    remembered = json.loads((tmp_path / "cache" / build.BUILD_SECONDS).read_text())
    assert remembered["Other"] == 3.0 and remembered["SteerableRoverBody"] > 0.01 and remembered["RoverBody"] > 0
    again = build.build_all(names, tmp_path / "fmus", jobs=2)  # up to date: not remembered
    assert not any(r.rebuilt for r in again)
    assert json.loads((tmp_path / "cache" / build.BUILD_SECONDS).read_text()) == remembered
