"""The Modelica package RoverTerramechanics: where it is, its classes, and rumoca's view of them.

rumoca (pinned in pyproject.toml) parses, resolves and flattens the package; its ``simulate``
runs a model with its own solver. rumoca does not read the ``experiment`` annotation, so
:func:`experiment` reads it from the source.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from . import catalog
from .catalog import FMU_PACKAGE as FMU_PACKAGE  # noqa: F401 - the package's names, read here too (catalog owns them)
from .catalog import MODELICA_ROOT as MODELICA_ROOT  # noqa: F401
from .catalog import PACKAGE as PACKAGE  # noqa: F401
from .catalog import fmu_class as fmu_class  # noqa: F401

if TYPE_CHECKING:  # pandas only for the annotation: an FMU's build never imports it
    import pandas as pd


def package_file() -> Path:
    """The top-level ``package.mo`` of RoverTerramechanics."""
    return catalog.MODELICA_ROOT / catalog.PACKAGE / "package.mo"


def class_files() -> dict[str, Path]:
    """Every class of the package by qualified name, mapped to the file that defines it
    (``package.mo`` for packages)."""
    files: dict[str, Path] = {}
    for path in sorted((catalog.MODELICA_ROOT / catalog.PACKAGE).rglob("*.mo")):
        parts = path.relative_to(catalog.MODELICA_ROOT).with_suffix("").parts
        if parts[-1] == "package":
            parts = parts[:-1]
        files[".".join(parts)] = path
    return files


def class_file(name: str) -> Path:
    """The file defining the class ``name`` (qualified, e.g. ``RoverTerramechanics.FMUs.Rover``)."""
    files = class_files()
    if name not in files:
        raise ValueError(f"model {name!r}: no such class in {catalog.MODELICA_ROOT / catalog.PACKAGE}; "
                         f"expected one of {sorted(files)}")
    return files[name]


def load(name: str):  # -> rumoca.Model (rumoca has no type stubs)
    """Parse, resolve and flatten the class ``name`` with rumoca, in a fresh session (a rumoca
    session cannot load the same package twice)."""
    import rumoca

    class_file(name)  # a clear error for an unknown class before rumoca's own
    session = rumoca.Session(roots=[str(catalog.MODELICA_ROOT)])
    return session.load(str(package_file()), model=name)


#: The FMUs whose number of wheels is a structural parameter (``rover.nAxles``, wheels per side).
ROVER_MODELS = ("Rover", "RoverBody", "SteerableRover", "SteerableRoverBody")
#: The package's own number of wheels per side: the FMUs of ``make fmus``.
DEFAULT_AXLES = 3


def variant_source(name: str, axles: int) -> str:
    """Modelica source of the FMU ``name`` built for ``axles`` wheels per side: a class of the same
    name extending the package's, with ``rover.nAxles`` and start positions ``rover.xLimb`` of that
    size (evenly spaced from +1.5 to -1.5 m; a rover sets its own at run time)."""
    if name not in ROVER_MODELS:
        raise ValueError(f"model {name!r}: the number of wheels is a parameter of {', '.join(ROVER_MODELS)} only")
    if isinstance(axles, bool) or not isinstance(axles, int) or not 1 <= axles <= 16:
        raise ValueError(f"axles = {axles!r}: expected 1 to 16 wheels per side")
    positions = [0.0] if axles == 1 else [1.5 - 3.0 * i / (axles - 1) for i in range(axles)]
    return (f'model {name} "{name} with {2 * axles} wheels ({axles} per side)"\n'
            f"  extends {fmu_class(name)}(rover(nAxles={axles}, xLimb={{{', '.join(map(repr, positions))}}}));\n"
            f"end {name};\n")


def load_variant(name: str, axles: int):  # -> rumoca.Model
    """:func:`load` of the FMU class ``name`` built for ``axles`` wheels per side (:func:`variant_source`)."""
    import rumoca

    text = variant_source(name, axles)
    session = rumoca.Session(roots=[str(catalog.MODELICA_ROOT)])
    return session.loads(text, model=name, filename=f"{name}_{axles}axles.mo")


@dataclass(frozen=True)
class Experiment:
    """The ``experiment`` annotation of a model: times in seconds."""

    start: float
    stop: float
    interval: float
    tolerance: float | None


def experiment(name: str) -> Experiment:
    """Read the ``experiment(...)`` annotation of the class ``name`` from its source file."""
    text = class_file(name).read_text()
    match = re.search(r"experiment\s*\(([^)]*)\)", text)
    if match is None:
        raise ValueError(f"model {name!r} has no experiment annotation in {class_file(name)}")
    values = dict(re.findall(r"(\w+)\s*=\s*([-+0-9.eE]+)", match.group(1)))
    stop = float(values.get("StopTime", 1.0))
    start = float(values.get("StartTime", 0.0))
    interval = float(values.get("Interval", (stop - start) / 500))
    tolerance = float(values["Tolerance"]) if "Tolerance" in values else None
    return Experiment(start, stop, interval, tolerance)


def simulate(name: str, *, params: Mapping[str, float] | None = None, stop: float | None = None,
             interval: float | None = None) -> pd.DataFrame:
    """rumoca's simulation of the class ``name`` (which must bind all its inputs), sampled at
    ``interval`` from the start to ``stop`` (defaults: its experiment annotation). Returns one
    column per variable, indexed by time [s].

    The solver tolerance is the annotation's ``Tolerance`` (relative and absolute), if it has one.
    ``params`` overrides tunable parameters by flat name (e.g. ``{"W": 575.0}``); structural
    parameters such as loop bounds cannot be overridden this way (rumoca compiles them in).
    """
    exp = experiment(name)
    stop = exp.stop if stop is None else stop
    interval = exp.interval if interval is None else interval
    if not (stop > exp.start and interval > 0):
        raise ValueError(f"stop={stop!r}, interval={interval!r}: expected stop > {exp.start} s and interval > 0 s")
    import rumoca

    model = load(name)
    if params:
        model = model.with_params(**params)
    # rumoca's default tolerance (~1e-6) is not the annotation's; pass the annotation's on.
    config = rumoca.SimConfig(rtol=exp.tolerance, atol=exp.tolerance) if exp.tolerance else None
    return model.simulate(t=(exp.start, stop), dt=interval, config=config).to_dataframe()
