"""``rover-cosim``: the command behind the Makefile targets."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path


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
    build = commands.add_parser("build-fmus", help="build the FMI 2.0 FMUs (ME + CS) from modelica/ into fmus/")
    build.add_argument("models", nargs="*", help="models to build (default: SingleWheel Rover RoverBody Wheel)")
    build.add_argument("--out", type=Path, default=Path("fmus"), help="output folder (default: fmus)")
    build.add_argument("--backend", default="auto", choices=("auto", "builtin", "omc"),
                       help="auto: omc where OpenModelica is on PATH, else the built-in rumoca/CasADi exporter")
    build.add_argument("--force", action="store_true", help="rebuild even when the FMU is up to date")
    build.add_argument("--jobs", type=int, default=None, help="parallel builds (default: number of CPUs)")
    return parser


def _build_fmus(args: argparse.Namespace) -> int:
    from fmubuild.build import FMU_MODELS, build_all
    from fmubuild.expressions import UnsupportedConstruct

    def report(result) -> None:  # type: ignore[no-untyped-def]
        if result.rebuilt:
            stages = ", ".join(f"{k} {v:.1f} s" for k, v in result.stages.items())
            print(f"built {result.path} in {result.seconds:.1f} s ({stages})", flush=True)
        else:
            print(f"{result.path} is up to date", flush=True)

    if args.jobs is not None and args.jobs < 1:
        print(f"rover-cosim build-fmus: --jobs {args.jobs}: expected >= 1", file=sys.stderr)
        return 2
    try:
        build_all(tuple(args.models) or FMU_MODELS, args.out, force=args.force, jobs=args.jobs,
                  backend=args.backend, report=report)
    except (UnsupportedConstruct, ValueError, RuntimeError) as error:
        print(f"rover-cosim build-fmus: {error}", file=sys.stderr)
        return 1
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.command == "build-fmus":
        return _build_fmus(args)
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
