"""rover-cosim: terramechanics rover co-simulation; the command behind the Makefile targets."""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
import threading
from collections.abc import Sequence
from contextlib import nullcontext

from rover_cosim import __version__

from .command import Command
from .options import HelpFormatter, figure_formats
from .systems import EXAMPLES as EXAMPLES  # noqa: F401 - the shipped example systems, for users of the package

#: The commands, one module of this package each (its ``COMMAND``), in the order ``--help`` lists
#: them: a new command is a new module and its line here.
MODULES = ("fig3", "run", "export_ssp", "cosim_study", "identify", "simulate", "montecarlo", "soils", "rovers",
           "blocks", "estimate_soil", "testbed_data", "report", "build_fmus")

#: Each command by its name.
COMMANDS: dict[str, Command] = {
    command.name: command for command in (importlib.import_module(f"{__name__}.{module}").COMMAND
                                          for module in MODULES)}


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command: the global options, then one sub-parser per command."""
    parser = argparse.ArgumentParser(prog="rover-cosim", description=__doc__, formatter_class=HelpFormatter,
                                     epilog="exit codes: 0 done; 1 the work failed (a run, a study where every "
                                     "run failed); 2 bad input (nothing computed); 130 interrupted")
    parser.add_argument("--version", action="version", version=f"rover-cosim {__version__}")
    parser.add_argument("--figures", type=figure_formats, default=("png",), metavar="FORMATS",
                        help="formats every figure is written in, beside PNG: e.g. png,pdf,svg (default: png)")
    parser.add_argument("--dpi", type=float, default=None,
                        help="resolution of the PNG figures (default: each figure's own, 100-150)")
    commands = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS.values():
        sub = commands.add_parser(command.name, help=command.help, formatter_class=HelpFormatter,
                                  description=command.summary,
                                  epilog="examples:\n" + "\n".join(f"  {example}" for example in command.examples))
        command.arguments(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """The command of ``argv`` (default: the process's arguments); its exit code. Run as the
    process itself (argv None), a signal that comes once the code is known no longer changes it."""
    code = _main(argv)
    if argv is None and threading.current_thread() is threading.main_thread():
        for number in (signal.SIGINT, signal.SIGTERM):  # the process only exits from here on
            signal.signal(number, signal.SIG_IGN)
    return code


def _terminate(signum: int, frame: object) -> None:
    """SIGTERM ends the command like Ctrl-C: the context managers close the FMUs and remove
    their temporary folder on the way out."""
    raise KeyboardInterrupt


def _main(argv: Sequence[str] | None) -> int:
    args = build_parser().parse_args(argv)
    main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, _terminate) if main_thread else None
    try:
        return _command(COMMANDS[args.command], args, argv)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _command(command: Command, args: argparse.Namespace, argv: Sequence[str] | None) -> int:
    """``command`` on ``args`` with its output held (a second writer refused), and the exit code
    of how it ended."""
    from rover_cosim.common.outputs import Busy, OutputError, committed, set_command_line, writing

    before, needed = committed(), command.result_sets(args)
    try:
        from rover_cosim.common import figures  # matplotlib: a while to import, a signal may come meanwhile

        try:
            figures.configure(args.figures, args.dpi)
        except ValueError as error:
            print(f"rover-cosim: {error}", file=sys.stderr)
            return 2
        set_command_line(["rover-cosim", *(sys.argv[1:] if argv is None else argv)])
        target = getattr(args, "out", None) or getattr(args, "output", None)
        with writing(target, f"rover-cosim {command.name}") if target is not None else nullcontext():
            return command.run(args)
    except Busy as busy:
        print(f"rover-cosim {command.name}: {busy}", file=sys.stderr)
        return 2
    except OutputError as error:
        print(f"rover-cosim {command.name}: {error}", file=sys.stderr)
        return 1
    except (KeyboardInterrupt, ImportError) as error:
        if isinstance(error, ImportError) and not _cut_short(error):
            raise
        if needed is not None and committed() - before >= needed:  # the signal came after the results
            print(f"rover-cosim {command.name}: interrupted after its results were written; they are whole",
                  file=sys.stderr)
            return 0
        print(f"rover-cosim {command.name}: interrupted; nothing more written", file=sys.stderr)
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
