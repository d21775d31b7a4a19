"""Benchmark of the identification sweep: the full plan (8 loads x 9 torques, torque steps on
SingleWheel.fmu) with 1 and with 2 local worker processes, from an empty cache each time, and the
re-run that finds every run in the cache. Written to results/bench/identification.json by
``make bench``. Not a test: nothing here asserts a time.
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.fmubuild import build
from rover_cosim.identification.sweep import SweepPlan, run_sweep


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/identification.json"))
    args = parser.parse_args()
    fmu = build.build_all(("SingleWheel",), Path("fmus"), backend="builtin", jobs=1)[0].path
    plan = SweepPlan()
    results = {}
    for workers in sorted({1, 2, os.cpu_count() or 1}):
        with tempfile.TemporaryDirectory(prefix="bench-sweep-") as cache:
            outcome = run_sweep(fmu, plan, Path(cache), workers=workers)
            rerun = run_sweep(fmu, plan, Path(cache), workers=workers)
        results[f"workers_{workers}"] = {"workers": workers, "runs": outcome.computed, "failed": len(outcome.failures),
                                         "wall_seconds": outcome.wall_seconds,
                                         "mean_run_seconds":
                                             sum(outcome.run_seconds.values()) / len(outcome.run_seconds),
                                         "cached_rerun_wall_seconds": rerun.wall_seconds}
        print(f"{workers} worker(s): {outcome.computed} runs in {outcome.wall_seconds:.2f} s "
              f"(re-run from the cache {rerun.wall_seconds:.2f} s)")
    base = results["workers_1"]["wall_seconds"]
    for entry in results.values():
        entry["speedup_over_1_worker"] = base / entry["wall_seconds"]
    record = run_record("make bench", {"plan": plan.__dict__, "cpus": os.cpu_count()})
    write_all({args.out: json_bytes({**record, "results": results})})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
