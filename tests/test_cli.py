"""The command line as a new user meets it: --version, help with every default and no markup,
`report` with nothing to report, `blocks`, a Python block's module beside its system file."""

from __future__ import annotations

import subprocess
import sys
from typing import Any

import pytest
from processes import alive

from rover_cosim import __version__
from rover_cosim.cli import build_parser, main


def test_version(capsys):
    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0 and capsys.readouterr().out.strip() == f"rover-cosim {__version__}"


@pytest.mark.parametrize("command", ["fig3", "run", "identify", "simulate", "montecarlo", "cosim-study", "export-ssp",
                                     "report", "build-fmus"])
def test_help_shows_every_default_without_markup(command, capsys):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = capsys.readouterr().out
    assert "``" not in text and ":func:" not in text and ":class:" not in text
    parser = build_parser()
    choices: Any = next(a for a in parser._actions if a.dest == "command").choices
    sub = choices[command]
    for action in sub._actions:
        if action.option_strings and action.default not in (None, False, [], "==SUPPRESS==") and action.nargs != 0:
            assert "default" in (sub.formatter_class(prog="x")._get_help_string(action) or ""), action.dest


def test_report_with_nothing_to_report_fails(tmp_path, capsys):
    assert main(["report", "--results", str(tmp_path)]) == 1
    assert "nothing to report" in capsys.readouterr().err
    assert not (tmp_path / "report.html").exists()


def test_blocks_lists_types_keys_and_defaults(capsys):
    assert main(["blocks"]) == 0
    text = capsys.readouterr().out
    for expected in ('type = "ramp"', "duration  required", "time      default 0.0", 'type = "python"', "[s]"):
        assert expected in text


def test_a_python_block_beside_its_system_file_is_found(fmu_dir, fmus, tmp_path, capsys):
    (tmp_path / "my_brake.py").write_text(
        "import numpy as np\n"
        "class Brake:\n"
        "    def __init__(self, name, k):\n"
        "        self.name, self.k = name, k\n"
        "        self.inputs, self.outputs, self.units = ('u',), ('y',), {'u': 'rad/s', 'y': 'N.m'}\n"
        "    def start(self, t0, u0):\n"
        "        return -self.k * u0\n"
        "    def step(self, t, h, u):\n"
        "        return -self.k * u\n")
    (tmp_path / "brake.toml").write_text(
        '[simulation]\nstop_time = 0.1\nstep = 1e-3\n\n'
        f'[[fmu]]\nname = "testbed"\npath = "{fmu_dir / "SingleWheel.fmu"}"\nstart = {{ omega = 5.0 }}\n\n'
        '[[block]]\nname = "brake"\ntype = "python"\nfactory = "my_brake:Brake"\nk = 100.0\n\n'
        '[[connection]]\nfrom = "testbed.omega"\nto = "brake.u"\n\n'
        '[[connection]]\nfrom = "brake.y"\nto = "testbed.tau"\n')
    assert main(["run", str(tmp_path / "brake.toml"), "-o", str(tmp_path / "brake.csv"), "--quiet"]) == 0
    assert (tmp_path / "brake.csv").exists()


def test_simulate_labels_what_it_prints(simulated, capsys):
    from rover_cosim.cli.simulate import print_straight

    print_straight(simulated)
    out = capsys.readouterr().out
    for label in ("time to reach 0.98 m/s [s]", "final velocity [m/s]", "Rover.fmu", "RoverBody + 6 Wheel",
                  "RMS(Fx - Fx_des), Rover.fmu [N]", "limb"):
        assert label in out, label


def test_papercuts_are_messages_naming_the_value(tmp_path, capsys):
    """An output folder that is a file, a soil file that is not there, an angle out of range in
    degrees, one soil shown with its units and sources."""
    existing = tmp_path / "a_file"
    existing.write_text("x")
    for command in (["fig3"], ["simulate"], ["identify"], ["cosim-study"]):
        assert main([*command, "--out", str(existing)]) == 2
        assert f"--out {existing}: is a file: expected a folder" in capsys.readouterr().err
    assert existing.read_text() == "x"
    assert main(["fig3", "--soil", str(tmp_path / "nofile.toml"), "--out", str(tmp_path / "f")]) == 2
    assert "nofile.toml not found" in capsys.readouterr().err
    assert main(["fig3", "--set", "soil.phi_deg=95", "--out", str(tmp_path / "f")]) == 2
    assert "phi_deg = 95.0 is not physical: expected 0 < phi_deg < 90 deg" in capsys.readouterr().err
    assert main(["soils", "lete_sand"]) == 0
    shown = capsys.readouterr().out
    assert "soil lete_sand: LETE sand" in shown and "c        1300 Pa" in shown and "(31.1 deg)" in shown
    assert "xc " in shown and "45 deg - phi/2" in shown
    assert main(["soils", "nothing_of_that_name"]) == 2
    assert "no shipped soil or wheel of that name" in capsys.readouterr().err


def test_stages_report_one_rising_fraction_over_a_jobs_runs():
    from rover_cosim.progress import Stages

    told: list[float] = []
    stages = Stages(told.append, 4)
    for k in range(4):
        callback = stages.stage(k)
        assert callback is not None
        for fraction in (0.0, 0.5, 1.0):
            callback(fraction)
    assert told == sorted(told) and told[0] == 0.0 and told[-1] == 1.0 and told[4] == 0.375
    assert Stages(None, 3).stage(1) is None


def test_every_command_says_what_it_does_with_an_example():
    parser = build_parser()
    commands = next(a for a in parser._actions if a.dest == "command").choices
    assert isinstance(commands, dict)
    for name, sub in commands.items():
        assert sub.description and len(sub.description.splitlines()) == 1, name
        assert f"rover-cosim {name}" in (sub.epilog or ""), name


@pytest.mark.parametrize("signal_name", ["SIGKILL", "SIGTERM"])
def test_workers_die_with_their_parent_however_it_dies(tmp_path, signal_name):
    """parallel_map's local workers (as identify and montecarlo use them), their parent killed
    while they work: none is alive a few seconds later."""
    import os
    import signal
    import subprocess
    import sys
    import time

    psutil = pytest.importorskip("psutil", reason="psutil not installed")
    script = ("import time, signal\n"
              "from rover_cosim.common.parallel import parallel_map\n"
              "def interrupt(*_):\n    raise KeyboardInterrupt\n"
              "signal.signal(signal.SIGTERM, interrupt)\n"  # as the CLI does
              "print('ready', flush=True)\n"
              "for _ in parallel_map(time.sleep, [(60,), (60,), (60,)], workers=2):\n    pass\n")
    parent = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert parent.stdout is not None and parent.stdout.readline().strip() == "ready"
    deadline = time.monotonic() + 30
    children: list = []
    while time.monotonic() < deadline and len(children) < 2:
        children = [c for c in psutil.Process(parent.pid).children() if "python" in c.name().lower()]
        time.sleep(0.2)
    assert len(children) >= 2, "the workers did not start"
    time.sleep(0.5)  # they are in their task now
    os.kill(parent.pid, getattr(signal, signal_name))
    parent.wait(timeout=30)
    # polled from /proc, a zombie counting as ended (psutil.wait_procs waits on for orphans that
    # are ended but not yet reaped)
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(alive(c.pid) for c in children):
        time.sleep(0.05)
    living = [c for c in children if alive(c.pid)]
    for process in living:
        process.kill()
    assert not living, f"{len(living)} workers outlived their parent ({signal_name})"


def _leave_a_scratch_folder(k: int) -> int:
    """A worker's task that, like the wheel test bed, leaves its temporary folder to the exit."""
    import tempfile

    from rover_cosim.common.scratch import scratch_prefix

    _leave_a_scratch_folder.kept = tempfile.TemporaryDirectory(prefix=scratch_prefix("testbed"))  # type: ignore[attr-defined]
    return k


def test_pool_workers_leave_no_temporary_folders(tmp_path, monkeypatch):
    import os
    import tempfile

    from rover_cosim.common.parallel import parallel_map

    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr(tempfile, "tempdir", None)
    assert sorted(parallel_map(_leave_a_scratch_folder, [(k,) for k in range(4)], workers=2)) == [0, 1, 2, 3]
    left = [p.name for p in tmp_path.iterdir() if p.name.startswith("rover-cosim-")
            and f"-{os.getpid()}-" not in p.name]
    assert not left, left


def test_the_exit_codes_are_documented():
    assert "exit codes: 0 done; 1 the work failed" in build_parser().format_help()


def test_a_scheduler_that_does_not_answer_is_named(monkeypatch):
    import time

    pytest.importorskip("distributed", reason="dask.distributed not installed")
    from rover_cosim.common.parallel import parallel_map

    monkeypatch.setenv("ROVER_COSIM_SCHEDULER_TIMEOUT", "0.5")
    with pytest.raises(RuntimeError,
                       match=r"Dask scheduler tcp://127.0.0.1:1: no Dask scheduler answered within 0.5 s"):
        list(parallel_map(time.sleep, [(0,)], scheduler="tcp://127.0.0.1:1"))


@pytest.mark.parametrize(("command", "option"), [
    (["montecarlo", "--study"], "--study"), (["montecarlo", "--model"], "--model"), (["identify", "--fmu"], "--fmu"),
    (["simulate", "--fmu-dir"], "--fmu-dir"), (["report", "--results"], "--results"), (["run"], "system"),
    (["soils"], "name"), (["fig3", "--soil"], "--soil"), (["fig3", "--out"], "--out"),
    (["run", "x.toml", "-o"], "-o/--output")])
@pytest.mark.parametrize("value", ["a" * 300, "/" + "b/" * 2100])
def test_paths_too_long_for_the_file_system_are_named(command, option, value, capsys):
    """Before: OSError (File name too long) tracebacks from the first look at the path."""
    with pytest.raises(SystemExit) as ended:
        main([*command, value])
    assert ended.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert f"error: argument {option}: " in err and "too long for a file name (expected at most 255 bytes a name" in err


@pytest.mark.parametrize(("command", "option"), [(["fig3", "--out"], "--out"), (["fig3", "--soil"], "--soil"),
                                                 (["fig3", "--wheel"], "--wheel"), (["run"], "system"),
                                                 (["identify", "--cache"], "--cache")])
def test_an_empty_path_is_refused_not_taken_as_the_current_folder_or_the_default(command, option, capsys):
    """Before: fig3 --out '' wrote into the current folder, --soil '' and --wheel '' ran the paper's."""
    with pytest.raises(SystemExit) as ended:
        main([*command, ""])
    assert ended.value.code == 2
    assert f"error: argument {option}: '': expected a path or a name (empty)" in capsys.readouterr().err


@pytest.mark.parametrize(("arguments", "message"), [
    (["simulate", "--record-interval", "inf"], "rover-cosim simulate: --record-interval: record interval inf s: "
                                                "expected a whole number of steps of 0.001 s"),
    (["simulate", "--record-interval", "-1"], "rover-cosim simulate: --record-interval: record interval -1.0 s: "
                                               "expected a whole number of steps of 0.001 s"),
    (["identify", "--record-interval", "inf"], "rover-cosim identify: --record-interval: record interval inf s: "
                                                "expected a whole number of steps of 0.0001 s"),
    (["build-fmus", "Nope"], "rover-cosim build-fmus: model 'Nope': expected one of SingleWheel, Rover"),
    (["cosim-study", "--fmu-dir", "/nonexistent"], "rover-cosim cosim-study: --fmu-dir /nonexistent: no such folder"),
    (["cosim-study", "--fmu-dir", "TMP"], "rover-cosim cosim-study: --fmu-dir TMP: /"),  # a folder without the FMUs
    (["identify", "--fmu", "TEXT"], "rover-cosim identify: --fmu TEXT: not an FMU (expected a zip archive holding a "
                                    "modelDescription.xml"),
    (["simulate", "--model", "TEXT"], "rover-cosim simulate: TEXT: not a JSON file"),
    (["montecarlo", "--model", "TEXT"], "rover-cosim montecarlo: TEXT: not a JSON file"),
])
def test_bad_input_found_by_the_fuzz_is_refused_before_the_work(arguments, message, tmp_path, capsys):
    """Before: simulate --record-interval inf an OverflowError traceback; -1, an unknown model of
    build-fmus, a missing --fmu-dir of cosim-study, an identified model that is not one and an
    FMU that is not one (identify's every run failing) exit 1 (the work failed) after starting it."""
    (tmp_path / "model.json").write_text("{}")
    extra = {"simulate": ["--fmu-dir", str(tmp_path), "--model", str(tmp_path / "model.json")]}.get(arguments[0], [])
    extra = extra if "--model" not in arguments else extra[:2]
    (tmp_path / "text.json").write_text("not JSON\n")
    named = {"TEXT": str(tmp_path / "text.json"), "TMP": str(tmp_path)}
    arguments = [named.get(a, a) for a in arguments]
    assert main([*arguments, *extra, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(message.replace("TEXT", named["TEXT"]).replace("TMP", named["TMP"])), err
    assert "Rover.fmu not found" in err or "TMP" not in message
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("address", ["5000", "/etc/passwd", "soil.c=800", "tcp://host", "host:port"])
def test_a_scheduler_that_is_not_an_address_is_refused_at_once(address, capsys):
    """Before: "no Dask scheduler answered within 30 s (ValueError: missing port number ...)", exit 1."""
    for command in ("identify", "montecarlo"):
        with pytest.raises(SystemExit) as ended:
            main([command, "--scheduler", address])
        assert ended.value.code == 2
        assert f"argument --scheduler: {address!r}: expected a Dask scheduler's address, e.g. tcp://host:8786" in \
            capsys.readouterr().err


def test_a_monte_carlo_of_absurdly_many_runs_is_refused_naming_the_limit(tmp_path, capsys):
    """Before: --runs 10**30 reached the free-space check ("needs about 5e27 MB")."""
    assert main(["montecarlo", "--runs", str(10**30), "--out", str(tmp_path / "mc")]) == 2
    assert f"runs = {10**30}: expected a whole number from 1 (the nominal included) to 1,000,000" in \
        capsys.readouterr().err


@pytest.mark.parametrize("argv", [["--help"], ["--version"], ["estimate-soil", "--help"], ["montecarlo", "--help"]])
def test_help_and_version_import_no_numerical_library(argv):
    """`rover-cosim --help` answers at once: the parser imports none of NumPy, SciPy, pandas, FMPy,
    matplotlib or CasADi (each command imports what it needs when it runs)."""
    script = ("import sys\nfrom rover_cosim.cli import main\n"
              "try:\n    main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
              "heavy = [m for m in ('numpy', 'scipy', 'pandas', 'fmpy', 'matplotlib', 'casadi') if m in sys.modules]\n"
              "print('HEAVY', heavy, file=sys.stderr)\n")
    done = subprocess.run([sys.executable, "-P", "-c", script, *argv], capture_output=True, text=True, check=False)
    assert "HEAVY []" in done.stderr, done.stderr[-2000:]


@pytest.mark.parametrize("argv, message", [
    (["simulate", "--adapt", "--calibration", "25"], "calibration 25.0 s: expected a length in (0, 20) s"),
    (["simulate", "--record-interval", "0.0015"], "record interval 0.0015 s: expected a whole number of steps"),
    (["montecarlo", "--runs", "0"], "--runs 0: expected >= 1"),
])
def test_a_bad_option_is_refused_before_the_job_is_imported(argv, message, tmp_path):
    """A refusal takes a fraction of a second: the command checks what it can before it imports its
    job (pandas, SciPy, matplotlib and the identification take seconds to import)."""
    script = ("import sys\nfrom rover_cosim.cli import main\n"
              "code = main(sys.argv[1:])\n"
              "heavy = [m for m in ('pandas', 'scipy', 'matplotlib', 'rover_cosim.jobs.simulate',\n"
              "                     'rover_cosim.jobs.montecarlo.job') if m in sys.modules]\n"
              "print('CODE', code, 'HEAVY', heavy, file=sys.stderr)\n")
    done = subprocess.run([sys.executable, "-P", "-c", script, *argv, "--out", str(tmp_path / "out"),
                           "--fmu-dir", str(tmp_path)],
                          capture_output=True, text=True, check=False, cwd=tmp_path)
    assert message in done.stderr and "CODE 2 HEAVY []" in done.stderr, done.stderr[-2000:]
    assert not (tmp_path / "out").exists()
