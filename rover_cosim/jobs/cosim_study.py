"""Coupling error of the co-simulated rover (RoverBody + 6 Wheel) against the monolithic Rover.fmu,
for Jacobi, Gauss-Seidel and the iterative master at communication steps of 1, 2, 5 and 10 ms
(``make cosim-study``).

Both plants get the same open-loop torque through the same master algorithm at the same
communication step, so what is left is the error of cutting the rover at the hubs: the body sees
the wheels' Fx one step late (and, under Jacobi, the wheels see the body's W and v_hub one step
late as well); the iterative master repeats each step until both sides agree at its end, with
the inputs interpolated over the step.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from rover_cosim.common.figures import render
from rover_cosim.common.outputs import json_bytes, run_record, summary_repr, write_all
from rover_cosim.common.rows import indices
from rover_cosim.orchestrator import algorithms
from rover_cosim.orchestrator.builder import replace_settings
from rover_cosim.orchestrator.examples import example
from rover_cosim.orchestrator.master import run
from rover_cosim.orchestrator.runs import system_record
from rover_cosim.orchestrator.system import System, load_system
from rover_cosim.progress import Stages

STEPS = (1e-3, 2e-3, 5e-3, 10e-3)  # s
ALGORITHMS = tuple(algorithms.ALGORITHMS)  # every master, in the registry's order


@dataclass
class CosimStudyResult:
    """What ``write_cosim_study`` wrote: the table of coupling errors and the files."""

    table: pd.DataFrame
    files: list[Path]

    def __repr__(self) -> str:
        return summary_repr("CosimStudyResult", self.files, rows=len(self.table))


def _system(name: str, fmu_dir: Path, **simulation: object) -> System:
    path = example(name)
    return replace_settings(load_system(path, fmu_dir=fmu_dir), name=f"{path.name} {simulation}", **simulation)


def coupling_errors(fmu_dir: Path, steps: tuple[float, ...] = STEPS, stop_time: float = 6.0,
                    progress: Callable[[float], None] | None = None) -> pd.DataFrame:
    """One row per (algorithm, step): largest and RMS error of the body velocity [m/s], largest
    error of the wheel loads [N] and of the drawbar forces [N] over the run, wall times [s]."""
    rows = []
    stages = Stages(progress, 2 * len(steps) * len(ALGORITHMS))
    for k, (step, algorithm) in enumerate((s, a) for s in steps for a in ALGORITHMS):
        mono_run = run(_system("rover_open_loop", fmu_dir, step=step, stop_time=stop_time, algorithm=algorithm),
                       progress=stages.stage(2 * k))
        mono = mono_run.data
        cosim_run = run(_system("rover_cosim", fmu_dir, step=step, stop_time=stop_time, algorithm=algorithm),
                        progress=stages.stage(2 * k + 1))
        cosim = cosim_run.data
        dv = (cosim["body.v"] - mono["rover.v"]).to_numpy()
        wheels = indices(mono.columns, "rover.Fz")
        dfz = np.max([np.abs(cosim[f"wheel{i}.Fz"] - mono[f"rover.Fz[{i}]"]).max() for i in wheels])
        dfx = np.max([np.abs(cosim[f"wheel{i}.Fx"] - mono[f"rover.Fx[{i}]"]).max() for i in wheels])
        rows.append({
            "algorithm": algorithm,
            "step_s": step,
            "max_abs_v_error_m_s": float(np.abs(dv).max()),
            "rms_v_error_m_s": float(np.sqrt(np.mean(dv**2))),
            "max_rel_v_error": float(np.abs(dv).max() / np.abs(mono["rover.v"]).max()),
            "max_abs_Fz_error_N": float(dfz),
            "max_abs_Fx_error_N": float(dfx),
            "cosim_wall_s": cosim_run.wall_seconds,
            "monolithic_wall_s": mono_run.wall_seconds,
        })
    return pd.DataFrame(rows)


def figure_png(table: pd.DataFrame) -> bytes:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    for algorithm, marker in zip(ALGORITHMS, ("o", "s", "D", "^")):
        part = table[table["algorithm"] == algorithm]
        axes[0].loglog(part["step_s"] * 1e3, part["max_abs_v_error_m_s"], marker=marker, label=algorithm)
        axes[1].loglog(part["step_s"] * 1e3, part["max_abs_Fz_error_N"], marker=marker, label=algorithm)
        axes[2].loglog(part["step_s"] * 1e3, part["cosim_wall_s"], marker=marker, label=algorithm)
    axes[0].set_ylabel("max |v_cosim - v_monolithic| [m/s]")
    axes[1].set_ylabel("max |Fz_cosim - Fz_monolithic| over limbs [N]")
    axes[2].set_ylabel("wall time of the co-simulated run [s]")
    for ax in axes:
        ax.set_xlabel("communication step [ms]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle("Co-simulated rover (RoverBody + 6 Wheel) against the monolithic Rover.fmu, 6 s open loop")
    fig.tight_layout()
    rendered = render(fig, 120)
    plt.close(fig)
    return rendered


#: The example systems the study runs (the monolithic rover, the co-simulated one).
SYSTEMS = ("rover_open_loop", "rover_cosim")


def systems(fmu_dir: Path) -> dict[str, System]:
    """The study's systems on the FMUs of ``fmu_dir`` (SystemFileError naming a missing FMU: the
    command checks them so before the work)."""
    return {name: load_system(example(name), fmu_dir=fmu_dir) for name in SYSTEMS}


def write_cosim_study(fmu_dir: Path, out_dir: Path,
                      progress: Callable[[float], None] | None = None) -> CosimStudyResult:
    """Run the study and write coupling_error.csv, .png and .json into ``out_dir`` (all or none)."""
    started = time.perf_counter()
    table = coupling_errors(fmu_dir, progress=progress)
    record = run_record("rover-cosim cosim-study", {"fmu_dir": str(fmu_dir), "steps_s": list(STEPS),
                                                    "algorithms": list(ALGORITHMS)})
    record["systems"] = {name: system_record(system) for name, system in systems(fmu_dir).items()}
    record["wall_seconds"] = time.perf_counter() - started
    files = {out_dir / "coupling_error.csv": table.to_csv(index=False, float_format="%.6g").encode(),
             out_dir / "coupling_error.png": figure_png(table),
             out_dir / "coupling_error.json": json_bytes(record)}
    write_all(files, folder=out_dir, stale=("coupling_error.*",))
    return CosimStudyResult(table, list(files))
