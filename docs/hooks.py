"""MkDocs hooks: the pages that follow the code and the results, generated at build time (never
kept as files, so they cannot drift): the command line from ``rover_cosim.cli``'s parser, the soil
and wheel library from its TOML files, the system-file keys and block types from the reader's own
tables, the FMUs' variables from their model descriptions, and the benchmark and validation
figures from ``results/`` (``make bench``, ``make run``); and the Modelica package's ``UsersGuide``,
set into the page ``guide/modelica.md`` from the package's own Documentation annotations.

Where they are read from: the FMUs from ``$ROVER_COSIM_DOCS_FMUS`` (default ``fmus/``), the results
from ``$ROVER_COSIM_DOCS_RESULTS`` (default ``results/``)."""

from __future__ import annotations

import argparse
import html
import json
import os
import re
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

from mkdocs.structure.files import File, Files


def cli_page() -> str:
    """Every ``rover-cosim`` command with its description and options, from the parser itself."""
    from rover_cosim.cli import build_parser

    parser = build_parser()
    lines = ["# Command line", "", "Generated from `rover_cosim.cli.build_parser()`.", "",
             "```text", parser.format_help().rstrip(), "```", ""]
    commands = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, sub in commands.choices.items():
        lines += [f"## rover-cosim {name}", "", "```text", sub.format_help().rstrip(), "```", ""]
    return "\n".join(lines)


def library_page() -> str:
    """The shipped soils, wheels and rovers: every value in SI, its title and source."""
    lines = ["# Soils, wheels and rovers", "", "Generated from the library files "
             "(`rover_cosim/terramechanics/library/*.toml`); `rover-cosim soils NAME` and `rover-cosim rovers NAME` "
             "show one with its notes.", ""]
    lines += format_section()
    lines += rover_format_section()
    folder = resources.files("rover_cosim.terramechanics") / "library"
    for kind in ("soils", "wheels", "rovers"):
        tables: dict[str, Any] = tomllib.loads((folder / f"{kind}.toml").read_text())
        lines += [f"## {kind.capitalize()}", ""]
        for name, table in tables.items():
            values = ", ".join(f"`{k}` = {v}" for k, v in table.items() if k not in ("title", "source", "notes"))
            lines += [f"### {name}", "", f"{table.get('title', '')}", "", f"Source: {table.get('source', '')}", "",
                      values or "(the paper's values)", ""]
    return "\n".join(lines)


def format_section() -> list[str]:
    """The TOML format of a soil or wheel file: every key with its unit, default and accepted range
    (from the parameter classes, their units and ranges)."""
    from dataclasses import fields

    from rover_cosim.terramechanics import Soil, Wheel
    from rover_cosim.terramechanics.library import DEGREES, METADATA
    from rover_cosim.terramechanics.parameters import RANGES, UNITS

    lines = ["## The file format", "",
             "A soil or wheel file is TOML: one table of keys (a file of one soil or wheel), or one table per "
             "name (`[my_soil]`; pick one with `FILE:NAME`). Every value is SI; a key left out keeps the "
             "paper's value (Table 2). Besides the keys below: "
             + ", ".join(f"`{k}`" for k in METADATA) + " (text, shown by `rover-cosim soils`; `notes` a table "
             "of remarks), and for a soil " + ", ".join(f"`{k}` (= `{v}` in degrees)" for k, v in DEGREES.items())
             + ". Use it with `--soil FILE` / `--wheel FILE` on any command, or `make run SOIL=FILE WHEEL=FILE`.",
             ""]
    for kind, cls in (("soil", Soil), ("wheel", Wheel)):
        default = cls()
        lines += [f"### {kind.capitalize()} keys", "", "| key | unit | default (paper) | accepted |",
                  "|---|---|---|---|"]
        for field in fields(cls):
            low, high = RANGES.get(field.name, (None, None))
            accepted = (f"{low:.6g}" if low is not None else "-inf") + " .. " + (f"{high:.6g}" if high is not None
                                                                                 else "inf")
            lines.append(f"| `{field.name}` | {UNITS.get(field.name, '')} | {getattr(default, field.name):.6g} | "
                         f"{accepted} |")
        lines.append("")
    return lines


def rover_format_section() -> list[str]:
    """The TOML format of a rover file: every key with its unit and the paper's value (from
    terramechanics.Rover and its units)."""
    from dataclasses import fields

    from rover_cosim.terramechanics.parameters import ROVER_UNITS, Rover

    doc = Rover.__doc__ or ""
    meaning = {}
    for line in doc.split("Attributes:")[-1].strip().splitlines():
        key, _, text = line.strip().partition(": ")
        if key.isidentifier() and text:
            meaning[key] = text.split(" [")[0]
    lines = ["### Rover keys", "", "A rover file is TOML as a soil's; the rover's wheels sit on two mirrored sides, "
             "`len(x_limb)` per side (wheels 1..n on the left from front to rear, n+1..2n on the right); its "
             "gravity is the soil's (where it drives). `wheel` names the rover's wheel (a name of the library or "
             "a wheel file), used unless `--wheel` names another. Use it with `--rover FILE` on any command, "
             "`--set rover.mass=740`, `--set rover.x_limb=1.2,-1.2`, or `make run ROVER=FILE`. The rover FMUs "
             "are built for its number of wheels on first use (`fmus/wheels<N>/`).", "",
             "| key | unit | default (paper) | meaning |", "|---|---|---|---|",
             "| `wheel` | - | paper | the rover's wheel |"]
    default = Rover()
    for field in fields(Rover):
        value = getattr(default, field.name)
        shown = ", ".join(f"{v:g}" for v in value) if isinstance(value, tuple) else f"{value:.6g}"
        lines.append(f"| `{field.name}` | {ROVER_UNITS[field.name]} | {shown} | {meaning.get(field.name, '')} |")
    return [*lines, ""]


REPOSITORY = Path(__file__).resolve().parent.parent


def _folder(variable: str, default: str) -> Path:
    return Path(os.environ.get(variable) or REPOSITORY / default)


def _cell(text: object) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _toml(value: Any) -> str:
    """A default as it is written in TOML (``None``: none, the meaning says what then happens)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    return f'"{value}"' if isinstance(value, str) else repr(value)


def system_files_page() -> str:
    """The keys of every section of a system file and the block types, from the reader's tables."""
    from rover_cosim.orchestrator import builder
    from rover_cosim.orchestrator.blocks import PYTHON_BLOCK, block_reference
    from rover_cosim.orchestrator.model import Iteration
    from rover_cosim.orchestrator.system import KEY_MEANINGS

    defaults = {**builder.SIMULATION_DEFAULTS, **{k: getattr(Iteration(), k) for k in builder.ITERATION_KEYS}}
    lines = ["# System files", "", "Generated from `rover_cosim.orchestrator.system.KEY_MEANINGS` (the keys the "
             "reader accepts), `builder.SIMULATION_DEFAULTS` and the block constructors. A system file is TOML "
             "(see [Co-simulation](../guide/cosimulation.md) for a whole example); `rover-cosim run FILE` "
             "checks it before it runs and names any problem with the file and the entry.", ""]
    sections = {"simulation": "[simulation]", "fmu": "[[fmu]]", "block": "[[block]]",
                "connection": "[[connection]]", "record": "[record]"}
    for section, keys in KEY_MEANINGS.items():
        lines += [f"## `{sections[section]}`", "", "| key | default | meaning |", "|---|---|---|"]
        for key, meaning in keys.items():
            default = _toml(defaults[key]) if section == "simulation" and key in defaults else ""
            default = default or ("required" if key in ("stop_time", "step", "name", "path", "type", "from", "to")
                                  else "")
            lines.append(f"| `{key}` | {_cell(default)} | {_cell(meaning)} |")
        lines.append("")
    lines += ["## Block types", "", "The keys of a `[[block]]` after `name` and `type`:", ""]
    for kind, doc, keys in block_reference():
        lines += [f"### `type = \"{kind}\"`", "", doc, "", "| key | default | meaning |", "|---|---|---|"]
        lines += [f"| `{k.name}` | {_cell('required' if k.default is None else k.default)} | {_cell(k.meaning)} |"
                  for k in keys]
        lines.append("")
    lines += ["### `type = \"python\"`", "", PYTHON_BLOCK[0].upper() + PYTHON_BLOCK[1:] + ".", "",
              "## Limits", "", "A system is checked against these before anything is allocated:", "",
              f"- communication steps per run: at most {builder.MAX_STEPS:,}",
              f"- recorded bytes per run: at most {builder.MAX_RECORD_BYTES / 2**30:g} GiB",
              f"- threads: at most {builder.MAX_THREADS}; instance names: at most {builder.MAX_NAME} characters", ""]
    return "\n".join(lines)


def fmu_variables_page() -> str:
    """Every variable of the FMUs `make fmus` builds, from their model descriptions."""
    from fmpy import read_model_description

    from rover_cosim.fmubuild.build import FMU_MODELS

    folder = _folder("ROVER_COSIM_DOCS_FMUS", "fmus")
    lines = ["# FMU variables", "", f"Generated from the model descriptions of the FMUs in `{folder.name}/` "
             "(`make fmus`); the same names in the FMI 3.0 FMUs (`make fmus3`). See [The FMUs](../guide/fmus.md).",
             ""]
    for name in FMU_MODELS:
        path = folder / f"{name}.fmu"
        lines += [f"## {name}", ""]
        if not path.exists():
            lines += [f"`{path}` is not built: run `make fmus` before `make docs`.", ""]
            continue
        description = read_model_description(str(path))
        experiment = description.defaultExperiment
        lines += [description.description or "", "", f"FMI {description.fmiVersion}; model identifier `{name}`; "
                  f"default experiment {experiment.stopTime if experiment else '-'} s.", "",
                  "| variable | causality | variability | unit | start | description |",
                  "|---|---|---|---|---|---|"]
        order = {"input": 0, "output": 1, "parameter": 2, "independent": 3}
        for v in sorted(description.modelVariables, key=lambda v: order.get(v.causality, 4)):
            if v.causality not in order:
                continue
            unit = v.unit or (v.declaredType.unit if v.declaredType else "") or ""
            start = "" if v.start is None else v.start
            lines.append(f"| `{v.name}` | {v.causality} | {v.variability} | {_cell(unit)} | {_cell(start)} "
                         f"| {_cell(v.description or '')} |")
        lines.append("")
    return "\n".join(lines)


def _flat(value: Any, prefix: str = "") -> list[tuple[str, Any]]:
    if isinstance(value, dict):
        return [row for key, item in value.items() for row in _flat(item, f"{prefix}.{key}" if prefix else str(key))]
    if isinstance(value, list) and len(value) > 8:
        return [(prefix, f"{len(value)} values")]
    return [(prefix, value)]


def _number(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return _cell(value)


def _goals_table(goals: Any) -> list[str]:
    """The goals a benchmark file measured (``bench_pipeline``'s ``goals``) as a table; none: no lines."""
    if not isinstance(goals, list) or not goals:
        return []
    verdicts = {True: "met", False: "not met", None: "not measured"}
    def shown(value: Any) -> str:
        return "-" if value is None else _number(value)

    rows = [f"| {_cell(g.get('goal'))} | {shown(g.get('measured'))} | {shown(g.get('baseline'))} | "
            f"{_cell(g.get('target'))} | {verdicts.get(g.get('met'), '?')} |" for g in goals if isinstance(g, dict)]
    return ["| goal | measured | baseline (the commit before) | goal | |", "|---|---|---|---|---|", *rows, ""]


def benchmarks_page() -> str:
    """The figures of the last ``make bench``, with the machine and date of each file."""
    folder = _folder("ROVER_COSIM_DOCS_RESULTS", "results") / "bench"
    files = sorted(folder.glob("*.json"))
    lines = ["# Benchmarks", "", f"Generated from `{folder.parent.name}/bench/*.json`, the files `make bench` writes "
             "(what each measures: [Development](../design/development.md#benchmark)). Timings are never asserted "
             "in tests; they are measured here, side by side in one run.", ""]
    if not files:
        return "\n".join(lines + [f"No benchmark results in `{folder}`: run `make bench`, then `make docs`.", ""])
    for path in files:
        record = json.loads(path.read_text())
        lines += [f"## {path.stem}", "", f"Measured {record.get('created_utc', '?')} at commit "
                  f"`{str(record.get('git_commit', '?'))[:12]}` on {record.get('platform', '?')}, Python "
                  f"{record.get('python', '?')}; parameters: `{_cell(json.dumps(record.get('parameters', {})))}`.", "",
                  *_goals_table(record.get("goals")), "| quantity | value |", "|---|---|"]
        lines += [f"| {_cell(key)} | {_number(value)} |" for key, value in _flat(record.get("results", {}))]
        lines.append("")
    return "\n".join(lines)


def validation_page() -> str:
    """The report's tables (Table 1, closed loop, paths, coupling, Monte Carlo), figures left to it."""
    from rover_cosim.report import sections

    results = _folder("ROVER_COSIM_DOCS_RESULTS", "results")
    lines = ["# Validation", "", f"Generated from `{results.name}/` (`make run`) by the report's own section "
             "functions (`rover_cosim.report.sections`); the figures are in `results/report.html`.", ""]
    if not (results / "identification" / "identification.json").exists():
        return "\n".join(lines + [f"No results in `{results}`: run `make run`, then `make docs`.", ""])
    record = sections.soil_record(results)
    lines += [f"Results of {record.get('created_utc', '?')}, {sections.soil_label(results)}.", ""]
    parts = [*sections.identification_section(results / "identification", sections.on_paper_soil(results)),
             *sections.closed_loop_section(results / "simulation", sections.on_paper_soil(results)),
             *sections.path_section(results / "simulation"), *sections.coupling_section(results),
             *sections.montecarlo_section(results / "montecarlo")]
    text = re.sub(r"<figure>.*?</figure>", "", "\n".join(parts), flags=re.S)
    text = re.sub(r"<h2>(.*?)</h2>", lambda m: "\n## " + re.sub(r"<.*?>", "", m.group(1)) + "\n", text)
    return "\n".join(lines) + "\n" + text + "\n"


GENERATED = {"reference/cli.md": cli_page, "reference/soils.md": library_page,
             "reference/system-files.md": system_files_page, "reference/fmu-variables.md": fmu_variables_page,
             "results/benchmarks.md": benchmarks_page, "results/validation.md": validation_page}

#: Where guide/modelica.md takes the UsersGuide.
USERS_GUIDE_MARK = "<!-- RoverTerramechanics.UsersGuide -->"


def users_guide() -> str:
    """Every class of ``RoverTerramechanics.UsersGuide``, in its package.order, as a section: its
    description, then its Documentation HTML (links to the guide's classes become links to the
    sections, links to other classes their names)."""
    from rover_cosim.fmubuild import source

    folder = source.MODELICA_ROOT / source.PACKAGE / "UsersGuide"
    sections = [_guide_html(folder / "package.mo"), ""]
    for name in (folder / "package.order").read_text().split():
        description = re.search(rf'^class {name} "(.*?)"', (folder / f"{name}.mo").read_text(), re.MULTILINE)
        if description is None:
            raise ValueError(f"{folder / name}.mo: expected 'class {name} \"description\"'")
        sections += [f"## {name}", "", f"*{html.escape(description.group(1))}*", "",
                     _guide_html(folder / f"{name}.mo"), ""]
    return "\n".join(sections)


def _guide_html(path: Path) -> str:
    """The Documentation HTML of a class of the guide, its links made to work on the site."""
    info = re.search(r'Documentation\(info="<html>(.*?)</html>"\)', path.read_text(), re.DOTALL)
    if info is None:
        raise ValueError(f"{path}: no Documentation(info=...)")
    body = info.group(1).replace('\\"', '"').strip()
    body = re.sub(r'<a\s+href="modelica://RoverTerramechanics\.UsersGuide\.(\w+)">',
                  lambda m: f'<a href="#{m.group(1).lower()}">', body)
    return re.sub(r'<a\s+href="modelica://[\w.]+">(.*?)</a>', r"<code>\1</code>", body, flags=re.DOTALL)


def on_page_markdown(markdown: str, page: Any, config: Any, files: Files) -> str:
    if page.file.src_uri == "guide/modelica.md":
        return markdown.replace(USERS_GUIDE_MARK, users_guide())
    return markdown


def on_files(files: Files, config: Any) -> Files:
    for path, make in GENERATED.items():
        files.append(File.generated(config, path, content=make()))
    return files
