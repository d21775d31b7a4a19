"""``rover-cosim report``: one self-contained HTML page of the results."""

from __future__ import annotations

import argparse
from pathlib import Path

from .command import Command
from .options import fail, output_file, path

#: What makes a results folder worth a report: any of these (globs under it).
PRODUCED = ("fig3_fx_vs_slip*.csv", "identification/fit_models.csv", "simulation/rms.csv",
            "simulation/path_metrics.csv", "montecarlo/runs.csv")


def arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--results", type=path, default=Path("results"), help="the results folder")
    parser.add_argument("--out", type=path, default=None, help="HTML file (default: <results>/report.html)")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace --out even if it is not a report this command wrote")


def owns(target: Path) -> bool:
    """Whether ``target`` is a page this command wrote (it names the command near its start)."""
    return b"rover-cosim report" in target.read_bytes()[:4096]


def run(args: argparse.Namespace) -> int:
    from rover_cosim.common.outputs import write_all
    from rover_cosim.report import build_report

    target = args.out or args.results / "report.html"
    if not any(any(args.results.glob(pattern)) for pattern in PRODUCED):
        fail("report", f"nothing to report in {args.results} (no results of fig3, identify or simulate; make them "
             "with `rover-cosim fig3`, `identify`, `simulate`)")
        return 1
    if not output_file(target, "report", COMMAND.needs_bytes, owns, args.overwrite, "--out"):
        return 2
    try:
        page = build_report(args.results)
    except (KeyError, ValueError, OSError, AttributeError, TypeError, RecursionError) as error:  # a results file
        # not as its job writes it: a value of another shape where a table or record was expected
        fail("report", f"{args.results}: a results file is not as its command writes it ({type(error).__name__}: "
             f"{error}); nothing written")
        return 1
    write_all({target: page.encode()})
    print(f"wrote {target}")
    return 0


COMMAND = Command(
    "report", help="results/report.html: figures and tables beside the paper's",
    summary="One self-contained HTML page of the results: figures, tables, provenance.",
    examples=("rover-cosim report --results results",), arguments=arguments, run=run, needs_bytes=20e6, owns=owns)
