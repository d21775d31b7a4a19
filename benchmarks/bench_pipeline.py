"""Benchmark of the commands a user waits for (issue 34, item 4): the stages of ``make run``
(build-fmus, fig3, identify, simulate, report), ``simulate --only path``, and ``montecarlo`` of the
shipped study on 1 and on 2 workers, each timed as a whole process from start to exit, one after
the other into a scratch results folder (nothing cached from earlier runs: a fresh FMU folder, a
fresh sweep cache, a fresh Monte Carlo cache). Written with the machine, the date and the commit
to results/bench/pipeline.json by ``make bench``, so that later changes are measured against it.

Reported per stage: wall seconds, exit code and the command line; for the Monte Carlo also runs
per minute (its runs counted from its runs.csv), and for the simulated stages the seconds of
simulated time per wall second where the stage's record says how much it simulated. Not a test:
nothing asserts a time.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from rover_cosim.common.outputs import json_bytes, run_record, write_all

FMU_NAMES = ("SingleWheel", "Rover", "RoverBody", "Wheel", "SteerableRover", "SteerableRoverBody")


def stages(folder: Path, runs: int) -> list[tuple[str, list[str]]]:
    """(name, arguments of ``rover-cosim``) of every timed stage, in order: each may use what
    the ones before it wrote in ``folder``."""
    fmus, results = folder / "fmus", folder / "results"
    model = results / "identification" / "model.json"
    return [
        ("build-fmus", ["build-fmus", "--out", str(fmus), "--backend", "builtin", *FMU_NAMES]),
        ("fig3", ["fig3", "--out", str(results)]),
        ("identify", ["identify", "--out", str(results / "identification"), "--fmu", str(fmus / "SingleWheel.fmu")]),
        ("simulate", ["simulate", "--out", str(results / "simulation"), "--fmu-dir", str(fmus), "--model", str(model)]),
        ("simulate --only path", ["simulate", "--only", "path", "--out", str(folder / "path"), "--fmu-dir", str(fmus),
                                  "--model", str(model)]),
        ("report", ["report", "--results", str(results)]),
        ("montecarlo, 1 worker", ["montecarlo", "--runs", str(runs), "--workers", "1", "--out", str(folder / "mc1"),
                                  "--fmu-dir", str(fmus), "--model", str(model)]),
        ("montecarlo, 2 workers", ["montecarlo", "--runs", str(runs), "--workers", "2", "--out", str(folder / "mc2"),
                                   "--fmu-dir", str(fmus), "--model", str(model)]),
    ]


def simulated_seconds(folder: Path, name: str) -> float | None:
    """Seconds of simulated time a stage ran, from its records (``run_wall_seconds``: one entry
    per run): the straight runs' common stop time, each path run's scenario's stop time."""
    total = 0.0
    straight = folder / "results" / "simulation" / "simulation.json"
    if name == "simulate" and straight.is_file():
        record = json.loads(straight.read_text())
        total += record["parameters"]["stop_time_s"] * len(record["run_wall_seconds"])
    path = folder / ("results/simulation" if name == "simulate" else "path") / "path_following.json"
    if name.startswith("simulate") and path.is_file():
        record = json.loads(path.read_text())
        scenarios = record["parameters"]["scenarios"]
        total += sum(scenarios[key.split("/")[0]]["stop_time_s"] for key in record["run_wall_seconds"])
    return total or None


def monte_carlo_runs(folder: Path) -> int | None:
    """Completed runs in a Monte Carlo's runs.csv (its data rows)."""
    path = folder / "runs.csv"
    if not path.is_file():
        return None
    return max(0, len(path.read_text().splitlines()) - 1)


def time_stage(name: str, arguments: list[str], folder: Path, code: Path | None = None) -> dict[str, Any]:
    """One stage as a whole process; ``code``: a checkout whose ``rover_cosim`` to run instead."""
    quiet = [] if arguments[0] in ("fig3", "report") else ["--quiet"]  # commands with progress bars
    argv = [sys.executable, "-P", "-m", "rover_cosim", *arguments, *quiet]
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}  # as installed
    if code is not None:
        env["PYTHONPATH"] = str(code)
    started = time.perf_counter()
    done = subprocess.run(argv, capture_output=True, text=True, check=False, env=env)
    wall = time.perf_counter() - started
    shown = " ".join(["rover-cosim", *argv[4:]]).replace(str(folder.parent), "<scratch>")
    entry: dict[str, Any] = {"command": shown, "wall_seconds": wall, "exit_code": done.returncode}
    if done.returncode != 0:
        entry["stderr"] = done.stderr[-2000:]
    if name.startswith("montecarlo"):
        out = Path(arguments[arguments.index("--out") + 1])
        runs = monte_carlo_runs(out)
        if runs:
            entry["runs"] = runs
            entry["runs_per_minute"] = 60.0 * runs / wall
    simulated = simulated_seconds(folder, name)
    if simulated:
        entry["simulated_seconds"] = simulated
        entry["real_time_factor"] = simulated / wall
    return entry


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/pipeline.json"))
    parser.add_argument("--runs", type=int, default=200, help="Monte Carlo samples (default 200)")
    parser.add_argument("--only", nargs="*", default=None, help="stage names to record (default: all; every stage "
                        "runs, since each may need what the ones before it wrote)")
    parser.add_argument("--baseline", type=Path, default=None, help="a checkout of another commit: every stage also "
                        "runs with its code, right after ours, into a folder of its own (ratios side by side)")
    args = parser.parse_args()
    if args.runs < 2:
        parser.error(f"--runs={args.runs}: expected an integer >= 2")
    results: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="bench-pipeline-") as scratch:
        folder, other = Path(scratch) / "ours", Path(scratch) / "baseline"
        pairs = zip(stages(folder, args.runs), stages(other, args.runs))
        for (name, arguments), (_, baseline_arguments) in pairs:
            entry = time_stage(name, arguments, folder)
            if args.baseline is not None:
                entry["baseline"] = time_stage(name, baseline_arguments, other, args.baseline)
                entry["ratio_to_baseline"] = entry["wall_seconds"] / entry["baseline"]["wall_seconds"]
            timed = args.only is None or name in args.only
            print(f"{name:24s} {entry['wall_seconds']:8.1f} s  exit {entry['exit_code']}"
                  + (f"  {entry['runs_per_minute']:.0f} runs/min" if "runs_per_minute" in entry else "")
                  + (f"  {entry['real_time_factor']:.1f}x real time" if "real_time_factor" in entry else "")
                  + (f"  (baseline {entry['baseline']['wall_seconds']:.1f} s: {entry['ratio_to_baseline']:.2f}x)"
                     if "baseline" in entry else "")
                  + ("" if timed else "  (not recorded)"))
            for run in (entry, entry.get("baseline", {})):
                if run.get("exit_code", 0) != 0:
                    print(run["stderr"], file=sys.stderr)
            if timed:
                results[name] = entry
    baseline = None
    if args.baseline is not None:
        done = subprocess.run(["git", "-C", str(args.baseline), "rev-parse", "HEAD"], capture_output=True, text=True,
                              check=False)
        baseline = {"path": str(args.baseline), "git_commit": done.stdout.strip() or None}
    record = run_record("make bench", {"monte_carlo_runs": args.runs, "cpus": os.cpu_count(), "baseline": baseline})
    write_all({args.out: json_bytes({**record, "results": results,
                                     "note": "each stage a whole rover-cosim process, one after the other, into "
                                             "a fresh scratch folder (no caches from earlier runs)"})})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
