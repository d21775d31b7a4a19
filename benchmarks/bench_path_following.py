"""Benchmark of path following (issue 34, item 2): each path scenario on SteerableRover.fmu with
the identified models (inverse steering) and with kinematic steering, and on the co-simulated
SteerableRoverBody + 6 Wheel, each run with the path controller's C twin (as by default) and with
the controller stepped in Python (its twin withheld), interleaved in the same run. Reported per
run: wall seconds, real-time factor, and the time per communication step inside each participant
(measured around its calls by the stepper; summed over threads).

Written to results/bench/path_following.json by ``make bench``. Not a test: nothing asserts a
time; the goal of issue 34 (path following at >= 20x real time) is recorded beside the figures.
Needs an identified model with a lateral part (``--model``; identified on the fly when missing).
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path
from typing import Any
from unittest import mock

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.control.path_controller import PathFollowingController
from rover_cosim.fmubuild import build
from rover_cosim.jobs import path_following
from rover_cosim.jobs.identify import model_file
from rover_cosim.orchestrator.master import run

GOAL_REAL_TIME = 20.0
PLANTS = ("inverse", "kinematic", "cosim")


def system(plant: str, scenario: str, fmu_dir: Path, model: Path) -> Any:
    if plant == "cosim":
        return path_following.cosim_system(fmu_dir, model, scenario)
    return path_following.monolithic_system(fmu_dir, model, scenario, plant)


def one_run(plant: str, scenario: str, fmu_dir: Path, model: Path, twin: bool) -> dict[str, Any]:
    """One run: wall seconds, steps, and seconds inside each participant."""
    made = system(plant, scenario, fmu_dir, model)
    if twin:
        result = run(made)
    else:
        with mock.patch.object(PathFollowingController, "native", lambda self: None):
            result = run(made)
    return {"wall_seconds": result.wall_seconds, "steps": result.steps, "simulated_seconds": made.stop_time,
            "participant_seconds": dict(result.step_seconds)}


def summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    wall = statistics.median(r["wall_seconds"] for r in runs)
    steps, simulated = runs[0]["steps"], runs[0]["simulated_seconds"]
    names = runs[0]["participant_seconds"]
    return {"wall_seconds": [r["wall_seconds"] for r in runs], "wall_seconds_median": wall,
            "simulated_seconds": simulated, "real_time_factor": simulated / wall,
            "per_step_us_inside": {name: 1e6 * statistics.median(r["participant_seconds"][name] for r in runs) / steps
                                   for name in names}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/path_following.json"))
    parser.add_argument("--model", type=Path, default=Path("results/identification/model.json"))
    parser.add_argument("--fmu-dir", type=Path, default=Path("fmus"))
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--scenarios", nargs="+", default=list(path_following.SCENARIOS),
                        choices=list(path_following.SCENARIOS))
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats={args.repeats}: expected an integer >= 1")
    build.build_all(build.FMU_MODELS, args.fmu_dir, backend="builtin")
    model = model_file(args.model, args.fmu_dir)
    runs: dict[str, list[dict[str, Any]]] = {}
    for _ in range(args.repeats):
        for scenario in args.scenarios:
            for plant in PLANTS:
                for twin in (True, False):
                    key = f"{scenario}/{plant}/{'c_twin' if twin else 'python_controller'}"
                    runs.setdefault(key, []).append(one_run(plant, scenario, args.fmu_dir, model, twin))
    results = {key: summary(entries) for key, entries in runs.items()}
    for key, entry in results.items():
        inside = ", ".join(f"{name} {us:.0f}" for name, us in entry["per_step_us_inside"].items())
        print(f"{key:40s} {entry['wall_seconds_median']:6.2f} s  {entry['real_time_factor']:5.1f}x real time  "
              f"(us per step inside: {inside})")
    simulated = sum(results[k]["simulated_seconds"] for k in results if k.endswith("c_twin"))
    wall = sum(results[k]["wall_seconds_median"] for k in results if k.endswith("c_twin"))
    before = sum(results[k]["wall_seconds_median"] for k in results if k.endswith("python_controller"))
    print(f"all runs: {simulated / wall:.1f}x real time with the C twin, {simulated / before:.1f}x with the "
          f"controller in Python (goal {GOAL_REAL_TIME:.0f}x)")
    record = run_record("make bench", {"repeats": args.repeats, "scenarios": args.scenarios, "model": str(model)})
    write_all({args.out: json_bytes({**record, "results": results,
                                     "real_time_factor_c_twin": simulated / wall,
                                     "real_time_factor_python_controller": simulated / before,
                                     "goal_real_time_factor": GOAL_REAL_TIME})})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
