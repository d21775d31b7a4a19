"""``rover-cosim build-fmus``: the FMUs of the Modelica library."""

from __future__ import annotations

import argparse
from typing import Any

from .command import Command, no_result_set
from .options import add_quiet, fail, path


def _models() -> tuple[str, ...]:
    from rover_cosim.fmubuild.catalog import fmu_models

    return fmu_models()


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("models", nargs="*", help=f"models to build (default: {' '.join(_models())})")
    parser.add_argument("--out", type=path, default="fmus", help="output folder (default: fmus)")
    parser.add_argument("--backend", default="auto", choices=("auto", "builtin", "omc"),
                        help="auto: omc where OpenModelica is on PATH, else the built-in rumoca/CasADi exporter")
    parser.add_argument("--force", action="store_true", help="rebuild even when the FMU is up to date")
    parser.add_argument("--jobs", type=int, default=None, help="parallel builds (default: number of CPUs)")
    parser.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                        help="2 (default): FMI 2.0 FMUs; 3: FMI 3.0 FMUs of the same model code (use another --out)")
    from rover_cosim.fmubuild import elementary

    parser.add_argument("--elementary", default=elementary.DEFAULT, choices=elementary.CHOICES,
                        help="the elementary functions (exp, log, pow, sin, cos, ...) the FMUs compute with: libm "
                        "(default: the C library's, the fastest on each host) or own (the FMUs' own: the same "
                        "bits on every host and platform; slower, see the design page)")
    add_quiet(parser)
    parser.add_argument("--platforms", default="host", metavar="LIST",
                        help="binaries/ folders to build: host (default: this machine's, by $CC or cc), all "
                        "(linux64, win64, darwin64, aarch64-linux, aarch64-darwin) or a comma-separated list of "
                        "those; other than host, cross-compiled by zig (pip install -e '.[platforms]'); "
                        "linux ones for glibc >= 2.17")


def run(args: argparse.Namespace) -> int:
    from rover_cosim.fmubuild.build import FMU_MODELS, build_all, steps_of
    from rover_cosim.fmubuild.expressions import UnsupportedConstruct
    from rover_cosim.fmubuild.platforms import parse as parse_platforms
    from rover_cosim.progress import ProgressBar

    if args.jobs is not None and args.jobs < 1:
        fail("build-fmus", f"--jobs {args.jobs}: expected >= 1")
        return 2
    unknown = [name for name in args.models if name not in FMU_MODELS]
    if unknown:
        fail("build-fmus", f"model {unknown[0]!r}: expected one of {', '.join(FMU_MODELS)}")
        return 2
    try:
        platforms = parse_platforms(args.platforms)
    except ValueError as error:
        fail("build-fmus", str(error))
        return 2
    models = tuple(args.models) or FMU_MODELS
    bar = ProgressBar("build-fmus", enabled=not args.quiet)
    progress = _Progress(bar, len(models), steps_of(platforms))
    try:
        build_all(models, args.out, force=args.force, jobs=args.jobs, backend=args.backend, platforms=platforms,
                  report=progress.report, step=progress.step, fmi_version=args.fmi_version,
                  elementary=args.elementary)
    except (UnsupportedConstruct, ValueError, RuntimeError) as error:
        bar.close()
        fail("build-fmus", str(error))
        return 1
    bar.close()
    return 0


class _Progress:
    """The bar over every FMU's stages (translate, generate, compile <folder>, package), and a line
    per FMU built or found up to date."""

    def __init__(self, bar: Any, fmus: int, per_fmu: int):
        self.bar, self.per_fmu, self.steps, self.total = bar, per_fmu, 0, fmus * per_fmu

    def step(self, _model: str, _stage: str) -> None:
        self.steps += 1
        self.bar(min(1.0, self.steps / max(1, self.total)))

    def report(self, result: Any) -> None:
        self.bar.clear()
        if result.rebuilt:
            stages = ", ".join(f"{k} {v:.1f} s" for k, v in result.stages.items())
            print(f"built {result.path} in {result.seconds:.1f} s ({stages})", flush=True)
        else:
            print(f"{result.path} is up to date", flush=True)
            self.total -= self.per_fmu  # nothing to wait for there


COMMAND = Command(
    "build-fmus", help="build the FMI 2.0 FMUs (ME + CS) from modelica/ into fmus/",
    summary="Build the FMI 2.0 FMUs (Model Exchange + Co-Simulation) from the Modelica library.",
    examples=("rover-cosim build-fmus --out fmus", "rover-cosim build-fmus Wheel --force",
              "rover-cosim build-fmus Wheel --platforms all", "rover-cosim build-fmus --platforms host,win64"),
    arguments=arguments, run=run, result_sets=no_result_set)
