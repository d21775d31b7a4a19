"""SSP 1.0 exchange: `rover-cosim export-ssp` writes archives that validate against the SSP schema
FMPy ships and that FMPy's fmpy.ssp and libcosimpy run to our trajectories; `rover-cosim run
system.ssp` equals the TOML run; blocks travel as system connectors plus an annotation."""

from __future__ import annotations

import tomllib
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
import tomli_w

from rover_cosim.cli import EXAMPLES, main
from rover_cosim.orchestrator.blocks import register_factory
from rover_cosim.orchestrator.master import run
from rover_cosim.orchestrator.model import SystemFileError
from rover_cosim.orchestrator.ssp import SspError, export_ssp, fmpy_parameter_set, load_ssp, validate_ssd
from rover_cosim.orchestrator.system import system_from_dict


def rover(fmu_dir: Path, **simulation: object) -> dict:
    data = tomllib.loads(EXAMPLES["rover_cosim"].read_text())
    data["simulation"].update(simulation)
    return data


def constant_torque(data: dict) -> dict:
    data["block"] = [{"name": "torque", "type": "constant", "value": 20.0, "unit": "N.m"}]
    return data


def test_export_validates_and_describes_the_system(fmu_dir, fmus, tmp_path):
    data = rover(fmu_dir)
    data["fmu"][0]["parameters"] = {"rover.M": 1600.0}
    system = system_from_dict(data, name="rover_cosim.toml", base=fmu_dir)
    exported = export_ssp(system, tmp_path / "rover.ssp")
    validate_ssd(exported.path)
    assert exported.external == ["torque"] and exported.folded == []
    with zipfile.ZipFile(exported.path) as archive:
        names = set(archive.namelist())
        ssd = archive.read("SystemStructure.ssd").decode()
        ssv = archive.read("resources/body.ssv").decode()
    assert 'name="rover.M"' in ssv and 'value="1600.0" unit="kg"' in ssv
    assert {"SystemStructure.ssd", "resources/RoverBody.fmu", "resources/Wheel.fmu", "resources/body.ssv"} <= names
    assert sum(name.endswith(".fmu") for name in names) == 2          # each FMU file once
    assert 'name="torque_y" kind="input"' in ssd and '<ssc:Real unit="N.m"/>' in ssd
    assert ssd.count("<ssd:Connection ") == len(system.connections)
    assert '<ssc:Unit name="N">' in ssd and 'kg="1" m="1" s="-2"' in ssd


def test_toml_to_ssp_to_run_equals_the_toml_run(fmu_dir, fmus, tmp_path):
    system = system_from_dict(rover(fmu_dir, stop_time=0.5), name="rover_cosim.toml", base=fmu_dir)
    again = load_ssp(export_ssp(system, tmp_path / "rover.ssp").path, tmp_path / "unpacked")
    assert [b.name for b in again.blocks] == ["torque"] and again.algorithm == system.algorithm
    ours, theirs = run(system).data, run(again).data
    pd.testing.assert_frame_equal(ours, theirs, check_exact=True)


def test_libcosim_runs_the_exported_rover_to_our_trajectories(fmu_dir, fmus, tmp_path):
    """libcosimpy's CosimExecution.from_ssp_file on the exported rover (constant torque, folded into
    the start values): equal to our Jacobi master at the same step to 1e-9 of scale."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    system = system_from_dict(constant_torque(rover(fmu_dir, stop_time=0.5, algorithm="jacobi")), name="c",
                              base=fmu_dir)
    exported = export_ssp(system, tmp_path / "constant.ssp")
    assert exported.folded == ["torque"]
    ours = run(system).data
    execution = CosimExecution.from_ssp_file(str(exported.path), step_size=round(1e-3 * 1e9))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    index = {(i.name.decode() if isinstance(i.name, bytes) else i.name): i.index for i in execution.slave_infos()}
    refs = {f.name: {v.name: v.valueReference for v in f.description.modelVariables} for f in system.fmus}
    columns = [("body", "v"), ("body", "pitch"), ("wheel1", "Fz"), ("wheel3", "Fx")]
    rows = []
    for _ in range(500):
        execution.step(1)
        rows.append([observer.last_real_values(index[i], [refs[i][v]])[0] for i, v in columns])
    theirs = np.array(rows)
    for k, (instance, variable) in enumerate(columns):
        expected = ours[f"{instance}.{variable}"].to_numpy()[1:]
        scale = max(1.0, float(np.abs(expected).max()))
        np.testing.assert_allclose(theirs[:, k], expected, rtol=0, atol=1e-9 * scale, err_msg=variable)
    assert theirs[-1, 0] > 0.05   # the folded torque drives the rover


def test_fmpy_runs_the_exported_rover_to_our_trajectories(fmu_dir, fmus, tmp_path):
    """FMPy's simulate_ssp (a Jacobi master) with the exported rover and the torque block's signal
    fed to the system connector torque_y. FMPy starts every connector at 0 for the first step (no
    exchange of initial values: the wheels see no load in it), which leaves the body a constant
    velocity offset (0.1 % of v at 1 s, constant to 1e-5 of scale after 0.1 s) and excites the
    pitch a little (0.6 %); otherwise the trajectories are ours: after 0.1 s within 1 % of scale."""
    from fmpy.ssp.simulation import simulate_ssp

    system = system_from_dict(rover(fmu_dir, stop_time=1.0, algorithm="jacobi"), name="r", base=fmu_dir)
    exported = export_ssp(system, tmp_path / "rover.ssp")
    ours = run(system).data
    torque: Any = system.blocks[0].block  # a TanhStep source: value(t)
    theirs = simulate_ssp(str(exported.path), stop_time=1.0, step_size=1e-3,
                          parameter_set=fmpy_parameter_set(exported.path), input={"torque_y": torque.value})
    for column in ("body.v", "body.pitch", "wheel1.Fz", "wheel3.Fz", "wheel2.Fx"):
        expected = ours[column].to_numpy()[1:1001]
        got = theirs[[n for n in theirs.dtype.names if n.endswith(column)][0]][:1000]
        scale = float(np.abs(expected).max())
        assert np.abs(got - expected)[100:].max() <= 1e-2 * scale, column
    v = "body.v"
    offset = theirs[[n for n in theirs.dtype.names if n.endswith(v)][0]][:1000] - ours[v].to_numpy()[1:1001]
    assert np.ptp(offset[100:]) <= 1e-4 * float(np.abs(ours[v]).max())


def test_cli_exports_and_runs_an_ssp(fmu_dir, fmus, tmp_path, capsys):
    archive = tmp_path / "rover.ssp"
    assert main(["export-ssp", "rover_cosim", "--fmu-dir", str(fmu_dir), "-o", str(archive)]) == 0
    out = capsys.readouterr().out
    assert "valid against the SSP 1.0 schema" in out and "blocks torque" in out
    assert main(["run", str(archive), "-o", str(tmp_path / "ssp.csv"), "--stop-time", "0.2", "--quiet"]) == 0
    assert main(["run", "rover_cosim", "--fmu-dir", str(fmu_dir), "-o", str(tmp_path / "toml.csv"),
                 "--stop-time", "0.2", "--quiet"]) == 0
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "ssp.csv"), pd.read_csv(tmp_path / "toml.csv"))
    assert main(["export-ssp", "rover_cosim", "--fmu-dir", str(fmu_dir), "-o", str(tmp_path / "x.zip")]) == 2
    assert "expected a .ssp file" in capsys.readouterr().err


def test_a_python_block_travels_as_connectors_and_an_annotation(fmu_dir, fmus, tmp_path):
    data = tomllib.loads(EXAMPLES["single_wheel_step"].read_text())
    data["simulation"]["stop_time"] = 0.3
    data["block"] = [{"name": "brake", "type": "python", "factory": "test_orchestrator:Gain", "k": -200.0}]
    data["connection"] = [{"from": "testbed.omega", "to": "brake.u"}, {"from": "brake.y", "to": "testbed.tau"}]
    data["fmu"][0]["start"] = {"omega": 5.0}
    system = system_from_dict(data, name="brake.toml", base=fmu_dir)
    exported = export_ssp(system, tmp_path / "brake.ssp")
    with pytest.raises(SystemFileError, match="factory 'test_orchestrator:Gain', which you have not allowed"):
        load_ssp(exported.path, tmp_path / "refused")
    register_factory("test_orchestrator:Gain")
    with zipfile.ZipFile(exported.path) as archive:
        ssd = archive.read("SystemStructure.ssd").decode()
    assert 'name="brake_y" kind="input"' in ssd and 'name="brake_u" kind="output"' in ssd
    again = load_ssp(exported.path, tmp_path / "unpacked")
    pd.testing.assert_frame_equal(run(system).data, run(again).data, check_exact=True)


def test_an_archive_with_a_python_block_runs_from_the_command_line_where_the_user_allows_its_module(
        fmu_dir, fmus, tmp_path, capsys):
    """The block's module beside the archive; refused (exit 2, naming --allow-factory) until the user
    allows that module, then the same rows as the system file it was exported from."""
    (tmp_path / "my_brake.py").write_text(
        "import numpy as np\n"
        "class Brake:\n"
        "    inputs, outputs, units = ('u',), ('y',), {'u': 'rad/s', 'y': 'N.m'}\n"
        "    def __init__(self, name, k):\n"
        "        self.name, self.k = name, k\n"
        "    def start(self, t0, u0, h):\n"
        "        return -self.k * u0\n"
        "    def step(self, t, h, u):\n"
        "        return -self.k * u\n")
    data = tomllib.loads(EXAMPLES["single_wheel_step"].read_text())
    data["simulation"]["stop_time"] = 0.2
    data["block"] = [{"name": "brake", "type": "python", "factory": "my_brake:Brake", "k": 100.0}]
    data["connection"] = [{"from": "testbed.omega", "to": "brake.u"}, {"from": "brake.y", "to": "testbed.tau"}]
    data["fmu"][0]["start"] = {"omega": 5.0}
    data["fmu"][0]["path"] = str(fmu_dir / "SingleWheel.fmu")
    (tmp_path / "brake.toml").write_text(tomli_w.dumps(data))
    assert main(["export-ssp", str(tmp_path / "brake.toml"), "-o", str(tmp_path / "brake.ssp")]) == 0
    out = tmp_path / "ssp.csv"
    assert main(["run", str(tmp_path / "brake.ssp"), "-o", str(out), "--quiet"]) == 2
    assert "`rover-cosim run --allow-factory my_brake`" in capsys.readouterr().err and not out.exists()
    assert main(["run", str(tmp_path / "brake.ssp"), "--allow-factory", "my_brake", "-o", str(out), "--quiet"]) == 0
    assert main(["run", str(tmp_path / "brake.toml"), "-o", str(tmp_path / "toml.csv"), "--quiet"]) == 0
    pd.testing.assert_frame_equal(pd.read_csv(out), pd.read_csv(tmp_path / "toml.csv"))


def test_a_broken_archive_is_a_clear_error(tmp_path):
    bad = tmp_path / "bad.ssp"
    bad.write_bytes(b"not a zip")
    with pytest.raises(SspError, match="not a readable SSP archive"):
        load_ssp(bad, tmp_path / "x")
    with zipfile.ZipFile(tmp_path / "invalid.ssp", "w") as archive:
        archive.writestr("SystemStructure.ssd", "<ssd:SystemStructureDescription xmlns:ssd="
                         "'http://ssp-standard.org/SSP1/SystemStructureDescription' version='1.0' name='x'/>")
    with pytest.raises(SspError, match="Failed to validate"):
        load_ssp(tmp_path / "invalid.ssp", tmp_path / "y")
