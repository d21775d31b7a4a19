"""The soil, wheel and rover library shipped with the package (``library/soils.toml``,
``library/wheels.toml``, ``library/rovers.toml``) and the choice of a soil, a wheel and a rover from
the command line.

A soil or wheel is given by name (a table of the shipped files) or by a TOML file of the same
form (one table; or several, then ``FILE:NAME``), then changed by ``--set`` assignments
(``soil.c=500``, ``soil.phi_deg=30``, ``wheel.b=0.2``, ``rover.mass=740``,
``rover.x_limb=1.2,-1.2``). A rover names its wheel (``wheel = "mer"``): the wheel of the choice
unless one is given. Angles may be given in degrees with an explicit key (``phi_deg``,
``xc_deg``); every other value is SI. A soil that leaves out ``xc`` gets 45 deg - phi/2
(Hegedus's destructive angle, as Ishigami et al. 2007 use it).

:func:`fmu_parameters` turns a soil and a wheel into the FMUs' parameter names (``soil.kxBeta``
...), so the FMUs take them without a rebuild; :func:`describe` gives the record a results folder
keeps.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib
from collections.abc import Mapping
from dataclasses import asdict, dataclass, fields, replace
from functools import lru_cache
from pathlib import Path
from typing import Any

from .parameters import Rover, Soil, Wheel

LIBRARY = Path(__file__).with_name("library")
SOILS, WHEELS, ROVERS = LIBRARY / "soils.toml", LIBRARY / "wheels.toml", LIBRARY / "rovers.toml"
#: The kinds of the library and their files.
FILES = {"soil": SOILS, "wheel": WHEELS, "rover": ROVERS}
DEFAULT = "paper"
METADATA = ("title", "source", "notes")
DEGREES = {"phi_deg": "phi", "xc_deg": "xc"}
#: numpy field -> Modelica record field, where they differ.
MODELICA_NAMES = {"kx_beta": "kxBeta", "ky_beta": "kyBeta", "n_slip": "nSlip", "grouser_height": "grouserHeight",
                  "grouser_count": "grouserCount"}
#: Rover field -> Modelica RoverParameters field, where they differ.
ROVER_MODELICA_NAMES = {"mass": "M", "h_cog": "hCoG", "x_limb": "xLimb", "y_limb": "yLimb", "k_limb": "kLimb",
                        "d_limb": "dLimb"}


@dataclass(frozen=True)
class Choice:
    """A soil and a wheel, with where they came from (for the results' record)."""

    soil: Soil
    wheel: Wheel
    soil_name: str
    wheel_name: str
    soil_entry: dict[str, Any]
    wheel_entry: dict[str, Any]
    overrides: tuple[str, ...] = ()
    rover: Rover = dataclasses.field(default_factory=Rover)
    rover_name: str = DEFAULT
    rover_entry: dict[str, Any] = dataclasses.field(default_factory=dict)


def _tables(path: Path) -> dict[str, Any]:
    try:
        return tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise ValueError(f"{path}: no such file") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, IsADirectoryError) as error:
        raise ValueError(f"{path}: not a readable TOML file ({error})") from None


@lru_cache(maxsize=4)
def _shipped_tables(path: Path) -> dict[str, Any]:
    return _tables(path)


def _shipped(path: Path) -> dict[str, Any]:
    """A shipped file's tables, read once per process (a copy: callers may change it)."""
    return copy.deepcopy(_shipped_tables(path))


def names(kind: str) -> list[str]:
    """The shipped soils (``kind = "soil"``), wheels or rovers."""
    return list(_tables(_file(kind)))


def _file(kind: str) -> Path:
    if kind not in FILES:
        raise ValueError(f"kind {kind!r}: expected one of {', '.join(FILES)}")
    return FILES[kind]


def entry(kind: str, spec: str) -> tuple[str, dict[str, Any]]:
    """(name, table) of a shipped name, a TOML file (one soil, or one table of them), or ``FILE:NAME``."""
    library = _shipped(_file(kind))
    if spec in library:
        return spec, dict(library[spec])
    path, name = spec, ""
    if not Path(spec).is_file() and ":" in spec:
        path, name = spec.rsplit(":", 1)
    if not Path(path).is_file():
        if Path(path).suffix.lower() == ".toml" or "/" in path:
            raise ValueError(f"{kind} file {path} not found (a {kind} is a shipped name: {', '.join(library)}; "
                             "a TOML file; or FILE:NAME)")
        raise ValueError(f"{kind} {spec!r}: expected one of {', '.join(library)}, a TOML file or FILE:NAME")
    tables = _tables(Path(path))
    if not tables:
        raise ValueError(f"{kind} {spec!r}: {path} is empty: expected the {kind}'s values (e.g. c = 800.0, "
                         "phi_deg = 37.2) or tables of them")
    if not any(isinstance(v, dict) and k != "notes" for k, v in tables.items()):
        return Path(path).stem, dict(tables)   # the file is one soil (or wheel)
    if name or len(tables) == 1:
        name = name or next(iter(tables))
        if name not in tables:
            raise ValueError(f"{kind} {spec!r}: {path} has no table {name!r} (has {', '.join(tables)})")
        return name, dict(tables[name])
    raise ValueError(f"{kind} {spec!r}: {path} has several tables ({', '.join(tables)}); name one as FILE:NAME")


def _rover_values(name: str, table: dict[str, Any]) -> dict[str, Any]:
    """A rover table's values (``wheel`` and the metadata left out), unknown keys refused."""
    known = {f.name for f in fields(Rover)}
    accepted = known | {"wheel"} | set(METADATA)
    unknown = sorted(set(table) - accepted)
    if unknown:
        raise ValueError(f"rover {name!r}: unknown key(s) {unknown}; expected {', '.join(sorted(accepted))}")
    values: dict[str, Any] = {}
    for key in known & set(table):
        value = table[key]
        if key == "x_limb":
            if not isinstance(value, list) or not value:
                raise ValueError(f"rover {name!r}: x_limb = {value!r}: expected a list of hub positions [m] of one "
                                 "side, front to rear, e.g. [1.5, 0.0, -1.5]")
            values[key] = tuple(value)
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"rover {name!r}: {key} = {value!r}: expected a number")
        else:
            values[key] = float(value)
    if "wheel" in table and not isinstance(table["wheel"], str):
        raise ValueError(f"rover {name!r}: wheel = {table['wheel']!r}: expected the name of a wheel (or a wheel file)")
    return values


def build_rover(name: str, table: dict[str, Any]) -> Rover:
    """The Rover of a table: the paper's values for what it leaves out."""
    values = {**_rover_values(DEFAULT, _shipped(ROVERS)[DEFAULT]), **_rover_values(name, table)}
    try:
        return Rover(**values)
    except (ValueError, TypeError) as error:
        raise ValueError(f"rover {name!r}: {error}") from None


def _values(kind: str, name: str, table: dict[str, Any]) -> dict[str, float]:
    """The table's parameter values in SI (degrees converted), unknown keys refused."""
    target = Soil if kind == "soil" else Wheel
    known = {f.name for f in fields(target)}
    accepted = known | (set(DEGREES) if kind == "soil" else set()) | set(METADATA)
    unknown = sorted(set(table) - accepted)
    if unknown:
        raise ValueError(f"{kind} {name!r}: unknown key(s) {unknown}; expected {', '.join(sorted(accepted))}")
    values: dict[str, float] = {}
    for key, value in table.items():
        if key in METADATA:
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ValueError(f"{kind} {name!r}: {key} = {value!r}: expected a number")
        if key in DEGREES:
            if DEGREES[key] in table:
                raise ValueError(f"{kind} {name!r}: both {key} and {DEGREES[key]} given")
            if not 0 < float(value) < 90:
                raise ValueError(f"{kind} {name!r}: {key} = {float(value)!r} is not physical: expected 0 < {key} < 90 "
                                 "deg")
            values[DEGREES[key]] = math.radians(float(value))
        else:
            values[key] = float(value)
    return values


def build(kind: str, name: str, table: dict[str, Any]) -> Soil | Wheel | Rover:
    """The Soil, Wheel or Rover of a table: the paper's values for what it leaves out, xc = 45 deg - phi/2."""
    if kind == "rover":
        return build_rover(name, table)
    values = _values(kind, name, table)
    if kind == "wheel":
        base_wheel = Wheel(**_values("wheel", DEFAULT, _shipped(WHEELS)[DEFAULT]))
        try:
            return replace(base_wheel, **values)
        except ValueError as error:
            raise ValueError(f"wheel {name!r}: {error}") from None
    base = _values("soil", DEFAULT, _shipped(SOILS)[DEFAULT])
    if "xc" not in values:
        base.pop("xc", None)  # Soil derives it from the soil's own phi: 45 deg - phi/2
    try:
        return Soil(**{**base, **values})
    except ValueError as error:
        raise ValueError(f"soil {name!r}: {error}") from None


def parse_set(assignments: list[str] | tuple[str, ...]) -> dict[str, dict[str, Any]]:
    """``["soil.c=500", "wheel.b=0.2", "rover.x_limb=1,-1"]`` -> {"soil": {"c": 500.0}, "wheel": {"b": 0.2},
    "rover": {"x_limb": (1.0, -1.0)}} (a list: comma-separated numbers)."""
    result: dict[str, dict[str, Any]] = {"soil": {}, "wheel": {}, "rover": {}}
    for text in assignments:
        key, equals, value = text.partition("=")
        kind, _, name = key.strip().partition(".")
        if not equals or kind not in result or not name:
            raise ValueError(f"--set {text!r}: expected soil.NAME=VALUE, wheel.NAME=VALUE or rover.NAME=VALUE")
        try:
            if kind == "rover" and name == "x_limb":
                result[kind][name] = tuple(float(part) for part in value.split(","))
            else:
                result[kind][name] = float(value)
        except ValueError:
            raise ValueError(f"--set {text!r}: {value!r} is not a number"
                             + (" (x_limb: comma-separated numbers [m], front to rear)" if name == "x_limb" else "")
                             ) from None
    return result


def choose(soil: str | None = None, wheel: str | None = None, assignments: list[str] | tuple[str, ...] = (),
           rover: str | None = None) -> Choice:
    """The soil, wheel and rover of the command line (defaults: the paper's; the wheel: the rover's
    own unless one is given), with ``--set`` applied."""
    changes = parse_set(assignments)
    soil_name, soil_table = entry("soil", soil or DEFAULT)
    rover_name, rover_table = entry("rover", rover or DEFAULT)
    rover_wheel = rover_table.get("wheel", DEFAULT)
    try:
        wheel_name, wheel_table = entry("wheel", wheel or rover_wheel)
    except ValueError as error:
        if wheel is None:
            raise ValueError(f"rover {rover_name!r}: its wheel: {error}") from None
        raise
    return _changed(soil_name, soil_table, wheel_name, wheel_table, changes["soil"], changes["wheel"],
                    tuple(assignments), rover_name, rover_table, changes["rover"])


def as_choice(value: Choice | Soil | Wheel | None = None, wheel: Wheel | None = None) -> Choice:
    """A Choice from what a caller has: a Choice (as it is), a Soil and/or a Wheel built in code
    (named "custom" in the records, the paper's for the other), or None (the paper's)."""
    if isinstance(value, Choice):
        if wheel is not None:
            raise ValueError("as_choice: a Choice already has its wheel; give a Soil and a Wheel instead")
        return value
    if isinstance(value, Wheel) and wheel is None:
        value, wheel = None, value
    if value is not None and not isinstance(value, Soil):
        raise ValueError(f"{value!r}: expected a Choice, a Soil or a Wheel")
    paper = choose()
    soil_entry = {"title": "a soil built in code", "source": "Python"} if value is not None else paper.soil_entry
    wheel_entry = {"title": "a wheel built in code", "source": "Python"} if wheel is not None else paper.wheel_entry
    soil_name = "custom" if value is not None else paper.soil_name
    wheel_name = "custom" if wheel is not None else paper.wheel_name
    return Choice(value if value is not None else paper.soil, wheel if wheel is not None else paper.wheel,
                  soil_name, wheel_name, soil_entry, wheel_entry, (), paper.rover, paper.rover_name, paper.rover_entry)


def vary(choice: Choice, soil: Mapping[str, float] | None = None, wheel: Mapping[str, float] | None = None,
         rover: Mapping[str, Any] | None = None) -> Choice:
    """``choice`` with some values changed, exactly as ``--set`` changes them (SI; angles in
    degrees under ``phi_deg``, ``xc_deg``): ``vary(choice, soil={"c": 500.0, "phi_deg": 30.0})``.
    ValueError with the library's message for a soil or wheel it refuses."""
    soil, wheel, rover = dict(soil or {}), dict(wheel or {}), dict(rover or {})
    overrides = tuple(f"{kind}.{key}={_shown(value)}" for kind, values in (("soil", soil), ("wheel", wheel),
                                                                          ("rover", rover))
                      for key, value in values.items())
    return _changed(choice.soil_name, dict(choice.soil_entry), choice.wheel_name, dict(choice.wheel_entry), soil,
                    wheel, choice.overrides + overrides, choice.rover_name, dict(choice.rover_entry), rover)


def _shown(value: Any) -> str:
    """A --set value as the command line gives it (a list: comma-separated)."""
    if isinstance(value, (list, tuple)):
        return ",".join(repr(float(v)) for v in value)
    return repr(float(value))


def _changed(soil_name: str, soil_table: dict[str, Any], wheel_name: str, wheel_table: dict[str, Any],
             soil: Mapping[str, float], wheel: Mapping[str, float], overrides: tuple[str, ...],
             rover_name: str = DEFAULT, rover_table: dict[str, Any] | None = None,
             rover: Mapping[str, Any] | None = None) -> Choice:
    """The Choice of the tables with ``soil``, ``wheel`` and ``rover`` values changed (the tables are changed)."""
    if rover_table is None:
        rover_table = dict(_shipped(ROVERS)[DEFAULT]) if rover_name == DEFAULT else {}
    rover_table.update({key: (list(value) if isinstance(value, tuple) else float(value))
                        for key, value in (rover or {}).items()})
    chosen_rover = build_rover(rover_name, rover_table)
    for field in soil:
        if field in DEGREES:
            soil_table.pop(DEGREES[field], None)
        elif field in DEGREES.values():
            soil_table.pop(f"{field}_deg", None)
    soil_table.update({key: float(value) for key, value in soil.items()})
    wheel_table.update({key: float(value) for key, value in wheel.items()})
    chosen_soil = build("soil", soil_name, soil_table)
    chosen_wheel = build("wheel", wheel_name, wheel_table)
    assert isinstance(chosen_soil, Soil) and isinstance(chosen_wheel, Wheel)
    return Choice(chosen_soil, chosen_wheel, soil_name, wheel_name, soil_table, wheel_table, overrides,
                  chosen_rover, rover_name, rover_table)


def fmu_parameters(soil: Soil, wheel: Wheel) -> dict[str, float]:
    """The soil and wheel as the FMUs' parameters (``soil.c``, ``soil.kxBeta``, ``wheel.r`` ...)."""
    values = soil_parameters(soil)
    values.update({f"wheel.{MODELICA_NAMES.get(k, k)}": v for k, v in asdict(wheel).items()})
    return values


def rover_parameters(rover: Rover, gravity: float) -> dict[str, float]:
    """The rover as the rover FMUs' parameters (``rover.M``, ``rover.xLimb[1]`` ...; ``rover.g``: the
    gravity [m/s²] where it drives, the soil's). The FMU must be built for its number of wheels."""
    values = {"rover.g": float(gravity)}
    for key, value in asdict(rover).items():
        name = f"rover.{ROVER_MODELICA_NAMES.get(key, key)}"
        if isinstance(value, tuple):
            values.update({f"{name}[{i}]": float(v) for i, v in enumerate(value, start=1)})
        else:
            values[name] = float(value)
    return values


def soil_parameters(soil: Soil, record: str = "soil") -> dict[str, float]:
    """The soil as the FMUs' parameters of the record ``record`` (``soil``; ``soilB``: the second
    soil of Wheel and SteerableRover, where a wheel's ``soilShare`` is 1)."""
    return {f"{record}.{MODELICA_NAMES.get(k, k)}": v for k, v in asdict(soil).items()}


def from_fmu_parameters(values: dict[str, float]) -> tuple[Soil, Wheel]:
    """The inverse of fmu_parameters (the paper's values for what ``values`` leaves out)."""
    modelica = {v: k for k, v in MODELICA_NAMES.items()}
    soil = {modelica.get(k[5:], k[5:]): v for k, v in values.items() if k.startswith("soil.")}
    if soil.get("xc") == 0:  # the FMUs' "from phi" (45 deg - phi/2), Soil's XC_FROM_PHI
        del soil["xc"]
    wheel = {modelica.get(k[6:], k[6:]): v for k, v in values.items() if k.startswith("wheel.")}
    return Soil(**soil), Wheel(**wheel)


def soil_label(choice: Choice) -> str:
    """"soil NAME, wheel NAME[, rover NAME] (changes)": how figures and pages name a Choice (the
    rover where it is not the paper's)."""
    return (f"soil {choice.soil_name}, wheel {choice.wheel_name}"
            + (f", rover {choice.rover_name}" if choice.rover_name != DEFAULT else "")
            + (f" ({', '.join(choice.overrides)})" if choice.overrides else ""))


def describe(choice: Choice) -> dict[str, Any]:
    """What a results folder records: names, titles, sources and every value (SI)."""
    return {"soil": {"name": choice.soil_name, "title": choice.soil_entry.get("title"),
                     "source": choice.soil_entry.get("source"), "values": asdict(choice.soil),
                     "phi_deg": math.degrees(choice.soil.phi)},
            "wheel": {"name": choice.wheel_name, "title": choice.wheel_entry.get("title"),
                      "source": choice.wheel_entry.get("source"), "values": asdict(choice.wheel)},
            "rover": {"name": choice.rover_name, "title": choice.rover_entry.get("title"),
                      "source": choice.rover_entry.get("source"),
                      "values": {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(choice.rover).items()},
                      "wheels": choice.rover.wheels},
            "set": list(choice.overrides)}
