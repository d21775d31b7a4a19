"""The plants the jobs run, built in code through the engine's SystemBuilder from domain objects
(the soil and wheel of a ``Choice``, the identified ``ModelSet``): the rover's hub wiring is
written here once, for any number of wheels, with or without the lateral interface.

A body FMU (RoverBody, SteerableRoverBody) and its wheel FMUs (Wheel) meet at each hub ``i``:
the body gives wheel ``i`` its load ``W[i]`` and hub speed ``v_hub[i]`` (and, steerable, the
lateral hub speed ``v_lat[i]``); the wheel gives the body its drawbar pull ``Fx`` (and lateral
force ``Fy``).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from functools import cache
from pathlib import Path

from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.terramechanics.library import Choice, fmu_parameters, rover_parameters

#: The rover FMUs' own number of wheels (``make fmus``): other rovers get FMUs built for theirs.
PACKAGE_WHEELS = 6


def soil_values(choice: Choice | None) -> dict[str, float]:
    """The FMU parameters of the chosen soil, wheel and rover (none without a choice: the FMUs'
    defaults); the rover's gravity is the soil's. An FMU takes those it has."""
    if choice is None:
        return {}
    return {**fmu_parameters(choice.soil, choice.wheel), **rover_parameters(choice.rover, choice.soil.gravity)}


def rover_fmu(fmu_dir: str | Path, name: str, choice: Choice | None) -> Path:
    """The rover FMU ``name`` (Rover, RoverBody, SteerableRover, SteerableRoverBody) for the rover of
    ``choice``: ``fmu_dir/NAME.fmu`` where it has the rover's number of wheels (the package's six;
    a missing one is the caller's to report), else ``fmu_dir/wheels<N>/NAME.fmu``, built on demand
    from the Modelica source for N wheels, with the elementary functions ``fmu_dir/NAME.fmu`` was
    built with, and kept (rebuilt only when its inputs change)."""
    path = Path(fmu_dir) / f"{name}.fmu"
    wheels = choice.rover.wheels if choice is not None else PACKAGE_WHEELS
    if (path.is_file() and len(hubs(path)) == wheels) or (wheels == PACKAGE_WHEELS and not path.is_file()):
        return path
    from rover_cosim.fmubuild.artifact import stored_elementary
    from rover_cosim.fmubuild.build import build_fmu

    folder = Path(fmu_dir) / f"wheels{wheels}"
    # with the elementary functions of the folder's own FMU (make fmus ELEMENTARY=own: own here too)
    try:
        return build_fmu(name, folder, axles=wheels // 2, elementary=stored_elementary(path)).path
    except Exception as error:  # noqa: BLE001 - a compiler, a file system, the exporter: said as one error
        raise ValueError(f"the rover {choice.rover_name if choice else ''} has {wheels} wheels: {name}.fmu for them "
                         f"could not be built into {folder} ({type(error).__name__}: {error})") from None


def add_plant_fmu(builder: SystemBuilder, name: str, path: str | Path, choice: Choice | None,
                  start: Mapping[str, float] | None = None) -> None:
    """An FMU given those of the soil and wheel parameters it has (none for a body)."""
    builder.add_fmu(name, path, start=start)
    builder.set_parameters(name, soil_values(choice), only_known=True)


def wire_hub(builder: SystemBuilder, body: str, wheel: str, i: int, *, lateral: bool = False) -> None:
    """The hub ``i`` between ``body`` and ``wheel`` (see the module docstring)."""
    builder.connect(f"{body}.W[{i}]", f"{wheel}.W")
    builder.connect(f"{body}.v_hub[{i}]", f"{wheel}.v_hub")
    if lateral:
        builder.connect(f"{body}.v_lat[{i}]", f"{wheel}.v_lat")
    builder.connect(f"{wheel}.Fx", f"{body}.Fx[{i}]")
    if lateral:
        builder.connect(f"{wheel}.Fy", f"{body}.Fy[{i}]")


def wire_hubs(builder: SystemBuilder, body: str, wheels: list[str], *, lateral: bool = False) -> None:
    """Every hub: wheel ``wheels[i - 1]`` on the body's hub ``i``."""
    for i, wheel in enumerate(wheels, start=1):
        wire_hub(builder, body, wheel, i, lateral=lateral)


def add_rover(builder: SystemBuilder, body_fmu: str | Path, wheel_fmu: str | Path, wheels: int,
              choice: Choice | None, *,
              body: str = "body", lateral: bool = False, body_start: Mapping[str, float] | None = None,
              wheel_start: Mapping[str, float] | None = None, wire: bool = True) -> list[str]:
    """A body and ``wheels`` wheel instances (``wheel1`` ...) on the chosen soil, their hubs wired
    unless ``wire`` is False (to wire them in another order); returns the wheels' names."""
    add_plant_fmu(builder, body, body_fmu, choice, body_start)
    names = [f"wheel{i}" for i in range(1, wheels + 1)]
    for name in names:
        add_plant_fmu(builder, name, wheel_fmu, choice, wheel_start)
    if wire:
        wire_hubs(builder, body, names, lateral=lateral)
    return names


def hubs(fmu: str | Path) -> range:
    """The hub numbers 1..N of a rover FMU (Rover, RoverBody, SteerableRover, SteerableRoverBody):
    N is the largest index of its indexed variables (``tau[i]``, ``Fz[i]``, ``W[i]``, ...), so the
    number of wheels comes from the model, not from a constant of ours."""
    path = Path(fmu)
    return range(1, _largest_index(str(path.resolve()), path.stat().st_mtime_ns) + 1)


@cache
def _largest_index(path: str, mtime_ns: int) -> int:
    from fmpy import read_model_description

    names = (variable.name for variable in read_model_description(path).modelVariables)
    found = [int(match.group(1)) for match in map(_INDEXED.fullmatch, names) if match]
    if not found:
        raise ValueError(f"{path}: no indexed variables (tau[i], Fz[i], ...): expected a rover FMU with a hub per "
                         "wheel")
    return max(found)


#: An indexed variable's name: ``name[i]``.
_INDEXED = re.compile(r"[A-Za-z_]\w*\[(\d+)\]")
