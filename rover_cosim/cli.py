"""rover-cosim: terramechanics rover co-simulation; the command behind the Makefile targets."""

from __future__ import annotations

import argparse
import math
import os
import signal
import sys
import tempfile
import threading
from collections.abc import Sequence
from contextlib import nullcontext
from pathlib import Path
from typing import Any

from rover_cosim import __version__
from rover_cosim.orchestrator.examples import examples

#: Example systems shipped with the package (FMU paths relative to --fmu-dir, default fmus/).
EXAMPLES = examples()


#: Bytes of one file name and of a whole path the file systems take (Linux: NAME_MAX, PATH_MAX).
NAME_MAX, PATH_MAX = 255, 4096


def _path_text(text: str) -> str:
    """A path (or a name standing for one) as given, refused when empty (an empty --out would be
    the current folder, an empty --soil the paper's) or when the system could not open it for its
    length: a name of more than NAME_MAX bytes, a path of more than PATH_MAX."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"{text!r}: expected a path or a name (empty)")
    longest = max((len(os.fsencode(part)) for part in Path(text).parts), default=0)
    if longest > NAME_MAX or len(os.fsencode(text)) >= PATH_MAX:
        shown = repr(text) if len(text) <= 60 else f"{text[:40]!r}...{text[-12:]!r} ({len(text)} characters)"
        raise argparse.ArgumentTypeError(f"{shown}: too long for a file name (expected at most {NAME_MAX} bytes a "
                                         f"name, {PATH_MAX - 1} a path)")
    return text


def _path(text: str) -> Path:
    """A path option (checked as _path_text)."""
    return Path(_path_text(text))


def _scheduler(text: str) -> str:
    """A Dask scheduler's address: [PROTOCOL://]HOST:PORT (tcp://10.0.0.5:8786, tls://[::1]:8786)."""
    import re

    if not re.fullmatch(r"([a-z][a-z0-9+.-]*://)?(\[[0-9A-Fa-f:.]+\]|[^\s/:\[\]]+):\d{1,5}", text):
        raise argparse.ArgumentTypeError(f"{text!r}: expected a Dask scheduler's address, e.g. tcp://host:8786")
    return text


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
        raise argparse.ArgumentTypeError(f"slip step={text!r}: expected a number in (0, 2]") from None
    if not 0 < step <= 2.0:
        raise argparse.ArgumentTypeError(f"slip step={step!r}: expected a number in (0, 2]")
    return step


def _figure_formats(text: str) -> tuple[str, ...]:
    from rover_cosim.common.figures import FORMATS

    formats = tuple(part.strip().lower() for part in text.split(",") if part.strip())
    unknown = [f for f in formats if f not in FORMATS]
    if unknown or not formats:
        raise argparse.ArgumentTypeError(f"figures={text!r}: expected some of {', '.join(FORMATS)}, comma-separated")
    return formats


def _slip_range(text: str) -> tuple[float, float]:
    try:
        first, last = (float(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"slip range={text!r}: expected FIRST,LAST (e.g. -0.5,0.9)") from None
    if not -1.0 <= first < last <= 1.0:
        raise argparse.ArgumentTypeError(f"slip range={text!r}: expected -1 <= FIRST < LAST <= 1")
    return first, last


def _add_soil_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--soil", type=_path_text, default=None, help="soil: a name of the shipped library "
                        "(rover-cosim soils lists them), a TOML file, or FILE:NAME (default: paper)")
    parser.add_argument("--wheel", type=_path_text, default=None,
                        help="wheel: a name of the shipped library, a TOML file, or FILE:NAME (default: paper)")
    parser.add_argument("--set", dest="assignments", action="append", default=[], metavar="KIND.NAME=VALUE",
                        help="change one value, SI units or *_deg for angles: --set soil.c=500 "
                        "--set soil.phi_deg=30 --set wheel.b=0.2 (repeatable)")


def _choice(args: argparse.Namespace, command: str):  # noqa: ANN202 - Choice, imported lazily
    """The soil and wheel of the command line, or None after printing why not."""
    from rover_cosim.terramechanics.library import choose

    try:
        return choose(args.soil, args.wheel, args.assignments)
    except (ValueError, TypeError) as error:
        print(f"rover-cosim {command}: {error}", file=sys.stderr)
        return None


class _Help(argparse.RawDescriptionHelpFormatter):
    """Every option's default in its help, unless the help already states it."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if ("default" in text or action.default in (None, argparse.SUPPRESS, False, []) or action.nargs == 0
                or action.option_strings == []):
            return text
        return f"{text} (default: {action.default})"


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="rover-cosim", description=__doc__, formatter_class=_Help,
                                     epilog="exit codes: 0 done; 1 the work failed (a run, a study where every "
                                     "run failed); 2 bad input (nothing computed); 130 interrupted")
    parser.add_argument("--version", action="version", version=f"rover-cosim {__version__}")
    parser.add_argument("--figures", type=_figure_formats, default=("png",), metavar="FORMATS",
                        help="formats every figure is written in, beside PNG: e.g. png,pdf,svg (default: png)")
    parser.add_argument("--dpi", type=float, default=None,
                        help="resolution of the PNG figures (default: each figure's own, 100-150)")
    commands = parser.add_subparsers(dest="command", required=True)
    original = commands.add_parser
    commands.add_parser = lambda *a, **k: original(*a, formatter_class=_Help, **k)  # type: ignore[method-assign]
    fig3 = commands.add_parser("fig3", help="paper Fig. 3: Fx against slip for loads 100..800 N (numpy reference)")
    fig3.add_argument("--out", type=_path, default=Path("results"), help="output folder (default: results)")
    fig3.add_argument("--loads", type=_positive_loads, default=None,
                      help="comma-separated wheel loads [N] (default: 100,200,...,800)")
    fig3.add_argument("--slip-step", type=_slip_step, default=0.01,
                      help="slip spacing, adjusted so that both ends of the range are points (default: 0.01)")
    fig3.add_argument("--slip-range", type=_slip_range, default=(0.0, 0.9), metavar="FIRST,LAST",
                      help="slip ratios from FIRST to LAST in [-1, 1] (negative: braking; default: 0,0.9)")
    _add_soil_options(fig3)
    run = commands.add_parser("run", help="co-simulate a system file (TOML or SSP) -> CSV + JSON sidecar")
    run.add_argument("system", type=_path_text,
                     help="system file (.toml, or an .ssp archive), one FMU (.fmu: run alone, with its "
                     "DefaultExperiment unless --stop-time/--step say otherwise), or the name of a shipped example: "
                     + ", ".join(EXAMPLES))
    run.add_argument("-o", "--output", type=_path, default=None,
                     help="CSV (full precision) or .parquet to write (default: results/<system name>.csv); a .json "
                     "sidecar goes beside it")
    run.add_argument("--fmu-dir", type=_path, default=None,
                     help="folder for relative FMU paths (default: the system file's folder; fmus/ for examples)")
    run.add_argument("--algorithm", choices=("jacobi", "gauss-seidel", "iterative"), default=None,
                     help="override the system file's master algorithm")
    run.add_argument("--step", type=float, default=None, help="override the communication step [s]")
    run.add_argument("--stop-time", type=float, default=None, help="override the stop time [s]")
    run.add_argument("--output-interval", type=float, default=None,
                     help="record a row every so often [s] (a whole number of steps; the last row always)")
    run.add_argument("--threads", type=int, default=None,
                     help="FMUs stepped at the same time (Jacobi; Gauss-Seidel where inputs are ready); "
                     "default: the system file's, else the number of cores")
    run.add_argument("--interface", choices=("co-simulation", "model-exchange"), default=None,
                     help="one FMU run alone: the interface to run (default: Co-Simulation where it has it; "
                     "Model Exchange is integrated by CVode)")
    run.add_argument("--start", type=_assignment, action="append", metavar="NAME=VALUE",
                     help="one FMU run alone: a parameter or start value (repeatable; TOML values: 2.5, 3, true, "
                     "\"text\")")
    run.add_argument("--input", type=_path, default=None, metavar="CSV",
                     help="one FMU run alone: input signals, first column time [s], one column per input "
                     "(continuous Real inputs interpolated, the others held; a repeated time is a step)")
    run.add_argument("--overwrite", action="store_true",
                     help="replace --output even if it is not a result of rover-cosim run")
    run.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    _add_soil_options(run)

    ssp = commands.add_parser("export-ssp", help="write a system file (TOML) as an SSP 1.0 archive (.ssp) that "
                              "FMPy, libcosim and OMSimulator read")
    ssp.add_argument("system", type=_path_text,
                     help="system file, or the name of a shipped example: " + ", ".join(EXAMPLES))
    ssp.add_argument("-o", "--output", type=_path, required=True, help="the .ssp archive to write")
    ssp.add_argument("--overwrite", action="store_true",
                     help="replace --output even if it is not an archive this command wrote")
    ssp.add_argument("--fmu-dir", type=_path, default=None,
                     help="folder for relative FMU paths (default: the system file's folder; fmus/ for examples)")

    study = commands.add_parser("cosim-study", help="coupling error of the co-simulated rover against the "
                                "monolithic one, Jacobi, Gauss-Seidel and iterative, steps 1-10 ms -> CSV + PNG")
    study.add_argument("--out", type=_path, default=Path("results/cosim_study"), help="output folder")
    study.add_argument("--fmu-dir", type=_path, default=Path("fmus"), help="where the FMUs are (default: fmus)")
    study.add_argument("-q", "--quiet", action="store_true", help="no progress bar")

    ident = commands.add_parser("identify", help="paper Sec. 3: step-torque sweep on SingleWheel.fmu, LUT and "
                                "Fx(W, slip) fits, validation at 275/575/875 N -> results/identification/")
    ident.add_argument("--out", type=_path, default=Path("results/identification"), help="output folder")
    ident.add_argument("--fmu", type=_path, default=Path("fmus/SingleWheel.fmu"), help="the test-bed FMU")
    ident.add_argument("--workers", type=int, default=None, help="local processes (default: all cores; 1: serial)")
    ident.add_argument("--scheduler", type=_scheduler, default=None, help="run on a Dask cluster, e.g. tcp://host:8786")
    ident.add_argument("--cache", type=_path, default=None, help="run cache (default: <out>/cache)")
    ident.add_argument("--record-interval", type=float, default=0.001,
                       help="rows kept in runs.csv [s] (a whole number of the sweep's 0.1 ms samples; default "
                       "0.001; 0.0001: every sample); the fits use every sample")
    _add_soil_options(ident)
    ident.add_argument("-q", "--quiet", action="store_true", help="no progress bar")

    simulate = commands.add_parser("simulate", help="paper Sec. 4: closed-loop rover, 20 s, on Rover.fmu and on "
                                   "RoverBody + 6 Wheel; then the steerable rover following a turn and a lane "
                                   "change -> results/simulation/")
    simulate.add_argument("--out", type=_path, default=Path("results/simulation"), help="output folder")
    simulate.add_argument("--fmu-dir", type=_path, default=Path("fmus"), help="where the FMUs are")
    simulate.add_argument("--model", type=_path, default=Path("results/identification/model.json"),
                          help="identified model (from `rover-cosim identify`)")
    simulate.add_argument("--only", choices=("straight", "path", "terrain"), default=None,
                          help="only the paper's straight run, only the path following, or only the terrain "
                               "scenarios (side-slope traverses; default: all three)")
    simulate.add_argument("--allow-model-mismatch", action="store_true",
                          help="use a model identified on another soil or wheel (refused otherwise; recorded)")
    simulate.add_argument("--adapt", action="store_true",
                          help="also run the straight run with the adaptive controller: a calibration phase, the "
                          "soil estimated from the rover's telemetry, the model identified again on SingleWheel.fmu "
                          "(implies --allow-model-mismatch: the point is a soil the model was not identified on)")
    simulate.add_argument("--calibration", type=float, default=3.0, metavar="SECONDS",
                          help="with --adapt: the calibration phase's length [s] (default 3)")
    simulate.add_argument("--sinkage-sensor", action="store_true",
                          help="with --adapt: the rover measures its wheels' sinkage (the estimate uses it)")
    simulate.add_argument("--record-interval", type=float, default=0.01,
                          help="rows kept in the trajectory files [s] (a whole number of 1 ms steps; default 0.01; "
                          "0.001: every step); metrics and figures use every step")
    simulate.add_argument("--crossing-soil", default="hit_lss1", metavar="SOIL",
                          help="the soil crossing's second soil, beyond its boundary: a library name, a TOML file or "
                          "FILE:NAME (default: hit_lss1)")
    simulate.add_argument("--crossing-belief", default=None, metavar="SOIL",
                          help="the second soil the soil crossing's controller believes in (its models are identified "
                          "on it), e.g. the soil.toml of `rover-cosim estimate-soil` (default: --crossing-soil)")
    simulate.add_argument("-q", "--quiet", action="store_true", help="no progress bars")
    _add_soil_options(simulate)

    monte = commands.add_parser("montecarlo", help="Monte Carlo over soil uncertainty: the paper's closed loop with "
                                "the identified model on every sampled soil, local processes or a Dask cluster -> "
                                "results/montecarlo/")
    monte.add_argument("--study", type=_path_text, default="lunar_regolith",
                       help="study file (TOML), or a shipped study: lunar_regolith (default)")
    monte.add_argument("--model", type=_path, default=Path("results/identification/model.json"),
                       help="identified model (from `rover-cosim identify` on the study's nominal soil)")
    monte.add_argument("--fmu-dir", type=_path, default=Path("fmus"), help="where the FMUs are")
    monte.add_argument("--out", type=_path, default=Path("results/montecarlo"), help="output folder")
    monte.add_argument("--runs", type=int, default=None, help="number of samples, the nominal included "
                       "(default: the study's)")
    monte.add_argument("--seed", type=int, default=None, help="random seed (default: the study's)")
    monte.add_argument("--workers", type=int, default=None, help="local processes (default: all cores; 1: serial)")
    monte.add_argument("--scheduler", type=_scheduler, default=None, help="run on a Dask cluster, e.g. tcp://host:8786")
    monte.add_argument("--cache", type=_path, default=None, help="run cache (default: <out>/cache)")
    monte.add_argument("--allow-model-mismatch", action="store_true",
                       help="use a model identified on another soil or wheel than the study's nominal ones "
                       "(refused otherwise; recorded)")
    monte.add_argument("--adapt", action="store_true",
                       help="also run every sample with the adaptive controller (a calibration phase, the soil "
                       "estimated from the rover's telemetry, the model identified again on SingleWheel.fmu): the "
                       "scenario straight_adapted beside straight, compared after the calibration")
    monte.add_argument("-q", "--quiet", action="store_true", help="no progress bar")

    soils = commands.add_parser("soils", help="the shipped soils and wheels (for --soil, --wheel), with their sources; "
                                "`soils NAME` shows one with every value and its unit")
    soils.add_argument("name", nargs="?", type=_path_text, default=None,
                       help="a soil or wheel (shipped name, TOML file or FILE:NAME)")
    commands.add_parser("blocks", help="the block types of system files, with their keys, units and defaults")
    _add_soil_estimation_commands(commands)

    report = commands.add_parser("report", help="results/report.html: figures and tables beside the paper's")
    report.add_argument("--results", type=_path, default=Path("results"), help="the results folder")
    report.add_argument("--out", type=_path, default=None, help="HTML file (default: <results>/report.html)")
    report.add_argument("--overwrite", action="store_true",
                        help="replace --out even if it is not a report this command wrote")

    build = commands.add_parser("build-fmus", help="build the FMI 2.0 FMUs (ME + CS) from modelica/ into fmus/")
    build.add_argument("models", nargs="*", help="models to build (default: SingleWheel Rover RoverBody Wheel "
                       "SteerableRover SteerableRoverBody)")
    build.add_argument("--out", type=_path, default=Path("fmus"), help="output folder (default: fmus)")
    build.add_argument("--backend", default="auto", choices=("auto", "builtin", "omc"),
                       help="auto: omc where OpenModelica is on PATH, else the built-in rumoca/CasADi exporter")
    build.add_argument("--force", action="store_true", help="rebuild even when the FMU is up to date")
    build.add_argument("--jobs", type=int, default=None, help="parallel builds (default: number of CPUs)")
    build.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                       help="2 (default): FMI 2.0 FMUs; 3: FMI 3.0 FMUs of the same model code (use another --out)")
    build.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    build.add_argument("--platforms", default="host", metavar="LIST",
                       help="binaries/ folders to build: host (default: this machine's, by $CC or cc), all "
                       "(linux64, win64, darwin64, aarch64-linux, aarch64-darwin) or a comma-separated list of "
                       "those; other than host, cross-compiled by zig (pip install -e '.[platforms]'); "
                       "linux ones for glibc >= 2.17")
    for name, sub in commands.choices.items():
        summary, *examples = USAGE[name]
        sub.description = summary
        sub.epilog = "examples:\n" + "\n".join(f"  {example}" for example in examples)
    return parser


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


def _numbers(kind: str, low: float, high: float, unit: str):  # noqa: ANN202 - an argparse type
    """A type of comma-separated numbers in [low, high] (``kind`` names them in messages)."""
    def parse(text: str) -> tuple[float, ...]:
        try:
            values = tuple(float(part) for part in text.split(","))
        except ValueError:
            raise argparse.ArgumentTypeError(f"{kind}={text!r}: expected comma-separated numbers{unit}") from None
        bad = [v for v in values if not low <= v <= high]
        if bad:
            raise argparse.ArgumentTypeError(f"{kind} {bad[0]!r}: expected a number in [{low:g}, {high:g}]{unit}")
        return values
    return parse


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 <= value <= 1:
        raise argparse.ArgumentTypeError(f"noise={text!r}: expected a fraction of each channel's range in [0, 1] "
                                         "(e.g. 0.02)")
    return value


#: The measured channels of single-wheel data (identification.testbed_data.CHANNELS).
CHANNEL_NAMES = ("Fx_N", "Tx_Nm", "sinkage_m", "Fy_N")


def _add_soil_estimation_commands(commands: Any) -> None:
    """estimate-soil and testbed-data (issue 33); the channels are named here without importing the
    estimator (it imports SciPy: seconds before --help; tests/test_soil_estimation.py keeps them equal)."""
    est = commands.add_parser("estimate-soil", help="soil parameters (c, phi, kphi, n, kx, ...) estimated from "
                              "single-wheel test-bed data (CSV) -> soil.toml, estimate.json, figures")
    est.add_argument("data", type=_path, help="CSV file: columns load_N, slip, any of Fx_N, Tx_Nm, sinkage_m, Fy_N "
                     "and optionally slip_angle_deg; one row per steady-state measurement")
    est.add_argument("--out", type=_path, default=Path("results/soil_estimate"), help="output folder")
    est.add_argument("--wheel", type=_path_text, default=None,
                     help="the test bed's wheel: a name of the shipped library, a TOML file, or FILE:NAME (default: "
                     "paper)")
    est.add_argument("--prior", type=_path_text, default=None,
                     help="the soil the search starts from; what is not estimated keeps its value: a shipped name, a "
                     "TOML file or FILE:NAME (default: paper)")
    est.add_argument("--set", dest="assignments", action="append", default=[], metavar="KIND.NAME=VALUE",
                     help="change one value of the prior or wheel (soil.c=500, wheel.b=0.2; repeatable)")
    est.add_argument("--parameters", type=_names, default=None, metavar="NAMES",
                     help="comma-separated soil fields to estimate, e.g. c,phi,kphi,n,kx (default: what the data's "
                     "columns allow; a0, a1, lam and the slip-angle growths only if the data determine them)")
    est.add_argument("--noise-scale", type=_noise_scales, default=None, metavar="CHANNEL=SD,...",
                     help="standard deviation of each channel's measurement noise in its unit, e.g. Fx_N=2,Tx_Nm=0.8 "
                     "(default: estimated from the fit's residuals)")
    gen = commands.add_parser("testbed-data", help="single-wheel test-bed data (the CSV estimate-soil reads) from the "
                              "reference wheel on a known soil, with seeded noise")
    gen.add_argument("--out", type=_path, required=True, help="the CSV file to write (.csv; a .json record of the "
                     "truth goes beside it)")
    _add_soil_options(gen)
    gen.add_argument("--loads", type=_positive_loads, default=None,
                     help="comma-separated wheel loads [N] (default: 150,300,450,600,750)")
    gen.add_argument("--slips", type=_numbers("slip", -1.0, 1.0, ""), default=None,
                     help="comma-separated slip ratios in [-1, 1] (default: -0.2,-0.1,...,0.8)")
    gen.add_argument("--slip-angles", type=_numbers("slip angle", -89.0, 89.0, " deg"), default=(0.0,),
                     metavar="DEGREES", help="comma-separated slip angles [deg]; any other than 0 adds Fy_N "
                     "(default: 0)")
    gen.add_argument("--channels", type=lambda text: tuple(p.strip() for p in text.split(",")), default=None,
                     help=f"measured columns, of {', '.join(CHANNEL_NAMES)} (default: Fx_N, Tx_Nm, sinkage_m, and "
                     "Fy_N at slip angles other than 0)")
    gen.add_argument("--sinkage", action=argparse.BooleanOptionalAction, default=True,
                     help="write the sinkage_m column (--no-sinkage: a test bed without a sinkage sensor)")
    gen.add_argument("--noise", type=_fraction, default=0.0,
                     help="Gaussian noise on every measured channel, its standard deviation a fraction of the "
                     "channel's range, e.g. 0.02 (default: 0)")
    gen.add_argument("--seed", type=int, default=0, help="seed of the noise (default: 0)")
    gen.add_argument("--overwrite", action="store_true",
                     help="replace --out even if it is not data this command wrote")


#: Per command: what it does (one line), then examples.
USAGE = {
    "fig3": ("Paper Fig. 3 from the numpy reference wheel: Fx against slip for several loads (CSV, PNG, JSON).",
             "rover-cosim fig3 --out results", "rover-cosim fig3 --soil lete_sand --slip-range=-0.5,0.9 --out results"),
    "run": ("Co-simulate a system file, an SSP archive or one FMU; trajectories as CSV (or Parquet) and a JSON record.",
            "rover-cosim run rover_cosim --fmu-dir fmus -o results/rover.csv",
            "rover-cosim run BouncingBall.fmu --interface model-exchange --stop-time 3 -o ball.csv",
            "rover-cosim run model.fmu --start gain=2 --input signals.csv -o out.parquet"),
    "export-ssp": ("Write a system file as an SSP 1.0 archive that FMPy, libcosim and OMSimulator read.",
                   "rover-cosim export-ssp rover_cosim --fmu-dir fmus -o rover.ssp"),
    "cosim-study": ("Coupling error of the co-simulated rover against the monolithic one per master and step.",
                    "rover-cosim cosim-study --fmu-dir fmus --out results/cosim_study"),
    "identify": ("Paper Sec. 3: the torque-step sweep on SingleWheel.fmu, the Fx(W, slip) models and Table 1.",
                 "rover-cosim identify --out results/identification",
                 "rover-cosim identify --soil my_soil.toml --out results/my_soil/identification --workers 2"),
    "simulate": ("Paper Sec. 4: the closed-loop rover on Rover.fmu and RoverBody + 6 Wheel, then path following.",
                 "rover-cosim simulate --out results/simulation", "rover-cosim simulate --only straight --quiet"),
    "montecarlo": ("The paper's closed loop over sampled soils: how often the 1 N RMS holds, and what matters most.",
                   "rover-cosim montecarlo --runs 20 --workers 2", "rover-cosim montecarlo --study my_study.toml"),
    "estimate-soil": ("Soil parameters with intervals from single-wheel test-bed data; soil.toml for --soil.",
                      "rover-cosim estimate-soil data.csv --out results/my_soil",
                      "rover-cosim estimate-soil data.csv --prior lunar_nominal --parameters c,phi,kphi,n,kx"),
    "testbed-data": ("Single-wheel test-bed data from the reference wheel on a known soil, with seeded noise.",
                     "rover-cosim testbed-data --soil lunar_nominal --noise 0.02 --seed 1 --out data.csv",
                     "rover-cosim testbed-data --soil paper --slip-angles 0,5,10 --no-sinkage --out lateral.csv"),
    "soils": ("The shipped soils and wheels with their sources; one of them with every value and unit.",
              "rover-cosim soils", "rover-cosim soils lete_sand"),
    "blocks": ("The block types a system file may use, with their keys, units and defaults.", "rover-cosim blocks"),
    "report": ("One self-contained HTML page of the results: figures, tables, provenance.",
               "rover-cosim report --results results"),
    "build-fmus": ("Build the FMI 2.0 FMUs (Model Exchange + Co-Simulation) from the Modelica library.",
                   "rover-cosim build-fmus --out fmus", "rover-cosim build-fmus Wheel --force",
                   "rover-cosim build-fmus Wheel --platforms all", "rover-cosim build-fmus --platforms host,win64"),
}


def _system_path(args: argparse.Namespace) -> tuple[Path, Path | None]:
    """The system file and FMU folder of ``args`` (a shipped example by name, unless a file of
    that name exists)."""
    path, fmu_dir = Path(args.system), args.fmu_dir
    if not path.is_file() and args.system in EXAMPLES:
        path, fmu_dir = EXAMPLES[args.system], fmu_dir or Path("fmus")
    return path, fmu_dir


def _load_run_system(args: argparse.Namespace, unpack: Path):  # noqa: ANN202 - System, imported lazily
    """The system of ``rover-cosim run`` with the command line's overrides (SystemFileError if
    bad); an .ssp archive is unpacked into ``unpack``."""
    from rover_cosim.orchestrator.builder import replace_settings
    from rover_cosim.orchestrator.ssp import SspError, load_ssp
    from rover_cosim.orchestrator.system import SystemFileError, load_system

    path, fmu_dir = _system_path(args)
    overrides = {key: value for key, value in (("algorithm", args.algorithm), ("step", args.step),
                                               ("stop_time", args.stop_time), ("threads", args.threads),
                                               ("output_interval", args.output_interval))
                 if value is not None}
    if path.suffix.lower() == ".fmu":
        return _one_fmu(path, overrides, args), path  # the overrides are its settings
    given = [flag for flag, value in (("--interface", args.interface), ("--start", args.start),
                                      ("--input", args.input)) if value]
    if given:
        raise SystemFileError(f"{path}: {', '.join(given)} apply to one FMU run alone (rover-cosim run model.fmu); "
                              "a system file gives its FMUs' interface, start values and inputs itself")
    if path.suffix.lower() == ".ssp":
        try:  # the overrides are settings of the archive's system, checked as its own
            return load_ssp(path, unpack, overrides), path
        except SspError as error:
            raise SystemFileError(f"{path}: {error}") from None
    system = load_system(path, fmu_dir=fmu_dir)
    if overrides:
        system = replace_settings(system, name=f"{path} (with command-line overrides)", **overrides)
    return system, path


def _one_fmu(path: Path, settings: dict[str, Any], args: argparse.Namespace):  # noqa: ANN202 - System
    """A system of the one FMU ``path`` (instance ``model``), every output recorded, the stop time
    and step from ``settings`` or the FMU's DefaultExperiment, the values of --start and the
    input file of --input."""
    from rover_cosim.orchestrator.single import single_fmu_system

    system, notes = single_fmu_system(path, settings, interface=args.interface, values=dict(args.start or []),
                                      input_file=args.input)
    for note in notes:
        print(f"rover-cosim run: {note}", file=sys.stderr)
    return system


def _assignment(text: str) -> tuple[str, Any]:
    """``NAME=VALUE`` of --start: the value as TOML writes it (1.5, 3, true, "text"), else as text."""
    import tomllib

    name, equals, value = text.partition("=")
    if not equals or not name.strip():
        raise argparse.ArgumentTypeError(f"{text!r}: expected NAME=VALUE (e.g. h=2.5, on=true, label=\"moon\")")
    try:
        return name.strip(), tomllib.loads(f"v = {value.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        return name.strip(), value.strip()


def _export_ssp(args: argparse.Namespace) -> int:
    from rover_cosim.orchestrator.ssp import SspError, export_ssp, validate_ssd
    from rover_cosim.orchestrator.system import SystemFileError, load_system

    path, fmu_dir = _system_path(args)
    problem = _unwritable(args.output) or (None if args.overwrite else _foreign(args.output, "export-ssp"))
    if problem:
        print(f"rover-cosim export-ssp: -o {args.output}: {problem}", file=sys.stderr)
        return 2
    try:
        exported = export_ssp(load_system(path, fmu_dir=fmu_dir), args.output)
        validate_ssd(exported.path)
    except (SystemFileError, SspError) as error:
        print(f"rover-cosim export-ssp: {error}", file=sys.stderr)
        return 2
    print(f"wrote {exported.path} (SystemStructure.ssd valid against the SSP 1.0 schema)")
    if exported.folded:
        print(f"constant blocks {', '.join(exported.folded)}: folded into the start values of the inputs they drive")
    if exported.external:
        print(f"blocks {', '.join(exported.external)}: Python, kept in an org.rover-cosim annotation (rover-cosim "
              "run restores them); other tools see their signals as the system's connectors <block>_<signal>")
    return 0


def _run(args: argparse.Namespace) -> int:
    from rover_cosim.orchestrator.builder import with_parameters
    from rover_cosim.orchestrator.system import SystemFileError
    from rover_cosim.terramechanics.library import describe, fmu_parameters

    choice = None
    if args.soil or args.wheel or args.assignments:
        choice = _choice(args, "run")
        if choice is None:
            return 2
    from rover_cosim.common.scratch import remove_stale_folders, scratch_prefix

    remove_stale_folders()
    with tempfile.TemporaryDirectory(prefix=scratch_prefix("ssp")) as unpack:
        try:
            system, path = _load_run_system(args, Path(unpack))
        except SystemFileError as error:
            print(f"rover-cosim run: {error}", file=sys.stderr)
            return 2
        extra = None
        if choice is not None:  # the chosen soil and wheel go to every FMU that has them
            system = with_parameters(system, fmu_parameters(choice.soil, choice.wheel))
            extra = describe(choice)
        return _run_system(args, system, path, extra)


def _run_system(args: argparse.Namespace, system, path: Path,  # noqa: ANN001 - System, imported lazily
                extra: dict[str, Any] | None = None) -> int:
    from rover_cosim.orchestrator.master import RunError, run
    from rover_cosim.orchestrator.runs import PartialWriter, sidecar_path, write_run
    from rover_cosim.progress import ProgressBar

    output = args.output or Path("results") / f"{path.stem}.csv"
    try:
        sidecar_path(output)
    except ValueError as error:
        print(f"rover-cosim run: {error}", file=sys.stderr)
        return 2
    problem = _unwritable(output, _run_bytes(system)) or (None if args.overwrite else _foreign(output, "run"))
    if problem:  # said before the run, not after it
        print(f"rover-cosim run: output {output}: {problem}", file=sys.stderr)
        return 2
    bar = ProgressBar(path.stem, enabled=not args.quiet)
    partial = PartialWriter(system, output)
    try:
        result = run(system, progress=bar, observers=[partial])
    except RunError as error:
        bar.close()
        kept = ""
        if partial.written:
            kept = f"; the {len(error.partial)} rows computed before it are in {partial.written[0]} (partial)"
        print(f"rover-cosim run: {error} ({output} not written{kept})", file=sys.stderr)
        return 1
    bar.close()
    for written in write_run(system, result, output, extra=extra):
        print(f"wrote {written}")
    if result.stopped:
        print(f"stopped: {result.stopped}")
    print(f"{result.steps} steps of {system.step:g} s ({system.algorithm}) in {result.wall_seconds:.2f} s")
    return 0


def _run_bytes(system) -> float:  # noqa: ANN001 - System, imported lazily
    """About the bytes of a run's CSV: its rows and recorded columns at ~25 characters a value."""
    rows = (system.stop_time - system.start_time) / system.step / system.record_every + 2
    return rows * (len(system.record) + 1) * 25


def _cosim_study(args: argparse.Namespace) -> int:
    from rover_cosim.jobs.cosim_study import systems, write_cosim_study
    from rover_cosim.orchestrator.master import RunError
    from rover_cosim.orchestrator.system import SystemFileError
    from rover_cosim.progress import ProgressBar

    if not _output_folder(args.out, "cosim-study"):
        return 2
    if not args.fmu_dir.is_dir():
        print(f"rover-cosim cosim-study: --fmu-dir {args.fmu_dir}: no such folder (build the FMUs with "
              "`rover-cosim build-fmus`)", file=sys.stderr)
        return 2
    try:
        systems(args.fmu_dir)  # its FMUs there
    except SystemFileError as error:
        print(f"rover-cosim cosim-study: --fmu-dir {args.fmu_dir}: {error}", file=sys.stderr)
        return 2
    bar = ProgressBar("cosim-study", enabled=not args.quiet)
    try:
        outcome = write_cosim_study(args.fmu_dir, args.out, progress=bar)
    except (SystemFileError, RunError) as error:
        bar.close()
        print(f"rover-cosim cosim-study: {error} (nothing written)", file=sys.stderr)
        return 1
    bar.close()
    print(outcome.table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    for path in outcome.files:
        print(f"wrote {path}")
    return 0


def _identify(args: argparse.Namespace) -> int:
    from rover_cosim.common.rows import steps_between_rows
    from rover_cosim.identification.sweep import SweepPlan
    from rover_cosim.jobs.identify import run_identification
    from rover_cosim.progress import ProgressBar

    if not _output_folder(args.out, "identify") or (args.cache and not _output_folder(args.cache, "identify", 0,
                                                                                       "--cache")):
        return 2
    if args.workers is not None and args.workers < 1:
        print(f"rover-cosim identify: --workers {args.workers}: expected >= 1", file=sys.stderr)
        return 2
    try:
        steps_between_rows(args.record_interval, SweepPlan().sample_time)
    except ValueError as error:
        print(f"rover-cosim identify: --record-interval: {error}", file=sys.stderr)
        return 2
    if not args.fmu.is_file():
        print(f"rover-cosim identify: FMU {args.fmu} not found (build them with `rover-cosim build-fmus`)",
              file=sys.stderr)
        return 2
    if not _is_fmu(args.fmu):
        print(f"rover-cosim identify: --fmu {args.fmu}: not an FMU (expected a zip archive holding a "
              "modelDescription.xml, e.g. fmus/SingleWheel.fmu)", file=sys.stderr)
        return 2
    choice = _choice(args, "identify")
    if choice is None:
        return 2
    bar = ProgressBar("sweep", enabled=not args.quiet)
    try:
        outcome = run_identification(args.fmu, args.out, workers=args.workers, scheduler=args.scheduler,
                                     cache_dir=args.cache, progress=bar, choice=choice,
                                     record_interval=args.record_interval)
    except (OSError, RuntimeError, ValueError) as error:
        bar.close()
        print(f"rover-cosim identify: {error} (nothing written)", file=sys.stderr)
        return 1
    bar.close()
    for name, sweep in (("sweep", outcome.sweep), ("lateral sweep", outcome.lateral_sweep)):
        print(f"{name}: {sweep.computed} runs computed, {sweep.cached} from the cache, "
              f"{len(sweep.failures)} failed, {sweep.wall_seconds:.1f} s")
    print("Table 1, Fit of Fx [%]:")
    print(outcome.fit.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    print("Lateral model, Fit of Fy [%] (Eq. 15) and largest settled error:")
    print(outcome.lateral_fit.to_string(index=False, float_format=lambda v: f"{v:.1f}"))
    for path in outcome.files:
        print(f"wrote {path}")
    return 0


def _is_fmu(path: Path) -> bool:
    """Whether ``path`` is an FMU: a zip archive with a modelDescription.xml."""
    import zipfile

    try:
        with zipfile.ZipFile(path) as archive:
            return "modelDescription.xml" in archive.namelist()
    except (OSError, zipfile.BadZipFile):
        return False


def _crossing_soils_known(args: argparse.Namespace) -> bool:
    """Whether the soil crossing's soils (--crossing-soil, --crossing-belief) are known; else says why."""
    from rover_cosim.terramechanics.library import choose

    for option, name in (("--crossing-soil", args.crossing_soil), ("--crossing-belief", args.crossing_belief)):
        try:
            if name is not None:
                choose(soil=name)
        except ValueError as error:
            print(f"rover-cosim simulate: {option}: {error}", file=sys.stderr)
            return False
    return True


def _simulate(args: argparse.Namespace) -> int:
    from rover_cosim.common.rows import steps_between_rows
    from rover_cosim.jobs.simulate import STEP
    from rover_cosim.orchestrator.master import RunError
    from rover_cosim.orchestrator.system import SystemFileError

    if not _output_folder(args.out, "simulate"):
        return 2
    if not args.fmu_dir.is_dir():
        print(f"rover-cosim simulate: --fmu-dir {args.fmu_dir}: no such folder (build the FMUs with "
              "`rover-cosim build-fmus`)", file=sys.stderr)
        return 2
    try:
        steps_between_rows(args.record_interval, STEP)
    except ValueError as error:
        print(f"rover-cosim simulate: --record-interval: {error}", file=sys.stderr)
        return 2
    if args.adapt and not (math.isfinite(args.calibration) and 0 < args.calibration < 20.0):
        print(f"rover-cosim simulate: --calibration {args.calibration}: expected a length in (0, 20) s, shorter "
              "than the 20 s run", file=sys.stderr)
        return 2
    if not _model_readable(args.model, "simulate"):
        return 2
    choice = _choice(args, "simulate")
    if choice is None:
        return 2
    if args.only in (None, "terrain") and not _crossing_soils_known(args):
        return 2
    try:
        _simulate_runs(args, choice)
    except (SystemFileError, RunError, ValueError) as error:
        print(f"rover-cosim simulate: {error} (nothing written)", file=sys.stderr)
        return 1
    return 0


def _simulate_runs(args: argparse.Namespace, choice: Any) -> None:
    """The runs ``rover-cosim simulate`` asked for (``--only``): the paper's straight run, the path
    following, the terrain scenarios, each writing its files."""
    from rover_cosim.control.adaptive import Calibration
    from rover_cosim.jobs.path_following import run_path_following
    from rover_cosim.jobs.simulate import run_simulation
    from rover_cosim.jobs.terrain import SoilCrossingScenario, run_terrain
    from rover_cosim.progress import ProgressBar

    allow = args.allow_model_mismatch or args.adapt
    adapt = Calibration(duration=args.calibration, sinkage_sensor=args.sinkage_sensor) if args.adapt else None
    if args.only in (None, "straight"):
        bar = ProgressBar("simulate: the paper's straight run", enabled=not args.quiet)
        straight = run_simulation(args.fmu_dir, args.model, args.out, choice, allow_model_mismatch=allow,
                                  progress=bar, record_interval=args.record_interval, adapt=adapt)
        bar.close()
        _print_straight(straight)
    if args.only in (None, "path"):
        bar = ProgressBar("simulate: path following", enabled=not args.quiet)
        path = run_path_following(args.fmu_dir, args.model, args.out, choice=choice, allow_model_mismatch=allow,
                                  progress=bar, record_interval=args.record_interval)
        bar.close()
        _print_path(path)
    if args.only in (None, "terrain"):
        bar = ProgressBar("simulate: side-slope traverses", enabled=not args.quiet)
        crossing = SoilCrossingScenario(soil_b=args.crossing_soil, believed_soil_b=args.crossing_belief)
        terrain = run_terrain(args.fmu_dir, args.model, args.out, choice=choice, allow_model_mismatch=allow,
                              progress=bar, record_interval=args.record_interval, crossing=crossing)
        bar.close()
        _print_terrain(terrain)


def _model_readable(path: Path, command: str) -> bool:
    """Whether ``path`` is an identified model (read whole, as the command will); else says why."""
    from rover_cosim.identification.model_set import ModelFileError, ModelSet

    try:
        ModelSet.read(path)
    except ModelFileError as error:
        print(f"rover-cosim {command}: {error}", file=sys.stderr)
        return False
    return True


def _montecarlo(args: argparse.Namespace) -> int:
    from rover_cosim.jobs.montecarlo import StudyError, load_study, run_montecarlo
    from rover_cosim.progress import ProgressBar

    for option, value, least in (("--workers", args.workers, 1), ("--runs", args.runs, 1), ("--seed", args.seed, 0)):
        if value is not None and value < least:
            print(f"rover-cosim montecarlo: {option} {value}: expected >= {least}", file=sys.stderr)
            return 2
    try:
        study = load_study(args.study, runs=args.runs, seed=args.seed)
        study = study.adapted() if args.adapt else study
        study.check_calibration()
    except StudyError as error:
        print(f"rover-cosim montecarlo: {error}", file=sys.stderr)
        return 2
    if not _output_folder(args.out, "montecarlo", NEEDS["montecarlo"] + MONTECARLO_RUN_BYTES * study.runs) or (
            args.cache and not _output_folder(args.cache, "montecarlo", 0, "--cache")):
        return 2
    if not _model_readable(args.model, "montecarlo"):
        return 2
    bar = ProgressBar("montecarlo", enabled=not args.quiet)
    try:
        outcome = run_montecarlo(study, args.fmu_dir, args.model, args.out, workers=args.workers,
                                 scheduler=args.scheduler, cache_dir=args.cache, progress=bar,
                                 allow_model_mismatch=args.allow_model_mismatch)
    except (OSError, RuntimeError, ValueError) as error:
        bar.close()
        print(f"rover-cosim montecarlo: {error} (nothing written)", file=sys.stderr)
        return 1
    bar.close()
    _print_montecarlo(outcome)
    if len(outcome.runs) and outcome.summary["runs_failed"] == len(outcome.runs):
        print(f"rover-cosim montecarlo: every run failed (see {args.out / 'failures.csv'})", file=sys.stderr)
        return 1
    return 0


def _percent(share: float | None) -> str:
    return "-" if share is None else f"{100 * share:.1f} %"


def _print_montecarlo(outcome) -> None:  # noqa: ANN001 - MonteCarloResult, imported lazily
    for path, problem in outcome.rejected.items():
        print(f"rover-cosim montecarlo: cache file {path}: {problem}; computed again", file=sys.stderr)
    summary = outcome.summary
    print(f"{outcome.computed} runs computed, {outcome.cached} from the cache, {summary['runs_failed']} failed, "
          f"{summary['wall_seconds']:.1f} s" + (f" ({summary['runs_per_minute']:.1f} runs/min)"
                                                  if summary["runs_per_minute"] else ""))
    for scenario, numbers in summary["scenarios"].items():
        share = numbers["share_meeting_1N_rms_of_completed"]
        print(f"{scenario}: {numbers['completed']} of {numbers['runs']} runs completed; RMS(Fx - Fx_des) <= 1 N on "
              f"every limb in {numbers['meeting_1N_rms']} ({'-' if share is None else f'{100 * share:.1f} %'} of "
              f"the completed); stuck in {numbers['stuck']}")
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
    for path in outcome.files:
        print(f"wrote {path}")


def _print_path(outcome) -> None:  # noqa: ANN001 - PathResult, imported lazily
    columns = {"cross_track_rms_m": "cross-track RMS [m]", "cross_track_max_m": "max [m]",
               "speed_error_max_percent": "speed error [%]"}
    table = outcome.metrics[["scenario", "run", *columns]].rename(columns=columns)
    rms = outcome.metrics.filter(like="rms_F")
    table["largest RMS(Fx - Fx_des) [N]"] = rms.filter(like="rms_Fx").max(axis=1)
    table["largest RMS(Fy - Fy_des) [N]"] = rms.filter(like="rms_Fy").max(axis=1)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    for path in outcome.files:
        print(f"wrote {path}")


def _print_terrain(outcome) -> None:  # noqa: ANN001 - TerrainResult, imported lazily
    columns = {"side_slope_deg": "side slope [deg]", "cross_track_rms_m": "cross-track RMS [m]",
               "cross_track_max_m": "max [m]", "heading_error_max_rad": "heading error max [rad]",
               "energy_per_metre_J_m": "energy [J/m]"}
    table = outcome.metrics[["scenario", "run", *columns]].rename(columns=columns)
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    for path in outcome.files:
        print(f"wrote {path}")


def _print_straight(outcome) -> None:  # noqa: ANN001 - SimulationResult, imported lazily
    import pandas as pd

    from rover_cosim.report.sections import CHECKS

    plants = {"monolithic": "Rover.fmu", "cosim": "RoverBody + 6 Wheel"}
    checks = pd.DataFrame({plants.get(p, p): {CHECKS[k][0]: v for k, v in values.items() if k in CHECKS}
                           for p, values in outcome.record["checks"].items()})
    print("Velocity and loads:")
    print(checks.to_string(float_format=lambda v: f"{v:.4g}"))
    table = pd.DataFrame({"limb": outcome.rms["monolithic"]["limb"],
                          "RMS(Fx - Fx_des), Rover.fmu [N]": outcome.rms["monolithic"]["rms_N"],
                          "RMS, RoverBody + 6 Wheel [N]": outcome.rms["cosim"]["rms_N"],
                          "RMS, one model at 424 N [N]": outcome.ablation["rms_fixed_load_N"]})
    print("Table 3 (limbs 4-6 mirror 1-3):")
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    adaptation = outcome.record.get("adaptation")
    if adaptation:
        soil = adaptation.get("estimated_soil") or {}
        print(f"Adaptive run: the model switched at {adaptation['switched_at_s']:g} s after "
              f"{adaptation['samples']} calibration samples ({adaptation['adapt_wall_s']:.1f} s to estimate and "
              f"identify); estimated c {soil.get('c', float('nan')):.4g} Pa, phi "
              f"{math.degrees(soil.get('phi', float('nan'))):.3g} deg, k_phi {soil.get('kphi', float('nan')):.4g}, "
              f"n {soil.get('n', float('nan')):.3g}, k_x {soil.get('kx', float('nan')):.3g} m; largest "
              f"RMS(Fx - Fx_des) after the calibration {max(adaptation['rms_after_calibration_N']):.3f} N "
              f"(nominal model: {max(adaptation['rms_after_calibration_nominal_model_N']):.3f} N)")
    for path in outcome.files:
        print(f"wrote {path}")


def _build_fmus(args: argparse.Namespace) -> int:
    from rover_cosim.fmubuild.build import FMU_MODELS, BuildResult, build_all, steps_of
    from rover_cosim.fmubuild.expressions import UnsupportedConstruct
    from rover_cosim.fmubuild.platforms import parse as parse_platforms
    from rover_cosim.progress import ProgressBar

    bar = ProgressBar("build-fmus", enabled=not args.quiet)
    done = {"steps": 0, "total": 1}

    def step(_model: str, _stage: str) -> None:  # translate, generate, compile <folder>, package
        done["steps"] += 1
        bar(min(1.0, done["steps"] / max(1, done["total"])))

    def report(result: BuildResult) -> None:
        bar.clear()
        if result.rebuilt:
            stages = ", ".join(f"{k} {v:.1f} s" for k, v in result.stages.items())
            print(f"built {result.path} in {result.seconds:.1f} s ({stages})", flush=True)
        else:
            print(f"{result.path} is up to date", flush=True)
            done["total"] -= done["per_fmu"]  # nothing to wait for there

    if args.jobs is not None and args.jobs < 1:
        print(f"rover-cosim build-fmus: --jobs {args.jobs}: expected >= 1", file=sys.stderr)
        return 2
    unknown = [name for name in args.models if name not in FMU_MODELS]
    if unknown:
        print(f"rover-cosim build-fmus: model {unknown[0]!r}: expected one of {', '.join(FMU_MODELS)}", file=sys.stderr)
        return 2
    try:
        platforms = parse_platforms(args.platforms)
    except ValueError as error:
        print(f"rover-cosim build-fmus: {error}", file=sys.stderr)
        return 2
    models = tuple(args.models) or FMU_MODELS
    done["per_fmu"] = steps_of(platforms)
    done["total"] = len(models) * done["per_fmu"]
    try:
        build_all(models, args.out, force=args.force, jobs=args.jobs, backend=args.backend, platforms=platforms,
                  report=report, step=step, fmi_version=args.fmi_version)
    except (UnsupportedConstruct, ValueError, RuntimeError) as error:
        bar.close()
        print(f"rover-cosim build-fmus: {error}", file=sys.stderr)
        return 1
    bar.close()
    return 0


def _report(args: argparse.Namespace) -> int:
    from rover_cosim.common.outputs import write_all
    from rover_cosim.report import build_report

    target = args.out or args.results / "report.html"
    produced = [p for p in ("fig3_fx_vs_slip*.csv", "identification/fit_models.csv", "simulation/rms.csv",
                            "simulation/path_metrics.csv", "montecarlo/runs.csv") if any(args.results.glob(p))]
    if not produced:
        print(f"rover-cosim report: nothing to report in {args.results} (no results of fig3, identify or "
              "simulate; make them with `rover-cosim fig3`, `identify`, `simulate`)", file=sys.stderr)
        return 1
    problem = _unwritable(target, NEEDS["report"]) or (None if args.overwrite else _foreign(target, "report"))
    if problem:
        print(f"rover-cosim report: --out {target}: {problem}", file=sys.stderr)
        return 2
    try:
        page = build_report(args.results)
    except (KeyError, ValueError, OSError) as error:  # a results file not as its job writes it
        print(f"rover-cosim report: {args.results}: a results file is not as its command writes it "
              f"({type(error).__name__}: {error}); nothing written", file=sys.stderr)
        return 1
    write_all({target: page.encode()})
    print(f"wrote {target}")
    return 0


def _blocks(args: argparse.Namespace) -> int:
    from rover_cosim.orchestrator.blocks import describe_blocks

    print(describe_blocks())
    return 0


def _foreign(target: Path, command: str) -> str | None:
    """Why ``target`` may not be replaced by ``command``'s result without --overwrite (None: it is
    absent, or a previous result of that command)."""
    import json
    import zipfile

    if not target.exists() or target.is_dir():
        return None
    try:
        if command in ("run", "testbed-data"):  # a JSON record beside the file names the command
            sidecar = target.with_suffix(".json")
            if sidecar.is_file() and json.loads(sidecar.read_text()).get("command") == f"rover-cosim {command}":
                return None
        elif command == "report":
            if b"rover-cosim report" in target.read_bytes()[:4096]:
                return None
        elif command == "export-ssp":
            with zipfile.ZipFile(target) as archive:
                if b"org.rover-cosim" in archive.read("SystemStructure.ssd"):
                    return None
    except (OSError, ValueError, KeyError, zipfile.BadZipFile):
        pass
    return (f"{target} exists and is not a result of rover-cosim {command}: pass --overwrite to replace it")


#: Bytes a command's results take, about (with its run cache; checked against the free space before
#: the work starts). The Monte Carlo adds MONTECARLO_RUN_BYTES per run, `run` its rows.
NEEDS = {"fig3": 5e6, "identify": 80e6, "simulate": 60e6, "montecarlo": 10e6, "cosim-study": 5e6, "report": 20e6,
         "export-ssp": 0.0, "estimate-soil": 5e6, "testbed-data": 2e6}
MONTECARLO_RUN_BYTES = 5e3


def _unwritable(target: Path, need_bytes: float = 0) -> str | None:
    """Why ``target`` (a file to write) cannot be written, or None (common.outputs.output_problem)."""
    from rover_cosim.common.outputs import output_problem

    return output_problem(target, folder=False, need_bytes=need_bytes)


def _output_folder(out: Path, command: str, need_bytes: float | None = None, option: str = "--out") -> bool:
    """Whether ``out`` can be an output folder (absent or a writable folder, with room for about
    the command's results); else says why (on stderr)."""
    from rover_cosim.common.outputs import output_problem

    problem = output_problem(out, folder=True, need_bytes=NEEDS[command] if need_bytes is None else need_bytes)
    if problem:
        print(f"rover-cosim {command}: {option} {out}: {problem}", file=sys.stderr)
        return False
    return True


def _soils(args: argparse.Namespace) -> int:
    from rover_cosim.terramechanics import library

    if args.name is not None:
        return _one_soil(args.name)
    for kind in ("soil", "wheel"):
        print(f"{kind}s (--{kind} NAME):")
        for name in library.names(kind):
            _, table = library.entry(kind, name)
            print(f"  {name:15s} {table.get('title', '')}")
            print(f"  {'':15s} source: {table.get('source', '')}")
    print(f"files: {library.SOILS}, {library.WHEELS}; `rover-cosim soils NAME` shows one")
    return 0


def _one_soil(name: str) -> int:
    """``rover-cosim soils NAME``: one soil or wheel, every value with its unit, and its source."""
    import math
    from dataclasses import asdict

    from rover_cosim.terramechanics import library
    from rover_cosim.terramechanics.parameters import UNITS

    found = []
    for kind in ("soil", "wheel"):
        try:
            entry_name, table = library.entry(kind, name)
            found.append((kind, entry_name, table, library.build(kind, entry_name, table)))
        except ValueError:
            continue
    if not found:
        print(f"rover-cosim soils: {name!r}: no shipped soil or wheel of that name, and no such TOML file (soils: "
              f"{', '.join(library.names('soil'))}; wheels: {', '.join(library.names('wheel'))})", file=sys.stderr)
        return 2
    for kind, entry_name, table, built in found:
        print(f"{kind} {entry_name}: {table.get('title', '')}")
        print(f"  source: {table.get('source', '')}")
        for key, value in asdict(built).items():
            shown = f"{value:.6g}" + (f" rad ({math.degrees(value):.4g} deg)" if key in ("phi", "xc") else "")
            given = "" if key in table or f"{key}_deg" in table else "  (default" + (
                ": 45 deg - phi/2)" if key == "xc" else ": the paper's)")
            print(f"  {key:8s} {shown} {UNITS.get(key, '') if key not in ('phi', 'xc') else ''}{given}")
        for key, note in table.get("notes", {}).items():
            print(f"  note {key}: {note}")
    return 0


def _fig3(args: argparse.Namespace) -> int:
    from rover_cosim.jobs.fig3 import PAPER_LOADS, slip_grid, write_fig3

    choice = _choice(args, "fig3")
    if choice is None or not _output_folder(args.out, "fig3"):
        return 2
    try:
        first, last = args.slip_range
        if args.slip_step > last - first:
            raise ValueError(f"slip step={args.slip_step!r}: expected at most the range's width {last - first:g}")
        written = write_fig3(args.out, args.loads or PAPER_LOADS, slip_grid(args.slip_step, last, first), choice)
    except ValueError as error:
        print(f"rover-cosim fig3: {error}", file=sys.stderr)
        return 2
    except RuntimeError as error:  # the wheel model cannot find an equilibrium on this soil
        print(f"rover-cosim fig3: {error} (the soil cannot carry the wheel here: look at its moduli and the "
              "loads; nothing written)", file=sys.stderr)
        return 1
    for path in written:
        print(f"wrote {path}")
    return 0


def _estimate_soil(args: argparse.Namespace) -> int:
    from rover_cosim.jobs.estimate_soil import run_estimate_soil
    from rover_cosim.terramechanics.library import choose

    if not _output_folder(args.out, "estimate-soil"):
        return 2
    try:
        choice = choose(args.prior, args.wheel, args.assignments)
        outcome = run_estimate_soil(args.data, args.out, choice, args.parameters, args.noise_scale)
    except (ValueError, TypeError) as error:
        print(f"rover-cosim estimate-soil: {error} (nothing written)", file=sys.stderr)
        return 2
    except RuntimeError as error:
        print(f"rover-cosim estimate-soil: {error} (nothing written)", file=sys.stderr)
        return 1
    print(outcome.estimate.summary())
    for path in outcome.files:
        print(f"wrote {path}")
    return 0


def _testbed_data(args: argparse.Namespace) -> int:
    from rover_cosim.jobs.estimate_soil import DEFAULT_LOADS, DEFAULT_SLIPS, write_testbed_data

    if args.out.suffix.lower() != ".csv":
        print(f"rover-cosim testbed-data: --out {args.out}: expected a .csv file name (its record goes beside it as "
              ".json)", file=sys.stderr)
        return 2
    problem = _unwritable(args.out, NEEDS["testbed-data"]) or (None if args.overwrite
                                                                else _foreign(args.out, "testbed-data"))
    if problem:
        print(f"rover-cosim testbed-data: --out {args.out}: {problem}", file=sys.stderr)
        return 2
    choice = _choice(args, "testbed-data")
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
        print(f"rover-cosim testbed-data: {error} (nothing written)", file=sys.stderr)
        return 2
    print(f"{outcome.data.rows} rows ({', '.join(outcome.data.channels)}) on soil {choice.soil_name}, wheel "
          f"{choice.wheel_name}, noise {args.noise:g} of each channel's range (seed {args.seed})")
    for path in outcome.files:
        print(f"wrote {path}")
    return 0


COMMANDS = {"build-fmus": _build_fmus, "run": _run, "export-ssp": _export_ssp, "cosim-study": _cosim_study,
            "identify": _identify,
            "simulate": _simulate, "montecarlo": _montecarlo, "report": _report, "fig3": _fig3, "soils": _soils,
            "estimate-soil": _estimate_soil, "testbed-data": _testbed_data,
            "blocks": _blocks}


def _terminate(signum: int, frame: object) -> None:
    """SIGTERM ends the command like Ctrl-C: the context managers close the FMUs and remove
    their temporary folder on the way out."""
    raise KeyboardInterrupt


def _result_sets(args: argparse.Namespace) -> int | None:
    """How many result sets (common.outputs.write_all calls) make the command's results whole;
    None: a command without results to write this way."""
    if args.command == "simulate":
        return 1 if args.only else 2
    return None if args.command in ("soils", "blocks", "build-fmus", "export-ssp") else 1


def main(argv: Sequence[str] | None = None) -> int:
    """The command of ``argv`` (default: the process's arguments); its exit code. Run as the
    process itself (argv None), a signal that comes once the code is known no longer changes it."""
    code = _main(argv)
    if argv is None and threading.current_thread() is threading.main_thread():
        for number in (signal.SIGINT, signal.SIGTERM):  # the process only exits from here on
            signal.signal(number, signal.SIG_IGN)
    return code


def _main(argv: Sequence[str] | None) -> int:
    args = build_parser().parse_args(argv)
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminate) if main_thread else None
    try:
        return _command(args, argv)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _command(args: argparse.Namespace, argv: Sequence[str] | None) -> int:
    """The command of ``args`` with its output held (a second writer refused), and the exit code
    of how it ended."""
    from rover_cosim.common.outputs import Busy, OutputError, committed, set_command_line, writing

    before, needed = committed(), _result_sets(args)
    try:
        from rover_cosim.common import figures  # matplotlib: a while to import, a signal may come meanwhile

        try:
            figures.configure(args.figures, args.dpi)
        except ValueError as error:
            print(f"rover-cosim: {error}", file=sys.stderr)
            return 2
        set_command_line(["rover-cosim", *(sys.argv[1:] if argv is None else argv)])
        target = getattr(args, "out", None) or getattr(args, "output", None)
        with writing(target, f"rover-cosim {args.command}") if target is not None else nullcontext():
            return COMMANDS[args.command](args)
    except Busy as busy:
        print(f"rover-cosim {args.command}: {busy}", file=sys.stderr)
        return 2
    except OutputError as error:
        print(f"rover-cosim {args.command}: {error}", file=sys.stderr)
        return 1
    except (KeyboardInterrupt, ImportError) as error:
        if isinstance(error, ImportError) and not _cut_short(error):
            raise
        if needed is not None and committed() - before >= needed:  # the signal came after the results
            print(f"rover-cosim {args.command}: interrupted after its results were written; they are whole",
                  file=sys.stderr)
            return 0
        print(f"rover-cosim {args.command}: interrupted; nothing more written", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader went away (`rover-cosim soils | head`)
        sys.stderr.close()
        return 0


def _cut_short(error: BaseException) -> bool:
    """Whether ``error`` (an ImportError) comes of a KeyboardInterrupt: a C extension whose
    initialisation a signal interrupted reports "initialization failed" instead."""
    seen: BaseException | None = error
    while seen is not None:
        if isinstance(seen, KeyboardInterrupt):
            return True
        seen = seen.__cause__ or seen.__context__
    return False


if __name__ == "__main__":
    sys.exit(main())
