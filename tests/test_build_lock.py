"""One process at a time builds a given FMU into a given folder (fmubuild.build._one_build_at_a_time):
a second `make fmus` or a parallel test worker waits for the first instead of writing the same
partial file."""

from __future__ import annotations

import multiprocessing
import time
from pathlib import Path

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
