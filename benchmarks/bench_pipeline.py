"""Benchmark of the commands a user waits for (issue 34, item 4): the stages of ``make run``
(build-fmus: the six FMUs of issue 49's goal, then the catalog's others; fig3, identify, simulate,
report), ``simulate --only path``, and ``montecarlo`` of the
shipped study on 1 and on 2 workers, each timed as a whole process from start to exit, one after
the other into a scratch results folder (nothing cached from earlier runs: a fresh FMU folder, a
fresh sweep cache, a fresh Monte Carlo cache). Written with the machine, the date and the commit
to results/bench/pipeline.json by ``make bench``, so that later changes are measured against it.

Reported per stage: wall seconds, exit code and the command line; for the Monte Carlo also runs
per minute (its runs counted from its runs.csv), and for the simulated stages the seconds of
simulated time per wall second where the stage's record says how much it simulated. Not a test:
nothing asserts a time.

``--baseline-rev REV`` (``make bench``: the previous commit) checks REV out into the scratch folder
(a git worktree, removed at the end) and runs every stage with its code right after ours, into a
folder of its own: each stage's ratio to it, measured side by side in one run. ``goals`` in the
output: issue 49's goals, each with what this run measured, the baseline's, the goal and whether
it is met (the benchmarks page shows them as a table).
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
from rover_cosim.fmubuild.build import FMU_MODELS

#: The six FMUs of issue 49's build goal; the others of the catalog (the leg-wheel rover's, which
#: ``simulate`` runs too) are built by a stage of their own, so that the goal stays comparable.
FMU_NAMES = ("SingleWheel", "Rover", "RoverBody", "Wheel", "SteerableRover", "SteerableRoverBody")
OTHER_FMUS = tuple(name for name in FMU_MODELS if name not in FMU_NAMES)


def stages(folder: Path, runs: int) -> list[tuple[str, list[str]]]:
    """(name, arguments of ``rover-cosim``) of every timed stage, in order: each may use what
    the ones before it wrote in ``folder``."""
    fmus, results = folder / "fmus", folder / "results"
    model = results / "identification" / "model.json"
    return [
        ("build-fmus", ["build-fmus", "--out", str(fmus), "--backend", "builtin", *FMU_NAMES]),
        ("build-fmus, the others", ["build-fmus", "--out", str(fmus), "--backend", "builtin", *OTHER_FMUS]),
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
        ("montecarlo --adapt, 2 workers", ["montecarlo", "--adapt", "--runs", str(max(2, runs // 4)), "--workers", "2",
                                           "--out", str(folder / "mca"), "--fmu-dir", str(fmus),
                                           "--model", str(model)]),
    ]


#: Issue 49's goals: (name, stage, quantity in the stage's entry, the goal, True: at least it).
GOALS = (
    ("closed loop, 20 s on Rover.fmu: real-time factor", "simulate", "closed_loop_real_time_factor", 50.0, True),
    ("Monte Carlo, 2 workers: runs per minute", "montecarlo, 2 workers", "runs_per_minute", 300.0, True),
    ("Monte Carlo --adapt, 2 workers: runs per minute", "montecarlo --adapt, 2 workers", "runs_per_minute", 120.0,
     True),
    ("simulate --only path, whole command: real-time factor", "simulate --only path", "real_time_factor", 20.0, True),
    ("six FMUs built (host only): seconds", "build-fmus", "wall_seconds", 20.0, False),
)


def goals(results: dict[str, Any]) -> list[dict[str, Any]]:
    """Each goal of ``GOALS`` with what the stages measured (and their baselines'), the goal and
    whether it is met; a stage not run or without the quantity: None."""
    rows = []
    for name, stage, quantity, goal, at_least in GOALS:
        entry = results.get(stage, {})
        value = entry.get(quantity)
        baseline = entry.get("baseline", {}).get(quantity)
        met = None if value is None else (value >= goal if at_least else value <= goal)
        rows.append({"goal": name, "measured": value, "baseline": baseline,
                     "target": f"{'>=' if at_least else '<='} {goal:g}", "met": met})
    return rows


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
    straight = folder / "results" / "simulation" / "simulation.json"
    if name == "simulate" and straight.is_file():  # the closed loop on Rover.fmu inside the command
        record = json.loads(straight.read_text())
        inside = record["run_wall_seconds"].get("monolithic")
        if inside:
            entry["closed_loop_real_time_factor"] = record["parameters"]["stop_time_s"] / inside
    return entry


def checkout(revision: str, folder: Path) -> Path:
    """``revision`` of this repository checked out into ``folder`` (a detached git worktree)."""
    root = Path(__file__).resolve().parent.parent
    done = subprocess.run(["git", "-C", str(root), "worktree", "add", "--detach", "--quiet", str(folder), revision],
                          capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"--baseline-rev {revision}: git worktree add failed: {done.stderr.strip()}")
    return folder


def remove_checkout(folder: Path) -> None:
    root = Path(__file__).resolve().parent.parent
    subprocess.run(["git", "-C", str(root), "worktree", "remove", "--force", str(folder)], capture_output=True,
                   check=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/pipeline.json"))
    parser.add_argument("--runs", type=int, default=200, help="Monte Carlo samples (default 200)")
    parser.add_argument("--only", nargs="*", default=None, help="stage names to record (default: all; every stage "
                        "runs, since each may need what the ones before it wrote)")
    parser.add_argument("--baseline", type=Path, default=None, help="a checkout of another commit: every stage also "
                        "runs with its code, right after ours, into a folder of its own (ratios side by side)")
    parser.add_argument("--baseline-rev", default=None, metavar="REV",
                        help="as --baseline, the commit REV checked out for the run (e.g. HEAD~1)")
    args = parser.parse_args()
    if args.runs < 2:
        parser.error(f"--runs={args.runs}: expected an integer >= 2")
    if args.baseline is not None and args.baseline_rev is not None:
        parser.error("--baseline and --baseline-rev: expected one of them")
    results: dict[str, Any] = {}
    baseline = None
    with tempfile.TemporaryDirectory(prefix="bench-pipeline-") as scratch:
        if args.baseline_rev is not None:
            args.baseline = checkout(args.baseline_rev, Path(scratch) / "code")
        if args.baseline is not None:
            done = subprocess.run(["git", "-C", str(args.baseline), "rev-parse", "HEAD"], capture_output=True,
                                  text=True, check=False)
            baseline = {"path": str(args.baseline), "revision": args.baseline_rev,
                        "git_commit": done.stdout.strip() or None}
        try:
            run_stages(args, Path(scratch), results)
        finally:
            if args.baseline_rev is not None:
                remove_checkout(Path(scratch) / "code")
    record = run_record("make bench", {"monte_carlo_runs": args.runs, "cpus": os.cpu_count(), "baseline": baseline})
    table = goals(results)
    for row in table:
        shown = "-" if row["measured"] is None else f"{row['measured']:.3g}"
        print(f"goal: {row['goal']}: {shown} (baseline {row['baseline']}), goal {row['target']}: "
              f"{'met' if row['met'] else 'not met' if row['met'] is not None else 'not measured'}")
    write_all({args.out: json_bytes({**record, "results": results, "goals": table,
                                     "note": "each stage a whole rover-cosim process, one after the other, into "
                                             "a fresh scratch folder (no caches from earlier runs)"})})
    print(f"wrote {args.out}")


def run_stages(args: argparse.Namespace, scratch: Path, results: dict[str, Any]) -> None:
    """Every stage, ours then (with ``args.baseline``) the baseline's, into ``results``."""
    folder, other = scratch / "ours", scratch / "baseline"
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


if __name__ == "__main__":
    main()
