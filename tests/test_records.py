"""What every record says of the code that made it (issue 46, item 4)."""

from __future__ import annotations


def test_every_record_says_the_working_directory_and_whether_the_tree_was_dirty(monkeypatch, tmp_path):
    """Issue 46, item 4: two records that name the same commit ran the same code only if neither
    tree had uncommitted changes, or both had the same diff (its digest is recorded)."""
    import hashlib

    from rover_cosim.common import outputs

    answers = {("rev-parse", "HEAD"): b"abc123\n", ("status", "--porcelain", "--untracked-files=no"): b" M x.py\n",
               ("diff", "HEAD"): b"the diff"}
    monkeypatch.setattr(outputs, "_git", lambda *arguments: answers.get(arguments))
    outputs.source_tree.cache_clear()
    monkeypatch.chdir(tmp_path)
    try:
        record = outputs.run_record("rover-cosim fig3", {})
    finally:
        outputs.source_tree.cache_clear()
    assert record["working_directory"] == str(tmp_path)
    assert record["git_commit"] == "abc123" and record["git_dirty"] is True
    assert record["git_diff_sha256"] == hashlib.sha256(b"the diff").hexdigest()
    answers[("status", "--porcelain", "--untracked-files=no")] = b""
    record = outputs.run_record("rover-cosim fig3", {})
    outputs.source_tree.cache_clear()
    assert record["git_dirty"] is False and "git_diff_sha256" not in record


def test_the_report_names_the_folder_it_was_made_from(tmp_path):
    from rover_cosim.cli import main

    results = tmp_path / "results_msl"
    assert main(["fig3", "--out", str(results), "--loads", "300", "--slip-step", "0.1"]) == 0
    assert main(["report", "--results", str(results)]) == 0
    page = (results / "report.html").read_text()
    assert f"files under <code>{results.as_posix()}/</code>" in page and "<code>results/</code>" not in page


def test_a_figure_names_the_record_it_was_written_with(tmp_path):
    import hashlib

    from PIL import Image

    from rover_cosim.cli import main
    from rover_cosim.common.outputs import PNG_RECORD_KEY, png_text

    assert main(["fig3", "--out", str(tmp_path), "--loads", "300", "--slip-step", "0.1"]) == 0
    png = (tmp_path / "fig3_fx_vs_slip.png").read_bytes()
    record = (tmp_path / "fig3_fx_vs_slip.json").read_bytes()
    assert png_text(png)[PNG_RECORD_KEY] == f"fig3_fx_vs_slip.json sha256:{hashlib.sha256(record).hexdigest()}"
    with Image.open(tmp_path / "fig3_fx_vs_slip.png") as image:  # still a valid PNG, its text readable
        image.load()
        assert image.info[PNG_RECORD_KEY].startswith("fig3_fx_vs_slip.json sha256:")


def test_a_record_says_the_units_of_the_tables_beside_it(tmp_path):
    """The CSV headers stay plain (what pandas users index by); the record written with them
    says each column's unit."""
    import json

    from rover_cosim.cli import main
    from rover_cosim.common.units import column_unit

    assert main(["fig3", "--out", str(tmp_path), "--loads", "300", "--slip-step", "0.1"]) == 0
    header = (tmp_path / "fig3_fx_vs_slip.csv").read_text().splitlines()[0]
    assert header == "load_N,slip,sinkage_m,Fx_N,Fz_N,Tx_Nm"
    units = json.loads((tmp_path / "fig3_fx_vs_slip.json").read_text())["units"]["fig3_fx_vs_slip.csv"]
    assert units == {"load_N": "N", "slip": "1", "sinkage_m": "m", "Fx_N": "N", "Fz_N": "N", "Tx_Nm": "N.m"}
    assert (column_unit("Fz_3"), column_unit("sinkage_6"), column_unit("omega_2"), column_unit("nonsense")) == (
        "N", "m", "rad/s", None)



def test_a_runs_record_gives_each_recorded_variable_its_declared_unit(fmu_dir, tmp_path):
    import json

    from rover_cosim.cli import main

    assert main(["run", str(fmu_dir / "SingleWheel.fmu"), "-q", "-o", str(tmp_path / "out.csv"), "--start", "tau=20",
                 "--stop-time", "0.05"]) == 0
    units = json.loads((tmp_path / "out.json").read_text())["units"]
    assert units["time"] == "s" and units["model.Fx"] == "N" and units["model.Tx"] == "N.m"
    assert units["model.omega"] == "rad/s" and units["model.sinkage"] == "m"
