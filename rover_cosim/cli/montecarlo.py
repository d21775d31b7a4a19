"""``rover-cosim montecarlo``: the paper's closed loop over sampled soils."""

from __future__ import annotations

import argparse
from typing import Any

from .command import Command
from .options import (
    add_fmu_dir,
    add_model,
    add_out,
    add_quiet,
    add_workers,
    at_least,
    fail,
    model_readable,
    output_folder,
    path_text,
    print_written,
    with_progress,
    workers_ok,
)

#: Bytes of the study's files besides its runs, and of each run's.
NEEDS, RUN_BYTES = 10e6, 5e3


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--study", type=path_text, default="lunar_regolith",
                        help="study file (TOML), or a shipped study: lunar_regolith (default)")
    add_model(parser, "identified model (from `rover-cosim identify` on the study's nominal soil)")
    add_fmu_dir(parser)
    add_out(parser, "results/montecarlo")
    parser.add_argument("--runs", type=int, default=None, help="number of samples, the nominal included "
                        "(default: the study's)")
    parser.add_argument("--seed", type=int, default=None, help="random seed (default: the study's)")
    add_workers(parser)
    parser.add_argument("--allow-model-mismatch", action="store_true",
                        help="use a model identified on another soil or wheel than the study's nominal ones "
                        "(refused otherwise; recorded)")
    parser.add_argument("--adapt", action="store_true",
                        help="also run every sample with the adaptive controller (a calibration phase, the soil "
                        "estimated from the rover's telemetry, the model identified again on SingleWheel.fmu): the "
                        "scenario straight_adapted beside straight, compared after the calibration")
    add_quiet(parser)


def run(args: argparse.Namespace) -> int:
    if not workers_ok("montecarlo", args) or not at_least("montecarlo", ("--runs", args.runs, 1),
                                                            ("--seed", args.seed, 0)):
        return 2
    from rover_cosim.jobs.montecarlo.study import StudyError, load_study

    try:
        study = load_study(args.study, runs=args.runs, seed=args.seed)
        study = study.adapted() if args.adapt else study
        study.check_calibration()
    except StudyError as error:
        fail("montecarlo", str(error))
        return 2
    if not output_folder(args.out, "montecarlo", NEEDS + RUN_BYTES * study.runs) or (
            args.cache and not output_folder(args.cache, "montecarlo", 0, "--cache")):
        return 2
    if not model_readable(args.model, "montecarlo"):
        return 2
    from rover_cosim.jobs.montecarlo.job import run_montecarlo

    outcome = with_progress("montecarlo", "montecarlo", args.quiet, lambda bar: run_montecarlo(
        study, args.fmu_dir, args.model, args.out, workers=args.workers, scheduler=args.scheduler,
        cache_dir=args.cache, progress=bar, allow_model_mismatch=args.allow_model_mismatch,
        run_timeout=args.run_timeout),
        (OSError, RuntimeError, ValueError))
    if outcome is None:
        return 1
    _print_outcome(outcome)
    if len(outcome.runs) and outcome.summary["runs_failed"] == len(outcome.runs):
        fail("montecarlo", f"every run failed (see {args.out / 'failures.csv'})")
        return 1
    return 0


def _percent(share: float | None) -> str:
    return "-" if share is None else f"{100 * share:.1f} %"


def _print_outcome(outcome: Any) -> None:
    for cache_file, problem in outcome.rejected.items():
        fail("montecarlo", f"cache file {cache_file}: {problem}; computed again")
    summary = outcome.summary
    print(f"{outcome.computed} runs computed, {outcome.cached} from the cache, {summary['runs_failed']} failed, "
          f"{summary['wall_seconds']:.1f} s" + (f" ({summary['runs_per_minute']:.1f} runs/min)"
                                                  if summary["runs_per_minute"] else ""))
    for scenario, numbers in summary["scenarios"].items():
        print(f"{scenario}: {numbers['completed']} of {numbers['runs']} runs completed; RMS(Fx - Fx_des) <= 1 N on "
              f"every limb in {numbers['meeting_1N_rms']} ({_percent(numbers['share_meeting_1N_rms_of_completed'])} "
              f"of the completed); stuck in {numbers['stuck']}")
        if "adapted_share_meeting_1N_rms_of_completed" in numbers:
            before = numbers["share_meeting_1N_rms_after_calibration_of_completed"]
            after = numbers["adapted_share_meeting_1N_rms_of_completed"]
            print(f"  after the calibration (t >= {numbers['after_calibration_from_s']:g} s), RMS <= 1 N on every "
                  f"limb: {_percent(before)} with the nominal model, {_percent(after)} adapted")
    ranking = outcome.sensitivity[outcome.sensitivity["output"] == "rms_Fx_max_N"].dropna(subset=["rank"])
    if len(ranking):
        print("Sensitivity of the largest RMS(Fx - Fx_des) (rank correlations: partial, and with the distance "
              "from the nominal value):")
        print(ranking.sort_values("rank")[["rank", "parameter", "prcc", "p_value", "distance_spearman",
                                           "distance_p_value", "strongest"]]
              .to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print_written(outcome.files)


COMMAND = Command(
    "montecarlo", help="Monte Carlo over soil uncertainty: the paper's closed loop with the identified model on "
    "every sampled soil, local processes or a Dask cluster -> results/montecarlo/",
    summary="The paper's closed loop over sampled soils: how often the 1 N RMS holds, and what matters most.",
    examples=("rover-cosim montecarlo --runs 20 --workers 2", "rover-cosim montecarlo --study my_study.toml"),
    arguments=arguments, run=run, needs_bytes=NEEDS)
