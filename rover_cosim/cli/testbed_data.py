"""``rover-cosim testbed-data``: single-wheel test-bed data from the reference wheel on a known soil."""

from __future__ import annotations

import argparse

from .command import Command
from .options import (
    add_soil_options,
    choice_of,
    fail,
    foreign_companion,
    numbers,
    output_file,
    path,
    positive_loads,
    print_written,
    recorded_by,
)

#: The measured channels of single-wheel data, named here without importing the estimator (it
#: imports SciPy: seconds before --help; tests/test_soil_estimation.py keeps them equal to
#: identification.testbed_data.CHANNELS).
CHANNEL_NAMES = ("Fx_N", "Tx_Nm", "sinkage_m", "Fy_N")


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 <= value <= 1:
        raise argparse.ArgumentTypeError(f"noise={text!r}: expected a fraction of each channel's range in [0, 1] "
                                         "(e.g. 0.02)")
    return value


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--out", type=path, required=True, help="the CSV file to write (.csv; a .json record of the "
                        "truth goes beside it)")
    add_soil_options(parser)
    parser.add_argument("--loads", type=positive_loads, default=None,
                        help="comma-separated wheel loads [N] (default: 150,300,450,600,750)")
    parser.add_argument("--slips", type=numbers("slip", -1.0, 1.0, ""), default=None,
                        help="comma-separated slip ratios in [-1, 1] (default: -0.2,-0.1,...,0.8)")
    parser.add_argument("--slip-angles", type=numbers("slip angle", -89.0, 89.0, " deg"), default=(0.0,),
                        metavar="DEGREES", help="comma-separated slip angles [deg]; any other than 0 adds Fy_N "
                        "(default: 0)")
    parser.add_argument("--channels", type=lambda text: tuple(p.strip() for p in text.split(",")), default=None,
                        help=f"measured columns, of {', '.join(CHANNEL_NAMES)} (default: Fx_N, Tx_Nm, sinkage_m, and "
                        "Fy_N at slip angles other than 0)")
    parser.add_argument("--sinkage", action=argparse.BooleanOptionalAction, default=True,
                        help="write the sinkage_m column (--no-sinkage: a test bed without a sinkage sensor)")
    parser.add_argument("--noise", type=_fraction, default=0.0,
                        help="Gaussian noise on every measured channel, its standard deviation a fraction of the "
                        "channel's range, e.g. 0.02 (default: 0)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the noise (default: 0)")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace --out even if it is not data this command wrote")


def run(args: argparse.Namespace) -> int:
    from rover_cosim.jobs.estimate_soil import DEFAULT_LOADS, DEFAULT_SLIPS, write_testbed_data

    if args.out.suffix.lower() != ".csv":
        fail("testbed-data", f"--out {args.out}: expected a .csv file name (its record goes beside it as .json)")
        return 2
    if not output_file(args.out, "testbed-data", COMMAND.needs_bytes, OWNS, args.overwrite, "--out"):
        return 2
    companion = None if args.overwrite else foreign_companion([args.out.with_suffix(".json")], "testbed-data")
    if companion:
        fail("testbed-data", f"--out {args.out}: {companion}")
        return 2
    choice = choice_of(args, "testbed-data")
    if choice is None:
        return 2
    channels = args.channels
    if channels is not None and not args.sinkage:
        channels = tuple(name for name in channels if name != "sinkage_m")
    elif channels is None and not args.sinkage:
        channels = ("Fx_N", "Tx_Nm") + (("Fy_N",) if any(a != 0 for a in args.slip_angles) else ())
    try:
        outcome = write_testbed_data(args.out, choice, args.loads or DEFAULT_LOADS, args.slips or DEFAULT_SLIPS,
                                     args.slip_angles, channels, args.noise, args.seed)
    except ValueError as error:
        fail("testbed-data", f"{error} (nothing written)")
        return 2
    except RuntimeError as error:  # the reference wheel finds no sinkage for a load and slip given
        fail("testbed-data", f"{error}: the wheel on this soil has no steady state there; expected loads and "
             "slips it can carry (nothing written)")
        return 2
    print(f"{outcome.data.rows} rows ({', '.join(outcome.data.channels)}) on soil {choice.soil_name}, wheel "
          f"{choice.wheel_name}, noise {args.noise:g} of each channel's range (seed {args.seed})")
    print_written(outcome.files)
    return 0


OWNS = recorded_by("testbed-data")

COMMAND = Command(
    "testbed-data", help="single-wheel test-bed data (the CSV estimate-soil reads) from the reference wheel on a "
    "known soil, with seeded noise",
    summary="Single-wheel test-bed data from the reference wheel on a known soil, with seeded noise.",
    examples=("rover-cosim testbed-data --soil lunar_nominal --noise 0.02 --seed 1 --out data.csv",
              "rover-cosim testbed-data --soil paper --slip-angles 0,5,10 --no-sinkage --out lateral.csv"),
    arguments=arguments, run=run, needs_bytes=2e6, owns=OWNS)
