"""``rover-cosim estimate-soil``: soil parameters from single-wheel test-bed data."""

from __future__ import annotations

import argparse

from .command import Command
from .options import add_out, add_overwrite, fail, foreign_results, output_folder, path, path_text, print_written


def _names(text: str) -> tuple[str, ...]:
    """Comma-separated soil fields to estimate (--parameters)."""
    from rover_cosim.identification.soil_estimation import SPECS

    names = tuple(part.strip() for part in text.split(",") if part.strip())
    unknown = [name for name in names if name not in SPECS]
    if unknown or not names or len(set(names)) != len(names):
        raise argparse.ArgumentTypeError(f"parameters={text!r}: expected distinct names of {', '.join(SPECS)}, "
                                         "comma-separated")
    return names


def _noise_scales(text: str) -> dict[str, float]:
    """CHANNEL=SD,... of --noise-scale: the noise's standard deviation per channel, in its unit."""
    from rover_cosim.identification.testbed_data import CHANNELS

    scales: dict[str, float] = {}
    for part in text.split(","):
        name, equals, value = part.partition("=")
        name = name.strip()
        try:
            number = float(value)
        except ValueError:
            number = float("nan")
        if not equals or name not in CHANNELS or not (0 < number < float("inf")) or name in scales:
            raise argparse.ArgumentTypeError(f"noise scale {part.strip()!r}: expected CHANNEL=SD with CHANNEL one of "
                                             f"{', '.join(CHANNELS)} (once each) and SD > 0 in its unit, e.g. "
                                             "Fx_N=2,Tx_Nm=0.8")
        scales[name] = number
    return scales


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("data", type=path, help="CSV file: columns load_N, slip, any of Fx_N, Tx_Nm, sinkage_m, Fy_N "
                        "and optionally slip_angle_deg; one row per steady-state measurement")
    add_out(parser, "results/soil_estimate")
    add_overwrite(parser, "the files in --out")
    parser.add_argument("--wheel", type=path_text, default=None,
                        help="the test bed's wheel: a name of the shipped library, a TOML file, or FILE:NAME (default: "
                        "paper)")
    parser.add_argument("--prior", type=path_text, default=None,
                        help="the soil the search starts from; what is not estimated keeps its value: a shipped name, "
                        "a TOML file or FILE:NAME (default: paper)")
    parser.add_argument("--set", dest="assignments", action="append", default=[], metavar="KIND.NAME=VALUE",
                        help="change one value of the prior or wheel (soil.c=500, wheel.b=0.2; repeatable)")
    parser.add_argument("--parameters", type=_names, default=None, metavar="NAMES",
                        help="comma-separated soil fields to estimate, e.g. c,phi,kphi,n,kx (default: what the data's "
                        "columns allow; a0, a1, lam and the slip-angle growths only if the data determine them)")
    parser.add_argument("--noise-scale", type=_noise_scales, default=None, metavar="CHANNEL=SD,...",
                        help="standard deviation of each channel's measurement noise in its unit, e.g. "
                        "Fx_N=2,Tx_Nm=0.8 (default: estimated from the fit's residuals)")


def run(args: argparse.Namespace) -> int:
    if not output_folder(args.out, "estimate-soil", COMMAND.needs_bytes):
        return 2
    from rover_cosim.jobs.estimate_soil import FILES, run_estimate_soil  # scipy, matplotlib: after the check
    from rover_cosim.terramechanics.library import choose

    mine = None if args.overwrite else foreign_results([args.out / name for name in FILES], args.out / "estimate.json",
                                                       "estimate-soil")
    if mine:
        fail("estimate-soil", f"--out {args.out}: {mine}")
        return 2
    try:
        choice = choose(args.prior, args.wheel, args.assignments)
        outcome = run_estimate_soil(args.data, args.out, choice, args.parameters, args.noise_scale)
    except (ValueError, TypeError) as error:
        fail("estimate-soil", f"{error} (nothing written)")
        return 2
    except RuntimeError as error:
        fail("estimate-soil", f"{error} (nothing written)")
        return 1
    print(outcome.estimate.summary())
    print_written(outcome.files)
    return 0


COMMAND = Command(
    "estimate-soil", help="soil parameters (c, phi, kphi, n, kx, ...) estimated from single-wheel test-bed data (CSV) "
    "-> soil.toml, estimate.json, figures",
    summary="Soil parameters with intervals from single-wheel test-bed data; soil.toml for --soil.",
    examples=("rover-cosim estimate-soil data.csv --out results/my_soil",
              "rover-cosim estimate-soil data.csv --prior lunar_nominal --parameters c,phi,kphi,n,kx"),
    arguments=arguments, run=run, needs_bytes=5e6)
