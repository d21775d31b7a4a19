"""Signals into and results out of a run, on the test FMU of our own (tests/fmus/typed.c): the
csv input block (FMPy's convention: continuous columns interpolated, discrete ones held, a
repeated time a step), `rover-cosim run model.fmu --input/--start`, full-precision CSV that reads
back equal to the bit, Parquet with typed columns, and rows recorded at an output interval."""

from __future__ import annotations

import json
from pathlib import Path

import fmpy
import numpy as np
import pandas as pd
import pytest

from rover_cosim.cli import main
from rover_cosim.orchestrator import SystemBuilder, run
from rover_cosim.orchestrator.blocks import CsvInput
from rover_cosim.orchestrator.model import SystemFileError
from rover_cosim.orchestrator.system import system_from_dict


@pytest.fixture()
def signals(tmp_path: Path) -> Path:
    """u ramps 0 -> 1 over 1 s; k steps 0 -> 5 at 0.5 s (a repeated time); b true from 0.3 s."""
    path = tmp_path / "in.csv"
    path.write_text("time,u,k,b\n0,0,0,false\n0.3,0.3,0,true\n0.5,0.5,0,true\n0.5,0.5,5,true\n1.0,1.0,5,true\n")
    return path


def test_the_csv_block_interpolates_continuous_columns_and_holds_the_others(signals):
    block = CsvInput("in", signals, hold=["k", "b"])
    assert block.outputs == ("u", "k", "b")
    np.testing.assert_allclose(block.values_at(0.25), [0.25, 0.0, 0.0])
    np.testing.assert_allclose(block.values_at(0.49), [0.49, 0.0, 1.0])
    np.testing.assert_allclose(block.values_at(0.5), [0.5, 5.0, 1.0])    # the later row of a repeated time
    np.testing.assert_allclose(block.values_at(-1.0), [0.0, 0.0, 0.0])   # before the first row: the first
    np.testing.assert_allclose(block.values_at(9.0), [1.0, 5.0, 1.0])    # after the last: the last


def test_bad_input_files_are_named(tmp_path):
    (tmp_path / "back.csv").write_text("time,u\n0,0\n1,1\n0.5,2\n")
    with pytest.raises(ValueError, match="time decreases at data row 3"):
        CsvInput("in", tmp_path / "back.csv")
    (tmp_path / "text.csv").write_text("time,u\n0,zero\n")
    with pytest.raises(ValueError, match="every value must be a number, true or false"):
        CsvInput("in", tmp_path / "text.csv")
    with pytest.raises(ValueError, match="hold/types name columns \\['v'\\]"):
        CsvInput("in", _ok(tmp_path), hold=["v"])


def _ok(folder: Path) -> Path:
    path = folder / "ok.csv"
    path.write_text("time,u\n0,0\n1,1\n")
    return path


def test_a_csv_block_in_a_system_file_drives_typed_inputs(typed, signals):
    data = {"simulation": {"stop_time": 1.0, "step": 0.1, "algorithm": "gauss-seidel"},
            "fmu": [{"name": "t", "path": str(typed)}],
            "block": [{"name": "in", "type": "csv", "file": signals.name, "hold": ["k", "b"],
                       "types": {"k": "Integer", "b": "Boolean"}}],
            "connection": [{"from": "in.u", "to": "t.u"}, {"from": "in.k", "to": "t.k"},
                           {"from": "in.b", "to": "t.b"}],
            "record": {"variables": ["t.y", "t.k2", "t.notb"]}}
    result = run(system_from_dict(data, name="in.toml", base=signals.parent, path=signals.parent / "in.toml")).data
    # the FMU steps from t with the inputs at t (its outputs then show them at t + h), as in FMPy
    before = np.maximum(result["time"] - 0.1, 0.0)
    np.testing.assert_allclose(result["t.y"], 2.0 * before, atol=1e-12)          # gain 2 * the ramp
    k = result["t.k2"] - np.arange(11)                                            # k2 = k + steps
    assert k.tolist() == [0] * 6 + [5] * 5
    assert result["t.notb"].tolist() == [True] * 4 + [False] * 7
    theirs = fmpy.simulate_fmu(str(typed), input=_fmpy_signals(signals), stop_time=1.0, output_interval=0.1,
                               output=["y", "k2", "notb"])
    np.testing.assert_allclose(result["t.y"], theirs["y"], atol=1e-12)
    assert result["t.k2"].tolist() == theirs["k2"].tolist() and result["t.notb"].tolist() == theirs["notb"].tolist()


def _fmpy_signals(signals: Path) -> np.ndarray:
    """The CSV file as FMPy's input array (k Integer, b Boolean)."""
    table = pd.read_csv(signals).replace({"true": True, "false": False})
    return np.array([tuple(row) for row in table.itertuples(index=False)],
                    dtype=[("time", float), ("u", float), ("k", np.int32), ("b", np.bool_)])


def test_run_one_fmu_with_an_input_file_and_start_values(typed, signals, tmp_path, capsys):
    out = tmp_path / "one.csv"
    assert main(["run", str(typed), "--input", str(signals), "--start", "gain=3", "--start", 'label="moon"',
                 "--start", "s=sea", "-o", str(out), "--quiet"]) == 0
    data = pd.read_csv(out)
    np.testing.assert_allclose(data["model.y"], 3.0 * np.maximum(data["time"] - 0.1, 0.0), atol=1e-12)  # u at t
    assert set(data["model.sout"]) == {"moon:sea"}
    record = json.loads(out.with_suffix(".json").read_text())
    assert record["blocks"] == {"input": "csv"}
    (tmp_path / "other.csv").write_text("time,u,nothing\n0,0,1\n1,1,1\n")
    assert main(["run", str(typed), "--input", str(tmp_path / "other.csv"), "-o", str(out), "--quiet"]) == 0
    assert "input columns nothing: not inputs of the FMU, left out" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit_:
        main(["run", str(typed), "--start", "nonsense", "-o", str(out), "--quiet"])
    assert exit_.value.code == 2 and "'nonsense': expected NAME=VALUE" in capsys.readouterr().err
    assert main(["run", str(typed), "--start", "counter=1", "-o", str(out), "--quiet"]) == 2
    assert "model.counter cannot be given a start value" in capsys.readouterr().err


def test_csv_values_read_back_equal_to_the_bit_and_parquet_keeps_types(typed, tmp_path):
    out = tmp_path / "run.csv"
    assert main(["run", str(typed), "--start", "gain=0.1", "--start", "u=0.3", "-o", str(out), "--quiet"]) == 0
    data = pd.read_csv(out)
    assert (data["model.y"] == 0.1 * 0.3).all()  # 0.030000000000000002: every digit kept
    parquet = tmp_path / "run.parquet"
    assert main(["run", str(typed), "-o", str(parquet), "--quiet"]) == 0
    table = pd.read_parquet(parquet)
    assert str(table["model.counter"].dtype) == "int64" and str(table["model.even"].dtype) == "bool"
    assert parquet.with_suffix(".json").is_file()


def test_rows_are_recorded_at_the_output_interval(typed, tmp_path):
    system = (SystemBuilder("decimated").simulation(stop_time=1.05, step=0.05, output_interval=0.2)
              .add_fmu("t", typed).record("t.counter").build())
    data = run(system).data
    np.testing.assert_allclose(data["time"], [0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.05])  # and the last row
    assert data["t.counter"].tolist() == [0, 4, 8, 12, 16, 20, 21]
    with pytest.raises(SystemFileError, match="output_interval: 0.07: expected a whole number of communication steps"):
        SystemBuilder("bad").simulation(stop_time=1.0, step=0.05, output_interval=0.07)
    with pytest.raises(SystemFileError, match="output_interval: inf: expected an interval > 0 s and at most"):
        SystemBuilder("bad").simulation(stop_time=1.0, step=0.05, output_interval=float("inf"))  # was an OverflowError
