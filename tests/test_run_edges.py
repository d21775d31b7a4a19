"""Runs that must not lose or hide anything: stop times between steps, output paths, non-finite
values, partial results, algebraic loops, the temporary folder of unpacked FMUs, SIGINT/SIGTERM."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from rover_cosim.cli import EXAMPLES, main
from rover_cosim.orchestrator.master import UNZIP_PREFIX, RunError, remove_stale_folders, run
from rover_cosim.orchestrator.recorder import communication_points
from rover_cosim.orchestrator.system import SystemFileError, system_from_dict


def example(name: str, **simulation: object) -> dict:
    data = tomllib.loads(EXAMPLES[name].read_text())
    data["simulation"].update(simulation)
    return data


class Scale:
    """y = k u (+ offset), no units; ``feedthrough`` as given."""

    def __init__(self, name: str, k: float, offset: float = 0.0, feedthrough: bool = True, nan_after: float = -1.0):
        self.name, self.k, self.offset, self.nan_after = name, k, offset, nan_after
        self.inputs, self.outputs = ("u",), ("y",)
        self.units: dict[str, str] = {}
        self.feedthrough = feedthrough

    def start(self, t0, u0):
        return self.k * u0 + self.offset

    def step(self, t, h, u):
        if 0 <= self.nan_after <= t + h:
            return np.array([np.nan])
        return self.k * u + self.offset


def ring(k1: float, k2: float, **simulation: object) -> dict:
    """Two Scale blocks in a ring (a -> b -> a) beside the single-wheel test bed."""
    data = example("single_wheel_step", stop_time=0.05, **simulation)
    data["block"].append({"name": "a", "type": "python", "factory": "test_run_edges:Scale", "k": k1, "offset": 1.0})
    data["block"].append({"name": "b", "type": "python", "factory": "test_run_edges:Scale", "k": k2})
    data["connection"] += [{"from": "a.y", "to": "b.u"}, {"from": "b.y", "to": "a.u"}]
    data["record"] = {"variables": ["a.y", "b.y", "testbed.v"]}
    return data


def test_stop_time_between_steps_ends_with_one_shorter_step(fmu_dir, fmus):
    np.testing.assert_allclose(communication_points(0.0, 0.2, 0.06), [0.0, 0.06, 0.12, 0.18, 0.2])
    long = communication_points(0.0, 200.0, 0.003)
    assert long[-1] == 200.0 and len(long) == 66668 and long[-2] == pytest.approx(199.998)
    np.testing.assert_allclose(communication_points(0.0, 1.0, 0.1), np.linspace(0, 1, 11))
    result = run(system_from_dict(example("single_wheel_step", step=0.06, stop_time=0.2), name="t.toml",
                                  base=fmu_dir))
    np.testing.assert_allclose(result.data["time"], [0.0, 0.06, 0.12, 0.18, 0.2])


def test_output_that_would_be_its_own_sidecar_is_refused(fmu_dir, fmus, tmp_path, capsys):
    target = tmp_path / "x.json"
    code = main(["run", "single_wheel_step", "--fmu-dir", str(fmu_dir), "-o", str(target), "--quiet"])
    assert code == 2 and "expected a .csv or .parquet file" in capsys.readouterr().err
    assert not list(tmp_path.iterdir())


def test_non_finite_value_names_participant_signal_and_time_and_keeps_the_rows(fmu_dir, fmus, tmp_path, capsys):
    """A block that turns NaN at 0.2 s (only recorded, nothing reads it): the run stops there with
    the block, the signal and the time named, and keeps the rows before it in a partial file."""
    text = EXAMPLES["single_wheel_step"].read_text().replace('stop_time = 2.0', 'stop_time = 0.3')
    text = text.replace('path = "SingleWheel.fmu"', f'path = "{fmu_dir / "SingleWheel.fmu"}"')
    text += ('\n[[block]]\nname = "probe"\ntype = "python"\nfactory = "test_run_edges:Scale"\nk = 1.0\n'
             'nan_after = 0.2\n\n[[connection]]\nfrom = "testbed.v"\nto = "probe.u"\n\n'
             '[record]\nvariables = ["probe.y", "testbed.v"]\n')
    system_file = tmp_path / "nan.toml"
    system_file.write_text(text)
    out = tmp_path / "out" / "nan.csv"
    code = main(["run", str(system_file), "-o", str(out), "--quiet"])
    message = capsys.readouterr().err
    assert code == 1 and "probe: output y = nan at t = 0.2 s" in message and "partial" in message, message
    assert not out.exists()
    partial = out.with_name("nan.partial.csv")
    rows = np.loadtxt(partial, delimiter=",", skiprows=1)
    assert rows[-1, 0] == pytest.approx(0.199) and np.all(np.isfinite(rows))
    assert '"partial": true' in partial.with_suffix(".json").read_text()


def test_algebraic_loop_is_named_and_refused_by_the_explicit_masters(fmu_dir, fmus):
    with pytest.raises(SystemFileError, match=r"algebraic loop .*a\.(u|y) -> .*b\.(u|y)"):
        system_from_dict(ring(0.5, 1.0), name="ring.toml", base=fmu_dir)
    no_feedthrough = ring(0.5, 1.0)
    no_feedthrough["block"][-1]["feedthrough"] = False
    assert system_from_dict(no_feedthrough, name="ring.toml", base=fmu_dir).algebraic_loop is None


def test_allowed_loop_runs_with_a_delay_and_the_iterative_master_solves_it(fmu_dir, fmus):
    delayed = run(system_from_dict(ring(0.5, 1.0, allow_algebraic_loops=True), name="r", base=fmu_dir)).data
    solved = run(system_from_dict(ring(0.5, 1.0, algorithm="iterative", tolerance=1e-10, max_iterations=60), name="r",
                                  base=fmu_dir)).data
    # The fixed point of y = 0.5 y + 1 is 2; the iterative master meets it at every point.
    np.testing.assert_allclose(solved["a.y"].iloc[1:], 2.0, rtol=1e-8)
    assert delayed["a.y"].iloc[1] != pytest.approx(2.0)
    with pytest.raises(RunError, match=r"did not converge .*still moving: .*(a\.y|b\.y)"):
        run(system_from_dict(ring(2.0, 1.0, algorithm="iterative"), name="r", base=fmu_dir))


def test_stale_unpack_folders_of_dead_runs_are_removed(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    folder = Path(tempfile.gettempdir()) / f"{UNZIP_PREFIX}{int(dead.stdout)}-stale"
    (folder / "body").mkdir(parents=True)
    mine = Path(tempfile.gettempdir()) / f"{UNZIP_PREFIX}{os.getpid()}-mine"
    mine.mkdir()
    try:
        assert folder in remove_stale_folders() and not folder.exists() and mine.exists()
    finally:
        mine.rmdir()


@pytest.mark.parametrize("sent", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_ends_a_run_with_one_line_and_no_leftovers(fmu_dir, fmus, tmp_path, sent):
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    process = subprocess.Popen([sys.executable, "-P", "-m", "rover_cosim", "run", "rover_cosim", "--fmu-dir",
                                str(fmu_dir), "--stop-time", "600", "-o", str(tmp_path / "out.csv"), "--quiet"],
                               stderr=subprocess.PIPE, text=True, env=env)
    deadline = time.time() + 180  # a busy machine: start-up and unpacking take their time
    unpacked = f"{UNZIP_PREFIX}*/fmu-*/modelDescription.xml"
    while not list(tmp_path.glob(unpacked)) and time.time() < deadline and process.poll() is None:
        time.sleep(0.1)
    if not list(tmp_path.glob(f"{UNZIP_PREFIX}*")):
        process.kill()
        pytest.fail(f"the run never unpacked its FMUs (exit {process.wait()}): {process.communicate()[1][-2000:]}")
    time.sleep(0.5)
    process.send_signal(sent)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    assert "Traceback" not in err and err.strip().endswith("interrupted; nothing more written"), err
    assert not list(tmp_path.glob(f"{UNZIP_PREFIX}*")) and not (tmp_path / "out.csv").exists()


def test_runs_on_two_soils_have_records_that_say_so(fmu_dir, fmus, tmp_path):
    """`rover-cosim run ... --soil` on two soils: the records name the soil and wheel, hold every
    FMU parameter set (the soil's among them) and the command line, and differ where results do."""
    import json

    records = {}
    for soil in ("paper", "lete_sand"):
        out = tmp_path / f"{soil}.csv"
        assert main(["run", "single_wheel_step", "--fmu-dir", str(fmu_dir), "--soil", soil, "--stop-time", "0.2",
                     "-o", str(out), "--quiet"]) == 0
        records[soil] = json.loads(out.with_suffix(".json").read_text())
    paper, lete = records["paper"], records["lete_sand"]
    assert paper["soil"]["name"] == "paper" and lete["soil"]["name"] == "lete_sand"
    assert paper["fmus"]["testbed"]["parameters"]["soil.c"] == 800.0
    assert lete["fmus"]["testbed"]["parameters"]["soil.c"] == 1300.0
    assert "--soil" in lete["command_line"] and "lete_sand" in lete["command_line"]
    assert paper["fmus"]["testbed"]["sha256"] == lete["fmus"]["testbed"]["sha256"]


@pytest.mark.parametrize("change, message", [
    ({"simulation": {"stop_time": float("inf")}}, "stop_time: inf: expected a finite time"),
    ({"simulation": {"stop_time": 1e300}}, "stop_time: 1e+300: expected a finite time"),
    ({"simulation": {"start_time": float("nan")}}, "start_time: nan: expected a finite time"),
    ({"simulation": {"step": 1e-300}}, "more than the 100,000,000 a run may take"),
    ({"simulation": {"threads": 10000}}, "threads: 10000: expected a whole number from 1 to 256"),
    ({"block": {"height": True}}, "height = True: expected a finite number"),
    ({"block": {"height": "575"}}, "height = '575': expected a finite number"),
])
def test_absurd_settings_and_untyped_block_values_are_refused_at_load(fmu_dir, fmus, change, message):
    data = example("single_wheel_step")
    data["simulation"].update(change.get("simulation", {}))
    if "block" in change:
        data["block"][0].update(change["block"])
        data["block"][0]["type"] = "step"
        data["block"][0] = {k: v for k, v in data["block"][0].items() if k in ("name", "type", "height", "time",
                                                                                "offset", "unit")}
    with pytest.raises(SystemFileError, match=message.replace("(", r"\(").replace(")", r"\)").replace("+", r"\+")):
        system_from_dict(data, name="t.toml", base=fmu_dir)


def test_an_exported_archive_is_an_ordinary_result_file(fmu_dir, fmus, tmp_path):
    import os

    from rover_cosim.common.outputs import result_mode
    from rover_cosim.orchestrator.ssp import export_ssp

    archive = export_ssp(system_from_dict(example("single_wheel_step"), name="t.toml", base=fmu_dir),
                         tmp_path / "x.ssp").path
    assert os.stat(archive).st_mode & 0o777 == result_mode() == (tmp_path / "x.ssp").stat().st_mode & 0o777
    assert result_mode() & 0o044  # readable by others under the usual umask, as the CSV results are


def test_outputs_do_not_replace_what_the_command_did_not_write(fmu_dir, fmus, tmp_path, capsys):
    """report --out, run -o and export-ssp -o refuse a file that is not their own earlier result
    (the report once overwrote an .fmu), unless --overwrite; their own results they replace."""
    victim = tmp_path / "precious.fmu"
    victim.write_bytes(fmus["Wheel"].read_bytes())
    results = tmp_path / "results"
    (results).mkdir()
    (results / "fig3_fx_vs_slip.csv").write_text("load_N,slip,Fx_N\n100,0.0,1.0\n100,0.1,5.0\n")
    assert main(["report", "--results", str(results), "--out", str(victim)]) == 2
    assert "is not a result of rover-cosim report: pass --overwrite" in capsys.readouterr().err
    assert victim.read_bytes() == fmus["Wheel"].read_bytes()
    page = tmp_path / "page.html"
    assert main(["report", "--results", str(results), "--out", str(page)]) == 0
    assert main(["report", "--results", str(results), "--out", str(page)]) == 0   # its own: replaced
    assert main(["report", "--results", str(results), "--out", str(victim), "--overwrite"]) == 0
    notes = tmp_path / "notes.csv"
    notes.write_text("mine\n")
    run = ["run", "single_wheel_step", "--fmu-dir", str(fmu_dir), "--stop-time", "0.05", "-q"]
    assert main([*run, "-o", str(notes)]) == 2 and notes.read_text() == "mine\n"
    assert main([*run, "-o", str(tmp_path / "r.csv")]) == 0 and main([*run, "-o", str(tmp_path / "r.csv")]) == 0
    capsys.readouterr()
    export = ["export-ssp", "single_wheel_step", "--fmu-dir", str(fmu_dir), "-o"]
    assert main([*export, str(notes.with_suffix(".ssp"))]) == 0
    (tmp_path / "other.ssp").write_text("not mine")
    assert main([*export, str(tmp_path / "other.ssp")]) == 2
    assert (tmp_path / "other.ssp").read_text() == "not mine"


def test_a_process_unpacks_an_fmu_file_once_and_again_when_it_changes(fmu_dir, fmus, tmp_path):
    """Runs in one process share one unpacked copy of each FMU file (a Monte Carlo worker's runs,
    a script's), and so do the instances of one run; a file that changed (its modification time)
    is unpacked anew."""
    from rover_cosim.orchestrator.builder import SystemBuilder
    from rover_cosim.orchestrator.unpacking import unpack

    copy = tmp_path / "Wheel.fmu"
    shutil.copyfile(fmus["Wheel"], copy)

    def system() -> Any:
        builder = SystemBuilder("two wheels").simulation(stop_time=0.01, step=1e-3)
        for name in ("a", "b"):
            builder.add_fmu(name, copy, start={"W": 424.0, "v_hub": 0.0, "tau": 20.0})
        return builder.build()

    first = run(system())
    entry = system().fmus[0]
    folder = unpack(entry)
    assert unpack(system().fmus[1]) == folder and (folder / "modelDescription.xml").is_file()
    second = run(system())
    pd.testing.assert_frame_equal(first.data, second.data, check_exact=True)
    assert unpack(entry) == folder  # the same copy, run after run
    os.utime(copy, ns=(copy.stat().st_atime_ns, copy.stat().st_mtime_ns + 10**9))  # the file changed
    changed = system().fmus[0]
    assert unpack(changed) != folder and run(system()).data.equals(first.data)


def test_an_fmus_log_message_reaches_the_terminal_tamed():
    """Escape sequences, CR/LF and a huge message from an FMU's logger: shown without control
    characters and cut to its first 500 characters (the rest counted); a NULL message is said."""
    from rover_cosim.orchestrator.participants import MESSAGE_LENGTH, clean_message

    assert clean_message(b"bad \x1b[2J\x1b[31mred\r\nsecond line\x07") == "bad \\x1b[2J\\x1b[31mred  second line\\x07"
    huge = clean_message(b"x" * 20_000_000)
    assert len(huge) < MESSAGE_LENGTH + 40 and huge.endswith("... (20000000 characters)")
    assert clean_message(None) == "(the FMU logged a NULL message)"
    assert clean_message("\u00e9t\u00e9 ok") == "\u00e9t\u00e9 ok"
