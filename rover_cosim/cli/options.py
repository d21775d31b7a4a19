"""The argument types and option groups that several commands share, each defined once, and the
checks of output paths every command makes before its work starts."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, TypeVar

Outcome = TypeVar("Outcome")

#: Bytes of one file name and of a whole path the file systems take (Linux: NAME_MAX, PATH_MAX).
NAME_MAX, PATH_MAX = 255, 4096


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Every option's default in its help, unless the help already states it."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if ("default" in text or action.default in (None, argparse.SUPPRESS, False, []) or action.nargs == 0
                or action.option_strings == []):
            return text
        return f"{text} (default: {action.default})"


def path_text(text: str) -> str:
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


def path(text: str) -> Path:
    """A path option (checked as path_text)."""
    return Path(path_text(text))


def scheduler(text: str) -> str:
    """A Dask scheduler's address: [PROTOCOL://]HOST:PORT (tcp://10.0.0.5:8786, tls://[::1]:8786)."""
    import re

    if not re.fullmatch(r"([a-z][a-z0-9+.-]*://)?(\[[0-9A-Fa-f:.]+\]|[^\s/:\[\]]+):\d{1,5}", text):
        raise argparse.ArgumentTypeError(f"{text!r}: expected a Dask scheduler's address, e.g. tcp://host:8786")
    from rover_cosim.common.parallel import scheduler_timeout

    try:
        scheduler_timeout()  # the time it may take to answer: said now, before any work
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None
    return text


#: N, the least wheel load a command takes (a thousandth of a newton: below, no sinkage is found).
LEAST_LOAD = 1e-3


def positive_loads(text: str) -> tuple[float, ...]:
    """Comma-separated wheel loads [N], each finite and >= LEAST_LOAD."""
    try:
        loads = tuple(float(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"loads={text!r}: expected comma-separated numbers in N, e.g. 100,200") from None
    bad = [w for w in loads if not (LEAST_LOAD <= w < float("inf"))]
    if bad:
        raise argparse.ArgumentTypeError(f"load={bad[0]!r} N: expected a finite load >= {LEAST_LOAD:g} N")
    return loads


def numbers(kind: str, low: float, high: float, unit: str) -> Callable[[str], tuple[float, ...]]:
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


def figure_formats(text: str) -> tuple[str, ...]:
    """--figures: comma-separated formats of common.figures.FORMATS."""
    from rover_cosim.common.figures import FORMATS

    formats = tuple(part.strip().lower() for part in text.split(",") if part.strip())
    unknown = [f for f in formats if f not in FORMATS]
    if unknown or not formats:
        raise argparse.ArgumentTypeError(f"figures={text!r}: expected some of {', '.join(FORMATS)}, comma-separated")
    return formats


def add_soil_options(parser: argparse.ArgumentParser) -> None:
    """--soil, --wheel, --rover and --set: the soil, wheel and rover a command runs on."""
    parser.add_argument("--soil", type=path_text, default=None, help="soil: a name of the shipped library "
                        "(rover-cosim soils lists them), a TOML file, or FILE:NAME (default: paper)")
    parser.add_argument("--wheel", type=path_text, default=None,
                        help="wheel: a name of the shipped library, a TOML file, or FILE:NAME (default: the rover's "
                        "wheel; the paper's)")
    parser.add_argument("--rover", type=path_text, default=None,
                        help="rover: a name of the shipped library (rover-cosim rovers lists them), a TOML file, or "
                        "FILE:NAME (default: paper); its wheel unless --wheel names one")
    parser.add_argument("--set", dest="assignments", action="append", default=[], metavar="KIND.NAME=VALUE",
                        help="change one value, SI units or *_deg for angles: --set soil.c=500 "
                        "--set soil.phi_deg=30 --set wheel.b=0.2 --set rover.mass=740 --set rover.x_limb=1.2,-1.2 "
                        "(repeatable)")


def add_out(parser: argparse.ArgumentParser, default: str, help: str = "output folder") -> None:  # noqa: A002
    """--out: the command's results folder."""
    parser.add_argument("--out", type=path, default=Path(default), help=help)


def add_overwrite(parser: argparse.ArgumentParser, what: str) -> None:
    """--overwrite: replace same-named files that are not the command's own results."""
    parser.add_argument("--overwrite", action="store_true",
                        help=f"replace {what} even where a file of that name is not a result of this command")


def add_fmu_dir(parser: argparse.ArgumentParser, help: str = "where the FMUs are") -> None:  # noqa: A002
    """--fmu-dir: the folder of the built FMUs."""
    parser.add_argument("--fmu-dir", type=path, default=Path("fmus"), help=help)


def add_model(parser: argparse.ArgumentParser, help: str) -> None:  # noqa: A002
    """--model: an identified model (model.json)."""
    parser.add_argument("--model", type=path, default=Path("results/identification/model.json"), help=help)


def add_workers(parser: argparse.ArgumentParser) -> None:
    """--workers, --scheduler and --cache: where a sweep or study runs and what it reuses."""
    parser.add_argument("--workers", type=int, default=None,
                        help="local processes (default and at most: the cores); a run whose process crashes or "
                        "overruns --run-timeout is recorded as failed and its process replaced")
    parser.add_argument("--run-timeout", type=float, default=None, metavar="SECONDS",
                        help="the longest one run may take (default: 20 x the slowest run so far once three "
                        "completed, at least 120 s)")
    parser.add_argument("--scheduler", type=scheduler, default=None,
                        help="run on a Dask cluster, e.g. tcp://host:8786")
    parser.add_argument("--cache", type=path, default=None, help="run cache (default: <out>/cache)")


def add_quiet(parser: argparse.ArgumentParser, help: str = "no progress bar") -> None:  # noqa: A002
    """-q/--quiet: no progress bar."""
    parser.add_argument("-q", "--quiet", action="store_true", help=help)


def fail(command: str, message: str) -> None:
    """Say on stderr why ``rover-cosim command`` stops."""
    print(f"rover-cosim {command}: {message}", file=sys.stderr)


def choice_of(args: argparse.Namespace, command: str) -> Any:
    """The soil, wheel and rover of the command line (terramechanics.library.Choice), or None after saying why not."""
    from rover_cosim.terramechanics.library import choose

    try:
        return choose(args.soil, args.wheel, args.assignments, getattr(args, "rover", None))
    except (ValueError, TypeError) as error:
        fail(command, str(error))
        return None


def unwritable(target: Path, need_bytes: float = 0) -> str | None:
    """Why ``target`` (a file to write) cannot be written, or None (common.outputs.output_problem)."""
    from rover_cosim.common.outputs import output_problem

    return output_problem(target, folder=False, need_bytes=need_bytes)


def output_folder(out: Path, command: str, need_bytes: float, option: str = "--out") -> bool:
    """Whether ``out`` can be an output folder (absent or a writable folder, with room for about
    ``need_bytes``); else says why."""
    from rover_cosim.common.outputs import output_problem

    problem = output_problem(out, folder=True, need_bytes=need_bytes)
    if problem:
        fail(command, f"{option} {out}: {problem}")
        return False
    return True


def output_file(target: Path, command: str, need_bytes: float, owns: Callable[[Path], bool], overwrite: bool,
                option: str) -> bool:
    """Whether ``target`` (one file) can be written by ``command``: writable, with room, and absent
    or a previous result of the command (``owns``) unless ``overwrite``; else says why."""
    problem = unwritable(target, need_bytes) or (None if overwrite else foreign(target, command, owns))
    if problem:
        fail(command, f"{option} {target}: {problem}")
        return False
    return True


def foreign(target: Path, command: str, owns: Callable[[Path], bool]) -> str | None:
    """Why ``target`` may not be replaced by ``command``'s result without --overwrite (None: it is
    absent, or a previous result of that command by ``owns``)."""
    if not target.exists() or target.is_dir():
        return None
    try:
        if owns(target):
            return None
    except (OSError, ValueError, KeyError):
        pass
    return f"{target} exists and is not a result of rover-cosim {command}: pass --overwrite to replace it"


def recorded_by(command: str) -> Callable[[Path], bool]:
    """``owns`` of a command that writes a JSON record beside its file naming the command."""
    def owns(target: Path) -> bool:
        import json

        sidecar = target.with_suffix(".json")
        return sidecar.is_file() and json.loads(sidecar.read_text()).get("command") == f"rover-cosim {command}"
    return owns


def model_readable(path: Path, command: str) -> bool:
    """Whether ``path`` is an identified model (read whole, as the command will); else says why."""
    from rover_cosim.identification.model_set import ModelFileError, ModelSet

    try:
        ModelSet.read(path)
    except ModelFileError as error:
        fail(command, str(error))
        return False
    return True


def fmu_dir_exists(fmu_dir: Path, command: str) -> bool:
    """Whether ``fmu_dir`` is a folder; else says to build the FMUs."""
    if not fmu_dir.is_dir():
        fail(command, f"--fmu-dir {fmu_dir}: no such folder (build the FMUs with `rover-cosim build-fmus`)")
        return False
    return True


def workers_ok(command: str, args: argparse.Namespace) -> bool:
    """--workers >= 1 (more than the cores: said, the cores used) and --run-timeout > 0 (finite)."""
    import math

    from rover_cosim.common.parallel import cores

    if not at_least(command, ("--workers", args.workers, 1)):
        return False
    timeout = args.run_timeout
    if timeout is not None and not (math.isfinite(timeout) and timeout > 0):
        fail(command, f"--run-timeout {timeout!r}: expected a time limit > 0 s")
        return False
    if args.workers is not None and args.scheduler is None and args.workers > cores():
        fail(command, f"note: --workers {args.workers}: more than the {cores()} cores of this machine; {cores()} used")
    return True


def at_least(command: str, *options: tuple[str, int | None, int]) -> bool:
    """Whether each (option, value, least) has value None or >= least; else names the first that has not."""
    for option, value, least in options:
        if value is not None and value < least:
            fail(command, f"{option} {value}: expected >= {least}")
            return False
    return True


def print_written(files: Iterable[Path]) -> None:
    """Say each file a command wrote."""
    for written in files:
        print(f"wrote {written}")


def with_progress(command: str, title: str, quiet: bool, job: Callable[[Callable[[float], None]], Outcome],
                  errors: tuple[type[Exception], ...]) -> Outcome | None:
    """``job(progress)`` under a progress bar titled ``title`` (drawn unless ``quiet``); None after
    saying why it failed with one of ``errors`` (the work failed: nothing written)."""
    from rover_cosim.progress import ProgressBar

    bar = ProgressBar(title, enabled=not quiet)
    try:
        outcome = job(bar)
    except errors as error:
        bar.close()
        fail(command, f"{error} (nothing written)")
        return None
    bar.close()
    return outcome


def option_ok(command: str, option: str, check: Callable[[], object]) -> bool:
    """Whether ``check()`` (a job's own check of a value) passes; else says why, naming ``option``."""
    try:
        check()
    except ValueError as error:
        fail(command, f"{option}: {error}")
        return False
    return True


def foreign_results(files: Iterable[Path], record: Path, command: str) -> str | None:
    """Why ``files`` (what a command writes into a folder, ``record`` its JSON record among them)
    may not be replaced without --overwrite: one exists and ``record`` does not say that
    ``rover-cosim command`` made them. None: none exists, or they are the command's."""
    import json

    present = [f for f in files if f.exists() and not f.is_dir()]
    if not present:
        return None
    try:
        if json.loads(record.read_text()).get("command") == f"rover-cosim {command}":
            return None
    except (OSError, ValueError, AttributeError):
        pass
    return (f"{present[0]} exists and is not a result of rover-cosim {command} (no record of it in {record.name}): "
            "pass --overwrite to replace it, or write elsewhere")


def foreign_companion(paths: Iterable[Path], command: str) -> str | None:
    """Why one of ``paths`` (the files a command writes beside its output: a JSON record, a partial
    table and its record) may not be replaced without --overwrite: it exists and no record of
    ``rover-cosim command`` says it made it. None: none such."""
    owned = recorded_by(command)
    for companion in paths:
        if not companion.exists() or companion.is_dir():
            continue
        try:
            if companion.suffix == ".json":
                import json

                if json.loads(companion.read_text()).get("command") == f"rover-cosim {command}":
                    continue
            elif owned(companion):
                continue
        except (OSError, ValueError, AttributeError):
            pass
        return (f"{companion} exists and is not a result of rover-cosim {command} (it would be replaced beside the "
                "output): pass --overwrite to replace it")
    return None
