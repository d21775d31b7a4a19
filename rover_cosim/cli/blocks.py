"""``rover-cosim blocks``: the block types of system files."""

from __future__ import annotations

import argparse

from .command import Command, no_result_set


def arguments(parser: argparse.ArgumentParser) -> None:
    """No arguments."""


def run(args: argparse.Namespace) -> int:
    from rover_cosim.orchestrator.blocks import describe_blocks

    print(describe_blocks())
    return 0


COMMAND = Command(
    "blocks", help="the block types of system files, with their keys, units and defaults",
    summary="The block types a system file may use, with their keys, units and defaults.",
    examples=("rover-cosim blocks",), arguments=arguments, run=run, result_sets=no_result_set)
