"""What a command of ``rover-cosim`` is: its name, its help, its arguments, the function that runs
it, and what the shared parts of the command line need to know of it (the room its results take,
how many result sets make them whole, which existing files are its own results)."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path


def one_result_set(args: argparse.Namespace) -> int | None:
    """The usual count: one call of common.outputs.write_all makes a command's results whole."""
    return 1


def no_result_set(args: argparse.Namespace) -> int | None:
    """A command that writes no results folder that way (it prints, or writes its own files)."""
    return None


@dataclass(frozen=True)
class Command:
    """One command: ``rover-cosim NAME ...``."""

    name: str
    #: one line in ``rover-cosim --help``
    help: str
    #: the first line of ``rover-cosim NAME --help``, then the examples
    summary: str
    examples: tuple[str, ...]
    #: adds the command's arguments to its parser
    arguments: Callable[[argparse.ArgumentParser], None]
    #: runs the command on the parsed arguments: the exit code (0 done, 1 the work failed, 2 bad input)
    run: Callable[[argparse.Namespace], int]
    #: bytes its results take, about (checked against the free space before the work starts)
    needs_bytes: float = 0.0
    #: how many result sets (common.outputs.write_all calls) make the results whole; None: none that way
    result_sets: Callable[[argparse.Namespace], int | None] = field(default=one_result_set)
    #: whether an existing file may be replaced without --overwrite: it is a previous result of this command
    owns: Callable[[Path], bool] | None = None
