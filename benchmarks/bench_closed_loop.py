"""Benchmark of the paper's closed loop (issue 18, part 6): 20 s at 1 ms, Gauss-Seidel, the
identified-model controller on the monolithic Rover.fmu and on the co-simulated RoverBody + 6
Wheel (FMUs stepped in threads, as by default), timed in the same run, each also with the
controller stepped in Python instead of its C twin; and where the time goes: per communication
step, the wall time, the time inside each participant's calls (measured by the native stepper;
summed over threads, so wall minus their sum, the "master's own share", is negative when
participants step in parallel) and, from the FMUs' statistics (one more run that records them), the model
evaluations, Jacobians and integrator steps of each FMU, and the force evaluations of each sinkage
solve (``contactEvaluations`` of every wheel, averaged over the communication points).

Written to results/bench/closed_loop.json by ``make bench``. Not a test: nothing asserts a
time; the goals of issue 18 (20 s in <= 1.0 s on Rover.fmu, <= 2.0 s co-simulated) are
recorded beside the measured figures. Needs an identified model (``--model``; identified on the
fly when missing). ``--baseline-fmu-dir`` times the same loops on other FMUs as well (e.g. those
of an earlier commit), interleaved with ours in the same run, and records the ratios.
"""

from __future__ import annotations

import argparse
import statistics
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pandas as pd

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.control.controller import InverseModelController
from rover_cosim.fmubuild import build
from rover_cosim.jobs.identify import model_file
from rover_cosim.jobs.simulate import STEP, STOP_TIME, cosim_system, monolithic_system
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.master import run

GOALS_S = {"monolithic": 1.0, "cosim": 2.0}  # wall seconds for 20 s simulated (issue 18)
STATISTICS = ("evaluations", "reusedEvaluations", "jacobians", "steps", "rejectedSteps")
BUILDERS = {"monolithic": monolithic_system, "cosim": cosim_system}


def system(plant: str, fmu_dir: Path, model: Path, stop_time: float, record: list[str] | None = None) -> Any:
    builder = SystemBuilder.from_system(BUILDERS[plant](fmu_dir, model), f"bench closed loop ({plant})")
    builder.simulation(stop_time=stop_time)
    if record is not None:
        builder.record(*record, replace=True)
    return builder.build()


def recorded_costs(plant: str) -> tuple[list[str], dict[str, list[str]]]:
    """Variables to record: per FMU its statistics, per wheel its solve's force evaluations."""
    if plant == "monolithic":
        fmus = {"rover": [f"rover.wheels[{i}].contactEvaluations" for i in range(1, 7)]}
    else:
        fmus = {"body": []} | {f"wheel{i}": [f"wheel{i}.contactEvaluations"] for i in range(1, 7)}
    record = [f"{fmu}.statistics.{name}" for fmu in fmus for name in STATISTICS]
    record += [v for solves in fmus.values() for v in solves]
    return record, fmus


def costs(plant: str, fmu_dir: Path, model: Path, stop_time: float) -> dict[str, Any]:
    """Per communication step and FMU: statistics; per wheel: force evaluations per solve."""
    record, fmus = recorded_costs(plant)
    data: pd.DataFrame = run(system(plant, fmu_dir, model, stop_time, record)).data
    steps = len(data) - 1
    per_fmu = {}
    for fmu, solves in fmus.items():
        last = data.iloc[-1]
        entry = {f"{name}_per_step": float(last[f"{fmu}.statistics.{name}"]) / steps for name in STATISTICS}
        if solves:
            entry["contact_evaluations_per_solve"] = float(data[solves].iloc[1:].to_numpy().mean())
            # Each evaluation of the model solves the sinkage of every wheel once.
            entry["contact_evaluations_per_step_per_wheel"] = (entry["evaluations_per_step"]
                                                               * entry["contact_evaluations_per_solve"])
        per_fmu[fmu] = entry
    return per_fmu


@contextmanager
def python_controller() -> Iterator[None]:
    """The controller block without its C twin: stepped in Python between native FMU steps
    (what the closed loop cost before the twin)."""
    original = InverseModelController.native
    InverseModelController.native = lambda self: None  # type: ignore[method-assign]
    try:
        yield
    finally:
        InverseModelController.native = original  # type: ignore[method-assign]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/closed_loop.json"))
    parser.add_argument("--model", type=Path, default=Path("results/identification/model.json"))
    parser.add_argument("--fmu-dir", type=Path, default=Path("fmus"))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--stop-time", type=float, default=STOP_TIME)
    parser.add_argument("--baseline-fmu-dir", type=Path, default=None,
                        help="FMUs to time beside ours (not rebuilt), e.g. an earlier commit's")
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats={args.repeats}: expected an integer >= 1")
    build.build_all(build.FMU_MODELS, args.fmu_dir, backend="builtin")
    fmu_dir = args.fmu_dir.resolve()
    model = model_file(args.model, fmu_dir)
    steps = round(args.stop_time / STEP)
    results: dict[str, dict[str, Any]] = {}
    baseline = args.baseline_fmu_dir.resolve() if args.baseline_fmu_dir else None
    for plant in BUILDERS:
        walls, overheads, baseline_walls, python_walls = [], [], [], []
        inside: dict[str, list[float]] = {}
        for _ in range(args.repeats):  # the variants interleaved, round by round
            outcome = run(system(plant, fmu_dir, model, args.stop_time))
            walls.append(outcome.wall_seconds)
            overheads.append(outcome.master_overhead_seconds)
            for name, seconds in outcome.step_seconds.items():
                inside.setdefault(name, []).append(1e6 * seconds / steps)
            with python_controller():
                python_walls.append(run(system(plant, fmu_dir, model, args.stop_time)).wall_seconds)
            if baseline:
                baseline_walls.append(run(system(plant, baseline, model, args.stop_time)).wall_seconds)
        wall = statistics.median(walls)
        goal = GOALS_S[plant] * args.stop_time / STOP_TIME
        results[plant] = {
            "wall_seconds": walls, "wall_seconds_median": wall, "real_time_factor": args.stop_time / wall,
            "wall_per_step_us": 1e6 * wall / steps,
            "master_overhead_per_step_us": 1e6 * statistics.median(overheads) / steps,
            "inside_participant_us_per_step": {name: statistics.median(v) for name, v in inside.items()},
            "python_controller_wall_seconds": python_walls,
            "speedup_over_python_controller": statistics.median(python_walls) / wall,
            "goal_wall_seconds": goal, "goal_met": wall <= goal,
            "fmu_costs": costs(plant, fmu_dir, model, args.stop_time),
        }
        print(f"{plant:10s} with the controller in Python {statistics.median(python_walls):6.2f} s")
        if baseline:
            results[plant].update(baseline_fmu_dir=str(baseline), baseline_wall_seconds=baseline_walls,
                                  speedup_over_baseline=statistics.median(baseline_walls) / wall)
            print(f"{plant:10s} baseline FMUs {statistics.median(baseline_walls):6.2f} s: "
                  f"{statistics.median(baseline_walls) / wall:.2f}x faster now")
        print(f"{plant:10s} {wall:6.2f} s for {args.stop_time:g} s (real-time factor {args.stop_time / wall:.1f}, "
              f"goal {goal:.1f} s), {1e6 * wall / steps:.0f} us/step, master's own "
              f"{results[plant]['master_overhead_per_step_us']:.0f} us/step")
        for fmu, entry in results[plant]["fmu_costs"].items():
            solves = (f", {entry['contact_evaluations_per_solve']:.2f} force evaluations per solve"
                      if "contact_evaluations_per_solve" in entry else "")
            print(f"  {fmu:7s} {entry['evaluations_per_step']:.2f} evaluations/step "
                  f"(+{entry['reusedEvaluations_per_step']:.2f} reused), {entry['jacobians_per_step']:.2f} "
                  f"Jacobians/step, {entry['steps_per_step']:.2f} integrator steps/step{solves}")
    record = run_record("make bench", {"repeats": args.repeats, "stop_time_s": args.stop_time, "step_s": STEP,
                                       "model": str(model), "algorithm": "gauss-seidel"})
    write_all({args.out: json_bytes({**record, "results": results})})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
