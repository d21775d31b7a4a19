"""``rover-cosim identify``: the paper's Sec. 3 on SingleWheel.fmu."""

from __future__ import annotations

import argparse
from pathlib import Path

from .command import Command
from .options import (
    add_out,
    add_quiet,
    add_soil_options,
    add_workers,
    choice_of,
    fail,
    option_ok,
    output_folder,
    path,
    print_written,
    with_progress,
    workers_ok,
)


def arguments(parser: argparse.ArgumentParser) -> None:
    add_out(parser, "results/identification")
    parser.add_argument("--fmu", type=path, default=Path("fmus/SingleWheel.fmu"), help="the test-bed FMU")
    add_workers(parser)
    parser.add_argument("--record-interval", type=float, default=0.001,
                        help="rows kept in runs.csv [s] (a whole number of the sweep's 0.1 ms samples; default "
                        "0.001; 0.0001: every sample); the fits use every sample")
    add_soil_options(parser)
    add_quiet(parser)


def is_fmu(fmu: Path) -> bool:
    """Whether ``fmu`` is an FMU: a zip archive with a modelDescription.xml."""
    import zipfile

    try:
        with zipfile.ZipFile(fmu) as archive:
            return "modelDescription.xml" in archive.namelist()
    except (OSError, zipfile.BadZipFile):
        return False


def _not_a_test_bed(fmu: Path) -> str | None:
    """Why ``fmu`` cannot be the identification's test bed (its model description read), or None."""
    import fmpy

    from rover_cosim.identification.testbed import not_a_test_bed

    try:
        return not_a_test_bed(fmpy.read_model_description(str(fmu), validate=False))
    except Exception as error:  # noqa: BLE001 - FMPy raises many kinds
        return f"its modelDescription.xml cannot be read ({error})"


def run(args: argparse.Namespace) -> int:
    from rover_cosim.jobs.identify import check_record_interval, run_identification

    if not output_folder(args.out, "identify", COMMAND.needs_bytes) or (
            args.cache and not output_folder(args.cache, "identify", 0, "--cache")):
        return 2
    if not workers_ok("identify", args) or not option_ok(
            "identify", "--record-interval", lambda: check_record_interval(args.record_interval)):
        return 2
    if not args.fmu.is_file():
        fail("identify", f"FMU {args.fmu} not found (build them with `rover-cosim build-fmus`)")
        return 2
    if not is_fmu(args.fmu):
        fail("identify", f"--fmu {args.fmu}: not an FMU (expected a zip archive holding a modelDescription.xml, "
             "e.g. fmus/SingleWheel.fmu)")
        return 2
    problem = _not_a_test_bed(args.fmu)
    if problem:
        fail("identify", f"--fmu {args.fmu}: {problem}; expected the single-wheel test bed, e.g. fmus/SingleWheel.fmu")
        return 2
    choice = choice_of(args, "identify")
    if choice is None:
        return 2
    outcome = with_progress("identify", "sweep", args.quiet, lambda bar: run_identification(
        args.fmu, args.out, workers=args.workers, scheduler=args.scheduler, cache_dir=args.cache, progress=bar,
        choice=choice, record_interval=args.record_interval, run_timeout=args.run_timeout),
        (OSError, RuntimeError, ValueError))
    if outcome is None:
        return 1
    for name, sweep in (("sweep", outcome.sweep), ("lateral sweep", outcome.lateral_sweep)):
        print(f"{name}: {sweep.computed} runs computed, {sweep.cached} from the cache, "
              f"{len(sweep.failures)} failed, {sweep.wall_seconds:.1f} s")
    print("Table 1, Fit of Fx [%]:")
    print(outcome.fit.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    print("Lateral model, Fit of Fy [%] (Eq. 15) and largest settled error:")
    print(outcome.lateral_fit.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    print_written(outcome.files)
    return 0


COMMAND = Command(
    "identify", help="paper Sec. 3: step-torque sweep on SingleWheel.fmu, LUT and Fx(W, slip) fits, validation at "
    "275/575/875 N -> results/identification/",
    summary="Paper Sec. 3: the torque-step sweep on SingleWheel.fmu, the Fx(W, slip) models and Table 1.",
    examples=("rover-cosim identify --out results/identification",
              "rover-cosim identify --soil my_soil.toml --out results/my_soil/identification --workers 2"),
    arguments=arguments, run=run, needs_bytes=80e6)
