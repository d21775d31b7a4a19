"""Benchmark of the leg-wheel rover (issue 47, item 7): the paper's straight run (20 s at 1 ms)
on LegWheelRover.fmu, on LegWheelRoverBody + 6 Wheel and, side by side, on Rover.fmu (the
spring-damper rover); the 20 deg side-slope traverse with the paper's posture and with posture
control; and the whole command the user waits for, ``rover-cosim simulate --only legwheel``.
Reported per run: wall seconds, real-time factor, the time per communication step inside each
participant; for the command, its wall seconds.

Written to results/bench/legwheel.json by ``make bench``. Not a test: nothing asserts a time; the
goal of issue 47 (the leg-wheel rover monolithic at >= 20x real time in a whole command) is
recorded beside the figures. Needs an identified model (``--model``; identified on the fly when
missing).
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.fmubuild import build
from rover_cosim.jobs import legwheel, simulate
from rover_cosim.jobs.identify import model_file
from rover_cosim.orchestrator.master import run

GOAL_REAL_TIME = 20.0


def _path_following_benchmark() -> Any:
    """benchmarks/bench_path_following.py, whose per-run summary this one shares (loaded from its
    file: ``python -P`` keeps this folder off the import path)."""
    spec = importlib.util.spec_from_file_location("bench_path_following",
                                                  Path(__file__).with_name("bench_path_following.py"))
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


summary = _path_following_benchmark().summary


def systems(fmu_dir: Path, model: Path) -> dict[str, Any]:
    return {"straight/LegWheelRover": legwheel.straight_system(fmu_dir, model),
            "straight/LegWheelRoverBody + 6 Wheel": legwheel.straight_cosim_system(fmu_dir, model),
            "straight/Rover (spring-damper limbs)": simulate.monolithic_system(fmu_dir, model),
            "slope/paper's posture": legwheel.slope_system(fmu_dir, model, "fixed"),
            "slope/posture control": legwheel.slope_system(fmu_dir, model, "posture")}


def one_run(made: Any) -> dict[str, Any]:
    result = run(made)
    return {"wall_seconds": result.wall_seconds, "steps": result.steps, "simulated_seconds": made.stop_time,
            "participant_seconds": dict(result.step_seconds)}


def command_simulated_seconds() -> float:
    """s: the simulated time of every run of ``simulate --only legwheel`` (three straight runs, the side
    slope and the climb twice each, the soft patch twice), from the job's own constants."""
    from rover_cosim.jobs.terrain import stop_time

    traverse = stop_time(legwheel.TRAVERSE, legwheel.SPEED)
    patch = stop_time(float(legwheel.PATCH["length"]), float(legwheel.PATCH["speed"]))  # type: ignore[arg-type]
    return 3 * simulate.STOP_TIME + 2 * len(legwheel.RUNS) * traverse + len(legwheel.PATCH_RUNS) * patch


def whole_command(fmu_dir: Path, model: Path) -> float:
    """s: ``rover-cosim simulate --only legwheel`` into a scratch folder, as a user runs it."""
    with tempfile.TemporaryDirectory(prefix="bench-legwheel-") as scratch:
        started = time.perf_counter()
        subprocess.run([sys.executable, "-P", "-m", "rover_cosim", "simulate", "--only", "legwheel", "--quiet",
                        "--out", scratch, "--fmu-dir", str(fmu_dir), "--model", str(model)], check=True,
                       stdout=subprocess.DEVNULL)
        return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/legwheel.json"))
    parser.add_argument("--model", type=Path, default=Path("results/identification/model.json"))
    parser.add_argument("--fmu-dir", type=Path, default=Path("fmus"))
    parser.add_argument("--repeats", type=int, default=1)
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats={args.repeats}: expected an integer >= 1")
    build.build_all(build.FMU_MODELS, args.fmu_dir, backend="builtin")
    model = model_file(args.model, args.fmu_dir)
    runs: dict[str, list[dict[str, Any]]] = {}
    commands = []
    for _ in range(args.repeats):  # interleaved: every run and the command once per repeat
        for key, made in systems(args.fmu_dir, model).items():
            runs.setdefault(key, []).append(one_run(made))
        commands.append(whole_command(args.fmu_dir, model))
    results = {key: summary(entries) for key, entries in runs.items()}
    for key, entry in results.items():
        inside = ", ".join(f"{name} {us:.0f}" for name, us in entry["per_step_us_inside"].items())
        print(f"{key:40s} {entry['wall_seconds_median']:6.2f} s  {entry['real_time_factor']:5.1f}x real time  "
              f"(us per step inside: {inside})")
    simulated = command_simulated_seconds()
    command = statistics.median(commands)
    print(f"rover-cosim simulate --only legwheel: {command:.1f} s for {simulated:g} s simulated in its runs "
          f"({simulated / command:.1f}x real time as a whole command; goal {GOAL_REAL_TIME:.0f}x for the monolithic "
          "rover)")
    record = run_record("make bench", {"repeats": args.repeats, "model": str(model)})
    write_all({args.out: json_bytes({**record, "results": results, "command_wall_seconds": commands,
                                     "command_real_time_factor": simulated / command,
                                     "goal_real_time_factor": GOAL_REAL_TIME})})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
