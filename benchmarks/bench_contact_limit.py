"""How far the wheel contact is from its arithmetic limit (issue 49, item 1): one wheel's force
evaluation (Fx, Fz, Tx at a sinkage and slip, 10 Gauss-Legendre nodes a piece as in the FMUs)
written node by node with the C library's sin, cos and exp (the shape of the FMUs' generated code)
and stage by stage over all nodes with polynomial sine, cosine, exp and log that the compiler
vectorises (fmubuild/runtime/contact.h, what the FMUs call since issue 49; benchmarks/contact_limit.c),
compiled with the FMUs' flags for the x86-64 baseline (SSE2, what the FMUs are built for) and for
AVX2 with FMA; timed side by side in one run over the sinkages and slips of every shipped
soil at 0.25-2x the paper's wheel load, slips -0.5...0.9.

Accuracy, stated with the times: the vector code's largest difference from the scalar code, and
the scalar code's from the numpy reference (``terramechanics.contact_forces`` with the same nodes,
driving, where both integrate the same two pieces), each as a fraction of Fz.

    python -P benchmarks/bench_contact_limit.py --out results/bench/contact_limit.json

Not a test: nothing is asserted. What the FMUs pay per contact evaluation is measured separately
(callgrind of the closed loop, in the design page).
"""

from __future__ import annotations

import argparse
import ctypes
import statistics
import subprocess
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.fmubuild.artifact import CFLAGS
from rover_cosim.fmubuild.platforms import host_compiler
from rover_cosim.terramechanics import Soil, Wheel, contact_forces, wheel_state
from rover_cosim.terramechanics.library import build, entry, names

KERNEL = Path(__file__).resolve().parent / "contact_limit.c"
RUNTIME = Path(__file__).resolve().parents[1] / "fmubuild" / "runtime"  # contact.h
NODES = 10  # the FMUs' Gauss-Legendre nodes per piece
#: The FMUs' flags (contact.h raises its own region to -O3 without trapping math, for gcc).
BASE_FLAGS = tuple(CFLAGS)
VARIANTS = {"x86-64 (SSE2)": (), "AVX2 + FMA": ("-mavx2", "-mfma")}
PAPER_LOAD = 423.9  # N, the paper's wheel load (Table 2 rover)
LOAD_FACTORS = (0.25, 0.5, 1.0, 1.5, 2.0)
SLIPS = (-0.5, -0.2, -0.05, 0.0, 0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9)


def parameters(soil: Soil, wheel: Wheel) -> np.ndarray:
    """contact_limit.c's p[]: r, b, kc, kphi, n, c, phi, kx, a0, a1, lambda."""
    return np.array([wheel.r, wheel.b, soil.kc, soil.kphi, soil.n, soil.c, soil.phi, soil.kx, soil.a0, soil.a1,
                     soil.lam])


def cases(soil: Soil, wheel: Wheel) -> tuple[np.ndarray, np.ndarray]:
    """Sinkages [m] and slips of the wheel carrying 0.25-2x the paper's load (numpy reference)."""
    loads, slips = np.meshgrid(PAPER_LOAD * np.array(LOAD_FACTORS), SLIPS)
    state = wheel_state(loads.ravel(), slips.ravel(), wheel, soil, nodes=NODES)
    h = np.asarray(state.sinkage, dtype=float)
    keep = h < wheel.r  # a soil that cannot carry the load at h < r: not a case
    return h[keep], slips.ravel()[keep]


def compile_kernel(folder: Path, name: str, flags: tuple[str, ...]) -> ctypes.CDLL:
    library = folder / f"contact_limit_{abs(hash(name))}.so"
    command = [host_compiler(), *BASE_FLAGS, "-fvisibility=default", *flags, "-I", str(RUNTIME), str(KERNEL)]
    subprocess.run([*command, "-o", str(library), "-lm"], check=True)
    kernel = ctypes.CDLL(str(library))
    pointer = ctypes.POINTER(ctypes.c_double)
    for function in (kernel.contact_scalar, kernel.contact_vector):
        function.argtypes = [pointer, ctypes.c_double, ctypes.c_double, pointer, pointer, ctypes.c_int, pointer]
        function.restype = None
    kernel.time_contact.argtypes = [ctypes.c_int, pointer, pointer, pointer, ctypes.c_int, pointer, pointer,
                                    ctypes.c_int, ctypes.c_int, pointer]
    kernel.time_contact.restype = ctypes.c_double
    return kernel


def _ptr(array: np.ndarray) -> Any:
    return array.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


def forces(kernel: ctypes.CDLL, vector: bool, p: np.ndarray, h: np.ndarray, slip: np.ndarray,
           u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """(cases, 3): Fx, Fz, Tx [N, N, N m] of one of the kernel's two codes."""
    function = kernel.contact_vector if vector else kernel.contact_scalar
    out = np.zeros((len(h), 3))
    row = np.zeros(3)
    for i in range(len(h)):
        function(_ptr(p), float(h[i]), float(slip[i]), _ptr(u), _ptr(w), NODES, _ptr(row))
        out[i] = row
    return out


def seconds_per_evaluation(kernel: ctypes.CDLL, vector: bool, p: np.ndarray, h: np.ndarray, slip: np.ndarray,
                           u: np.ndarray, w: np.ndarray, repeat: int) -> float:
    check = ctypes.c_double()
    return float(kernel.time_contact(int(vector), _ptr(p), _ptr(h), _ptr(slip), len(h), _ptr(u), _ptr(w), NODES,
                                     repeat, ctypes.byref(check)))


def gauss_legendre_unit() -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights on [0, 1]."""
    x, w = np.polynomial.legendre.leggauss(NODES)
    return np.ascontiguousarray((x + 1) / 2), np.ascontiguousarray(w / 2)


Case = tuple[np.ndarray, np.ndarray, np.ndarray]  # p[], sinkages [m], slips


def shipped_cases(wheel: Wheel) -> dict[str, Case]:
    """Every shipped soil that carries the loads at some sinkage below r: its p[], sinkages, slips."""
    found = {}
    for name in names("soil"):
        soil = build("soil", name, entry("soil", name)[1])
        assert isinstance(soil, Soil)
        h, slip = cases(soil, wheel)
        if len(h):
            found[name] = (parameters(soil, wheel), h, slip)
    return found


def largest_differences(kernels: dict[str, ctypes.CDLL], usable: dict[str, Case], wheel: Wheel,
                        u: np.ndarray, w: np.ndarray) -> dict[str, float]:
    """Vectorised against node by node (every case), node by node against the numpy reference
    (driving, h <= r/2), each as a fraction of the largest Fz of the soil."""
    errors = {"vector_vs_scalar": 0.0, "scalar_vs_numpy_driving": 0.0}
    for name, (p, h, slip) in usable.items():
        soil = build("soil", name, entry("soil", name)[1])
        assert isinstance(soil, Soil)
        reference = contact_forces(h, slip, wheel, soil, NODES)
        theirs = np.stack([reference.Fx, reference.Fz, reference.Tx], axis=1)
        driving = (slip >= 0) & (h <= wheel.r / 2)
        for kernel in kernels.values():
            scalar = forces(kernel, False, p, h, slip, u, w)
            scale = np.abs(scalar[:, 1]).max()
            vector = forces(kernel, True, p, h, slip, u, w)
            errors["vector_vs_scalar"] = max(errors["vector_vs_scalar"], float(np.abs(vector - scalar).max() / scale))
            if driving.any():
                errors["scalar_vs_numpy_driving"] = max(
                    errors["scalar_vs_numpy_driving"], float(np.abs(scalar[driving] - theirs[driving]).max() / scale))
    return errors


def timed(kernels: dict[str, ctypes.CDLL], usable: dict[str, Case], u: np.ndarray, w: np.ndarray, rounds: int,
          repeat: int) -> dict[str, Any]:
    """Per variant: ns per evaluation of each code, per soil (medians over interleaved rounds) and
    their mean over the soils."""
    timings: dict[tuple[str, str, str], list[float]] = {}
    for _ in range(rounds):  # interleaved: scalar and vector of each variant, soil by soil
        for name, kernel in kernels.items():
            for code in ("scalar", "vector"):
                for soil_name, (p, h, slip) in usable.items():
                    timings.setdefault((name, code, soil_name), []).append(
                        seconds_per_evaluation(kernel, code == "vector", p, h, slip, u, w, repeat))
    variants = {}
    for name in kernels:
        row: dict[str, Any] = {"flags": [*BASE_FLAGS, *VARIANTS[name]]}
        for code in ("scalar", "vector"):
            per_soil = {soil: 1e9 * statistics.median(timings[(name, code, soil)]) for soil in usable}
            row[f"{code}_ns_per_soil"] = per_soil
            row[f"{code}_ns"] = statistics.mean(per_soil.values())
        row["scalar_over_vector"] = row["scalar_ns"] / row["vector_ns"]
        row["scalar_over_vector_paper_soil"] = row["scalar_ns_per_soil"]["paper"] / row["vector_ns_per_soil"]["paper"]
        variants[name] = row
    return variants


def measure(rounds: int, repeat: int) -> dict[str, Any]:
    u, w = gauss_legendre_unit()
    wheel = Wheel()
    usable = shipped_cases(wheel)
    with tempfile.TemporaryDirectory(prefix="bench-contact-limit-") as tmp:
        kernels = {name: compile_kernel(Path(tmp), name, flags) for name, flags in VARIANTS.items()}
        return {"soils": sorted(usable), "cases": {name: len(case[1]) for name, case in usable.items()},
                "largest_difference_over_Fz": largest_differences(kernels, usable, wheel, u, w),
                "variants": timed(kernels, usable, u, w, rounds, repeat)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/bench/contact_limit.json"))
    parser.add_argument("--rounds", type=int, default=5, help="interleaved rounds; medians reported")
    parser.add_argument("--repeat", type=int, default=200, help="evaluations of each case per round")
    args = parser.parse_args()
    measured = measure(args.rounds, args.repeat)
    record = run_record("benchmarks/bench_contact_limit.py", {"nodes": NODES, "load_factors": LOAD_FACTORS,
                                                              "paper_load_N": PAPER_LOAD, "slips": SLIPS,
                                                              "rounds": args.rounds, "repeat": args.repeat})
    record["results"] = measured
    write_all({args.out: json_bytes(record)})
    for name, row in measured["variants"].items():
        paper = (row["scalar_ns_per_soil"]["paper"], row["vector_ns_per_soil"]["paper"])
        print(f"{name:14s} node by node, libm {row['scalar_ns']:6.1f} ns   vectorised {row['vector_ns']:6.1f} ns   "
              f"({row['scalar_over_vector']:.2f}x; the paper's soil {paper[0]:.1f} and {paper[1]:.1f} ns, "
              f"{paper[0] / paper[1]:.2f}x)")
    errors = measured["largest_difference_over_Fz"]
    print(f"largest difference / Fz: vectorised vs libm {errors['vector_vs_scalar']:.1e}, "
          f"libm vs numpy reference (driving) {errors['scalar_vs_numpy_driving']:.1e}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
