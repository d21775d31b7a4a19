"""Soil estimation measured (issue 33): known soils of the library recovered from generated
single-wheel data, at several noise levels and with and without sinkage, and the estimated soil's
prediction error at loads and slips not in the data; the coverage of the 95 % intervals over
many noise seeds; the fit times.

Data: the generator's default grid (identification.testbed_data.generate_testbed_data: loads
150-750 N by 150 N, slips -0.2 ... 0.8 by 0.1, 55 rows), Gaussian noise of the given fraction of
each channel's range, seeds 1, 2, 3, 4 for the four soils (the same seed for every noise level and
set of columns of a soil). The search starts from the paper's soil (from the lunar one when
the paper's soil is the truth), whose k_c is kept: k_φ then carries k_c/b + k_φ, so the tables
compare that modulus. Held out: loads 225, 375, 525, 675 N x slips -0.15, -0.05, 0.05, ..., 0.75
(none in the data), noise-free; errors in per cent of each channel's range there.

    python -P benchmarks/bench_soil_estimation.py --out results/bench/soil_estimation.json \\
        --markdown results/bench/soil_estimation.md

Not a test: nothing is asserted; docs/guide/soil-estimation.md quotes the tables.
"""

from __future__ import annotations

import argparse
import math
import statistics
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.common.outputs import json_bytes, run_record, write_all
from rover_cosim.identification.soil_estimation import SoilEstimate, estimate_soil
from rover_cosim.identification.testbed_data import generate_testbed_data, prediction_error
from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.library import choose

SOILS = ("paper", "lunar_nominal", "lete_sand", "clayey_soil")
NOISES = (0.0, 0.02, 0.05)
#: The test bed's columns, and what a rover measures (wheel torque; sinkage if it has a sensor).
COLUMNS = {"Fx, Tx, sinkage": ("Fx_N", "Tx_Nm", "sinkage_m"), "Fx, Tx": ("Fx_N", "Tx_Nm"),
           "Tx, sinkage": ("Tx_Nm", "sinkage_m"), "Tx": ("Tx_Nm",)}
HELD_LOADS = (225.0, 375.0, 525.0, 675.0)
HELD_SLIPS = tuple(float(s) for s in np.round(np.arange(-0.15, 0.76, 0.1), 10))
SEED = 1
COVERAGE_SEEDS = tuple(range(1, 21))
SHOWN = ("c", "phi", "kx", "bekker", "n", "a0", "a1", "lam")
#: The lateral case: 3 loads x 6 slips x 4 slip angles = 72 rows with Fy; held out at 7.5 and 15 deg.
LATERAL = {"loads": (200.0, 450.0, 700.0), "slips": (0.0, 0.1, 0.2, 0.4, 0.6, 0.8), "slip_angles_deg": (0.0, 5.0, 10.0,
                                                                                                          20.0)}
LATERAL_HELD = {"loads": (300.0, 600.0), "slips": (0.05, 0.3, 0.5, 0.7), "slip_angles_deg": (7.5, 15.0)}
LATERAL_SHOWN = ("phi", "kx", "ky", "ky_beta", "kx_beta")


def prior_for(truth: str) -> Soil:
    return choose("lunar_nominal" if truth == "paper" else "paper").soil


def true_value(soil: Soil, name: str, wheel: Wheel) -> float:
    return soil.bekker_modulus(wheel.b) if name == "bekker" else float(getattr(soil, name))


def recovered(estimate: SoilEstimate, truth: Soil) -> dict[str, dict[str, Any]]:
    """Per estimated parameter (k_phi as the modulus k_c/b + k_phi): truth, estimate, interval, inside."""
    out = {}
    for name, e in estimate.parameters.items():
        key, value, low, high = name, e.value, e.low, e.high
        if name == "kphi":
            key, m = "bekker", estimate.bekker_modulus
            value, low, high = m.value, m.low, m.high
        true = true_value(truth, key, estimate.wheel)
        slack = 1e-9 * abs(true)  # noise-free data: intervals of ~1e-12, the truth equal to ~1e-13
        out[key] = {"truth": true, "estimate": value, "low": low, "high": high, "determined": e.determined,
                    "inside": bool(low - slack <= true <= high + slack) if math.isfinite(low) else None,
                    "relative_error": value / true - 1 if true else None}
    return out


def one_case(truth_name: str, noise: float, channels: tuple[str, ...], seed: int | None = None) -> dict[str, Any]:
    """One estimate; ``seed`` None: SEED plus the soil's place in SOILS (each soil its own noise)."""
    seed = SEED + SOILS.index(truth_name) if seed is None else seed
    truth, wheel = choose(truth_name).soil, Wheel()
    data = generate_testbed_data(truth, wheel, noise=noise, seed=seed, channels=channels)
    estimate = estimate_soil(data, wheel, prior_for(truth_name))
    held = generate_testbed_data(truth, wheel, loads=HELD_LOADS, slips=HELD_SLIPS)
    errors = prediction_error(estimate.predict(held.load_N, held.slip), held)
    return {"soil": truth_name, "noise": noise, "channels": list(channels), "seed": seed,
            "seconds": estimate.seconds, "evaluations": estimate.evaluations,
            "parameters": recovered(estimate, truth),
            "kept_at_prior": {k: f.reason for k, f in estimate.fixed.items()},
            "held_out_error_percent_of_range": {k: {"rms": v.rms_percent, "max": v.max_percent}
                                                for k, v in errors.items()}}


def lateral_case(truth_name: str, noise: float) -> dict[str, Any]:
    """Data with slip angles and Fy: the lateral moduli, and Fx, Tx, sinkage, Fy held out."""
    seed = SEED + SOILS.index(truth_name)
    truth, wheel = choose(truth_name).soil, Wheel()
    data = generate_testbed_data(truth, wheel, noise=noise, seed=seed, **LATERAL)  # type: ignore[arg-type]
    estimate = estimate_soil(data, wheel, prior_for(truth_name))
    held = generate_testbed_data(truth, wheel, **LATERAL_HELD)  # type: ignore[arg-type]
    angles = 0.0 if held.slip_angle_deg is None else held.slip_angle_deg
    errors = prediction_error(estimate.predict(held.load_N, held.slip, angles), held)
    return {"soil": truth_name, "noise": noise, "rows": data.rows, "seconds": estimate.seconds,
            "parameters": recovered(estimate, truth),
            "kept_at_prior": {k: f.reason for k, f in estimate.fixed.items()},
            "held_out_error_percent_of_range": {k: {"rms": v.rms_percent, "max": v.max_percent}
                                                for k, v in errors.items()}}


def coverage(truth_name: str, noise: float = 0.02) -> dict[str, Any]:
    """Share of the 95 % intervals holding the truth over COVERAGE_SEEDS (all three channels)."""
    hits: dict[str, list[bool]] = {}
    times = []
    for seed in COVERAGE_SEEDS:
        case = one_case(truth_name, noise, COLUMNS["Fx, Tx, sinkage"], seed)
        times.append(case["seconds"])
        for name, p in case["parameters"].items():
            if p["inside"] is not None:
                hits.setdefault(name, []).append(p["inside"])
    return {"soil": truth_name, "noise": noise, "seeds": len(COVERAGE_SEEDS),
            "share_inside": {k: sum(v) / len(v) for k, v in hits.items()},
            "times_estimated": {k: len(v) for k, v in hits.items()}, "median_seconds": statistics.median(times)}


def _shown(p: dict[str, Any], name: str) -> str:
    scale = 180 / math.pi if name == "phi" else 1.0
    interval = "—" if p["low"] is None or not math.isfinite(p["low"]) else \
        f"[{p['low'] * scale:.3g}, {p['high'] * scale:.3g}]"
    mark = "" if p["inside"] in (True, None) else " ✗"
    return f"{p['estimate'] * scale:.4g} {interval}{mark}"


def markdown(cases: list[dict[str, Any]], covered: list[dict[str, Any]], lateral: list[dict[str, Any]]) -> str:
    lines = []
    for soil in SOILS:
        truth = choose(soil).soil
        row = [c for c in cases if c["soil"] == soil and c["channels"] == list(COLUMNS["Fx, Tx, sinkage"])]
        lines += [f"**{soil}** (Fx, Tx, sinkage; ✗: truth outside the 95 % interval; — kept at the prior)", "",
                  "| parameter | truth | " + " | ".join(f"noise {100 * c['noise']:g} %" for c in row) + " |",
                  "|---|---|" + "---|" * len(row)]
        for name in SHOWN:
            true = true_value(truth, name, Wheel()) * (180 / math.pi if name == "phi" else 1.0)
            cells = [_shown(c["parameters"][name], name) if name in c["parameters"] else "—" for c in row]
            label = {"bekker": "k_c/b + k_φ", "phi": "φ [deg]"}.get(name, name)
            lines.append(f"| {label} | {true:.4g} | " + " | ".join(cells) + " |")
        lines.append("")
    lines += ["Held-out prediction error (every channel predicted, measured or not), RMS (max) in % of the "
              "channel's range; fit time:", "",
              "| soil | columns | noise | Fx | Tx | sinkage | time [s] |", "|---|---|---|---|---|---|---|"]
    for c in cases:
        e = c["held_out_error_percent_of_range"]
        cells = [f"{e[k]['rms']:.2f} ({e[k]['max']:.2f})" for k in ("Fx_N", "Tx_Nm", "sinkage_m")]
        columns = next(k for k, v in COLUMNS.items() if list(v) == c["channels"])
        lines.append(f"| {c['soil']} | {columns} | {100 * c['noise']:g} % | " + " | ".join(cells)
                     + f" | {c['seconds']:.2f} |")
    lines += ["", f"Coverage of the 95 % intervals over {len(COVERAGE_SEEDS)} noise seeds (2 % noise):", "",
              "| soil | " + " | ".join(SHOWN) + " | median fit [s] |", "|---|" + "---|" * (len(SHOWN) + 1)]
    for c in covered:
        cells = [f"{100 * c['share_inside'][k]:.0f} % ({c['times_estimated'][k]})" if k in c["share_inside"] else "—"
                 for k in SHOWN]
        lines.append(f"| {c['soil']} | " + " | ".join(cells) + f" | {c['median_seconds']:.2f} |")
    lines += ["", "With slip angles (0, 5, 10, 20 deg; 72 rows with Fy), held out at 7.5 and 15 deg:", "",
              "| soil | noise | " + " | ".join(LATERAL_SHOWN) + " | Fx | Tx | sinkage | Fy | time [s] |",
              "|---|---|" + "---|" * (len(LATERAL_SHOWN) + 5)]
    for c in lateral:
        truth = choose(c["soil"]).soil
        cells = [(_shown(c["parameters"][k], k) if k in c["parameters"] else "—")
                 + f" (truth {true_value(truth, k, Wheel()) * (180 / math.pi if k == 'phi' else 1):.3g})"
                 for k in LATERAL_SHOWN]
        e = c["held_out_error_percent_of_range"]
        errors = [f"{e[k]['rms']:.2f} ({e[k]['max']:.2f})" for k in ("Fx_N", "Tx_Nm", "sinkage_m", "Fy_N")]
        lines.append(f"| {c['soil']} | {100 * c['noise']:g} % | " + " | ".join(cells + errors)
                     + f" | {c['seconds']:.2f} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("results/bench/soil_estimation.json"))
    parser.add_argument("--markdown", type=Path, default=None, help="also write the tables as Markdown")
    parser.add_argument("--no-coverage", action="store_true", help="leave out the coverage over 20 seeds")
    args = parser.parse_args()
    cases = [one_case(soil, noise, channels) for soil in SOILS for channels in COLUMNS.values() for noise in NOISES]
    lateral = [lateral_case(soil, noise) for soil in ("paper", "lunar_nominal") for noise in (0.0, 0.02)]
    covered = [] if args.no_coverage else [coverage(soil) for soil in ("lunar_nominal", "lete_sand", "clayey_soil")]
    times = [c["seconds"] for c in cases]
    summary = {"fit_seconds": {"median": statistics.median(times), "max": max(times)}, "rows": 55,
               "held_out": {"loads_N": HELD_LOADS, "slips": HELD_SLIPS}}
    text = markdown(cases, covered, lateral)
    files = {args.out: json_bytes({**run_record("benchmarks/bench_soil_estimation.py", summary), "cases": cases,
                                   "lateral": lateral, "coverage": covered})}
    if args.markdown:
        files[args.markdown] = text.encode()
    write_all(files)
    print(text)
    print(f"fits: median {statistics.median(times):.2f} s, max {max(times):.2f} s (55 rows)")


if __name__ == "__main__":
    main()
