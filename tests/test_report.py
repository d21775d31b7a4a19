"""The HTML report: labelled tables without NaN, every table in a scrolling box (readable from
1024 px), the soil named, and a real browser rendering it (headless Chromium, when installed)."""

from __future__ import annotations

import base64
import html
import json
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
    assert "Soil, wheel and rover in use (Table 2)" in page and "friction angle φ" in page
    assert "Rover <b>paper: ATHLETE-like" in page and "static wheel load 423.9 N" in page


def test_every_table_scrolls_inside_its_box(page):
    tables = page.count("<table")
    assert tables >= 8 and page.count("<div class='scroll'><table") == tables


def test_outside_the_papers_scope_is_described_with_numbers(page):
    section = page[page.index("Behaviour outside the paper"):]
    # the paper's soil: a resistance at the lightest load, a pull at the heaviest
    assert re.search(r"At zero slip Fx is a resistance of \d+\.\d N at 100 N and a pull of \d+\.\d N at 800 N",
                     section)
    assert "pulls at zero slip at" in section


def _fig3_only(folder, values):
    """A results folder with only a Fig. 3 table: Fx at zero slip per load as given."""
    folder.mkdir()
    rows = ["load_N,slip,Fx_N"] + [f"{load},0.0,{fx}" for load, fx in values] + [f"{load},0.1,50" for load, _ in values]
    (folder / "fig3_fx_vs_slip.csv").write_text("\n".join(rows) + "\n")
    return build_report(folder)


def test_the_zero_slip_sentence_follows_the_sign_of_the_force(tmp_path):
    resisting = _fig3_only(tmp_path / "r", [(100, -0.8), (800, -3.5)])
    assert "a resistance of 0.8 N at 100 N and a resistance of 3.5 N at 800 N" in resisting
    assert "a rolling wheel needs some slip to pull" in resisting
    pulling = _fig3_only(tmp_path / "p", [(100, 2.0), (800, 40.9)])
    assert "a pull of 2.0 N at 100 N and a pull of 40.9 N at 800 N" in pulling
    assert "the wheel pulls already when it rolls without slip" in pulling
    assert "needs some slip to pull" not in pulling


def _links(page: str) -> list[str]:
    """Every src and href attribute of the page's tags."""
    from html.parser import HTMLParser

    found: list[str] = []

    class Links(HTMLParser):
        def handle_starttag(self, tag, attrs):  # noqa: ANN001, ANN202 - HTMLParser's hook
            found.extend(value or "" for name, value in attrs if name in ("src", "href"))

    Links().feed(page)
    return found


INJECTIONS = ("<script>alert(1)</script>", "<img src=x onerror=alert(1)>", "<iframe src=https://example.org>")


def test_what_the_user_wrote_is_escaped_and_the_page_loads_nothing_remote(tmp_path):
    from rover_cosim.terramechanics.library import choose

    soil_file = tmp_path / "evil.toml"
    soil_file.write_text(f"title = {INJECTIONS[1]!r}\nsource = {INJECTIONS[2]!r}\nc = 500.0\nphi_deg = 30.0\n")
    named = tmp_path / "<script>alert(1)<_script>.toml"
    named.write_text(soil_file.read_text())
    results = tmp_path / "results"
    write_fig3(results, choice=choose(soil=str(named)))
    page = build_report(results)
    for text in ("<script", "<img src=x", "<iframe"):  # as tags: nowhere (as text, escaped, they may be)
        assert text not in page, text
    assert "&lt;script&gt;alert(1)&lt;_script&gt;" in page and "&lt;iframe src=https://example.org&gt;" in page
    assert not [value for value in _links(page) if not value.startswith(("data:", "#"))]  # nothing remote
    assert "reproduction of Yoshikawa" not in page and "paper Fit" not in page


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


#: Measures the page in the browser once it has loaded: its width against the window's, every
#: image decoded, every error event (a resource that failed, a script error).
PROBE = ("<script>window.__errors=[];window.addEventListener('error',function(e){window.__errors.push("
         "String(e.message||(e.target&&(e.target.src||e.target.href))))},true);"
         "window.addEventListener('load',function(){var images=Array.prototype.slice.call(document.images);"
         "var broken=images.filter(function(i){return !(i.complete&&i.naturalWidth>0)}).length;"
         "var d=document.documentElement;document.body.setAttribute('data-check',JSON.stringify({scroll:"
         "d.scrollWidth,client:d.clientWidth,images:images.length,broken:broken,errors:window.__errors}))});"
         "</script>")


def _rendered(page: str, folder) -> dict:
    """What the probe measured in headless Chromium at 1024 px."""
    html_file = folder / "probed.html"
    html_file.write_text(page.replace("<head>", "<head>" + PROBE, 1))
    dom = subprocess.run(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                          "--window-size=1024,800", "--virtual-time-budget=5000", "--dump-dom", html_file.as_uri()],
                         check=True, capture_output=True, text=True, timeout=120).stdout
    found = re.search(r'data-check="([^"]*)"', dom)
    assert found, "the probe did not run"
    return json.loads(html.unescape(found.group(1)))


@pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium not on PATH (Debian package `chromium`)")
def test_the_report_loads_every_figure_without_errors_or_overflow_in_chromium(page, tmp_path):
    check = _rendered(page, tmp_path)
    assert check["client"] == 1024 and check["scroll"] <= check["client"], check  # no sideways scrolling
    assert check["images"] >= 8 and check["broken"] == 0 and check["errors"] == [], check


@pytest.mark.skipif(shutil.which("chromium") is None, reason="chromium not on PATH (Debian package `chromium`)")
def test_the_probe_sees_overflow_broken_figures_and_errors(tmp_path):
    bad = ("<html><head></head><body><img src='data:image/png;base64,AAAA'><div style='width:1500px'>x</div>"
           "</body></html>")
    check = _rendered(bad, tmp_path)
    assert check["scroll"] > 1024 and check["broken"] == 1 and len(check["errors"]) == 1, check


def test_study_values_are_escaped_and_a_linked_figure_is_not_embedded(tmp_path):
    """A summary.json whose values carry markup (runs, seed, stop time, not only the title) and a
    figure that is a link to another file of the machine: the markup is text, the link is named and
    not read."""
    results = tmp_path / "results"
    write_fig3(results)
    secret = tmp_path / "secret.txt"
    secret.write_text("not for the page")
    figure = next(results.glob("fig3_fx_vs_slip*.png"))
    figure.unlink()
    figure.symlink_to(secret)
    (results / "montecarlo").mkdir()
    (results / "montecarlo" / "summary.json").write_text(json.dumps({
        "parameters": {"title": "<b>t</b>", "runs": "<script>1</script>", "seed": "<img src=x>", "soil": "s",
                       "stop_time_s": "<iframe src=y>"}, "scenarios": {}}))
    page = build_report(results)
    for text in ("<script", "<img src=x", "<iframe", "<b>t</b>"):
        assert text not in page, text
    assert "&lt;script&gt;1&lt;/script&gt;" in page and "&lt;iframe src=y&gt;" in page
    assert "is not a regular file (a link or a folder): not embedded" in page
    assert base64.b64encode(b"not for the page").decode() not in page


def test_table_3_of_a_four_wheel_rover_names_its_wheels_and_its_static_load(tmp_path):
    """A rover of four wheels (issue 46): the mirror, the co-simulated plant and the ablation's load
    come from its results, not the paper's six wheels and 424 N; the paper's column stays out."""
    from rover_cosim.report.sections import closed_loop_section

    simulation = tmp_path / "simulation"
    simulation.mkdir()
    rms = "limb,rms_N\n1,0.10\n2,0.09\n3,0.10\n4,0.09\n"
    (simulation / "rms.csv").write_text(rms)
    (simulation / "rms_cosim.csv").write_text(rms)
    (simulation / "ablation_fixed_load.csv").write_text("limb,rms_lut_N,rms_fixed_load_N\n" + "".join(
        f"{i},0.1,0.7\n" for i in range(1, 5)))
    (simulation / "simulation.json").write_text(json.dumps({"parameters": {"fixed_load_ablation_N": 174.15},
                                                            "checks": {}}))
    text = "\n".join(closed_loop_section(simulation, paper_soil=False))
    assert "limbs 3-4 mirror 1-2" in text and "RoverBody + 4 Wheel" in text and "one model at 174 N" in text
    assert "424" not in text and "6 Wheel" not in text and "paper RMS" not in text
