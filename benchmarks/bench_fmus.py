"""Benchmark of the FMU build and of the built FMUs' Co-Simulation speed.

- Build: all four FMUs from a clean output folder (``--force`` into a temporary folder), in
  parallel as ``make fmus`` does; wall time in all, and per FMU the time of each stage
  (translate, generate, compile, package) measured inside its build process.
- Run: SingleWheel, Wheel and Rover stepped through FMPy's FMI 2.0 slave wrapper at a 1 ms
  communication step, reading every output after each step (what a co-simulation master does);
  steps per second, median of a few repeats. For context, the same SingleWheel run as Model
  Exchange with FMPy's CVODE, and rumoca's own simulation of Examples.SingleWheelStep.

Written to results/bench/fmus.json by ``make bench``. Not a test: nothing here asserts a time;
the floor of issue 4 (all four FMUs built from a clean tree in under 120 s) is recorded beside
the measured figure.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import fmpy
from fmpy.fmi2 import FMU2Slave

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.fmubuild import build, source

FLOOR_BUILD_SECONDS = 120.0
RUNS = {
    # name: (start values, simulated seconds)
    "SingleWheel": ({"W": 575.0, "tau": 60.0}, 4.0),
    "Wheel": ({"W": 575.0, "tau": 60.0, "v_hub": 0.3}, 4.0),
    "Rover": ({f"tau[{i}]": 40.0 for i in range(1, 7)}, 1.0),
}
STEP = 1e-3


def time_build(jobs: int) -> dict:
    with tempfile.TemporaryDirectory(prefix="bench-fmus-") as folder:
        start = time.perf_counter()
        results = build.build_all(build.FMU_MODELS, Path(folder), force=True, jobs=jobs, backend="builtin")
        wall = time.perf_counter() - start
        sizes = {r.name: r.path.stat().st_size for r in results}
    return {
        "jobs": jobs,
        "wall_seconds": wall,
        "per_fmu": {r.name: {"seconds": r.seconds, "stages": r.stages, "bytes": sizes[r.name]} for r in results},
        "floor_seconds": FLOOR_BUILD_SECONDS,
        "floor_met": wall < FLOOR_BUILD_SECONDS,
    }


def time_cs(path: Path, name: str, values: dict[str, float], seconds: float, folder: Path) -> float:
    """Wall seconds for stepping ``seconds`` at 1 ms with a getReal of all outputs per step."""
    md = fmpy.read_model_description(str(path))
    unzipped = folder / name
    if not unzipped.exists():
        fmpy.extract(str(path), str(unzipped))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    outputs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipped), modelIdentifier=name, instanceName="bench")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.setReal([refs[k] for k in values], list(values.values()))
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    steps = round(seconds / STEP)
    start = time.perf_counter()
    for k in range(steps):
        fmu.doStep(k * STEP, STEP)
        fmu.getReal(outputs)
    wall = time.perf_counter() - start
    fmu.terminate()
    fmu.freeInstance()
    return wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/fmus.json"))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats={args.repeats}: expected an integer >= 1")
    if args.jobs < 1:
        parser.error(f"--jobs={args.jobs}: expected an integer >= 1")

    built = time_build(args.jobs)
    print(f"clean build of {len(build.FMU_MODELS)} FMUs with {args.jobs} jobs: {built['wall_seconds']:.1f} s "
          f"(floor {FLOOR_BUILD_SECONDS:.0f} s)")
    for name, entry in built["per_fmu"].items():
        stages = ", ".join(f"{k} {v:.1f} s" for k, v in entry["stages"].items())
        print(f"  {name:12s} {entry['seconds']:5.1f} s ({stages})")

    fmus = {r.name: r.path for r in build.build_all(build.FMU_MODELS, Path("fmus"), backend="builtin")}
    runs = {}
    with tempfile.TemporaryDirectory(prefix="bench-cs-") as folder:
        for name, (values, seconds) in RUNS.items():
            walls = [time_cs(fmus[name], name, values, seconds, Path(folder)) for _ in range(args.repeats)]
            steps = seconds / STEP
            runs[name] = {"start_values": values, "simulated_s": seconds, "communication_step_s": STEP,
                          "wall_seconds": walls, "steps_per_s_median": steps / statistics.median(walls),
                          "steps_per_s_best": steps / min(walls),
                          "realtime_factor_median": seconds / statistics.median(walls)}
            print(f"{name:12s} CS at 1 ms: {runs[name]['steps_per_s_median']:,.0f} steps/s (median of "
                  f"{args.repeats}), {runs[name]['realtime_factor_median']:.1f}x real time")

    values, seconds = RUNS["SingleWheel"]
    start = time.perf_counter()
    fmpy.simulate_fmu(str(fmus["SingleWheel"]), fmi_type="ModelExchange", stop_time=seconds, output_interval=STEP,
                      start_values=values)
    me_wall = time.perf_counter() - start
    start = time.perf_counter()
    source.simulate(f"{source.PACKAGE}.Examples.SingleWheelStep", params={"W": 575.0, "tauStep": 60.0},
                    stop=seconds, interval=0.01)
    rumoca_wall = time.perf_counter() - start
    context = {"SingleWheel_ME_fmpy_cvode_1ms_output_seconds": me_wall,
               "SingleWheelStep_rumoca_simulate_seconds": rumoca_wall}
    print(f"context: SingleWheel ME (FMPy CVODE, output every 1 ms) {me_wall:.2f} s; "
          f"rumoca simulate SingleWheelStep {rumoca_wall:.2f} s (4 s simulated)")

    record = run_record("make bench", {"repeats": args.repeats, "jobs": args.jobs})
    write_all({args.out: json_bytes({**record, "build": built, "cosimulation": runs, "context": context})})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
