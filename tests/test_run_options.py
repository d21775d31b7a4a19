"""`rover-cosim run` options for other tools' FMUs (issue 44): --record (locals and any variable,
glob patterns; a run that would record nothing but time says what it could record),
--relative-tolerance for Model Exchange, --validate strict|warn|off for a model description that
fails FMPy's validation (FMPy runs those with validate=False). On the own integrator FMU."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import pandas as pd
import pytest
from c_fmu import built_or_skip
from integrator_fmu import build_integrator

from rover_cosim.cli import main


@pytest.fixture(scope="module")
def integrator(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_or_skip(build_integrator(tmp_path_factory.mktemp("integrator")))


def _variant(fmu: Path, folder: Path, name: str, change: tuple[str, str], *more: tuple[str, str]) -> Path:
    """A copy of ``fmu`` whose modelDescription.xml has the text changes ``change``, ``more``."""
    target = folder / f"{name}.fmu"
    with zipfile.ZipFile(fmu) as source, zipfile.ZipFile(target, "w") as copy:
        for item in source.infolist():
            data = source.read(item)
            if item.filename == "modelDescription.xml":
                text = data.decode()
                for old, new in (change, *more):
                    assert old in text, old
                    text = text.replace(old, new)
                data = text.encode()
            copy.writestr(item, data)
    return target


def test_record_names_locals_and_glob_patterns(integrator, tmp_path, capsys):
    out = tmp_path / "r.csv"
    assert main(["run", str(integrator), "--record", "x", "--record", "der*", "--start", "u=2", "-o", str(out),
                 "--quiet"]) == 0
    data = pd.read_csv(out)
    assert list(data.columns) == ["time", "model.x", "model.der(x)"]
    assert (data["model.der(x)"] == 2.0).all() and data["model.x"].iloc[-1] == pytest.approx(2.0)
    assert main(["run", str(integrator), "--record", "zz*", "-o", str(tmp_path / "none.csv"), "--quiet"]) == 2
    assert "--record 'zz*': names no variable of the FMU that can be recorded" in capsys.readouterr().err
    assert not (tmp_path / "none.csv").exists()


def test_an_fmu_without_outputs_says_what_it_could_record(integrator, tmp_path, capsys):
    quiet = _variant(integrator, tmp_path, "Quiet", ('causality="output"', 'causality="local"'),
                     ('<Outputs>\n      <Unknown index="1"/>\n      <Unknown index="4" dependencies="3"/>\n'
                      '      <Unknown index="6" dependencies="5"/>\n      <Unknown index="7" dependencies=""/>\n'
                      '    </Outputs>\n', ""))
    out = tmp_path / "q.csv"
    assert main(["run", str(quiet), "--validate", "off", "-o", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert "no output that can be recorded: only time would be; name what to record with --record" in err
    assert "it has x, der(x), u, y, k, m, r" in err
    assert main(["run", str(quiet), "--validate", "off", "--record", "*", "-o", str(out), "--quiet"]) == 0
    assert list(pd.read_csv(out).columns) == ["time", "model.x", "model.der(x)", "model.u", "model.y", "model.k",
                                              "model.m", "model.r"]


def test_relative_tolerance_reaches_the_model_exchange_integrator(integrator, tmp_path, capsys):
    out = tmp_path / "t.csv"
    assert main(["run", str(integrator), "--interface", "model-exchange", "--relative-tolerance", "1e-10",
                 "--start", "u=1", "-o", str(out), "--quiet"]) == 0
    assert json.loads(out.with_suffix(".json").read_text())["parameters"]["relative_tolerance"] == 1e-10
    assert pd.read_csv(out)["model.x"].iloc[-1] == pytest.approx(1.0, abs=1e-9)
    assert main(["run", str(integrator), "--relative-tolerance", "2", "-o", str(out), "--quiet"]) == 2
    assert "relative_tolerance: 2.0: expected 0 < relative_tolerance < 1" in capsys.readouterr().err


def test_validate_strict_refuses_warn_runs_and_says_off_runs_and_records(integrator, tmp_path, capsys):
    odd = _variant(integrator, tmp_path, "Odd", ('variableNamingConvention="flat"',
                                                 'variableNamingConvention="flat" madeUpAttribute="1"'))
    out = tmp_path / "v.csv"
    assert main(["run", str(odd), "-o", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "Odd.fmu: its modelDescription.xml fails FMPy's validation" in err and "madeUpAttribute" in err
    assert "--validate warn runs it as FMPy does with validate=False" in err and not out.exists()
    assert main(["run", str(odd), "--validate", "warn", "--start", "u=1", "-o", str(out), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert "fails FMPy's validation, run all the same (--validate warn)" in err and "madeUpAttribute" in err
    record = json.loads(out.with_suffix(".json").read_text())["fmus"]["model"]
    assert record["validation"] == "warn" and any("madeUpAttribute" in p for p in record["validation_problems"])
    assert pd.read_csv(out)["model.x"].iloc[-1] == pytest.approx(1.0)
    assert main(["run", str(odd), "--validate", "off", "-o", str(out), "--quiet", "--overwrite"]) == 0
    assert "validation" not in capsys.readouterr().err
    assert json.loads(out.with_suffix(".json").read_text())["fmus"]["model"]["validation"] == "off"


def test_run_does_not_replace_a_users_files_beside_its_output(integrator, tmp_path, capsys):
    """The record (x.json) and the partial rows (x.partial.csv) a run may write beside x.csv: a
    user's file of that name is named and kept unless --overwrite; the run's own are replaced."""
    out = tmp_path / "x.csv"
    mine = tmp_path / "x.json"
    mine.write_text('{"my": "notes"}')
    assert main(["run", str(integrator), "--start", "u=1", "-o", str(out), "--quiet"]) == 2
    assert f"{mine} exists and is not a result of rover-cosim run" in capsys.readouterr().err
    assert mine.read_text() == '{"my": "notes"}' and not out.exists()
    mine.unlink()
    (tmp_path / "x.partial.csv").write_text("time,a\n0,1\n")
    assert main(["run", str(integrator), "--start", "u=1", "-o", str(out), "--quiet"]) == 2
    assert "x.partial.csv exists and is not a result of rover-cosim run" in capsys.readouterr().err
    (tmp_path / "x.partial.csv").unlink()
    assert main(["run", str(integrator), "--start", "u=1", "-o", str(out), "--quiet"]) == 0
    assert main(["run", str(integrator), "--start", "u=2", "-o", str(out), "--quiet"]) == 0  # its own: replaced
    assert pd.read_csv(out)["model.x"].iloc[-1] == pytest.approx(2.0)
    (tmp_path / "y.json").write_text("{}")
    assert main(["run", str(integrator), "-o", str(tmp_path / "y.csv"), "--quiet", "--overwrite"]) == 0


def test_testbed_data_does_not_replace_a_users_record(tmp_path, capsys):
    (tmp_path / "w.json").write_text('{"mine": 1}')
    assert main(["testbed-data", "--out", str(tmp_path / "w.csv")]) == 2
    assert "w.json exists and is not a result of rover-cosim testbed-data" in capsys.readouterr().err
    assert (tmp_path / "w.json").read_text() == '{"mine": 1}' and not (tmp_path / "w.csv").exists()
