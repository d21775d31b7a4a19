"""A bounded, seeded fuzz of what users type: system files (every key of a shipped system given
odd values), soil tables, and command-line options. Every case must end in the engine's own
message (SystemFileError / ValueError, or an exit code 2 or 1 with one line on stderr), never in
another exception: a new traceback fails here."""

from __future__ import annotations

import copy
import math
import random

import pytest
from fuzz_harness import _paths, _set

from rover_cosim.cli import main
from rover_cosim.orchestrator.examples import example
from rover_cosim.orchestrator.model import SystemFileError
from rover_cosim.orchestrator.system import system_from_dict
from rover_cosim.terramechanics import library

SEED = 20261201
ODD = [-1, 0, 1, 1e300, -1e300, 1e-300, math.inf, -math.inf, math.nan, True, False, "x", "", "1e3", "a" * 5000,
       [], [1, 2], {}, {"a": 1}, 2**63, -(2**63) - 1, 0.5, "wheel.W", "nosuch.var"]


def test_system_files_with_odd_values_end_in_a_message(fmu_dir, fmus):
    import tomllib

    base = tomllib.loads(example("single_wheel_step").read_text())
    rng = random.Random(SEED)
    paths = _paths(base)
    for case in range(300):
        data = copy.deepcopy(base)
        for _ in range(rng.randint(1, 3)):
            _set(data, rng.choice(_paths(data) or paths), copy.deepcopy(rng.choice(ODD)))  # not ODD's own list
        try:
            system_from_dict(data, name=f"fuzz case {case}", base=fmu_dir)
        except SystemFileError:
            pass
        except Exception as error:  # noqa: BLE001 - what the fuzz looks for
            pytest.fail(f"case {case}: {type(error).__name__}: {error} from {data}")


def test_soil_tables_with_odd_values_end_in_a_message():
    rng = random.Random(SEED + 1)
    keys = ["c", "phi_deg", "kc", "kphi", "n", "kx", "a0", "a1", "lam", "kx_beta", "ky", "ky_beta", "rho",
            "gravity", "xc_deg", "phi", "xc", "title", "notes", "unknown"]
    for case in range(400):
        table = {rng.choice(keys): rng.choice(ODD) for _ in range(rng.randint(1, 4))}
        try:
            library.build("soil", f"fuzz {case}", table)
        except ValueError:
            pass
        except Exception as error:  # noqa: BLE001
            pytest.fail(f"case {case}: {type(error).__name__}: {error} from {table}")


def test_command_line_options_with_odd_values_end_in_a_message(tmp_path, capsys):
    rng = random.Random(SEED + 2)
    values = ["-1", "0", "nan", "inf", "1e300", "1e-300", "x", "", "300,", ",", "1,2,3", "-0.5,0.9", "0.5", "5000",
              "a" * 300, "/" + "b/" * 2100]
    commands = [["fig3", "--loads"], ["fig3", "--slip-step"], ["fig3", "--slip-range"], ["fig3", "--set"],
                ["fig3", "--soil"], ["soils"], ["--dpi"], ["--figures"], ["run", "nosuch.toml", "--step"],
                ["run"], ["montecarlo", "--study"], ["montecarlo", "--model"], ["identify", "--fmu"],
                ["simulate", "--model"], ["report", "--results"], ["export-ssp", "-o", "x.ssp"]]
    for case in range(120):
        command = [*rng.choice(commands), rng.choice(values)]
        if command[0] == "--dpi" or command[0] == "--figures":
            command += ["soils"]
        if command[0] == "fig3":
            command += ["--out", str(tmp_path / f"f{case}"), "--loads", "300"] if "--loads" not in command else \
                ["--out", str(tmp_path / f"f{case}")]
        code: object
        try:
            code = main(command)
        except SystemExit as exit_:
            code = exit_.code
        except Exception as error:  # noqa: BLE001
            pytest.fail(f"{command}: {type(error).__name__}: {error}")
        assert code in (0, 1, 2), command
        err = capsys.readouterr().err
        assert "Traceback" not in err, command
