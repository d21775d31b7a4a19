"""Benchmark of the numpy reference wheel: wheel states solved per second on one core.

Each case solves a batch of 100 000 (load, slip) pairs with ``terramechanics.wheel_state`` and
reports the best and median of a few repeats, with the accuracy reached (max |Fz/W - 1|).
Written to results/bench/reference.json by ``make bench``. Not a test: nothing here asserts a
time; the floor from issue 2 (100 000 states/s) is recorded beside the measured figure.
"""

from __future__ import annotations

import os

for _variable in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_variable] = "1"

import argparse
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.terramechanics import DEFAULT_NODES, contact_forces, wheel_state

FLOOR_STATES_PER_S = 100_000
BATCH = 100_000
CASES = {
    # the paper's operating range: Fig. 3 slips, identification and validation loads
    "paper_range": {"load_N": (100.0, 900.0), "slip": (0.0, 0.9)},
    # the whole range wheel_state promises to solve, braking included
    "full_range": {"load_N": (1.0, 5000.0), "slip": (-1.0, 1.0)},
}


def pin_to_one_core() -> int | None:
    """Run on a single CPU where the OS allows it; returns that CPU's number."""
    try:
        cpu = min(os.sched_getaffinity(0))
        os.sched_setaffinity(0, {cpu})
        return cpu
    except (AttributeError, OSError):
        return None


def batch(case: dict[str, tuple[float, float]], seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    (w_low, w_high), (s_low, s_high) = case["load_N"], case["slip"]
    return rng.uniform(w_low, w_high, BATCH), rng.uniform(s_low, s_high, BATCH)


def time_case(case: dict, repeats: int) -> dict:
    seconds, errors = [], []
    for repeat in range(repeats):
        loads, slips = batch(case, seed=repeat)
        start = time.perf_counter()
        state = wheel_state(loads, slips)
        seconds.append(time.perf_counter() - start)
        errors.append(float(np.max(np.abs(state.Fz / loads - 1.0))))
    sinkages = state.sinkage
    start = time.perf_counter()
    contact_forces(sinkages, slips)
    force_seconds = time.perf_counter() - start
    return {
        **case,
        "batch": BATCH,
        "repeats": repeats,
        "seconds": seconds,
        "states_per_s_best": BATCH / min(seconds),
        "states_per_s_median": BATCH / statistics.median(seconds),
        "max_relative_Fz_error": max(errors),
        "contact_force_evaluations_per_s": BATCH / force_seconds,
        "floor_states_per_s": FLOOR_STATES_PER_S,
        "floor_met_by_median": BATCH / statistics.median(seconds) >= FLOOR_STATES_PER_S,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/reference.json"))
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    if args.repeats < 1:
        parser.error(f"--repeats={args.repeats}: expected an integer >= 1")

    cpu = pin_to_one_core()
    wheel_state(np.linspace(100, 800, 3000), 0.3)  # warm-up: imports, caches, page faults
    results = {}
    for name, case in CASES.items():
        results[name] = time_case(case, args.repeats)
        print(f"{name:12s} {results[name]['states_per_s_median']:>10,.0f} states/s (median of {args.repeats}), "
              f"best {results[name]['states_per_s_best']:,.0f}; max |Fz/W-1| = "
              f"{results[name]['max_relative_Fz_error']:.1e}")
    record = run_record("make bench", {"nodes": DEFAULT_NODES, "pinned_cpu": cpu,
                                       "processor": platform.processor()})
    write_all({args.out: json_bytes({**record, "results": results})})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
