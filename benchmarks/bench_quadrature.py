"""The contact's quadrature chosen by measured error (issue 49, item 1): how far the wheel in
equilibrium (terramechanics.wheel_state: the same Gauss-Legendre rule in s = u² on each side of θm
as the FMUs' contactForces) is from a 96-node reference, for each node count per piece, over every
soil and wheel of the library (the MSL wheel with its grousers), loads of 0.25-2x the wheel's
static load, slips -0.8 ... 0.9 and slip angles 0-0.5 rad; and what each count costs in the
numpy reference (one batch of every case).

Errors: the largest over all cases of |F_N - F_ref| divided by the load (Fx, Fy), by the load times
the radius (Tx), by the reference sinkage (sinkage). The paper's printed digits set the need:
Table 1 to 0.1 %, Table 3 to 1 mN against errors of 0.2 N; the FMUs' trajectories are written
with 8 significant digits.

    python -P benchmarks/bench_quadrature.py --out results/bench/quadrature.json \\
        --markdown results/bench/quadrature.md

Not a test: nothing is asserted.
"""

from __future__ import annotations

import argparse
import itertools
import time
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.terramechanics import wheel_state
from rover_cosim.terramechanics.library import choose, names

REFERENCE_NODES = 96
COUNTS = (4, 6, 8, 10, 12, 16, 24)
SLIPS = np.concatenate([np.linspace(-0.8, -0.01, 12), [0.0], np.geomspace(0.002, 0.9, 20)])
SLIP_ANGLES = (0.0, 0.1, 0.3, 0.5)  # rad
LOAD_FACTORS = (0.25, 0.5, 1.0, 2.0)  # of the static load of a paper-sized rover on the wheel
CHANNELS = ("Fx", "Tx", "sinkage", "Fy")
RTOL = 1e-12


def _static_load(wheel: Any, soil: Any) -> float:
    """N: the paper's 424 N scaled by the wheel's footprint r·b and the soil's gravity."""
    return 424.0 * wheel.r * wheel.b / (0.355 * 0.175) * soil.gravity / 9.81


def _errors(state: Any, reference: Any, radius: float) -> dict[str, float]:
    scale = {"Fx": np.abs(reference.Fz), "Tx": np.abs(reference.Fz) * radius, "sinkage": np.abs(reference.sinkage),
             "Fy": np.abs(reference.Fz)}
    return {k: float(np.max(np.abs(getattr(state, k) - getattr(reference, k)) / scale[k])) for k in CHANNELS}


def measure() -> dict[str, Any]:
    worst = {n: dict.fromkeys(CHANNELS, 0.0) for n in COUNTS}
    where: dict[int, dict[str, str]] = {n: {} for n in COUNTS}
    seconds = dict.fromkeys(COUNTS, 0.0)
    cases, skipped = 0, []
    for soil_name, wheel_name in itertools.product(names("soil"), names("wheel")):
        choice = choose(soil=soil_name, wheel=wheel_name)
        soil, wheel = choice.soil, choice.wheel
        for factor in LOAD_FACTORS:
            load, slip, beta = (a.ravel() for a in np.meshgrid([factor * _static_load(wheel, soil)], SLIPS,
                                                               SLIP_ANGLES, indexing="ij"))
            try:
                reference = wheel_state(load, slip, wheel, soil, nodes=REFERENCE_NODES, rtol=RTOL, slip_angle=beta)
            except (ValueError, RuntimeError) as error:  # a load the wheel cannot carry on that soil
                skipped.append(f"{soil_name}/{wheel_name} at {factor:g}x: {error}")
                continue
            cases += load.size
            for n in COUNTS:
                started = time.perf_counter()
                state = wheel_state(load, slip, wheel, soil, nodes=n, rtol=RTOL, slip_angle=beta)
                seconds[n] += time.perf_counter() - started
                for channel, value in _errors(state, reference, wheel.r).items():
                    if value > worst[n][channel]:
                        worst[n][channel] = value
                        where[n][channel] = f"{soil_name}/{wheel_name} at {factor:g}x the static load"
    rows = [{"nodes_per_piece": n, **{f"max_error_{k}": worst[n][k] for k in CHANNELS},
             "worst_case_Fx": where[n].get("Fx", ""), "numpy_seconds": seconds[n]} for n in COUNTS]
    return {"reference_nodes": REFERENCE_NODES, "cases": cases, "skipped": skipped, "rows": rows}


def markdown(result: dict[str, Any]) -> str:
    lines = [f"Quadrature error against {result['reference_nodes']} nodes per piece, {result['cases']} cases "
             "(every soil and wheel of the library, 4 loads, 33 slips, 4 slip angles):", "",
             "| nodes per piece | Fx / W | Tx / (W r) | sinkage (relative) | Fy / W | numpy time [s] |",
             "|---|---|---|---|---|---|"]
    for row in result["rows"]:
        lines.append(f"| {row['nodes_per_piece']} | {row['max_error_Fx']:.1e} | {row['max_error_Tx']:.1e} | "
                     f"{row['max_error_sinkage']:.1e} | {row['max_error_Fy']:.1e} | {row['numpy_seconds']:.2f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("results/bench/quadrature.json"))
    parser.add_argument("--markdown", type=Path, default=None)
    args = parser.parse_args()
    result = measure()
    record = run_record("benchmarks/bench_quadrature.py", {"counts": list(COUNTS), "slip_angles_rad": SLIP_ANGLES,
                                                           "load_factors": LOAD_FACTORS, "rtol": RTOL})
    record["quadrature"] = result
    files = {args.out: json_bytes(record)}
    if args.markdown:
        files[args.markdown] = markdown(result).encode()
    write_all(files)
    print(markdown(result))


if __name__ == "__main__":
    main()
