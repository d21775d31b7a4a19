"""The co-simulation orchestrator: system files and their errors, the master algorithms against
the monolithic rover and against libcosim, Python blocks, results on disk, the CLI."""

from __future__ import annotations

import io
import json
import tomllib

import numpy as np
import pytest

from rover_cosim.cli import EXAMPLES, main
from rover_cosim.orchestrator.libcosim import run_libcosim
from rover_cosim.orchestrator.master import RunError, run
from rover_cosim.orchestrator.system import SystemFileError, load_system, system_from_dict
from rover_cosim.progress import ProgressBar


def example(name: str, **simulation: object) -> dict:
    data = tomllib.loads(EXAMPLES[name].read_text())
    data["simulation"].update(simulation)
    return data


@pytest.fixture(scope="module")
def system(fmu_dir):
    """A checked System from a parsed system file, FMUs taken from the built fmus/."""
    def load(data: dict, name: str = "test.toml"):
        return system_from_dict(data, name=name, base=fmu_dir)
    return load


@pytest.fixture(scope="module")
def rover_runs(system) -> dict[str, object]:
    """The co-simulated rover (RoverBody + 6 Wheel, Gauss-Seidel, 1 ms) and the monolithic
    Rover.fmu under the same open-loop torque, 6 s."""
    return {"cosim": run(system(example("rover_cosim"))).data,
            "monolithic": run(system(example("rover_open_loop"))).data}


# --- example systems ----------------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_shipped_examples_load(fmu_dir, fmus, name: str):
    loaded = load_system(EXAMPLES[name], fmu_dir=fmu_dir)
    assert loaded.step == 1e-3 and loaded.fmus and loaded.record


def test_cosimulated_rover_matches_the_monolithic_rover(rover_runs):
    """Body velocity within 1 % (of its largest value) and every wheel load within 2 % over the run."""
    cosim, mono = rover_runs["cosim"], rover_runs["monolithic"]
    np.testing.assert_array_equal(cosim["time"], mono["time"])
    v_error = np.abs(cosim["body.v"] - mono["rover.v"]).max()
    assert v_error <= 0.01 * mono["rover.v"].abs().max(), v_error
    for i in range(1, 7):
        relative = np.abs(cosim[f"wheel{i}.Fz"] - mono[f"rover.Fz[{i}]"]) / mono[f"rover.Fz[{i}]"]
        assert relative.max() <= 0.02, (i, relative.max())
    assert mono["rover.v"].iloc[-1] > 0.9  # the run really drives the rover to ~1 m/s


def test_libcosim_runs_the_same_cosimulated_rover_to_the_same_trajectories(system, fmus):
    """libcosim's fixed-step master exchanges values like our Jacobi master: same FMUs, same step,
    same trajectories (to round-off)."""
    data = example("rover_cosim", algorithm="jacobi", stop_time=1.0)
    ours = run(system(data)).data.iloc[1:].reset_index(drop=True)
    theirs = run_libcosim(system(data)).data
    assert theirs is not None and len(theirs) == len(ours) == 1000
    for column in ("body.v", "body.pitch", "wheel1.Fz", "wheel3.Fz", "wheel2.slip", "wheel6.omega"):
        scale = max(1.0, float(np.abs(ours[column]).max()))
        np.testing.assert_allclose(theirs[column], ours[column], rtol=0, atol=1e-9 * scale, err_msg=column)


def test_jacobi_and_gauss_seidel_differ_by_a_coupling_error_that_shrinks_with_the_step(system, fmus):
    reference = run(system(example("rover_cosim", stop_time=1.0, step=2.5e-4))).data.set_index("time")
    errors = {}
    for algorithm in ("jacobi", "gauss-seidel"):
        for step in (1e-3, 4e-3):
            data = run(system(example("rover_cosim", stop_time=1.0, step=step, algorithm=algorithm))).data
            common = reference["body.v"].reindex(data["time"], method="nearest").to_numpy()
            errors[algorithm, step] = float(np.abs(data["body.v"].to_numpy() - common).max())
    for algorithm in ("jacobi", "gauss-seidel"):
        assert errors[algorithm, 1e-3] < errors[algorithm, 4e-3], errors


# --- blocks -------------------------------------------------------------------------------------

class Gain:
    """A user block for the test: y = k u, loaded through type = "python"."""

    def __init__(self, name: str, k: float):
        self.name, self.k = name, k
        self.inputs, self.outputs, self.units = ("u",), ("y",), {"u": "rad/s", "y": "N.m"}

    def start(self, t0, u0):
        return self.k * u0

    def step(self, t, h, u):
        return self.k * u


def test_python_block_closes_a_loop_around_an_fmu(system, fmus):
    """A speed-feedback brake written in Python (tau = -k omega) slows a spinning wheel."""
    data = example("single_wheel_step", stop_time=0.5)
    data["block"] = [{"name": "brake", "type": "python", "factory": "test_orchestrator:Gain", "k": -200.0}]
    data["connection"] = [{"from": "testbed.omega", "to": "brake.u"}, {"from": "brake.y", "to": "testbed.tau"}]
    data["fmu"][0]["start"] = {}
    result = run(system(data)).data
    np.testing.assert_allclose(result["brake.y"], -200.0 * result["testbed.omega"], rtol=0, atol=1e-12)
    assert np.all(np.isfinite(result.to_numpy()))


def test_sources_take_part_like_fmus(system, fmus):
    data = example("single_wheel_step", stop_time=0.3)
    result = run(system(data)).data
    expected = np.where(result["time"] >= 0.1 - 1e-12, 60.0, 0.0)
    np.testing.assert_array_equal(result["torque.y"], expected)
    assert abs(result["testbed.v"].iloc[100]) < 0.01 < result["testbed.v"].iloc[-1]  # drives after the step


# --- bad system files ---------------------------------------------------------------------------

def broken(change) -> dict:
    data = example("rover_cosim")
    change(data)
    return data


def set_connection(data: dict, index: int, **entry: str) -> None:
    data["connection"][index].update(entry)


BAD_SYSTEMS = {
    "unknown FMU file": (lambda d: d["fmu"][0].update(path="NoSuch.fmu"), "NoSuch.fmu not found"),
    "unknown instance": (lambda d: set_connection(d, 0, **{"from": "bdy.W[1]"}), "no instance 'bdy'"),
    "unknown variable": (lambda d: set_connection(d, 0, **{"from": "body.Wx[1]"}), "has no variable 'Wx[1]'"),
    "input as source": (lambda d: set_connection(d, 0, **{"from": "wheel2.W"}),
                        "wheel2.W is not an output"),
    "output as target": (lambda d: set_connection(d, 0, to="wheel1.Fz"), "wheel1.Fz is not an input"),
    "unit mismatch": (lambda d: set_connection(d, 0, **{"from": "body.v_hub[1]"}), "unit mismatch"),
    "input connected twice": (lambda d: d["connection"].append({"from": "body.W[2]", "to": "wheel1.W"}),
                              "wheel1.W is connected twice"),
    "input left open": (lambda d: d["connection"].pop(0), "input wheel1.W is neither connected nor given a value"),
    "zero step": (lambda d: d["simulation"].update(step=0.0), "step: 0.0: expected a communication step > 0"),
    "negative stop time": (lambda d: d["simulation"].update(stop_time=-1.0), "stop_time: -1.0: expected a stop time"),
    "unknown algorithm": (lambda d: d["simulation"].update(algorithm="newton"), "algorithm: 'newton'"),
    "parameter that is an input": (lambda d: d["fmu"][1].update(parameters={"tau": 1.0}),
                                   "wheel1.tau is not a parameter"),
    "unknown block type": (lambda d: d["block"][0].update(type="sine"), "type 'sine'"),
    "duplicate name": (lambda d: d["fmu"][2].update(name="wheel1"), "name 'wheel1' is used twice"),
    "path as instance name": (lambda d: d["fmu"][0].update(name="/tmp/body"), "expected an identifier"),
    "unknown block key": (lambda d: d["block"][0].update(slope=20.0),
                          "unknown key(s) ['slope']; it accepts begin, end, time, width, unit"),
    "missing block key": (lambda d: d["block"][0].pop("width"), "missing key(s) ['width']"),
    "misspelt table": (lambda d: d.update(recrd={"variables": ["body.v"]}), "unknown table(s) ['recrd']"),
    "unknown record key": (lambda d: d.update(record={"variable": ["body.v"]}),
                           "unknown key(s) ['variable']; expected ['variables']"),
    "unknown connection key": (lambda d: set_connection(d, 0, gain="2"), "unknown key(s) ['gain']"),
    "unknown fmu key": (lambda d: d["fmu"][0].update(parameter={"rover.M": 1.0}), "unknown key(s) ['parameter']"),
    "unknown simulation key": (lambda d: d["simulation"].update(stoptime=2.0), "unknown key(s) ['stoptime']"),
}


@pytest.mark.parametrize("case", sorted(BAD_SYSTEMS))
def test_bad_system_files_get_an_error_naming_the_entry(system, fmus, case: str):
    change, expected = BAD_SYSTEMS[case]
    with pytest.raises(SystemFileError) as error:
        system(broken(change), name="bad.toml")
    message = str(error.value)
    assert message.startswith("bad.toml: ") and expected in message, message


def test_not_toml_and_missing_file(tmp_path):
    (tmp_path / "bad.toml").write_text("[simulation\nstep = 1")
    with pytest.raises(SystemFileError, match="not valid TOML"):
        load_system(tmp_path / "bad.toml")
    with pytest.raises(SystemFileError, match="no such system file"):
        load_system(tmp_path / "missing.toml")


# --- results, failures, CLI ---------------------------------------------------------------------

def test_cli_run_writes_csv_and_sidecar(fmu_dir, fmus, tmp_path, capsys):
    out = tmp_path / "out" / "step.csv"
    assert main(["run", "single_wheel_step", "-o", str(out), "--fmu-dir", str(fmu_dir), "--stop-time", "0.2",
                 "--quiet"]) == 0
    import pandas as pd

    data = pd.read_csv(out)
    assert list(data.columns[:3]) == ["time", "torque.y", "testbed.v"] and len(data) == 201
    sidecar = json.loads(out.with_suffix(".json").read_text())
    assert sidecar["steps"] == 200 and sidecar["parameters"]["algorithm"] == "gauss-seidel"
    assert len(sidecar["fmus"]["testbed"]["sha256"]) == 64 and sidecar["versions"]["numpy"]
    assert sidecar["wall_seconds"] > 0
    assert "wrote" in capsys.readouterr().out


def test_a_failing_run_names_the_instance_and_writes_nothing(fmu_dir, fmus, tmp_path, capsys):
    """An internal step limit of 1e-12 s makes the FMU's integrator give up in the first step."""
    path = tmp_path / "failing.toml"
    fmu_path = (fmu_dir / "SingleWheel.fmu").as_posix()
    lines = ["[simulation]", "stop_time = 0.2", "step = 1e-3", "[[fmu]]", 'name = "testbed"', f'path = "{fmu_path}"',
             'parameters = { W = 575.0, "solver.maxStep" = 1e-12 }', 'start = { tau = 60.0 }']
    path.write_text("\n".join(lines) + "\n")
    out = tmp_path / "failing.csv"
    assert main(["run", str(path), "-o", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "testbed (SingleWheel.fmu): fmi2DoStep at t = 0 s failed" in err and "failing.csv not written" in err
    assert list(tmp_path.iterdir()) == [path]
    with pytest.raises(RunError):
        run(load_system(path))


def test_cli_reports_a_bad_system_file(tmp_path, capsys):
    (tmp_path / "s.toml").write_text("[simulation]\nstop_time = 1.0\nstep = -1.0\n")
    assert main(["run", str(tmp_path / "s.toml")]) == 2
    assert "step: -1.0: expected a communication step > 0" in capsys.readouterr().err


class FakeTerminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_bar_only_on_a_terminal_and_after_its_delay():
    silent = io.StringIO()
    bar = ProgressBar("run", stream=silent, delay=0.0)
    bar(0.5)
    bar.close()
    assert silent.getvalue() == ""
    terminal = FakeTerminal()
    bar = ProgressBar("run", stream=terminal, delay=0.0)
    bar(1.0)
    bar.close()
    assert "100.0%" in terminal.getvalue() and terminal.getvalue().endswith("\n")
    quiet = FakeTerminal()
    bar = ProgressBar("run", stream=quiet, enabled=False, delay=0.0)
    bar(1.0)
    assert quiet.getvalue() == ""
