"""Parallel stepping in the master (issue 18, part 5): FMUs whose inputs are ready step at the
same time in threads, with the same results as one after the other, and errors still named."""

from __future__ import annotations

import tomllib

import pandas as pd
import pytest

from rover_cosim.cli import EXAMPLES
from rover_cosim.orchestrator.algorithms import GaussSeidel, independent_runs
from rover_cosim.orchestrator.execution import Execution
from rover_cosim.orchestrator.master import RunError, run
from rover_cosim.orchestrator.system import SystemFileError, system_from_dict
from rover_cosim.orchestrator.wiring import wire


def rover(**simulation: object) -> dict:
    data = tomllib.loads(EXAMPLES["rover_cosim"].read_text())
    data["simulation"].update(stop_time=0.5, **simulation)
    return data


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
def test_threads_give_the_serial_results_exactly(fmu_dir, fmus, algorithm):
    serial = run(system_from_dict(rover(algorithm=algorithm), name="s", base=fmu_dir)).data
    threaded = run(system_from_dict(rover(algorithm=algorithm, threads=3), name="t", base=fmu_dir)).data
    pd.testing.assert_frame_equal(serial, threaded, check_exact=True)


def test_the_wheels_after_the_body_form_one_group(fmu_dir, fmus):
    system = system_from_dict(rover(), name="s", base=fmu_dir)
    wiring = wire(system)
    from rover_cosim.orchestrator.master import participants_of

    with participants_of(system, wiring) as participants:
        master = Execution(GaussSeidel(), participants, wiring, threads=2)
        groups = [[participants[i].name for i in group] for group in
                  independent_runs(participants, master.inputs, master.outputs)]
        master.close()
    assert groups == [["torque"], ["body"], [f"wheel{i}" for i in range(1, 7)]]


def test_an_error_in_a_thread_is_named(fmu_dir, fmus):
    data = rover(threads=2)
    data["fmu"][3]["parameters"] = {"solver.maxStep": 1e-12}   # wheel3 cannot integrate a step
    with pytest.raises(RunError, match=r"wheel3 \(Wheel.fmu\): fmi2DoStep at t = 0 s failed"):
        run(system_from_dict(data, name="t", base=fmu_dir))


def test_threads_must_be_a_whole_number(fmu_dir, fmus):
    with pytest.raises(SystemFileError, match="threads: 0"):
        system_from_dict(rover(threads=0), name="t", base=fmu_dir)
