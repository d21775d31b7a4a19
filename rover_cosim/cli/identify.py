"""``rover-cosim identify``: the paper's Sec. 3 on SingleWheel.fmu."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

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
    parser.add_argument("--plan", type=path, default=None, metavar="FILE",
                        help="the identification plan as a TOML file (loads, torques, fit_torque_max, "
                        "validation_loads, validation_torques; SI). Default: the paper's for the paper's soil, wheel "
                        "and rover, else the paper's scaled to the rover's static wheel load and the wheel's torque "
                        "on the soil (printed before the sweep)")
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


def plan_of(args: argparse.Namespace, choice: Any) -> Any:
    """The identification plan (--plan, or the one for the choice), said before the sweep; None
    after saying why there is none (a plan file it cannot read, a rover that cannot be driven)."""
    from rover_cosim.identification.plan import NotDrivable, plan_for, read_plan

    try:
        plan = read_plan(args.plan) if args.plan is not None else plan_for(choice)
    except NotDrivable as error:
        fail("identify", f"not drivable: {error} (nothing run)")
        return None
    except ValueError as error:
        fail("identify", f"--plan: {error}")
        return None
    if not plan.is_paper:
        print(f"identification plan: {plan.basis}")
        loads, torques = ", ".join(f"{w:g}" for w in plan.loads), ", ".join(f"{t:g}" for t in plan.torques)
        print(f"  loads {loads} N; torques {torques}"
              f" N·m; fits: torque <= {plan.fit_torque_max:g} N·m, slip in {plan.slip_window}; validation at "
              f"{', '.join(f'{w:g}' for w in plan.validation_loads)} N")
    return plan


def run(args: argparse.Namespace) -> int:
    if not output_folder(args.out, "identify", COMMAND.needs_bytes) or (
            args.cache and not output_folder(args.cache, "identify", 0, "--cache")):
        return 2
    from rover_cosim.jobs.identify import check_record_interval, run_identification  # after the folder checks

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
    plan = plan_of(args, choice)
    if plan is None:
        return 2
    outcome = with_progress("identify", "sweep", args.quiet, lambda bar: run_identification(
        args.fmu, args.out, workers=args.workers, scheduler=args.scheduler, cache_dir=args.cache, progress=bar,
        choice=choice, record_interval=args.record_interval, run_timeout=args.run_timeout, identification=plan),
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
