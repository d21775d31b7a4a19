"""The FMUs' own elementary functions against the C library's (issue 49, item 1), side by side in
one run: each function's cost per call (throughput: independent arguments; latency: each call
waiting for the previous result), compiled from fmubuild/runtime/elementary.h with the FMUs' flags;
and the paper's closed loop (20 s) on Rover.fmu and on RoverBody + 6 Wheel, built with
``--elementary libm`` and ``--elementary own`` into temporary folders, run alternately, best of
``--repeat``.

    python -P benchmarks/bench_elementary.py --out results/bench/elementary.json \\
        --model results/identification/model.json

Not a test: nothing is asserted. Accuracy is tests/test_elementary.py's.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.fmubuild import build
from rover_cosim.fmubuild.artifact import CFLAGS

ROOT = Path(__file__).resolve().parents[1]
RUNTIME = ROOT / "fmubuild" / "runtime"
HARNESS = ROOT / "tests" / "elementary_harness.c"
FUNCTIONS = ("exp", "log", "pow", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "tanh")
#: Arguments of the kind the wheel's contact passes (angles, positive bases, moderate exponents).
RANGES = {"exp": (-5.0, 5.0), "log": (0.01, 10.0), "pow": (0.01, 1.0), "sin": (-1.5, 1.5), "cos": (-1.5, 1.5),
          "tan": (-1.5, 1.5), "asin": (-1.0, 1.0), "acos": (-1.0, 1.0), "atan": (-3.0, 3.0), "atan2": (-3.0, 3.0),
          "tanh": (-3.0, 3.0)}
CALLS = 1_000_000
LATENCY = r"""
/* each call waits for the previous one: y feeds the next argument, scaled to nothing */
double chain(int which, int ours, long n, const double *x, double *work) {
    double y = 0.0;
    for (long i = 0; i < n; i++) {
        double a = x[i] + y * 1e-300;
        apply(which, ours, 1, &a, &x[(i + 1) % n], work);
        y = work[0];
    }
    return y;
}
"""


def compile_harness(folder: Path) -> ctypes.CDLL:
    source = folder / "harness.c"
    source.write_text(HARNESS.read_text() + LATENCY)
    library = folder / "harness.so"
    compiler = os.environ.get("CC") or shutil.which("cc") or "gcc"
    flags = [f for f in CFLAGS if not f.startswith("-fvisibility")]  # the harness exports apply and chain
    subprocess.run([compiler, *flags, "-I", str(RUNTIME), str(source), "-o", str(library), "-lm"], check=True)
    lib = ctypes.CDLL(str(library))
    lib.chain.restype = ctypes.c_double
    return lib


def per_call(lib: ctypes.CDLL, repeat: int) -> dict[str, Any]:
    rng = np.random.default_rng(0)
    pointer = ctypes.POINTER(ctypes.c_double)
    out, work = np.empty(CALLS), np.empty(1)
    y = rng.uniform(0.5, 1.5, CALLS)
    rows: dict[str, Any] = {}
    for which, name in enumerate(FUNCTIONS):
        x = rng.uniform(*RANGES[name], CALLS)
        best = {("throughput", 0): np.inf, ("throughput", 1): np.inf, ("latency", 0): np.inf, ("latency", 1): np.inf}
        for _ in range(repeat):
            for ours in (0, 1):
                start = time.perf_counter()
                lib.apply(which, ours, CALLS, x.ctypes.data_as(pointer), y.ctypes.data_as(pointer),
                          out.ctypes.data_as(pointer))
                best["throughput", ours] = min(best["throughput", ours], time.perf_counter() - start)
                start = time.perf_counter()
                lib.chain(which, ours, CALLS // 4, x.ctypes.data_as(pointer), work.ctypes.data_as(pointer))
                best["latency", ours] = min(best["latency", ours], (time.perf_counter() - start) * 4)
        rows[name] = {f"{kind}_{'own' if ours else 'libm'}_ns": seconds / CALLS * 1e9
                      for (kind, ours), seconds in best.items()}
        rows[name]["throughput_ratio_own_over_libm"] = best["throughput", 1] / best["throughput", 0]
        print(f"{name:6s} throughput libm {rows[name]['throughput_libm_ns']:5.1f} ns own "
              f"{rows[name]['throughput_own_ns']:5.1f} ns; latency libm {rows[name]['latency_libm_ns']:5.1f} ns own "
              f"{rows[name]['latency_own_ns']:5.1f} ns", flush=True)
    return rows


def closed_loops(model: Path, folder: Path, repeat: int) -> dict[str, Any]:
    from rover_cosim.jobs.simulate import cosim_system, monolithic_system
    from rover_cosim.orchestrator.master import run

    fmus = {}
    for choice in ("libm", "own"):
        fmus[choice] = folder / choice
        build.build_all(["Rover", "RoverBody", "Wheel"], fmus[choice], backend="builtin", elementary=choice)
    rows: dict[str, Any] = {}
    for kind, system_of in (("Rover.fmu", monolithic_system), ("RoverBody + 6 Wheel", cosim_system)):
        best = {"libm": np.inf, "own": np.inf}
        for _ in range(repeat):
            for choice in best:
                system = system_of(fmus[choice], model)
                start = time.perf_counter()
                run(system)
                best[choice] = min(best[choice], time.perf_counter() - start)
        rows[kind] = {"libm_s": best["libm"], "own_s": best["own"], "own_over_libm": best["own"] / best["libm"]}
        print(f"{kind}: libm {best['libm']:.3f} s, own {best['own']:.3f} s ({best['own'] / best['libm']:.2f}x)",
              flush=True)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--model", type=Path, required=True, help="identified model (rover-cosim identify)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench-elementary-") as tmp:
        per_function = per_call(compile_harness(Path(tmp)), args.repeat)
        loops = closed_loops(args.model, Path(tmp), args.repeat)
    record = run_record("benchmarks/bench_elementary.py", {"calls": CALLS, "ranges": RANGES, "repeat": args.repeat,
                                                           "cflags": list(CFLAGS), "model": str(args.model)})
    record["per_call"] = per_function
    record["closed_loop_20s"] = loops
    write_all({args.out: json_bytes(record)})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
