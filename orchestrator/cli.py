"""``rover-cosim``: the command behind the Makefile targets."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Sequence


def _positive_loads(text: str) -> tuple[float, ...]:
    try:
        loads = tuple(float(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"loads={text!r}: expected comma-separated numbers in N, e.g. 100,200") from None
    bad = [w for w in loads if not (0 < w < float("inf"))]
    if bad:
        raise argparse.ArgumentTypeError(f"load={bad[0]!r} N: expected a finite load > 0 N")
    return loads


def _slip_step(text: str) -> float:
    try:
        step = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"slip step={text!r}: expected a number in (0, 0.9]") from None
    if not 0 < step <= 0.9:
        raise argparse.ArgumentTypeError(f"slip step={step!r}: expected a number in (0, 0.9]")
    return step


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rover-cosim", description=__doc__)
    commands = parser.add_subparsers(dest="command", required=True)
    fig3 = commands.add_parser("fig3", help="paper Fig. 3: Fx against slip for loads 100..800 N (numpy reference)")
    fig3.add_argument("--out", type=Path, default=Path("results"), help="output folder (default: results)")
    fig3.add_argument("--loads", type=_positive_loads, default=None,
                      help="comma-separated wheel loads [N] (default: 100,200,...,800)")
    fig3.add_argument("--slip-step", type=_slip_step, default=0.01,
                      help="slip spacing over 0..0.9, adjusted so that 0.9 is a point (default: 0.01)")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.command == "fig3":
        from .fig3 import PAPER_LOADS, slip_grid, write_fig3

        try:
            written = write_fig3(args.out, args.loads or PAPER_LOADS, slip_grid(args.slip_step))
        except ValueError as error:
            print(f"rover-cosim fig3: {error}", file=sys.stderr)
            return 2
        for path in written:
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
