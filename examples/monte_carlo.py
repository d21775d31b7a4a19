"""A Monte Carlo study of your own: the paper's closed loop on soils drawn from your study file.

The study (examples/my_study.toml unless --study names another file) gives each uncertain soil
parameter a distribution around a nominal soil; every sample runs the closed-loop rover
(Rover.fmu) with the controller identified on the nominal soil, unchanged. The controller's model
is --model (e.g. results/identification/model.json of `make identify`); without it, the script
identifies one first on the study's nominal soil, into <out>/identification.

    python examples/monte_carlo.py --out my_study --model results/identification/model.json
    python examples/monte_carlo.py --out my_study --quick       # 3 runs of 5 s, a small sweep

Writes <out>/montecarlo/: runs.csv (per run: the sample and its metrics), sensitivity.csv,
summary.json, failures.csv and figures (see the user guide's Monte Carlo page). Runs are cached
in <out>/montecarlo/cache, so a second call with more --runs computes only the new ones.
"""

from __future__ import annotations

import argparse
import os
from dataclasses import replace
from pathlib import Path

from rover_cosim.identification.sweep import SweepPlan
from rover_cosim.jobs.identify import run_identification
from rover_cosim.jobs.montecarlo import load_study, run_montecarlo
from rover_cosim.terramechanics.library import choose

NAME = "monte_carlo"
HERE = Path(__file__).resolve().parent
#: The small identification sweep of --quick (as in examples/own_soil.py).
QUICK_PLAN = SweepPlan(loads=(200.0, 450.0, 700.0), torques=(5.0, 15.0, 30.0, 40.0), stop_time=0.02)
QUICK_LATERAL_PLAN = SweepPlan(loads=(200.0, 400.0, 600.0, 800.0), torques=(5.0, 10.0, 30.0),
                               slip_angles_deg=(0.0, 5.0, 10.0, 25.0), stop_time=0.02, sample_time=1e-3)


def output_folder(parser: argparse.ArgumentParser, folder: Path) -> Path:
    """``folder``, made if missing; one that holds files this example did not write is refused."""
    marker = folder / f".{NAME}"
    if folder.is_dir() and any(folder.iterdir()) and not marker.exists():
        parser.error(f"{folder} holds files this example did not write: choose a new or empty folder with --out")
    folder.mkdir(parents=True, exist_ok=True)
    marker.touch()
    return folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("example_output") / NAME, help="output folder")
    parser.add_argument("--study", type=Path, default=HERE / "my_study.toml", help="the study's TOML file")
    parser.add_argument("--model", type=Path, default=None,
                        help="the identified model (model.json) of the study's nominal soil; default: identify one")
    parser.add_argument("--fmu-dir", type=Path, default=Path("fmus"), help="where the FMUs are (make fmus)")
    parser.add_argument("--runs", type=int, default=None, help="samples, the nominal included (default: the study's)")
    parser.add_argument("--stop-time", type=float, default=None, help="length of each run [s] (default: the study's)")
    parser.add_argument("--workers", type=int, default=None, help="local processes (default: all cores)")
    parser.add_argument("--quick", action="store_true", default=bool(os.environ.get("ROVER_COSIM_EXAMPLE_QUICK")),
                        help="3 runs of 5 s and, without --model, a small sweep; also ROVER_COSIM_EXAMPLE_QUICK=1")
    args = parser.parse_args()
    if not (args.fmu_dir / "Rover.fmu").is_file():
        parser.error(f"Rover.fmu not in {args.fmu_dir}: build the FMUs with `make fmus`")
    if args.model is not None and not args.model.is_file():
        parser.error(f"{args.model} not found: make one with `make identify`, or leave --model out")

    # The study file, checked (a wrong key or distribution is an error naming it); the number of
    # runs and the run length may be shortened from the command line.
    study = load_study(args.study, runs=args.runs or (3 if args.quick else None))
    if args.stop_time or args.quick:
        study = replace(study, stop_time=args.stop_time or 5.0)
    out = output_folder(parser, args.out)

    model = args.model
    if model is None:   # the controller's model, identified on the study's nominal soil and wheel
        identified = run_identification(args.fmu_dir / "SingleWheel.fmu", out / "identification",
                                        plan=QUICK_PLAN if args.quick else None,
                                        lateral_plan=QUICK_LATERAL_PLAN if args.quick else None,
                                        workers=args.workers, choice=choose(study.soil, study.wheel))
        model = out / "identification" / "model.json"
        print(f"identified the controller's model on soil {study.soil}: {model} ({len(identified.files)} files)")

    result = run_montecarlo(study, args.fmu_dir, model, out / "montecarlo", workers=args.workers)
    print(f"{study.title}: {len(result.runs)} runs of {study.stop_time:g} s "
          f"({result.computed} computed, {result.cached} from the cache, {len(result.failures)} failed)")
    shown = ["sample", *study.names, "rms_Fx_max_N", "position_lag_m", "max_slip"]
    print(result.runs[[c for c in shown if c in result.runs]].to_string(index=False, float_format=lambda x: f"{x:.4g}"))
    # Rank correlations of the largest force error with each parameter (tens of runs make them meaningful).
    ranking = result.sensitivity[result.sensitivity["output"] == "rms_Fx_max_N"].sort_values("rank")
    if len(ranking):
        print(f"what the largest RMS force error depends on ({len(result.runs)} runs):")
        print(ranking[["parameter", "spearman", "prcc", "distance_spearman", "rank"]]
              .to_string(index=False, float_format=lambda x: f"{x:.3g}"))
    print("wrote " + ", ".join(str(p) for p in result.files))


if __name__ == "__main__":
    main()
