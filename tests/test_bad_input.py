"""Bad input found by the fuzz of issue 45 that ended in a traceback or a misleading message:
each now gets one line naming the value and what was expected, and exit 2, before any work."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from c_fmu import built_or_skip
from misbehave_fmu import build_misbehave

from rover_cosim.cli import main

STUDY = Path(__file__).parents[1] / "rover_cosim" / "jobs" / "montecarlo" / "studies" / "lunar_regolith.toml"


@pytest.fixture(scope="module")
def misbehave(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_misbehave(tmp_path_factory.mktemp("misbehave")))


def _refused(argv: list[str], said: str, capsys: pytest.CaptureFixture[str]) -> None:
    code: object
    try:
        code = main(argv)
    except SystemExit as exit_:  # argparse's own refusals
        code = exit_.code
    err = capsys.readouterr().err
    assert code == 2, (argv, err)
    assert said in err and "Traceback" not in err, err


@pytest.mark.parametrize(("option", "said"), [
    (["--output-interval", "1e308"], "output_interval: 1e+308: expected an interval > 0 s and at most"),
    (["--output-interval", "1e23"], "expected an interval > 0 s and at most the run's length (1.0 s)"),
    (["--start", "at=nan"], "at: nan: expected a finite number (Real)"),
    (["--start", "at=-inf"], "at: -inf: expected a finite number (Real)"),
])
def test_run_refuses_absurd_numbers(misbehave, tmp_path, capsys, option, said):
    _refused(["run", str(misbehave), "-q", "-o", str(tmp_path / "x.csv"), *option], said, capsys)
    assert not (tmp_path / "x.csv").exists()


def test_an_input_file_with_a_column_twice_is_refused(misbehave, tmp_path, capsys):
    signals = tmp_path / "in.csv"
    signals.write_text("time,u,u\n0,1,2\n")
    _refused(["run", str(misbehave), "-q", "-o", str(tmp_path / "x.csv"), "--input", str(signals)],
             "column 'u' appears more than once", capsys)


def test_identify_and_testbed_data_refuse_absurd_numbers(tmp_path, capsys, monkeypatch):
    _refused(["identify", "--record-interval", "1e308", "--out", str(tmp_path / "id")],
             "record interval 1e+308 s: expected a whole number of steps", capsys)
    _refused(["testbed-data", "--loads", "1e-308", "--out", str(tmp_path / "t.csv")],
             "load=1e-308 N: expected a finite load >= 0.001 N", capsys)
    monkeypatch.setenv("ROVER_COSIM_SCHEDULER_TIMEOUT", "abc")
    _refused(["identify", "--scheduler", "tcp://127.0.0.1:1", "--out", str(tmp_path / "id2")],
             "ROVER_COSIM_SCHEDULER_TIMEOUT = 'abc': expected a number of seconds > 0", capsys)
    assert not (tmp_path / "id").exists() and not (tmp_path / "id2").exists()


@pytest.mark.parametrize(("pattern", "replacement", "said"), [
    (r'distribution = "lognormal"', 'distribution = ["uniform"]', "distribution = ['uniform']: expected one of"),
    (r"(\[correlation\]\nparameters = ).*", r'\1[["soil.c"]]', "expected a list of distinct parameter names"),
    (r"(\nmatrix = ).*", r"\1[[1e400, 0], [0, 1]]", "expected 2 x 2 finite numbers"),
    (r"(\nmatrix = ).*", r'\1"x"', "expected a square table of numbers"),
])
def test_a_study_of_odd_shapes_is_refused(tmp_path, capsys, pattern, replacement, said):
    study = tmp_path / "study.toml"
    study.write_text(re.sub(pattern, replacement, STUDY.read_text(), count=1))
    _refused(["montecarlo", "--study", str(study), "--out", str(tmp_path / "mc"), "-q"], said, capsys)


def test_soils_says_why_a_file_of_the_users_is_neither_a_soil_nor_a_wheel(tmp_path, capsys):
    mixed = tmp_path / "mixed.toml"
    mixed.write_text("c = 800.0\nr = 0.3\n")
    _refused(["soils", str(mixed)], "neither a soil nor a wheel: as a soil: soil 'mixed': unknown key(s) ['r']",
             capsys)


@pytest.mark.parametrize("text", ["[1, 2]", "[" * 100_000 + "]" * 100_000, "3.5", '{"parameters": [1]}'])
def test_a_report_input_of_another_shape_is_a_message(tmp_path, capsys, text):
    results = tmp_path / "results"
    assert main(["fig3", "--out", str(results), "--loads", "300", "--slip-step", "0.1"]) == 0
    (results / "montecarlo").mkdir()
    (results / "montecarlo" / "summary.json").write_text(text)
    capsys.readouterr()
    assert main(["report", "--results", str(results), "--out", str(tmp_path / "r.html")]) == 1
    err = capsys.readouterr().err
    assert "a results file is not as its command writes it" in err and "Traceback" not in err
    assert not (tmp_path / "r.html").exists()


def test_fig3_and_estimate_soil_refuse_to_replace_a_users_file(tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "fig3_fx_vs_slip.png").write_text("my own figure")
    fig3 = ["fig3", "--out", str(out), "--loads", "300", "--slip-step", "0.1"]
    _refused(fig3, "fig3_fx_vs_slip.png exists and is not a result of rover-cosim fig3", capsys)
    assert (out / "fig3_fx_vs_slip.png").read_text() == "my own figure"
    assert main([*fig3, "--overwrite"]) == 0 and main(fig3) == 0  # then it is the command's own: replaced
    (out / "soil.toml").write_text("# my soil")
    _refused(["estimate-soil", str(tmp_path / "data.csv"), "--out", str(out)],
             "soil.toml exists and is not a result of rover-cosim estimate-soil", capsys)
    assert (out / "soil.toml").read_text() == "# my soil"


@pytest.mark.parametrize(("index", "said"), [("0", '<Unknown index="0"> in Outputs: expected an index from 1 to 3'),
                                             ("9", '<Unknown index="9"> in Outputs: expected an index from 1 to 3')])
def test_a_model_structure_index_outside_the_variables_is_refused(misbehave, tmp_path, capsys, index, said):
    """FMPy reads index 0 as the last variable (silently wrong) and fails on one past the end
    with "list index out of range"."""
    import zipfile

    edited = tmp_path / "Edited.fmu"
    with zipfile.ZipFile(misbehave) as source, zipfile.ZipFile(edited, "w") as target:
        for item in source.infolist():
            data = source.read(item)
            if item.filename == "modelDescription.xml":
                data = data.replace(b'<Unknown index="1"/>', f'<Unknown index="{index}"/>'.encode())
            target.writestr(item, data)
    for validate in ("strict", "off"):
        _refused(["run", str(edited), "-q", "-o", str(tmp_path / "x.csv"), "--validate", validate], said, capsys)


def test_identify_refuses_an_fmu_that_is_not_a_test_bed_before_any_run(misbehave, tmp_path, capsys):
    _refused(["identify", "--fmu", str(misbehave), "--out", str(tmp_path / "id")],
             "not a SingleWheel FMU (no variables ['W', 'tau'", capsys)
    assert not (tmp_path / "id").exists()


@pytest.mark.parametrize(("settings", "said"), [
    ({"interfaces": ["a"]}, "interfaces = \"['a']\": expected an object of texts"),
    ({"blocks": [1]}, "blocks = '[1]': expected a list of objects"),
    ({"iteration": 3}, "iteration = '3': expected an object of numbers"),
    ({"record": "a.x"}, "record = 'a.x': expected a list of texts"),
    ({"allow_algebraic_loops": "yes"}, "allow_algebraic_loops = 'yes': expected true or false"),
    ({"step": True}, "step = 'True': expected a number"),
    ({"block_connections": [{"from": "a.y"}]}, "block_connections 1: expected"),
    ({"blocks": [{"type": "step"}]}, "block 1: expected a name and a type"),
    ({"bogus": 1}, "unknown key 'bogus'"),
])
def test_an_ssp_annotation_of_odd_shapes_is_refused(settings, said):
    """The master annotation is the archive author's JSON: each key is checked for its shape
    before use (a list where an object belongs was a traceback, "yes" was taken as true)."""
    from rover_cosim.orchestrator.ssp import SspError, _check_shapes

    with pytest.raises(SspError, match=re.escape(said)):
        _check_shapes(settings)
    _check_shapes({"step": 0.001, "algorithm": "jacobi", "order": ["a"], "record": ["a.x"],
                   "iteration": {"tolerance": 1e-6}, "allow_algebraic_loops": False,
                   "blocks": [{"name": "u", "type": "step"}], "interfaces": {"a": "x"},
                   "block_connections": [{"from": "u.y", "to": "a.u"}]})


def test_estimate_soil_refuses_an_absurd_load_and_a_huge_field(tmp_path, capsys):
    data = tmp_path / "data.csv"
    assert main(["testbed-data", "--out", str(data)]) == 0
    lines = data.read_text().splitlines()
    big, huge = tmp_path / "big.csv", tmp_path / "huge.csv"
    big.write_text("\n".join([lines[0], "1e300" + lines[1][lines[1].index(","):], *lines[2:]]) + "\n")
    huge.write_text("\n".join([lines[0], "x" * 200_000 + lines[1][lines[1].index(","):], *lines[2:]]) + "\n")
    capsys.readouterr()
    _refused(["estimate-soil", str(big), "--out", str(tmp_path / "e1")], "1e+300 N: expected a load > 0 N and at most",
             capsys)
    _refused(["estimate-soil", str(huge), "--out", str(tmp_path / "e2")], "not a CSV table of numbers", capsys)


def test_a_study_of_an_unknown_soil_is_bad_input_before_any_work(tmp_path, capsys):
    study = tmp_path / "study.toml"
    study.write_text(STUDY.read_text().replace('soil = "paper"', 'soil = "nosuchsoil"', 1))
    _refused(["montecarlo", "--study", str(study), "--out", str(tmp_path / "mc"), "-q"],
             "soil = 'nosuchsoil': soil 'nosuchsoil': expected one of paper", capsys)

