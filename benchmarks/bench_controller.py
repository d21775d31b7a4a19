"""Benchmark of the paper's controller block (issue 18, part 4): the per-step inverse of the
identified longitudinal model on six wheels, by whole-array numpy operations (the first
implementation, ``LongitudinalInverse.reference_torques``) and by plain floats per wheel
(``torques``, what the block uses), side by side in one run on the same inputs; and the whole
block's step. Needs an identified model: ``--model`` (default results/identification/model.json;
identified on the fly into a temporary folder when missing). Written to
results/bench/controller.json by ``make bench``. Not a test: nothing asserts a time; the aim (4x)
is recorded beside the measured ratio, and the largest difference of the two paths' torques.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.control.controller import InverseModelController
from rover_cosim.control.longitudinal import LongitudinalInverse
from rover_cosim.fmubuild import build

STEPS = 5000
AIM = 4.0


def model_file(given: Path) -> Path:
    if given.is_file():
        return given
    from rover_cosim.jobs.identify import run_identification

    fmu = build.build_all(["SingleWheel"], Path("fmus"))[0].path
    folder = Path(tempfile.mkdtemp(prefix="bench-controller-"))
    run_identification(fmu, folder, workers=2)
    return folder / "model.json"


def time_path(inverse: LongitudinalInverse, method: str, loads: np.ndarray,
              forces: np.ndarray) -> tuple[float, np.ndarray]:
    """Median over 5 repeats of the time per step [s], and the torques of the last repeat."""
    walls, torques = [], np.empty(loads.shape)
    for _ in range(5):
        inverse.filter_state[:] = 0.0
        call = getattr(inverse, method)
        started = time.perf_counter()
        for k in range(STEPS):
            torques[k] = call(loads[k], forces[k], True)
        walls.append((time.perf_counter() - started) / STEPS)
    return statistics.median(walls), torques


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", type=Path, default=Path("results/bench/controller.json"))
    parser.add_argument("--model", type=Path, default=Path("results/identification/model.json"))
    args = parser.parse_args()
    path = model_file(args.model)
    block = InverseModelController("ctrl", str(path))
    rng = np.random.default_rng(1)
    loads = 424.0 + 60.0 * rng.standard_normal((STEPS, 6))
    forces = 26.0 * np.sin(np.linspace(0, 20, STEPS))[:, None] * np.ones(6)
    numpy_seconds, numpy_torques = time_path(block.inverse, "reference_torques", loads, forces)
    float_seconds, float_torques = time_path(block.inverse, "torques", loads, forces)
    u = np.concatenate([[1.0, 0.5], loads[0]])
    block.start(0.0, u)
    started = time.perf_counter()
    for k in range(STEPS):
        u[2:] = loads[k]
        block.step(k * 1e-3, 1e-3, u)
    block_seconds = (time.perf_counter() - started) / STEPS
    result = run_record("benchmarks/bench_controller.py", {"steps": STEPS, "model": str(path)})
    result.update({"numpy_us_per_step": numpy_seconds * 1e6, "plain_float_us_per_step": float_seconds * 1e6,
                   "speedup": numpy_seconds / float_seconds, "aim": AIM,
                   "largest_torque_difference_N_m": float(np.abs(numpy_torques - float_torques).max()),
                   "block_step_us": block_seconds * 1e6})
    write_all({args.out: json_bytes(result)})
    print(f"numpy {numpy_seconds * 1e6:.1f} us/step, plain floats {float_seconds * 1e6:.1f} us/step "
          f"({numpy_seconds / float_seconds:.1f}x; aim {AIM}x), block step {block_seconds * 1e6:.1f} us, "
          f"largest difference {result['largest_torque_difference_N_m']:.2e} N·m")


if __name__ == "__main__":
    main()
