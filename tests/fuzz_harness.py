"""A seeded fuzz of what reaches the tool from outside (``make fuzz SEED=... CASES=...``; not part
of ``make test``: minutes, not seconds). Each case is one command run in this process through
``rover_cosim.cli.main`` on a hostile input; a case fails when it

- raises anything but SystemExit (a traceback),
- exits with a code other than 0 (done), 1 (the work failed) or 2 (bad input),
- writes "Traceback" to stderr, or more than one line for a refusal,
- leaves a file outside its own output folder (a sentinel tree is compared before and after), or a
  temporary or half-written file inside it (``*.tmp*``, ``.*.partial``).

Kinds of case (each drawn with its share of CASES):

- ``system``: the shipped single-wheel system file, one to three keys given odd values, run;
- ``study``: the shipped Monte Carlo study, keys odd (stops at the study's checks or the model);
- ``soil``: a soil or wheel table with odd values, shown by ``rover-cosim soils FILE``;
- ``option``: a command with an option given an odd value;
- ``description``: the test FMU's modelDescription.xml with an attribute changed (index="0", a
  causality, a valueReference, a start, a type), run as one FMU;
- ``report``: a results folder whose summary.json and model.json are odd shapes (an array, deep
  nesting, markup in every string), reported.

Say ``--kinds system,option`` to draw from some only. The summary says how many cases ran, and
how many gave a traceback, a crash (the harness itself would die: run it under a shell that says
so), a bad exit code or data loss; exit 1 if any did.
"""

from __future__ import annotations

import argparse
import contextlib
import copy
import io
import json
import math
import random
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parent))

ODD: list[Any] = [-1, 0, 1, 1e300, -1e300, 1e-300, math.inf, -math.inf, math.nan, True, False, "x", "", "1e3",
                  "a" * 5000, [], [1, 2], ["x"], {}, {"a": 1}, 2**63, -(2**63) - 1, 0.5, "wheel.W", "nosuch.var",
                  "<b>bold</b>", "\x1b[31mred", "é\u202e", [[1, 2], [3]]]
VALUES = ["-1", "0", "nan", "inf", "-inf", "1e308", "1e-308", "1e23", "x", "", ",", "1,2,3", "-0.5,0.9", "0.5",
          "5000", "a" * 300, "/" + "b/" * 2100, "\x1b[2J", "1e22", "2147483648", "-0"]
OPTIONS = [["fig3", "--loads"], ["fig3", "--slip-step"], ["fig3", "--slip-range"], ["fig3", "--set"],
           ["fig3", "--soil"], ["fig3", "--wheel"], ["fig3", "--rover"], ["soils"], ["rovers"], ["--dpi"],
           ["--figures"], ["identify", "--plan"], ["identify", "--rover"],
           ["run", "MISBEHAVE", "--step"], ["run", "MISBEHAVE", "--stop-time"],
           ["run", "MISBEHAVE", "--output-interval"],
           ["run", "MISBEHAVE", "--relative-tolerance"], ["run", "MISBEHAVE", "--fmu-timeout"],
           ["run", "MISBEHAVE", "--start"], ["run", "MISBEHAVE", "--record"], ["run", "MISBEHAVE", "--threads"],
           ["run", "MISBEHAVE", "--isolation"], ["run"], ["montecarlo", "--study"], ["montecarlo", "--runs"],
           ["montecarlo", "--workers"], ["montecarlo", "--run-timeout"], ["montecarlo", "--seed"],
           ["identify", "--fmu"], ["identify", "--record-interval"], ["identify", "--workers"],
           ["simulate", "--model"], ["simulate", "--calibration"], ["report", "--results"],
           ["export-ssp", "-o", "x.ssp"], ["testbed-data", "--out", "t.csv", "--loads"],
           ["testbed-data", "--out", "t.csv", "--slips"], ["testbed-data", "--out", "t.csv", "--noise"],
           ["estimate-soil", "--data"]]


def _paths(data: Any, prefix: tuple = ()) -> list[tuple]:
    """Every key path of a nested dict/list structure."""
    found: list[tuple] = []
    if isinstance(data, dict):
        for key, value in data.items():
            found.append((*prefix, key))
            found += _paths(value, (*prefix, key))
    elif isinstance(data, list):
        for k, value in enumerate(data):
            found.append((*prefix, k))
            found += _paths(value, (*prefix, k))
    return found


def _set(data: Any, path: tuple, value: Any) -> None:
    for key in path[:-1]:
        data = data[key]
    data[path[-1]] = value


def _mutated(base: dict[str, Any], rng: random.Random) -> dict[str, Any]:
    data = copy.deepcopy(base)
    for _ in range(rng.randint(1, 3)):
        paths = _paths(data)
        if paths:
            _set(data, rng.choice(paths), copy.deepcopy(rng.choice(ODD)))
    return data


def _toml(data: dict[str, Any]) -> str:
    """``data`` as TOML where it can be written (NaN and inf as TOML's nan and inf), else a text
    that is not TOML at all (a case all the same)."""
    import tomli_w

    try:
        return tomli_w.dumps(data)
    except (TypeError, ValueError):
        return repr(data)


class Harness:
    """The cases' shared files: the shipped inputs read once, a work folder, a sentinel tree."""

    def __init__(self, work: Path):
        import tomllib

        from rover_cosim.orchestrator.examples import example

        self.work = work
        self.system = tomllib.loads(example("single_wheel_step").read_text())
        self.fmu_dir = Path(__file__).parents[1] / "fmus"  # the built FMUs (make fmus)
        studies = Path(__file__).parents[1] / "rover_cosim" / "jobs" / "montecarlo" / "studies"
        self.study = tomllib.loads((studies / "lunar_regolith.toml").read_text())
        self.sentinel = work / "sentinel"
        self.sentinel.mkdir()
        (self.sentinel / "precious.txt").write_text("do not touch")
        self.misbehave = self._misbehave()

    def _misbehave(self) -> Path | None:
        from c_fmu import compile_fmu
        from misbehave_fmu import model_description

        built = compile_fmu("misbehave.c", "Misbehave", self.work, "Misbehave", model_description())
        return built if isinstance(built, Path) else None

    def snapshot(self) -> dict[str, bytes]:
        return {str(p.relative_to(self.work)): p.read_bytes() for p in self.work.rglob("*")
                if p.is_file() and not p.is_relative_to(self.work / "cases")}

    # --- the kinds of case ---------------------------------------------------------------------
    def system_case(self, rng: random.Random, folder: Path) -> list[str]:
        data = _mutated(self.system, rng)
        path = folder / "system.toml"
        path.write_text(_toml(data))
        return ["run", str(path), "--fmu-dir", str(self.fmu_dir), "-q", "-o", str(folder / "out.csv"),
                "--stop-time", "0.05"]

    def study_case(self, rng: random.Random, folder: Path) -> list[str]:
        path = folder / "study.toml"
        path.write_text(_toml(_mutated(self.study, rng)))
        return ["montecarlo", "--study", str(path), "--out", str(folder / "mc"), "--runs", "2", "-q",
                "--model", str(folder / "no-model.json")]

    def soil_case(self, rng: random.Random, folder: Path) -> list[str]:
        """A fuzzed soil or wheel file through `soils`, or a fuzzed rover file through `rovers`."""
        rover = rng.random() < 0.3
        keys = (["mass", "Iyy", "h_cog", "x_limb", "y_limb", "k_limb", "wheel", "title", "unknown"] if rover else
                ["c", "phi_deg", "kc", "kphi", "n", "kx", "a0", "a1", "lam", "r", "b", "title", "source", "unknown"])
        table = {rng.choice(keys): rng.choice(ODD) for _ in range(rng.randint(1, 4))}
        path = folder / "library.toml"
        path.write_text(_toml({"fuzzed": table}))
        return ["rovers" if rover else "soils", f"{path}:fuzzed"]

    def option_case(self, rng: random.Random, folder: Path) -> list[str]:
        command = [str(self.misbehave) if part == "MISBEHAVE" else part for part in rng.choice(OPTIONS)]
        command.append(rng.choice(VALUES))
        if command[0] in ("--dpi", "--figures"):
            command.append("soils")
        if command[0] == "fig3":
            command += ["--out", str(folder / "f")] + ([] if "--loads" in command else ["--loads", "300"])
        if command[0] in ("run", "testbed-data") and "-o" not in command and "--out" not in command:
            command += ["-o", str(folder / "out.csv")]
        if command[0] in ("montecarlo", "identify", "simulate"):
            command += ["--out", str(folder / "out"), "-q"]
        return [part.replace("t.csv", str(folder / "t.csv")) for part in command]

    def description_case(self, rng: random.Random, folder: Path) -> list[str]:
        from misbehave_fmu import model_description

        text = model_description()
        edits = [('index="1"', f'index="{rng.choice(["0", "-1", "99", "x", ""])}"'),
                 ('causality="output"', f'causality="{rng.choice(["input", "parameter", "local", "bogus"])}"'),
                 ('valueReference="1"', f'valueReference="{rng.choice(["0", "-1", "4294967296", "x"])}"'),
                 ('<Real start="0.5"/>', rng.choice(['<Real start="nan"/>', '<Real start="x"/>', "<Integer/>",
                                                     '<Real start="1e999"/>'])),
                 ('stepSize="0.1"', f'stepSize="{rng.choice(["0", "-1", "nan", "1e300"])}"'),
                 ('fmiVersion="2.0"', f'fmiVersion="{rng.choice(["1.0", "3.0", "", "2.0.1"])}"'),
                 ('variability="fixed"', f'variability="{rng.choice(["continuous", "constant", "x"])}"')]
        for old, new in rng.sample(edits, rng.randint(1, 3)):
            text = text.replace(old, new, 1)
        fmu = folder / "Misbehave.fmu"
        if self.misbehave is None:
            return ["soils"]
        shutil.copy(self.misbehave, fmu)
        with zipfile.ZipFile(self.misbehave) as source, zipfile.ZipFile(fmu, "w") as target:
            for item in source.infolist():
                data = text.encode() if item.filename == "modelDescription.xml" else source.read(item)
                target.writestr(item, data)
        return ["run", str(fmu), "-q", "-o", str(folder / "out.csv"),
                "--validate", rng.choice(["strict", "warn", "off"])]

    def _fig3(self) -> Path:
        """A results folder holding a real fig3 result (made once)."""
        from rover_cosim.cli import main as cli

        base = self.work / "fig3-results"
        if not base.is_dir():
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
                cli(["fig3", "--out", str(base), "--loads", "300", "--slip-step", "0.1"])
        return base

    def report_case(self, rng: random.Random, folder: Path) -> list[str]:
        results = folder / "results"
        shutil.copytree(self._fig3(), results)
        (results / "identification").mkdir(parents=True)
        (results / "montecarlo").mkdir(parents=True)
        tables = ["", "a,b\n1,2\n", "sample,scenario,status,error\n0,straight,ok,<b>\n", "\x00\xff", "x\n" * 1000]
        for name in rng.sample(["identification/fit_models.csv", "montecarlo/runs.csv", "simulation/rms.csv"], 2):
            (results / name).parent.mkdir(exist_ok=True)
            (results / name).write_text(rng.choice(tables), errors="surrogateescape")
        shapes = [json.dumps(shape) for shape in ([1, 2], "text", None, 1e308, {"a": "<script>alert(1)</script>"},
                                                  {"runs": "<b>", "seed": "<i>", "stop_time": "\x1b[31m",
                                                   "title": "<h1>"})]
        shapes += ["[" * 100_000 + "]" * 100_000, "{", "\xff\xfe"]  # 100k deep, cut short, not UTF-8
        (results / "identification" / "model.json").write_text(rng.choice(shapes), errors="surrogateescape")
        (results / "montecarlo" / "summary.json").write_text(rng.choice(shapes), errors="surrogateescape")
        return ["report", "--results", str(results), "--out", str(folder / "report.html")]


    def _exported(self) -> Path:
        """The single-wheel example as an SSP archive (made once)."""
        from rover_cosim.cli import main as cli

        archive = self.work / "single_wheel.ssp"
        if not archive.is_file():
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
                cli(["export-ssp", "single_wheel_step", "-o", str(archive), "--fmu-dir", str(self.fmu_dir)])
        return archive

    def ssp_case(self, rng: random.Random, folder: Path) -> list[str]:
        """The exported archive with its master annotation (JSON) or an XML attribute made odd."""
        import re

        source = self._exported()
        archive = folder / "system.ssp"
        with zipfile.ZipFile(source) as zf, zipfile.ZipFile(archive, "w") as out:
            for item in zf.infolist():
                data = zf.read(item)
                if item.filename == "SystemStructure.ssd":
                    text = data.decode()
                    found = re.search(r"(<[^>]*Master[^>]*>)(.*?)(</)", text, re.S)
                    if found and rng.random() < 0.7:
                        settings = json.loads(found.group(2).replace("&quot;", '"'))
                        shown = _mutated(settings, rng) if settings else {"x": 1}
                        if rng.random() < 0.3:
                            shown[rng.choice(["blocks", "interfaces", "iteration", "record", "block_connections",
                                              "allow_algebraic_loops", "order", "bogus"])] = rng.choice(ODD)
                        body = json.dumps(shown).replace("&", "&amp;").replace("<", "&lt;")
                        text = text[:found.start(2)] + body + text[found.end(2):]
                    else:
                        attributes = re.findall(r'(\w+)="([^"]*)"', text)
                        name, value = rng.choice(attributes)
                        text = text.replace(f'{name}="{value}"', f'{name}="{rng.choice(VALUES)[:50]}"', 1)
                    data = text.encode()
                out.writestr(item, data)
        return ["run", str(archive), "-q", "-o", str(folder / "out.csv"), "--stop-time", "0.05"]


KINDS = ("system", "study", "soil", "option", "description", "report", "ssp")


def run_case(harness: Harness, kind: str, rng: random.Random, folder: Path) -> tuple[str, str]:
    """(outcome, detail): outcome one of ok, traceback, exit, loss; detail: for ok, the exit code."""
    from rover_cosim.cli import main

    folder.mkdir(parents=True)
    command = getattr(harness, f"{kind}_case")(rng, folder)
    before = harness.snapshot()
    err = io.StringIO()
    code: object
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = main(command)
    except SystemExit as exit_:
        code = exit_.code
    except BaseException as error:  # noqa: BLE001 - what the fuzz looks for
        import traceback

        frame = traceback.extract_tb(error.__traceback__)[-1]
        return "traceback", (f"{command}: {type(error).__name__}: {str(error)[:300]} (at {Path(frame.filename).name}:"
                             f"{frame.lineno})")
    said = err.getvalue()
    if code not in (0, 1, 2):
        return "exit", f"{command}: exit {code!r}"
    if "Traceback" in said:
        return "traceback", f"{command}: {said[-300:]}"
    if harness.snapshot() != before:
        return "loss", f"{command}: changed files outside its output folder"
    leftovers = [p.name for p in folder.rglob("*") if ".tmp" in p.name or p.name.startswith(".")]
    if leftovers:
        return "loss", f"{command}: left {leftovers[:3]}"
    return "ok", str(code)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=20261206)
    parser.add_argument("--cases", type=int, default=600)
    parser.add_argument("--kinds", type=lambda t: tuple(t.split(",")), default=KINDS)
    args = parser.parse_args(argv)
    unknown = set(args.kinds) - set(KINDS)
    if unknown:
        parser.error(f"--kinds: {sorted(unknown)}: expected some of {', '.join(KINDS)}")
    rng = random.Random(args.seed)
    counts = dict.fromkeys(("ok", "traceback", "exit", "loss"), 0)
    codes: dict[str, dict[str, int]] = {kind: {} for kind in args.kinds}
    found: list[str] = []
    with tempfile.TemporaryDirectory(prefix="rover-cosim-fuzz-") as work:
        harness = Harness(Path(work))
        for case in range(args.cases):
            kind = args.kinds[case % len(args.kinds)]
            outcome, detail = run_case(harness, kind, random.Random(rng.getrandbits(64)),
                                       Path(work) / "cases" / f"{case:05d}")
            counts[outcome] += 1
            if outcome == "ok":
                codes[kind][detail] = codes[kind].get(detail, 0) + 1
            else:
                found.append(f"case {case} ({kind}): {outcome}: {detail}")
                print(found[-1], flush=True)
            shutil.rmtree(Path(work) / "cases" / f"{case:05d}", ignore_errors=True)
    print(f"fuzz seed {args.seed}: {args.cases} cases ({', '.join(args.kinds)}): {counts['traceback']} tracebacks, "
          f"{counts['exit']} bad exit codes, {counts['loss']} with files changed or left, 0 crashes (the harness "
          "ran to its end)")
    print("exit codes by kind: " + "; ".join(f"{kind} {dict(sorted(c.items()))}" for kind, c in codes.items()))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
