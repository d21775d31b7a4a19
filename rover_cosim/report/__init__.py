"""``make report``: results/report.html, one self-contained page (figures embedded, no network):
our figures and tables beside the paper's values, the soil and wheel in use, and the provenance
of every run. ``page``: HTML building blocks; ``sections``: one function per part of the page."""

from __future__ import annotations

import html
from pathlib import Path

from . import sections
from .page import document


def build_report(results: Path) -> str:
    results = Path(results)
    identification, simulation = results / "identification", results / "simulation"
    paper_soil = sections.on_paper_soil(results)
    label = html.escape(sections.soil_label(results))
    folder = html.escape(results.as_posix().rstrip("/") + "/")  # the folder it was made from, as given
    if paper_soil:
        parts = ["<h1>rover-cosim: reproduction of Yoshikawa et al. (paper's soil and wheel)</h1>",
                 (f"<p>Every number below is read from the files under <code>{folder}</code> written by "
                  "<code>make run</code>; the paper's values are quoted beside ours.</p>")]
    else:
        parts = [f"<h1>rover-cosim: the paper's pipeline on {label}</h1>",
                 (f"<p>Every number below is read from the files under <code>{folder}</code>. The soil, wheel or rover "
                  "is not the paper's, so the paper's numbers are not set beside these.</p>")]
    parts += sections.soil_section(results)
    parts += sections.fig3_section(results)
    parts += sections.identification_section(identification, paper_soil)
    parts += sections.lateral_section(identification)
    parts += sections.closed_loop_section(simulation, paper_soil)
    parts += sections.path_section(simulation)
    parts += sections.terrain_section(simulation)
    parts += sections.legwheel_section(simulation)
    parts += sections.effects_section(simulation)
    parts += sections.coupling_section(results)
    parts += sections.montecarlo_section(results / "montecarlo")
    parts += sections.scope_section(results)
    parts += sections.provenance_section(results)
    return document(f"rover-cosim report: {sections.soil_label(results)}", parts)


__all__ = ["build_report"]
