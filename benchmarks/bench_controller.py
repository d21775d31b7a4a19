"""Benchmark of the paper's controller block: the per-step cost of its one law on six wheels in
Python (``LongitudinalInverse.torques``, and the whole block's step: what runs where no C
compiler works) and of its C twin (``inverse_controller.c``, called through ctypes here; the
native stepper calls it from C), side by side in one run on the same inputs, with the largest
difference of their outputs (0: the same arithmetic). Needs an identified model: ``--model``
(default results/identification/model.json; identified on the fly into a temporary folder when
missing). Written to results/bench/controller.json by ``make bench``. Not a test: nothing asserts
a time.
"""

from __future__ import annotations

import argparse
import ctypes
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


def model_file(given: Path) -> Path:
    if given.is_file():
        return given
    from rover_cosim.jobs.identify import run_identification

    fmu = build.build_all(["SingleWheel"], Path("fmus"))[0].path
    folder = Path(tempfile.mkdtemp(prefix="bench-controller-"))
    run_identification(fmu, folder, workers=2)
    return folder / "model.json"


def time_law(inverse: LongitudinalInverse, loads: np.ndarray, forces: np.ndarray) -> float:
    """Median over 5 repeats of the law's time per step [s]."""
    walls = []
    for _ in range(5):
        inverse.filter_state[:] = 0.0
        started = time.perf_counter()
        for k in range(STEPS):
            inverse.torques(loads[k], forces[k], True)
        walls.append((time.perf_counter() - started) / STEPS)
    return statistics.median(walls)


def time_block(block: InverseModelController, inputs: np.ndarray) -> tuple[float, np.ndarray]:
    """The Python block's time per step [s] (median of 5) and its outputs of the last repeat."""
    walls, outputs = [], np.empty((STEPS, len(block.outputs)))
    for _ in range(5):
        block.start(0.0, inputs[0])
        started = time.perf_counter()
        for k in range(STEPS):
            outputs[k] = block.step(k * 1e-3, 1e-3, inputs[k])
        walls.append((time.perf_counter() - started) / STEPS)
    return statistics.median(walls), outputs


def time_twin(block: InverseModelController, inputs: np.ndarray) -> tuple[float, np.ndarray] | None:
    """The C twin's time per step [s] through ctypes (set inputs, step, get outputs; median of 5)
    and its outputs, or None without a compiler."""
    walls, outputs = [], np.empty((STEPS, len(block.outputs)))
    for _ in range(5):
        block.start(0.0, inputs[0])
        twin = block.native()
        if twin is None:
            return None
        calls = twin.calls(len(block.inputs), len(block.outputs))
        library = twin.library
        set_real, get_real = library.controller_set_real, library.controller_get_real
        do_step = library.controller_do_step
        for function in (set_real, get_real):
            function.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p]
        do_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
        inputs_vr = np.array(calls.input_references, dtype=np.uint32)
        outputs_vr = np.array(calls.output_references, dtype=np.uint32)
        row = np.empty(len(block.outputs))
        started = time.perf_counter()
        for k in range(STEPS):
            u = np.ascontiguousarray(inputs[k])
            set_real(twin.component, inputs_vr.ctypes.data, len(inputs_vr), u.ctypes.data)
            do_step(twin.component, k * 1e-3, 1e-3, 1)
            get_real(twin.component, outputs_vr.ctypes.data, len(outputs_vr), row.ctypes.data)
            outputs[k] = row
        walls.append((time.perf_counter() - started) / STEPS)
        twin.close()
    return statistics.median(walls), outputs


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
    inputs = np.column_stack([1e-3 * np.arange(STEPS), np.full(STEPS, 0.5), loads])
    law_seconds = time_law(block.inverse, loads, forces)
    block_seconds, python_outputs = time_block(block, inputs)
    twin = time_twin(block, inputs)
    result = run_record("benchmarks/bench_controller.py", {"steps": STEPS, "model": str(path)})
    result.update({"python_law_us_per_step": law_seconds * 1e6, "python_block_us_per_step": block_seconds * 1e6,
                   "c_twin_us_per_step_through_ctypes": twin[0] * 1e6 if twin else None,
                   "largest_output_difference": float(np.abs(twin[1] - python_outputs).max()) if twin else None})
    write_all({args.out: json_bytes(result)})
    twin_text = (f"C twin {twin[0] * 1e6:.1f} us/step through ctypes, largest difference "
                 f"{result['largest_output_difference']:.2e}") if twin else "no C compiler: no C twin"
    print(f"Python law {law_seconds * 1e6:.1f} us/step, Python block {block_seconds * 1e6:.1f} us/step; {twin_text}")


if __name__ == "__main__":
    main()
