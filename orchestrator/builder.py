"""Building a :class:`~rover_cosim.orchestrator.model.System` in code, checked as it is built.

```python
from rover_cosim.orchestrator import SystemBuilder, run
from rover_cosim.orchestrator.blocks import Constant

system = (SystemBuilder("one wheel")
          .simulation(stop_time=2.0, step=1e-3, algorithm="jacobi")
          .add_fmu("wheel", "fmus/SingleWheel.fmu", parameters={"W": 424.0})
          .add_block("torque", Constant("torque", 20.0, unit="N.m"))
          .connect("torque.y", "wheel.tau")
          .record("wheel.slip", "wheel.Fx")
          .build())
result = run(system)
```

Every problem is a :class:`SystemFileError` naming the system and the call (or, for a system
file, the entry: the TOML reader in ``system`` passes its own labels): an unknown instance or
variable, a parameter that is not one, a connection not from an output to an input, a unit
mismatch, an input connected twice or left undriven, an algebraic loop an explicit master cannot
run.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import zipfile
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import fmpy
from fmpy.model_description import ValidationError

from rover_cosim.common.units import base_units

from .algorithms import ALGORITHMS
from .blocks import BLOCK_TYPES, Block, make_block
from .loops import describe, find_loop
from .model import (
    ISOLATION,
    VALIDATION,
    VARIABLE_TYPES,
    BlockEntry,
    Connection,
    FmuEntry,
    Iteration,
    Port,
    System,
    SystemFileError,
    Value,
    compatible_types,
    elements_of,
    typed_value,
)

#: Instance names: identifiers, so that a name is never a path or a port separator.
IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
#: The simulation settings and their defaults (stop_time and step have none).
SIMULATION_DEFAULTS: dict[str, Any] = {"start_time": 0.0, "algorithm": "gauss-seidel", "order": None,
                                       "allow_algebraic_loops": False, "threads": None, "native": True,
                                       "relative_tolerance": 1e-6, "output_interval": None, "fmu_timeout": None}
ITERATION_KEYS = ("tolerance", "max_iterations", "relaxation")
#: Limits a run is checked against before anything is allocated: the communication steps of a
#: run, the bytes of its recorded rows, the threads stepping FMUs, the largest time [s].
MAX_STEPS = 100_000_000
MAX_RECORD_BYTES = 8 * 2**30
MAX_THREADS = 256
MAX_TIME = 1e12
#: The longest instance name (it names a folder).
MAX_NAME = 100


def number(value: Any, where: str) -> float:
    """``value`` as a float; SystemFileError (``where``: its label, with the system's name) for
    anything that is not a real number."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SystemFileError(f"{where}: {value!r}: expected a number")
    return float(value)


def parse_port(text: Any, where: str) -> Port:
    """``"instance.variable"`` (or a Port) as a Port."""
    if isinstance(text, Port):
        return text
    if not isinstance(text, str) or "." not in text:
        raise SystemFileError(f"{where}: {text!r}: expected \"instance.variable\"")
    return Port.parse(text)


def recordable(variable: Any) -> bool:
    """Whether an FMU's variable can be recorded: a scalar of a type that travels (not an FMI 3.0
    array, Binary or Clock), not the independent variable (time, recorded anyway)."""
    return (not getattr(variable, "dimensions", None) and variable.type not in ("Binary", "Clock")
            and variable.causality != "independent")


def read_fmu(fmu_path: Path, where: str, validation: str = "strict") -> tuple[Any, tuple[str, ...]]:
    """The model description of an FMI 2.0 or 3.0 FMU file with a Co-Simulation or Model
    Exchange interface (``where``: the label of messages), and what FMPy's validation found wrong
    with it where ``validation`` (``VALIDATION``) lets it run all the same; SystemFileError for
    anything else."""
    try:
        found = fmu_path.is_file()
    except OSError as error:  # a name too long, a path through a file
        raise SystemFileError(f"{where}: FMU file {str(fmu_path)[:200]!r}: not a usable path "
                              f"({error.strerror})") from None
    if not found:
        raise SystemFileError(f"{where}: FMU file {fmu_path} not found (build them with `rover-cosim build-fmus`)")
    description, problems = _description(fmu_path, where, validation)
    version = str(description.fmiVersion)
    if version.split(".")[0] not in ("2", "3"):
        raise SystemFileError(f"{where}: {fmu_path.name} is an FMI {version} FMU: expected FMI 2.0 or 3.0")
    if description.coSimulation is None and description.modelExchange is None:
        raise SystemFileError(f"{where}: {fmu_path.name} has neither a Co-Simulation nor a Model Exchange interface "
                              "(Scheduled Execution FMUs are not supported)")
    clocks = [v.name for v in description.modelVariables if v.type == "Clock"]
    if clocks:
        raise SystemFileError(f"{where}: {fmu_path.name} has clocks ({', '.join(clocks[:3])}): FMI 3.0 clocks and "
                              "clocked variables are not supported")
    return description, problems


#: Model descriptions read, by the FMU file (its path, inode, modification time and size) and the
#: validation: a job builds many systems of one FMU (the leg-wheel scenarios read LegWheelRover's
#: 2,183 variables nine times), and a Monte Carlo study one per run. The descriptions are not
#: changed by their readers.
_READ: dict[tuple[Any, ...], tuple[Any, tuple[str, ...]]] = {}
_READ_KEPT = 64


def _description(fmu_path: Path, where: str, validation: str) -> tuple[Any, tuple[str, ...]]:
    """FMPy's reading of the model description, checked as ``validation`` says (``read_fmu``);
    read once per version of the file."""
    if validation not in VALIDATION:
        raise SystemFileError(f"{where}: validation = {validation!r}: expected one of {', '.join(VALIDATION)}")
    status = fmu_path.stat()
    key = (str(fmu_path.resolve()), status.st_ino, status.st_mtime_ns, status.st_size, validation)
    if key not in _READ:
        if len(_READ) >= _READ_KEPT:
            _READ.pop(next(iter(_READ)))
        _READ[key] = _read_description(fmu_path, where, validation)
    return _READ[key]


def _read_description(fmu_path: Path, where: str, validation: str) -> tuple[Any, tuple[str, ...]]:
    problem = _structure_problem(fmu_path)
    if problem:  # FMPy reads index 0 as the last variable, and fails on one past the end with "list index ..."
        raise SystemFileError(f"{where}: {fmu_path.name}: its modelDescription.xml: {problem}")
    try:
        try:
            return fmpy.read_model_description(str(fmu_path)), ()
        except ValidationError as invalid:
            problems = tuple(str(p) for p in invalid.problems)
            if validation == "strict":
                shown = "; ".join(problems[:3]) + (f" (and {len(problems) - 3} more)" if len(problems) > 3 else "")
                raise SystemFileError(f"{where}: {fmu_path.name}: its modelDescription.xml fails FMPy's validation: "
                                      f"{shown}; --validate warn runs it as FMPy does with validate=False") from None
            return fmpy.read_model_description(str(fmu_path), validate=False), problems
    except SystemFileError:
        raise
    except Exception as failure:  # noqa: BLE001 - fmpy raises many kinds
        raise SystemFileError(f"{where}: {fmu_path} is not a readable FMU: {failure}") from None


def _structure_problem(fmu_path: Path) -> str | None:
    """What is wrong with the variable indices of an FMI 2.0 ModelStructure (each Unknown's index
    and dependencies are 1-based places among the ScalarVariables), or None (also for FMI 3.0,
    which names value references, and for an archive FMPy will say is unreadable)."""
    from lxml import etree

    try:
        with zipfile.ZipFile(fmu_path) as archive:
            root = etree.fromstring(archive.read("modelDescription.xml"), etree.XMLParser(resolve_entities=False,
                                                                                          huge_tree=False))
    except Exception:  # noqa: BLE001 - unreadable: FMPy's reading says how
        return None
    if not str(root.get("fmiVersion", "")).startswith("2"):
        return None
    count = len(root.findall("ModelVariables/ScalarVariable"))
    for unknown in root.iterfind("ModelStructure/*/Unknown"):
        section = unknown.getparent().tag
        for attribute in ("index", "dependencies"):
            given = unknown.get(attribute, "") if attribute == "dependencies" else unknown.get("index")
            for text in str(given).split():
                if not text.isdigit() or not 1 <= int(text) <= count:
                    return (f"<Unknown {attribute}=\"{unknown.get(attribute)}\"> in {section}: expected "
                            f"{'indices' if attribute == 'dependencies' else 'an index'} from 1 to {count} (1-based "
                            "places among its ScalarVariables)")
    return None


def interfaces_of(description: Any) -> list[str]:
    """The interfaces an FMU offers (``INTERFACES`` order: Co-Simulation first)."""
    return [name for name, section in (("co-simulation", description.coSimulation),
                                       ("model-exchange", description.modelExchange)) if section is not None]


def _check_binary(fmu_path: Path, identifier: str, version: int, where: str) -> None:
    """SystemFileError unless the FMU has a binary for this platform, naming the ones it has."""
    folder = fmpy.platform if version == 2 else fmpy.platform_tuple
    wanted = f"binaries/{folder}/{identifier}{fmpy.sharedLibraryExtension}"
    with zipfile.ZipFile(fmu_path) as archive:
        names = archive.namelist()
    if wanted in names:
        return
    libraries = {f"{identifier}{extension}" for extension in (".so", ".dll", ".dylib")}
    platforms = sorted({n.split("/")[1] for n in names if n.startswith("binaries/") and n.count("/") == 2
                        and n.split("/")[2] in libraries})
    sources = any(n.startswith("sources/") and n.endswith(".c") for n in names)
    has = ", ".join(platforms) if platforms else "none"
    raise SystemFileError(f"{where}: {fmu_path.name} has no binary for this platform ({wanted}); the platform "
                          f"folders holding a binary of {identifier}: {has}"
                          + ("; it ships C sources, which `fmpy compile` can build" if sources else ""))


def optional_inputs(fmu_path: Path, description: Any = None) -> set[str]:
    """Inputs that keep their start value when left unconnected: for an FMU built by rover-cosim
    those its build record (documentation/build.json) declares optional (its other inputs are
    couplings a system must make); for any other FMU every input whose model description declares
    a start value (FMI 2.0 gives every input one), as FMPy and libcosim treat them."""
    try:
        with zipfile.ZipFile(fmu_path) as archive:
            return set(json.loads(archive.read("documentation/build.json")).get("optional_inputs", []))
    except KeyError:  # not built by rover-cosim
        variables = description.modelVariables if description is not None else []
        return {v.name for v in variables if v.causality == "input" and v.start is not None}
    except (OSError, ValueError, zipfile.BadZipFile):
        return set()


def block_port_type(block: Block, variable: str) -> str:
    """The FMI type of a block's port: Real, unless the block's optional ``types`` name another."""
    return str(getattr(block, "types", {}).get(variable, "Real"))


def dependency_graph(fmus: list[FmuEntry], blocks: list[BlockEntry],
                     connections: list[Connection]) -> dict[Port, list[Port]]:
    """port -> the ports that depend on it directly: connections, and each participant's outputs
    on its inputs (FMUs: ModelStructure, an output without a dependency list on every input;
    blocks: their ``feedthrough``, True by default for a block with inputs)."""
    graph: dict[Port, list[Port]] = {}
    for connection in connections:
        graph.setdefault(connection.source, []).append(connection.target)
    for fmu in fmus:
        inputs = [v.name for v in fmu.description.modelVariables if v.causality == "input"]
        for unknown in fmu.description.outputs:
            sources = inputs if unknown.dependencies is None else [d.name for d in unknown.dependencies
                                                                   if d.causality == "input"]
            for name in sources:
                graph.setdefault(Port(fmu.name, name), []).append(Port(fmu.name, unknown.variable.name))
    for entry in blocks:
        block = entry.block
        if getattr(block, "feedthrough", bool(block.inputs)):
            for name in block.inputs:
                graph.setdefault(Port(entry.name, name), []).extend(Port(entry.name, o) for o in block.outputs)
    return graph


@dataclass
class _Settings:
    """The simulation settings being built, with the label their messages use."""

    values: dict[str, Any]
    iteration: dict[str, Any]
    where: str = "simulation"


class SystemBuilder:
    """A system built call by call, each call checked against what is there (see the module
    docstring). ``name`` names the system in messages; relative FMU paths start at ``base``
    (default: the working folder). Methods return the builder, so calls chain."""

    def __init__(self, name: str = "system", *, base: Path | None = None, path: Path | None = None,
                 validation: str = "strict"):
        self.name = name
        #: How the FMUs' model descriptions are checked (``VALIDATION``)
        self.validation = validation
        self.base = Path(base) if base is not None else None
        self.path = path
        self._settings = _Settings(dict(SIMULATION_DEFAULTS), {})
        self._fmus: dict[str, FmuEntry] = {}
        self._blocks: dict[str, BlockEntry] = {}
        self._where: dict[str, str] = {}      # instance -> the label of the call that added it
        self._claimed: set[str] = set()
        self._connections: list[Connection] = []
        self._driven: dict[Port, str] = {}     # input -> the label of the connection driving it
        self._record: list[Port] | None = None
        self._settings_from: dict[str, str] = {}
        self._given: set[str] = set()  # the settings given (not defaults)

    # --- messages -------------------------------------------------------------------------------
    def error(self, where: str, message: str) -> SystemFileError:
        return SystemFileError(f"{self.name}: {where}: {message}")

    def _number(self, value: Any, where: str) -> float:
        return number(value, f"{self.name}: {where}")

    # --- settings -------------------------------------------------------------------------------
    def simulation(self, *, where: str | None = None, **settings: Any) -> SystemBuilder:
        """Set simulation settings (the others keep their values): ``stop_time``, ``step``,
        ``start_time`` [s]; ``algorithm`` (jacobi, gauss-seidel, iterative); ``order`` (instance
        names, Gauss-Seidel order; default: sources, FMUs, other blocks; the sources step last in
        any order); ``tolerance``,
        ``max_iterations``, ``relaxation`` (iterative only); ``allow_algebraic_loops``;
        ``threads`` (FMUs stepped at the same time; None: the cores); ``native`` (FMUs stepped from C);
        ``relative_tolerance`` (of the integrator of Model Exchange FMUs, and told to every FMU);
        ``output_interval`` [s] (rows recorded every so often, a whole number of steps; default: every step)."""
        if where is not None:
            self._settings.where = where
        accepted = {"stop_time", "step", *SIMULATION_DEFAULTS, *ITERATION_KEYS}
        unknown = set(settings) - accepted
        if unknown:
            raise self.error(self._settings.where, f"unknown setting(s) {sorted(unknown)}; expected {sorted(accepted)}")
        for key, value in settings.items():
            (self._settings.iteration if key in ITERATION_KEYS else self._settings.values)[key] = value
            self._given.add(key)
        self._check_times()
        self._check_switches()
        return self

    def _check_times(self) -> None:
        values, where = self._settings.values, self._settings.where
        if "step" not in values or "stop_time" not in values:
            return  # checked once both are there (build() says which is missing)
        start_time = self._number(values["start_time"], f"{where} start_time")
        stop_time = self._number(values["stop_time"], f"{where} stop_time")
        step = self._number(values["step"], f"{where} step")
        for key, value in (("start_time", start_time), ("stop_time", stop_time), ("step", step)):
            if not math.isfinite(value) or abs(value) > MAX_TIME:
                raise self.error(f"{where} {key}", f"{value!r}: expected a finite time within ±{MAX_TIME:g} s")
        if not step > 0:
            raise self.error(f"{where} step", f"{step!r}: expected a communication step > 0 s")
        if not stop_time > start_time:
            raise self.error(f"{where} stop_time", f"{stop_time!r}: expected a stop time > start time {start_time} s")
        if step > stop_time - start_time:
            raise self.error(f"{where} step", f"{step!r} s is longer than the run ({stop_time - start_time!r} s)")
        steps = (stop_time - start_time) / step
        if steps > MAX_STEPS:
            raise self.error(f"{where} step", f"{step!r} s makes {steps:.3g} communication steps of a "
                             f"{stop_time - start_time!r} s run: more than the {MAX_STEPS:,} a run may take "
                             "(a larger step, or a shorter run)")
        self._check_interval(values.get("output_interval"), stop_time - start_time, step)

    def _check_interval(self, interval: Any, length: float, step: float) -> None:
        """output_interval: a whole number of steps [s] within the run's ``length`` [s]."""
        where = self._settings.where
        if interval is None:
            return
        interval = self._number(interval, f"{where} output_interval")
        if not 0 < interval <= length:
            raise self.error(f"{where} output_interval", f"{interval!r}: expected an interval > 0 s and at most "
                             f"the run's length ({length!r} s)")
        multiple = interval / step
        if abs(multiple - round(multiple)) > 1e-9 * max(1.0, multiple) or round(multiple) < 1:
            raise self.error(f"{where} output_interval", f"{interval!r}: expected a whole number of communication "
                             f"steps ({step!r} s) > 0")

    def _check_switches(self) -> None:
        values, where = self._settings.values, self._settings.where
        if not isinstance(values["algorithm"], str) or values["algorithm"] not in ALGORITHMS:
            raise self.error(f"{where} algorithm", f"{values['algorithm']!r}: expected one of {', '.join(ALGORITHMS)}")
        self._iteration()
        allow = values["allow_algebraic_loops"]
        if not isinstance(allow, bool):
            raise self.error(f"{where} allow_algebraic_loops", f"{allow!r}: expected true or false")
        threads = values["threads"]
        if threads is not None and (isinstance(threads, bool) or not isinstance(threads, int)
                                    or not 1 <= threads <= MAX_THREADS):
            raise self.error(f"{where} threads", f"{threads!r}: expected a whole number from 1 to {MAX_THREADS} "
                             "(FMUs stepped at the same time)")
        tolerance = self._number(values["relative_tolerance"], f"{where} relative_tolerance")
        if not 0 < tolerance < 1:
            raise self.error(f"{where} relative_tolerance", f"{tolerance!r}: expected 0 < relative_tolerance < 1 "
                             "(of the integrator of Model Exchange FMUs)")
        if not isinstance(values["native"], bool):
            raise self.error(f"{where} native", f"{values['native']!r}: expected true or false (FMUs stepped from C)")
        timeout = values["fmu_timeout"]
        if timeout is not None and not 0 < self._number(timeout, f"{where} fmu_timeout") <= MAX_TIME:
            raise self.error(f"{where} fmu_timeout", f"{timeout!r}: expected a time limit > 0 s (and at most "
                             f"{MAX_TIME:g} s) for one call of an FMU run in a child process")

    def _iteration(self) -> Iteration:
        given, algorithm, where = self._settings.iteration, self._settings.values["algorithm"], self._settings.where
        if given and algorithm != "iterative":
            raise self.error(where, f"{', '.join(sorted(given))} only apply to algorithm = \"iterative\" "
                             f"(this system uses {algorithm!r})")
        default = Iteration()
        tolerance = self._number(given.get("tolerance", default.tolerance), f"{where} tolerance")
        relaxation = self._number(given.get("relaxation", default.relaxation), f"{where} relaxation")
        bound = given.get("max_iterations", default.max_iterations)
        if not tolerance > 0:
            raise self.error(f"{where} tolerance", f"{tolerance!r}: expected > 0")
        if not 0 < relaxation <= 1:
            raise self.error(f"{where} relaxation", f"{relaxation!r}: expected 0 < relaxation <= 1")
        if isinstance(bound, bool) or not isinstance(bound, int) or bound < 1:
            raise self.error(f"{where} max_iterations", f"{bound!r}: expected a whole number >= 1")
        return Iteration(tolerance, bound, relaxation)

    # --- components -----------------------------------------------------------------------------
    def claim(self, instance: Any, where: str) -> str:
        """Reserve the instance name ``instance`` (an identifier used once)."""
        if not isinstance(instance, str) or not IDENTIFIER.fullmatch(instance) or len(instance) > MAX_NAME:
            shown = instance if not isinstance(instance, str) or len(instance) <= 80 else instance[:60] + "..."
            raise self.error(where, f"name = {shown!r}: expected an identifier of at most {MAX_NAME} characters "
                             "(letters, digits and _, not starting with a digit; it names the instance and its folder)")
        if instance in self._claimed:
            raise self.error(where, f"name {instance!r} is used twice")
        self._claimed.add(instance)
        return instance

    def _claim_for(self, name: str, where: str) -> None:
        if name not in self._claimed or name in self._where:
            self.claim(name, where)

    def add_fmu(self, name: str, path: str | Path, *, parameters: Mapping[str, Any] | None = None,
                start: Mapping[str, Any] | None = None, interface: str | None = None,
                isolation: str = "auto", where: str | None = None) -> SystemBuilder:
        """An FMU instance ``name`` of the FMU file ``path`` (relative: to the builder's base), with
        parameter values and start values (inputs, and states with an exact start) by variable name.
        ``interface``: "co-simulation" or "model-exchange" (the engine integrates it); default
        Co-Simulation where the FMU offers it, else Model Exchange. ``isolation``: where it runs
        (``ISOLATION``: "auto", "process": a child process of its own, "none": this process)."""
        where = where or f"add_fmu({name!r})"
        if isolation not in ISOLATION:
            raise self.error(f"{where} isolation", f"{isolation!r}: expected one of {', '.join(ISOLATION)}")
        self._claim_for(name, where)
        if not isinstance(path, (str, Path)):
            raise self.error(where, f"path = {path!r}: expected a file name")
        fmu_path = Path(path)
        if not fmu_path.is_absolute() and self.base is not None:
            fmu_path = self.base / fmu_path
        description, problems = read_fmu(fmu_path, f"{self.name}: {where}", self.validation)
        offered = interfaces_of(description)
        chosen = offered[0] if interface is None else interface
        if chosen not in offered:
            raise self.error(f"{where} interface", f"{interface!r}: expected one that {fmu_path.name} offers: "
                             f"{', '.join(offered)}")
        entry = FmuEntry(name, fmu_path, {}, {}, description, chosen, self.validation, problems, isolation)
        _check_binary(fmu_path, entry.capabilities.modelIdentifier, entry.fmi_version, f"{self.name}: {where}")
        self._fmus[name] = entry
        self._where[name] = where
        self.set_parameters(name, parameters or {}, where=where)
        self.set_start(name, start or {}, where=where)
        return self

    def _values(self, instance: str, key: str, values: Mapping[str, Any], where: str | None) -> dict[str, Value]:
        if instance not in self._fmus:
            raise self.error(where or f"set_{key}({instance!r})", f"no FMU {instance!r}; expected one of "
                             f"{', '.join(self._fmus) or '(none yet)'}")
        fmu = self._fmus[instance]
        where = where or self._where[instance]
        if not isinstance(values, Mapping):
            raise self.error(f"{where} {key}", "expected a table, e.g. { \"name\" = 1.0 }")
        variables = fmu.variables()
        checked: dict[str, Value] = {}
        for variable, value in values.items():
            variable, value = self._degrees(variable, value, variables, f"{where} {key}")
            if variable not in variables:
                raise self.error(f"{where} {key}", f"{fmu.name} has no variable {variable!r}")
            v = variables[variable]
            self._scalar(fmu, v, f"{where} {key}")
            if key == "parameters" and v.causality != "parameter":
                raise self.error(f"{where} parameters", f"{fmu.name}.{variable} is not a parameter "
                                 f"(causality {v.causality}); inputs and states go under start")
            if key == "start" and not (v.causality == "input" or v.initial in ("exact", "approx")):
                raise self.error(f"{where} start", f"{fmu.name}.{variable} cannot be given a start value "
                                 f"(causality {v.causality}, initial {v.initial})")
            if v.variability == "constant":
                raise self.error(f"{where} {key}", f"{fmu.name}.{variable} is a constant (variability constant): "
                                 "it cannot be given a value")
            try:
                checked[variable] = typed_value(value, v.type)
            except ValueError as problem:
                raise self.error(f"{where} {key} {variable}", str(problem)) from None
        return checked

    def _scalar(self, fmu: FmuEntry, variable: Any, where: str) -> None:
        """SystemFileError for an array variable (FMI 3.0 dimensions) or a type that cannot travel."""
        if getattr(variable, "dimensions", None):
            elements = elements_of(variable)
            if elements:
                raise self.error(where, f"{fmu.name}.{variable.name} is an array (FMI 3.0 dimensions): name its "
                                 f"elements, {elements[0].name} ... {elements[-1].name}")
            raise self.error(where, f"{fmu.name}.{variable.name} is an array (FMI 3.0 dimensions): array variables "
                             "are not supported (scalar variables are)")
        if variable.type in ("Binary", "Clock"):
            raise self.error(where, f"{fmu.name}.{variable.name} is a {variable.type}: FMI 3.0 Binary and Clock "
                             "variables are not supported")

    def _degrees(self, variable: str, value: Any, variables: Mapping[str, Any], where: str) -> tuple[str, Any]:
        """``NAME_deg`` of an angle variable NAME in rad, as --set takes it (soil.phi_deg = 35):
        (NAME, the value in rad); any other (variable, value) as it is."""
        base = variable[:-4] if variable.endswith("_deg") else ""
        if variable in variables or base not in variables or variables[base].unit != "rad":
            return variable, value
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(f"{where} {variable}", f"{value!r}: expected a number of degrees")
        return base, math.radians(value)

    def set_parameters(self, instance: str, values: Mapping[str, Any], *, where: str | None = None,
                       only_known: bool = False) -> SystemBuilder:
        """Parameter values of the FMU ``instance`` (they override those given before);
        ``only_known``: those of ``values`` the FMU has as parameters (a soil to each wheel, none
        to a body), else every name must be one."""
        if only_known:
            names = self.parameter_names(instance)
            values = {k: v for k, v in values.items() if k in names}
        self._fmus_entry(instance, where).parameters.update(self._values(instance, "parameters", values, where))
        return self

    def set_start(self, instance: str, values: Mapping[str, Any], *, where: str | None = None) -> SystemBuilder:
        """Start values of the FMU ``instance``'s inputs (and states with an exact start)."""
        self._fmus_entry(instance, where).start.update(self._values(instance, "start", values, where))
        return self

    def _fmus_entry(self, instance: str, where: str | None) -> FmuEntry:
        if instance not in self._fmus:
            raise self.error(where or f"FMU {instance!r}", f"no FMU {instance!r}; expected one of "
                             f"{', '.join(self._fmus) or '(none yet)'}")
        return self._fmus[instance]

    def parameter_names(self, instance: str) -> set[str]:
        """The parameters the FMU ``instance`` has (to give it only those of a set it has)."""
        return {v.name for v in self._fmus_entry(instance, None).description.modelVariables
                if v.causality == "parameter"}

    def setting_from(self, key: str, origin: str) -> SystemBuilder:
        """Say where the setting ``key`` came from (the run record's ``settings_from``)."""
        self._settings_from[key] = origin
        return self

    def fmu_entry(self, instance: str) -> FmuEntry:
        """The FMU component ``instance`` as built so far."""
        return self._fmus_entry(instance, None)

    def fmu_names(self) -> list[str]:
        return list(self._fmus)

    def add_block(self, name: str, block: Block | str, *, kind: str | None = None, keys: dict[str, Any] | None = None,
                  where: str | None = None) -> SystemBuilder:
        """A Python block ``name``: any object with the block interface (``blocks``), or a factory
        ``"module:callable"`` called with ``name`` and the ``keys`` (the module looked up in the
        builder's base folder first, else the current folder), as a system file's ``type = "python"``
        block; the system then keeps the factory, so that a system file or SSP archive of it names it. ``kind`` and
        ``keys`` of an object: the block type and keys it was made from, when it came from a file."""
        where = where or f"add_block({name!r})"
        if isinstance(block, str):
            keys, kind = {"factory": block, **(keys or {})}, "python"
            try:
                block = make_block(name, kind, keys, self.base if self.base is not None else Path.cwd())
            except ValueError as failure:
                raise self.error(where, str(failure)) from None
        self._claim_for(name, where)
        for attribute in ("inputs", "outputs", "start", "step"):
            if not hasattr(block, attribute):
                raise self.error(where, f"{block!r} is not a block: it has no {attribute!r}")
        if not hasattr(block, "units"):
            setattr(block, "units", {})  # noqa: B010 - the protocol reads it as a property
        for variable, kind_of in getattr(block, "types", {}).items():
            if kind_of not in VARIABLE_TYPES or kind_of == "String":
                raise self.error(where, f"types {variable} = {kind_of!r}: expected a number or Boolean type "
                                 f"({', '.join(k for k in VARIABLE_TYPES if k != 'String')})")
        unknown = [v for v in getattr(block, "ramped_outputs", ()) if v not in block.outputs]
        if unknown:
            raise self.error(where, f"ramped_outputs {unknown}: not outputs of the block (outputs "
                             f"{list(block.outputs)})")
        if kind is None:
            kind = next((k for k, cls in BLOCK_TYPES.items() if type(block) is cls), "python")
        self._blocks[name] = BlockEntry(name, kind, block, keys)
        self._where[name] = where
        return self

    # --- connections and recording --------------------------------------------------------------
    def _lookup(self, port: Port, where: str) -> tuple[str, str | None]:
        """(causality, unit) of ``port``; errors for unknown instances and variables."""
        if port.instance in self._fmus:
            fmu = self._fmus[port.instance]
            variables = fmu.variables()
            if port.variable not in variables:
                raise self.error(where, f"{fmu.name} ({fmu.path.name}) has no variable {port.variable!r}")
            v = variables[port.variable]
            self._scalar(fmu, v, where)
            return v.causality, v.unit if v.type in ("Real", "Float64", "Float32") else None
        if port.instance not in self._blocks:
            names = sorted([*self._fmus, *self._blocks])
            raise self.error(where, f"no instance {port.instance!r}; expected one of {', '.join(names)}")
        block = self._blocks[port.instance].block
        if port.variable in block.inputs:
            return "input", block.units.get(port.variable)
        if port.variable in block.outputs:
            return "output", block.units.get(port.variable)
        raise self.error(where, f"block {port.instance} has no variable {port.variable!r} "
                         f"(inputs {list(block.inputs)}, outputs {list(block.outputs)})")

    def _type(self, port: Port) -> str:
        """The FMI type of ``port`` (a block's ports are Real unless its ``types`` say otherwise)."""
        if port.instance in self._fmus:
            return self._fmus[port.instance].variable_type(port.variable)
        return block_port_type(self._blocks[port.instance].block, port.variable)

    def connect(self, source: str | Port, target: str | Port, *, where: str | None = None,
                label: str | None = None) -> SystemBuilder:
        """A connection from the output ``source`` to the input ``target`` (``"instance.variable"``),
        of the same unit; each input is driven once."""
        where = where or f"connect({str(source)!r}, {str(target)!r})"
        number_ = len(self._connections) + 1
        label = label or f"connection {number_}"
        source_port = parse_port(source, f"{self.name}: {where} from")
        target_port = parse_port(target, f"{self.name}: {where} to")
        source_causality, source_unit = self._lookup(source_port, where)
        target_causality, target_unit = self._lookup(target_port, where)
        if source_causality != "output":
            raise self.error(where, f"{source_port} is not an output (causality {source_causality}); "
                             "a connection goes from an output to an input")
        if target_causality != "input":
            raise self.error(where, f"{target_port} is not an input (causality {target_causality}); "
                             "a connection goes from an output to an input")
        source_type, target_type = self._type(source_port), self._type(target_port)
        if not compatible_types(source_type, target_type):
            raise self.error(where, f"type mismatch: {source_port} is {source_type}, {target_port} is {target_type} "
                             "(a connection joins variables of the same type; Integer and Enumeration may meet)")
        if source_unit is not None and target_unit is not None:
            try:
                same = base_units(source_unit) == base_units(target_unit)
            except ValueError as problem:
                raise self.error(where, str(problem)) from None
            if not same:
                raise self.error(where, f"unit mismatch: {source_port} is in {source_unit}, {target_port} in "
                                 f"{target_unit}")
        if target_port in self._driven:
            raise self.error(where, f"input {target_port} is connected twice (also by {self._driven[target_port]})")
        self._driven[target_port] = label
        self._connections.append(Connection(number_, source_port, target_port))
        return self

    def record(self, *ports: str | Port, where: str | None = None, replace: bool = False) -> SystemBuilder:
        """Record these ports (in addition to those recorded before, unless ``replace``); without
        any call to record, every output of every participant is recorded. A port may be a glob
        pattern (``"model.*"``, ``"wheel?.F[xz]"``): every variable it matches that can be recorded
        (of an FMU: any causality, locals too; of a block: its inputs and outputs), in the order of
        the instances and their variables; a pattern that matches none is an error naming it."""
        where = where or "record"
        recorded = self._record if self._record is not None and not replace else []
        seen = set(recorded)
        for text in ports:
            matched = self._matching(text, where) if isinstance(text, str) and self._pattern(text) else None
            for port in matched if matched is not None else [parse_port(text, f"{self.name}: {where}")]:
                self._lookup(port, f"{where} {str(text)!r}")
                if port not in seen:
                    seen.add(port)
                    recorded.append(port)
        self._record = recorded
        return self

    def _pattern(self, text: str | Port) -> bool:
        """Whether ``text`` is a glob pattern rather than a port (an array element's name,
        ``y[1]``, is a port)."""
        if not isinstance(text, str) or not set("*?[") & set(text) or "." not in text:
            return False
        port = Port.parse(text)
        if port.instance in self._fmus:
            return port.variable not in self._fmus[port.instance].variables()
        return not (port.instance in self._blocks and port.variable in (*self._blocks[port.instance].block.inputs,
                                                                         *self._blocks[port.instance].block.outputs))

    def _matching(self, pattern: str, where: str) -> list[Port]:
        """The ports a glob ``pattern`` ("instance.variable", either part a pattern) matches."""
        from fnmatch import fnmatchcase

        instance, dot, variable = pattern.partition(".")
        if not dot:
            raise self.error(where, f"{pattern!r}: expected \"instance.variable\" (either may be a glob pattern)")
        found: list[Port] = []
        for name, fmu in self._fmus.items():
            if fnmatchcase(name, instance):
                found += [Port(name, v.name) for v in fmu.variables().values()
                          if fnmatchcase(v.name, variable) and recordable(v)]
        for name, entry in self._blocks.items():
            if fnmatchcase(name, instance):
                ports = (*entry.block.inputs, *entry.block.outputs)
                found += [Port(name, v) for v in ports if fnmatchcase(v, variable)]
        if not found:
            raise self.error(where, f"{pattern!r} matches no variable that can be recorded (instances: "
                             f"{', '.join([*self._fmus, *self._blocks])})")
        return found

    # --- the system -----------------------------------------------------------------------------
    def _check_inputs_driven(self) -> None:
        """Every FMU input connected or given a start value (unless the FMU's build record marks it
        optional: an input its Modelica source gives a default); every block input connected."""
        for fmu in self._fmus.values():
            optional = optional_inputs(fmu.path, fmu.description)
            for v in fmu.description.modelVariables:
                if (v.causality == "input" and Port(fmu.name, v.name) not in self._driven and v.name not in fmu.start
                        and v.name not in optional):
                    raise self.error(self._where[fmu.name], f"input {fmu.name}.{v.name} is neither connected nor "
                                     "given a value (connect it, or give it a start value)")
        for entry in self._blocks.values():
            for variable in entry.block.inputs:
                if Port(entry.name, variable) not in self._driven:
                    raise self.error(self._where[entry.name], f"input {entry.name}.{variable} is not connected")

    def _default_experiment(self) -> None:
        """A start time, stop time or step the settings leave out, from the FMUs' DefaultExperiment:
        the latest start, the largest stop time and the smallest step (``settings_from`` says where
        each came from)."""
        values = self._settings.values
        for key, attribute, pick in (("start_time", "startTime", max), ("stop_time", "stopTime", max),
                                     ("step", "stepSize", min)):
            if key in values and (key != "start_time" or key in self._given):
                continue
            given = [(float(getattr(f.description.defaultExperiment, attribute)), f.name) for f in self._fmus.values()
                     if f.description.defaultExperiment is not None
                     and getattr(f.description.defaultExperiment, attribute) is not None]
            if given:
                value, name = pick(given)
                if key == "start_time" and value == values.get("start_time", 0.0):
                    continue  # the default start time: nothing taken from elsewhere
                values[key] = value
                self._settings_from[key] = f"DefaultExperiment {attribute} of {name} ({self._fmus[name].path.name})"
        self._check_times()

    def _check_capabilities(self) -> None:
        """What the FMUs declare they cannot do, against the settings: the iterative master
        restores states; a fixed-step FMU gets no shorter last step."""
        values = self._settings.values
        for fmu in self._fmus.values():
            capabilities = fmu.capabilities
            if values["algorithm"] == "iterative" and not capabilities.canGetAndSetFMUstate:
                raise self.error(self._where[fmu.name], f"{fmu.name} ({fmu.path.name}) cannot save and restore its "
                                 "state (canGetAndSetFMUstate is false), which the iterative master needs to repeat a "
                                 "step; use algorithm jacobi or gauss-seidel")
            steps = (float(values["stop_time"]) - float(values["start_time"])) / float(values["step"])
            fixed = fmu.interface == "co-simulation" and not capabilities.canHandleVariableCommunicationStepSize
            if fixed and abs(steps - round(steps)) > 1e-9 * max(1.0, steps):
                raise self.error(self._where[fmu.name], f"{fmu.name} ({fmu.path.name}) takes one fixed communication "
                                 "step (canHandleVariableCommunicationStepSize is false): the run must be a whole "
                                 f"number of steps, {steps:.6g} are not")

    def _order(self) -> list[str]:
        order, where = self._settings.values["order"], self._settings.where
        blocks = list(self._blocks.values())
        if order is None:  # (Gauss-Seidel steps the sources after the others whatever the order)
            return ([b.name for b in blocks if not b.block.inputs] + list(self._fmus)
                    + [b.name for b in blocks if b.block.inputs])
        names = sorted([*self._fmus, *self._blocks])
        if not isinstance(order, (list, tuple)) or sorted(map(str, order)) != names:
            raise self.error(f"{where} order", f"{order!r}: expected every instance once: {names}")
        return [str(name) for name in order]

    def _outputs(self, instance: str) -> list[Port]:
        """What is recorded by default: every output, an FMI 3.0 array as its elements (Binary and
        Clock variables are left out)."""
        if instance in self._fmus:
            return [Port(instance, v.name) for v in self._fmus[instance].variables().values()
                    if v.causality == "output" and recordable(v)]
        return [Port(instance, o) for o in self._blocks[instance].block.outputs]

    def _loop(self) -> list[Port] | None:
        values = self._settings.values
        loop = find_loop(dependency_graph(list(self._fmus.values()), list(self._blocks.values()), self._connections))
        if loop and values["algorithm"] != "iterative" and not values["allow_algebraic_loops"]:
            raise self.error("connections", f"algebraic loop (direct feedthrough all the way round): {describe(loop)}; "
                             "use algorithm = \"iterative\" to solve it, or allow_algebraic_loops = true in "
                             "the simulation settings to break it with a one-step delay in the order of the "
                             "participants")
        return loop

    def build(self) -> System:
        """The checked System (the builder can go on and build another)."""
        values, where = self._settings.values, self._settings.where
        self._default_experiment()
        for key in ("stop_time", "step"):
            if key not in values:
                raise self.error(where, f"{key} is missing (seconds; and no FMU has a DefaultExperiment that gives it)")
        if not self._fmus and not self._blocks:
            raise self.error("components", "the system has no FMU and no block")
        self._check_inputs_driven()
        self._check_capabilities()
        order = self._order()
        record = self._record if self._record is not None else [p for i in order for p in self._outputs(i)]
        rows = (float(values["stop_time"]) - float(values["start_time"])) / float(values["step"]) + 2
        if rows * max(1, len(record)) * 8 > MAX_RECORD_BYTES:
            raise self.error("record", f"{len(record)} recorded variables over {rows:.3g} communication points "
                             f"would take {rows * len(record) * 8 / 2**30:.3g} GiB: more than the "
                             f"{MAX_RECORD_BYTES / 2**30:g} GiB a run records (record fewer variables, or a larger "
                             "step)")
        iteration = self._iteration()
        loop = self._loop()
        return System(self.path, [_copy_fmu(f) for f in self._fmus.values()],
                      [BlockEntry(b.name, b.kind, b.block, b.keys) for b in self._blocks.values()],
                      list(self._connections), float(values["step"]), float(values["stop_time"]),
                      float(values["start_time"]), values["algorithm"], order, list(record), iteration, loop,
                      values["threads"], values["native"], values["allow_algebraic_loops"], self.name,
                      dict(self._settings_from), float(values["relative_tolerance"]),
                      None if values["output_interval"] is None else float(values["output_interval"]),
                      None if values["fmu_timeout"] is None else float(values["fmu_timeout"]))

    @classmethod
    def from_system(cls, system: System, name: str | None = None) -> SystemBuilder:
        """A builder holding ``system`` (its FMUs' descriptions are not read again): change it
        (``simulation``, ``set_parameters``, more components and connections) and build anew."""
        builder = cls(name or system.name, path=system.path)
        settings: dict[str, Any] = {"stop_time": system.stop_time, "step": system.step, "start_time": system.start_time,
                    "algorithm": system.algorithm, "order": list(system.order),
                    "allow_algebraic_loops": system.allow_algebraic_loops, "threads": system.threads_setting,
                    "native": system.native, "relative_tolerance": system.relative_tolerance,
                    "output_interval": system.output_interval, "fmu_timeout": system.fmu_timeout}
        if system.algorithm == "iterative":
            settings.update(tolerance=system.iteration.tolerance, max_iterations=system.iteration.max_iterations,
                            relaxation=system.iteration.relaxation)
        builder.simulation(**settings)
        for fmu in system.fmus:
            builder.claim(fmu.name, f"FMU {fmu.name!r}")
            builder._fmus[fmu.name] = _copy_fmu(fmu)
            builder._where[fmu.name] = f"FMU {fmu.name!r}"
        for entry in system.blocks:
            builder.add_block(entry.name, entry.block, kind=entry.kind, keys=entry.keys)
        for connection in system.connections:
            builder.connect(connection.source, connection.target)
        builder._record = list(system.record)
        return builder


def _copy_fmu(fmu: FmuEntry) -> FmuEntry:
    return FmuEntry(fmu.name, fmu.path, dict(fmu.parameters), dict(fmu.start), fmu.description, fmu.interface,
                    fmu.validation, fmu.problems, fmu.isolation)


def replace_settings(system: System, *, name: str | None = None, **settings: Any) -> System:
    """``system`` with other simulation settings (checked as when it was built: the step against
    the run, an algebraic loop against the algorithm)."""
    return SystemBuilder.from_system(system, name).simulation(**settings).build()


def with_isolation(system: System, isolation: str) -> System:
    """``system`` with every FMU run as ``isolation`` says (``ISOLATION``); ValueError for another word."""
    if isolation not in ISOLATION:
        raise ValueError(f"isolation {isolation!r}: expected one of {', '.join(ISOLATION)}")
    changed = replace_settings(system)
    changed.fmus = [dataclasses.replace(fmu, isolation=isolation) for fmu in changed.fmus]
    return changed


def with_parameters(system: System, values: Mapping[str, float], *, only_known: bool = True,
                    instances: Iterable[str] | None = None) -> System:
    """``system`` with parameter ``values`` given to its FMUs (``instances``: these only; default
    all). ``only_known``: each FMU gets those of the values it has as parameters (a soil to every
    wheel, none to the body); else every value must be a parameter of every FMU named."""
    builder = SystemBuilder.from_system(system)
    for instance in instances if instances is not None else builder.fmu_names():
        builder.set_parameters(instance, values, only_known=only_known)
    return builder.build()
