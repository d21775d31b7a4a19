"""Benchmark of FMU isolation (issue 45): what running an FMU in a child process of its own costs,
measured as the user waits for it (the whole ``rover-cosim run`` command, start to exit) and
per communication step, side by side with the same FMU in the tool's process, in one run.

Cases:
- ``trivial``: the integrator test FMU (tests/fmus/integrator.c, x' = u: nothing to compute),
  FMPy-style defaults (1 s at 10 ms: 100 steps, a typical foreign FMU's DefaultExperiment), and
  10,000 steps (the worst case: the cost per step is all messaging);
- ``single_wheel``: our SingleWheel.fmu (a real model) for 2 s at 1 ms.

``--isolation none`` steps the trivial FMU natively (C) in-process; ``process`` sends one message
each way per step. The ratio process/none of the whole command is what decides the default
(issue 45: isolate other tools' FMUs by default when that costs less than ~10 % of the run).
Written to results/bench/isolation.json by ``make bench``; nothing asserts a time.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parents[1] / "tests"))

from rover_cosim.common.outputs import json_bytes, run_record, write_all  # noqa: E402


def _command(fmu: Path, isolation: str, out: Path, extra: list[str]) -> float:
    """Seconds of one whole ``rover-cosim run`` process."""
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "rover_cosim", "run", str(fmu), "-q", "--isolation", isolation,
                    "-o", str(out), "--overwrite", *extra], check=True, capture_output=True)
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("results/bench/isolation.json"))
    parser.add_argument("--fmu-dir", type=Path, default=Path("fmus"))
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    from integrator_fmu import build_integrator

    results: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as work:
        folder = Path(work)
        built = build_integrator(folder)
        cases: dict[str, tuple[Path, list[str], int]] = {}
        if isinstance(built, Path):
            cases["trivial_100_steps"] = (built, ["--stop-time", "1", "--step", "0.01"], 100)
            cases["trivial_10000_steps"] = (built, ["--stop-time", "1", "--step", "1e-4"], 10_000)
        else:
            results["trivial"] = {"skipped": built}
        wheel = args.fmu_dir / "SingleWheel.fmu"
        if wheel.is_file():
            options = ["--stop-time", "2", "--step", "1e-3", "--start", "tau=40"]
            cases["single_wheel_2000_steps"] = (wheel, options, 2000)
        else:
            results["single_wheel"] = {"skipped": f"{wheel} not built (make fmus)"}
        for name, (fmu, extra, steps) in cases.items():
            times: dict[str, list[float]] = {"none": [], "process": []}
            for isolation in times:  # once each first: bytecode caches written, the FMU's pages warm
                _command(fmu, isolation, folder / f"{name}.csv", extra)
            for _ in range(args.repeats):  # interleaved, so that a slower moment of the machine hits both
                for isolation in times:
                    times[isolation].append(_command(fmu, isolation, folder / f"{name}.csv", extra))
            none, process = statistics.median(times["none"]), statistics.median(times["process"])
            results[name] = {"steps": steps, "command_s": {"none": none, "process": process},
                             "all_s": times, "ratio_process_to_none": process / none,
                             "extra_per_step_us": (process - none) / steps * 1e6}
            print(f"{name}: whole command {none:.3f} s in-process, {process:.3f} s isolated "
                  f"({process / none:.2f}x; {(process - none) / steps * 1e6:.1f} us more per step)")
    record = run_record("make bench", {"repeats": args.repeats})
    write_all({args.out: json_bytes({**record, "results": results})})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
