"""``rover-cosim fig3``: the paper's Fig. 3 from the numpy reference wheel."""

from __future__ import annotations

import argparse
from pathlib import Path

from .command import Command
from .options import (
    add_out,
    add_overwrite,
    add_soil_options,
    choice_of,
    fail,
    foreign_results,
    output_folder,
    print_written,
)


def _slip_step(text: str) -> float:
    try:
        step = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"slip step={text!r}: expected a number in (0, 2]") from None
    if not 0 < step <= 2.0:
        raise argparse.ArgumentTypeError(f"slip step={step!r}: expected a number in (0, 2]")
    return step


def _slip_range(text: str) -> tuple[float, float]:
    try:
        first, last = (float(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"slip range={text!r}: expected FIRST,LAST (e.g. -0.5,0.9)") from None
    if not -1.0 <= first < last <= 1.0:
        raise argparse.ArgumentTypeError(f"slip range={text!r}: expected -1 <= FIRST < LAST <= 1")
    return first, last


def arguments(parser: argparse.ArgumentParser) -> None:
    from .options import positive_loads

    add_out(parser, "results", "output folder (default: results)")
    parser.add_argument("--loads", type=positive_loads, default=None,
                        help="comma-separated wheel loads [N] (default: 100,200,...,800)")
    parser.add_argument("--slip-step", type=_slip_step, default=0.01,
                        help="slip spacing, adjusted so that both ends of the range are points (default: 0.01)")
    parser.add_argument("--slip-range", type=_slip_range, default=(0.0, 0.9), metavar="FIRST,LAST",
                        help="slip ratios from FIRST to LAST in [-1, 1] (negative: braking; default: 0,0.9)")
    add_soil_options(parser)
    add_overwrite(parser, "the figure's files in --out")


def run(args: argparse.Namespace) -> int:
    from rover_cosim.common.figures import SETTINGS

    choice = choice_of(args, "fig3")
    if choice is None or not output_folder(args.out, "fig3", COMMAND.needs_bytes):
        return 2
    from rover_cosim.jobs.fig3 import PAPER_LOADS, file_names, slip_grid, write_fig3  # matplotlib: after the checks
    names = file_names(choice)
    extra = [args.out / f"{Path(names['png']).stem}.{kind}" for kind in SETTINGS.formats if kind != "png"]
    mine = None if args.overwrite else foreign_results(
        [args.out / name for name in names.values()] + extra, args.out / names["json"], "fig3")
    if mine:
        fail("fig3", f"--out {args.out}: {mine}")
        return 2
    try:
        first, last = args.slip_range
        written = write_fig3(args.out, args.loads or PAPER_LOADS, slip_grid(args.slip_step, last, first), choice)
    except ValueError as error:
        fail("fig3", str(error))
        return 2
    except RuntimeError as error:  # the wheel model cannot find an equilibrium on this soil
        fail("fig3", f"{error} (the soil cannot carry the wheel here: look at its moduli and the loads; nothing "
             "written)")
        return 1
    print_written(written)
    return 0


COMMAND = Command(
    "fig3", help="paper Fig. 3: Fx against slip for loads 100..800 N (numpy reference)",
    summary="Paper Fig. 3 from the numpy reference wheel: Fx against slip for several loads (CSV, PNG, JSON).",
    examples=("rover-cosim fig3 --out results",
              "rover-cosim fig3 --soil lete_sand --slip-range=-0.5,0.9 --out results"),
    arguments=arguments, run=run, needs_bytes=5e6)
