"""``rover-cosim cosim-study``: the coupling error of the co-simulated rover per master and step."""

from __future__ import annotations

import argparse

from .command import Command
from .options import add_fmu_dir, add_out, add_quiet, fail, fmu_dir_exists, output_folder, print_written, with_progress


def arguments(parser: argparse.ArgumentParser) -> None:
    add_out(parser, "results/cosim_study")
    add_fmu_dir(parser, "where the FMUs are (default: fmus)")
    add_quiet(parser)


def run(args: argparse.Namespace) -> int:
    if not output_folder(args.out, "cosim-study", COMMAND.needs_bytes) or not fmu_dir_exists(args.fmu_dir,
                                                                                             "cosim-study"):
        return 2
    from rover_cosim.jobs.cosim_study import systems, write_cosim_study  # pandas, matplotlib: after the checks
    from rover_cosim.orchestrator.master import RunError
    from rover_cosim.orchestrator.system import SystemFileError

    try:
        systems(args.fmu_dir)  # its FMUs there
    except SystemFileError as error:
        fail("cosim-study", f"--fmu-dir {args.fmu_dir}: {error}")
        return 2
    outcome = with_progress("cosim-study", "cosim-study", args.quiet,
                            lambda bar: write_cosim_study(args.fmu_dir, args.out, progress=bar),
                            (SystemFileError, RunError))
    if outcome is None:
        return 1
    print(outcome.table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print_written(outcome.files)
    return 0


COMMAND = Command(
    "cosim-study", help="coupling error of the co-simulated rover against the monolithic one, Jacobi, Gauss-Seidel "
    "and iterative, steps 1-10 ms -> CSV + PNG",
    summary="Coupling error of the co-simulated rover against the monolithic one per master and step.",
    examples=("rover-cosim cosim-study --fmu-dir fmus --out results/cosim_study",),
    arguments=arguments, run=run, needs_bytes=5e6)
