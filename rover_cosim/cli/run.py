"""``rover-cosim run``: co-simulate a system file, an SSP archive or one FMU."""

from __future__ import annotations

import argparse
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from .command import Command
from .options import (
    add_soil_options,
    choice_of,
    fail,
    foreign,
    foreign_companion,
    path,
    path_text,
    print_written,
    recorded_by,
    unwritable,
)
from .systems import EXAMPLES, system_path


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


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("system", type=path_text,
                        help="system file (.toml, or an .ssp archive), one FMU (.fmu: run alone, with its "
                        "DefaultExperiment unless --stop-time/--step say otherwise), or the name of a shipped "
                        "example: " + ", ".join(EXAMPLES))
    parser.add_argument("-o", "--output", type=path, default=None,
                        help="CSV (full precision) or .parquet to write (default: results/<system name>.csv); a "
                        ".json sidecar goes beside it")
    parser.add_argument("--fmu-dir", type=path, default=None,
                        help="folder for relative FMU paths (default: the system file's folder; fmus/ for examples)")
    algorithm = parser.add_argument("--algorithm", default=None, help="override the system file's master algorithm")
    algorithm.choices = _Algorithms()  # after add_argument, which would read them at once
    parser.add_argument("--step", type=float, default=None, help="override the communication step [s]")
    parser.add_argument("--stop-time", type=float, default=None, help="override the stop time [s]")
    parser.add_argument("--relative-tolerance", type=float, default=None, metavar="TOL",
                        help="of the integrator (CVode) of Model Exchange FMUs, and told to every FMU (default: the "
                        "system file's, else 1e-6)")
    parser.add_argument("--output-interval", type=float, default=None,
                        help="record a row every so often [s] (a whole number of steps; the last row always)")
    parser.add_argument("--threads", type=int, default=None,
                        help="FMUs stepped at the same time (Jacobi; Gauss-Seidel where inputs are ready); "
                        "default: the system file's, else the number of cores")
    parser.add_argument("--interface", choices=("co-simulation", "model-exchange"), default=None,
                        help="one FMU run alone: the interface to run (default: Co-Simulation where it has it; "
                        "Model Exchange is integrated by CVode)")
    parser.add_argument("--start", type=_assignment, action="append", metavar="NAME=VALUE",
                        help="one FMU run alone: a parameter or start value (repeatable; TOML values: 2.5, 3, true, "
                        "\"text\")")
    parser.add_argument("--input", type=path, default=None, metavar="CSV",
                        help="one FMU run alone: input signals, first column time [s], one column per input "
                        "(continuous Real inputs interpolated, the others held; a repeated time is a step)")
    parser.add_argument("--validate", choices=("strict", "warn", "off"), default="strict",
                        help="an FMU whose modelDescription.xml fails FMPy's validation: refused (strict), run as "
                        "FMPy runs it with validate=False after listing the problems (warn), or run silently (off; "
                        "the record says so)")
    parser.add_argument("--allow-factory", action="append", metavar="MODULE", default=[],
                        help="an SSP archive may name Python blocks of this module (module or module:callable; "
                        "repeatable): the archive's code runs only where you allow it; the module is looked up "
                        "beside the archive first")
    parser.add_argument("--isolation", choices=("auto", "process", "none"), default=None,
                        help="where the FMUs run: each in a child process of its own (process: a crash, exit() or "
                        "hang of an FMU ends the run with a message, the rows so far kept), in this process (none: "
                        "the fastest) or auto (the default: none for FMUs this project generated, else process; a "
                        "system file may say per FMU)")
    parser.add_argument("--fmu-timeout", type=float, default=None, metavar="SECONDS",
                        help="the longest one call of an FMU run in a child process may take (default: no limit); a "
                        "hanging FMU is ended and the run fails with the rows computed so far kept")
    parser.add_argument("--record", action="append", metavar="NAME",
                        help="a variable to record instead of every output (repeatable; glob patterns: 'x*', '*'); "
                        "one FMU run alone: its variable names, locals too; a system: instance.variable")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace --output even if it is not a result of rover-cosim run")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    add_soil_options(parser)


class _Algorithms:
    """The master algorithms' names (orchestrator.algorithms.ALGORITHMS) as argparse's choices, read
    when they are first asked for: the registry imports the engine, which `rover-cosim --help` need not."""

    def _names(self) -> tuple[str, ...]:
        from rover_cosim.orchestrator.algorithms import ALGORITHMS

        return tuple(ALGORITHMS)

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and name in self._names()

    def __iter__(self) -> Iterator[str]:
        return iter(self._names())


def _load_system(args: argparse.Namespace, unpack: Path) -> tuple[Any, Path]:
    """The system of ``rover-cosim run`` with the command line's overrides (SystemFileError if
    bad); an .ssp archive is unpacked into ``unpack``."""
    from rover_cosim.orchestrator.builder import SystemBuilder, with_isolation

    system_file, fmu_dir = system_path(args.system, args.fmu_dir)
    overrides = {key: value for key, value in (("algorithm", args.algorithm), ("step", args.step),
                                               ("stop_time", args.stop_time), ("threads", args.threads),
                                               ("output_interval", args.output_interval),
                                               ("relative_tolerance", args.relative_tolerance),
                                               ("fmu_timeout", args.fmu_timeout))
                 if value is not None}
    if system_file.suffix.lower() == ".fmu":
        system = _one_fmu(system_file, overrides, args)  # the overrides are its settings
        return (with_isolation(system, args.isolation) if args.isolation else system), system_file
    system, system_file = _system_of_file(system_file, fmu_dir, overrides, unpack, args)
    if args.record:  # instead of the file's [record]
        system = SystemBuilder.from_system(system).record(*args.record, where="--record", replace=True).build()
    if args.isolation:
        system = with_isolation(system, args.isolation)
    if not system.record:
        fail("run", f"{system_file}: records nothing but time (no participant has an output that can be recorded): "
             "name what to record with --record instance.variable (glob patterns too, e.g. --record 'model.*')")
    return system, system_file


def _system_of_file(system_file: Path, fmu_dir: Path | None, overrides: dict[str, Any], unpack: Path,
                    args: argparse.Namespace) -> tuple[Any, Path]:
    """The system of a system file or SSP archive with the command line's overrides."""
    from rover_cosim.orchestrator.builder import replace_settings
    from rover_cosim.orchestrator.ssp import SspError, load_ssp
    from rover_cosim.orchestrator.system import SystemFileError, load_system

    given = [flag for flag, value in (("--interface", args.interface), ("--start", args.start),
                                      ("--input", args.input)) if value]
    if given:
        raise SystemFileError(f"{system_file}: {', '.join(given)} apply to one FMU run alone (rover-cosim run "
                              "model.fmu); a system file gives its FMUs' interface, start values and inputs itself")
    if system_file.suffix.lower() == ".ssp":
        try:  # the overrides are settings of the archive's system, checked as its own
            return load_ssp(system_file, unpack, overrides, validation=args.validate,
                            factories=args.allow_factory), system_file
        except SspError as error:
            raise SystemFileError(f"{system_file}: {error}") from None
    system = load_system(system_file, fmu_dir=fmu_dir, validation=args.validate)
    if overrides:
        system = replace_settings(system, name=f"{system_file} (with command-line overrides)", **overrides)
    return system, system_file


def _one_fmu(fmu: Path, settings: dict[str, Any], args: argparse.Namespace) -> Any:
    """A system of the one FMU ``fmu`` (instance ``model``), every output recorded, the stop time
    and step from ``settings`` or the FMU's DefaultExperiment, the values of --start and the
    input file of --input."""
    from rover_cosim.orchestrator.single import single_fmu_system

    system, notes = single_fmu_system(fmu, settings, interface=args.interface, values=dict(args.start or []),
                                      input_file=args.input, record=args.record or (), validation=args.validate)
    for note in notes:
        fail("run", note)
    return system


def run(args: argparse.Namespace) -> int:
    from rover_cosim.common.scratch import remove_stale_folders, scratch_prefix
    from rover_cosim.orchestrator.builder import with_parameters
    from rover_cosim.orchestrator.system import SystemFileError
    from rover_cosim.terramechanics.library import describe, fmu_parameters

    choice = None
    if args.soil or args.wheel or args.assignments:
        choice = choice_of(args, "run")
        if choice is None:
            return 2
    remove_stale_folders()
    with tempfile.TemporaryDirectory(prefix=scratch_prefix("ssp")) as unpack:
        try:
            system, system_file = _load_system(args, Path(unpack))
        except SystemFileError as error:
            fail("run", str(error))
            return 2
        extra = None
        if choice is not None:  # the chosen soil and wheel go to every FMU that has them
            system = with_parameters(system, fmu_parameters(choice.soil, choice.wheel))
            extra = describe(choice)
        for fmu in system.fmus:
            if fmu.problems and fmu.validation == "warn":
                fail("run", f"{fmu.path.name}: its modelDescription.xml fails FMPy's validation, run all the same "
                     f"(--validate warn): " + "; ".join(fmu.problems[:5])
                     + (f" (and {len(fmu.problems) - 5} more)" if len(fmu.problems) > 5 else ""))
        return _run_system(args, system, system_file, extra)


def _run_system(args: argparse.Namespace, system: Any, system_file: Path, extra: dict[str, Any] | None) -> int:
    from rover_cosim.common.outputs import OutputError
    from rover_cosim.orchestrator.master import RunError
    from rover_cosim.orchestrator.master import run as run_system
    from rover_cosim.orchestrator.runs import Publisher, TableStream, partial_path, sidecar_path
    from rover_cosim.progress import ProgressBar

    output = args.output or Path("results") / f"{system_file.stem}.csv"
    try:
        sidecar_path(output)
    except ValueError as error:
        fail("run", str(error))
        return 2
    companions = (sidecar_path(output), partial_path(output), sidecar_path(partial_path(output)))
    problem = unwritable(output, _run_bytes(system)) or (None if args.overwrite else (
        foreign(output, "run", OWNS) or foreign_companion(companions, "run")))
    if problem:  # said before the run, not after it
        fail("run", f"output {output}: {problem}")
        return 2
    bar = ProgressBar(system_file.stem, enabled=not args.quiet)
    stream = TableStream(output)  # the rows go to a file beside the output as they come: memory bounded
    publisher = Publisher(stream, system, extra)  # the result written before the FMUs are freed
    try:
        result = run_system(system, progress=bar, sink=stream, observers=[publisher])
    except RunError as error:
        bar.close()
        kept = ""
        if stream.rows > 1:
            try:
                written = stream.publish_partial(system, str(error))
                kept = f"; the {stream.rows} rows computed before it are in {written[0]} (partial)"
            except OutputError as lost:
                kept = f"; the rows computed before it: {lost}"
        else:
            stream.discard()
        fail("run", f"{error} ({output} not written{kept})")
        _write_fmu_log(output, error.fmu_log)
        return 1
    except BaseException:
        stream.discard()
        raise
    bar.close()
    publisher.noted(result)
    print_written(publisher.written)
    _write_fmu_log(output, result.fmu_log)
    for note in result.notes:
        fail("run", f"warning: {note} (after the last step; {output} is complete)")
    if result.stopped:
        print(f"stopped: {result.stopped}")
    print(f"{result.steps} steps of {system.step:g} s ({system.algorithm}) in {result.wall_seconds:.2f} s")
    return 0


#: The first line of the FMU log a run writes beside its output (how a later run knows it is its own).
FMU_LOG_HEADER = "# rover-cosim run: FMU messages too long to print, whole"


def fmu_log_path(output: Path) -> Path:
    """Where a run's FMU log goes: ``NAME.fmu.log`` beside ``NAME.csv``."""
    return output.with_name(f"{output.stem}.fmu.log")


def _write_fmu_log(output: Path, log: dict[str, list[str]]) -> None:
    """The FMUs' error messages that were too long to print, whole, beside the output (not over a
    file of that name that a run did not write)."""
    from rover_cosim.common.outputs import OutputError, write_all

    if not log:
        return
    target = fmu_log_path(output)
    if target.exists() and not target.read_bytes().startswith(FMU_LOG_HEADER.encode()):
        fail("run", f"the FMUs' long messages are not written: {target} exists and is not a run's FMU log")
        return
    text = FMU_LOG_HEADER + "\n" + "".join(f"\n## {name}\n" + "\n".join(messages) + "\n"
                                          for name, messages in log.items())
    try:
        write_all({target: text.encode()}, complete=False)
    except OutputError as error:
        fail("run", f"the FMUs' long messages: {error}")
        return
    print(f"wrote {target} (the FMUs' messages too long to print, whole)")


def _run_bytes(system: Any) -> float:
    """About the bytes of a run's CSV: its rows and recorded columns at ~25 characters a value."""
    rows = (system.stop_time - system.start_time) / system.step / system.record_every + 2
    return rows * (len(system.record) + 1) * 25


OWNS = recorded_by("run")

COMMAND = Command(
    "run", help="co-simulate a system file (TOML or SSP) -> CSV + JSON sidecar",
    summary="Co-simulate a system file, an SSP archive or one FMU; trajectories as CSV (or Parquet) and a JSON "
    "record.",
    examples=("rover-cosim run rover_cosim --fmu-dir fmus -o results/rover.csv",
              "rover-cosim run BouncingBall.fmu --interface model-exchange --stop-time 3 -o ball.csv",
              "rover-cosim run model.fmu --start gain=2 --input signals.csv -o out.parquet"),
    arguments=arguments, run=run, owns=OWNS)
