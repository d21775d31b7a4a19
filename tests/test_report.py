"""The HTML report: labelled tables without NaN, every table in a scrolling box (readable from
1024 px), the soil named, and a real browser rendering it (headless Chromium, when installed)."""

from __future__ import annotations

import re
import shutil
import subprocess

import numpy as np
import pytest
from PIL import Image

from rover_cosim.jobs.fig3 import write_fig3
from rover_cosim.report import build_report


@pytest.fixture(scope="module")
def page(simulated, results_root) -> str:
    """The report of the session's results, with Fig. 3 (`make fig3`) beside them."""
    write_fig3(results_root)
    return build_report(results_root)


def _text(page: str) -> str:
    """The page without embedded images and provenance JSON."""
    return re.sub(r"<pre>.*?</pre>|src='data:[^']*'", "", page, flags=re.S)


def test_tables_are_labelled_and_have_no_nan(page):
    text = _text(page)
    assert ">nan<" not in text.lower() and "NaN" not in text
    for raw in ("rms_lut_N", "final_v_m_s", "fit_percent_quadratic", "time_to_98_percent_s"):
        assert raw not in text, raw
    assert "mirror of limb 1" in page and "final velocity [m/s]" in page
    assert "Soil and wheel in use (Table 2)" in page and "friction angle φ" in page


def test_every_table_scrolls_inside_its_box(page):
    tables = page.count("<table")
    assert tables >= 8 and page.count("<div class='scroll'><table") == tables


def test_outside_the_papers_scope_is_described_with_numbers(page):
    section = page[page.index("Behaviour outside the paper"):]
    assert re.search(r"At zero slip Fx is the rolling resistance: -?\d+\.\d N", section)


@pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium not on PATH (Debian package `chromium`)")
def test_report_renders_in_headless_chromium_at_1024_px(page, tmp_path):
    html_file, shot = tmp_path / "report.html", tmp_path / "shot.png"
    html_file.write_text(page)
    subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                    "--window-size=1024,4000", f"--screenshot={shot}", html_file.as_uri()],
                   check=True, capture_output=True, timeout=120)
    image = np.asarray(Image.open(shot).convert("L"))
    assert image.shape[1] == 1024
    drawn = np.nonzero((image < 200).any(axis=0))[0]
    assert drawn.min() > 5 and drawn.max() < 1019   # nothing cut off at the window's edges
    assert (image < 200).mean() > 0.01              # text, tables and figures, not a blank page
