"""SSP 1.0 (System Structure and Parameterization) exchange of systems: export to an ``.ssp``
archive that FMPy, libcosim and OMSimulator read, and import of one back into a System.

The archive holds the FMUs (``resources/<file>.fmu``, each file once), ``SystemStructure.ssd``
(one system: a component per FMU instance with its connected, recorded and bound variables as
connectors with their units, the connections, the units in SI base units, the default experiment)
and each component's parameter and start values as a parameter set ``resources/<instance>.ssv``
bound to the component (variable names as in the FMU).

Blocks are Python and cannot travel in SSP. A constant block is folded into the start values of
the inputs it drives (exact). Any other block stays outside: each of its outputs becomes an input
connector of the system (``<block>_<output>``) wired to the FMU inputs it drove, each of its
inputs an output connector of the system; the block itself (type and keys) is kept in a
``org.rover-cosim`` annotation, so ``rover-cosim run system.ssp`` runs the whole system again,
while other tools see a system with inputs to drive. The master settings (step, algorithm,
recorded variables) go in the same annotation.
"""

from __future__ import annotations

import json
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lxml import etree

from rover_cosim.common.units import base_units

from .blocks import make_block
from .builder import SystemBuilder
from .model import BlockEntry, Connection, System, Value

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
ANNOTATION_TYPE = "org.rover-cosim"


class SspError(ValueError):
    """An SSP archive that cannot be written or read; the message names what and why."""


@dataclass
class Export:
    """What export_ssp wrote: the archive, and the blocks left outside as system connectors."""

    path: Path
    folded: list[str]        # constant blocks folded into start values
    external: list[str]      # blocks whose signals became system connectors


def _q(namespace: str, tag: str) -> str:
    return f"{{{namespace}}}{tag}"


#: The SSP element of each FMI type (an Enumeration travels as its number, an Integer).
SSP_TYPES = {"Real": "Real", "Integer": "Integer", "Enumeration": "Integer", "Boolean": "Boolean", "String": "String"}


def _connector(parent: etree._Element, name: str, kind: str, unit: str | None, variable_type: str = "Real") -> None:
    connector = etree.SubElement(parent, _q(SSD, "Connector"), name=name, kind=kind)
    typed = etree.SubElement(connector, _q(SSC, SSP_TYPES[variable_type]))
    if unit and variable_type == "Real":
        typed.set("unit", unit)


def _units(parent: etree._Element, units: set[str]) -> None:
    if not units:
        return
    element = etree.SubElement(parent, _q(SSD, "Units"))
    for unit in sorted(units):
        exponents, factor = base_units(unit)
        node = etree.SubElement(element, _q(SSC, "Unit"), name=unit)
        base = etree.SubElement(node, _q(SSC, "BaseUnit"), {k: str(v) for k, v in exponents.items()})
        if factor != 1.0:
            base.set("factor", repr(factor))


def _classify_blocks(system: System) -> tuple[dict[str, float], list[BlockEntry]]:
    """(constant block name -> value, for constants that drive FMU inputs only; the other blocks)."""
    fmus = {f.name for f in system.fmus}
    constants, external = {}, []
    for entry in system.blocks:
        targets = [c.target.instance for c in system.connections if c.source.instance == entry.name]
        if entry.kind == "constant" and all(t in fmus for t in targets):
            constants[entry.name] = float(entry.block.constant)  # type: ignore[attr-defined]
        else:
            external.append(entry)
    return constants, external


def export_ssp(system: System, out: Path) -> Export:
    """Write ``system`` as an SSP 1.0 archive ``out`` (written whole or not at all)."""
    out = Path(out)
    if out.suffix.lower() != ".ssp":
        raise SspError(f"output {out}: expected a .ssp file")
    writer = _SsdWriter(system)
    files = writer.files()
    for fmu in system.fmus:
        files[f"resources/{fmu.path.name}"] = fmu.path.read_bytes()
    _write_zip(out, files)
    return Export(out, sorted(writer.constants), sorted(writer.outside))


class _SsdWriter:
    """SystemStructure.ssd and the parameter sets of one System (see the module docstring)."""

    def __init__(self, system: System):
        self.system = system
        self.fmus = {f.name: f for f in system.fmus}
        self.constants, external = _classify_blocks(system)
        self.external = external
        self.outside = {e.name for e in external}
        self.units: set[str] = set()
        self.parameters: dict[str, list[tuple[str, Value, str | None]]] = {name: [] for name in self.fmus}
        self.root = etree.Element(_q(SSD, "SystemStructureDescription"), nsmap={"ssd": SSD, "ssc": SSC},
                                  version="1.0", name=system.path.stem if system.path else "system")
        self.top = etree.SubElement(self.root, _q(SSD, "System"), name="system")

    def files(self) -> dict[str, bytes]:
        system_connectors = etree.SubElement(self.top, _q(SSD, "Connectors"))
        elements = etree.SubElement(self.top, _q(SSD, "Elements"))
        components = {name: self._component(elements, name) for name in self.fmus}
        connections = etree.SubElement(self.top, _q(SSD, "Connections"))
        for c in self.system.connections:
            self._connection(connections, c)
        self._system_connectors(system_connectors)
        for element in (system_connectors, connections):
            if not len(element):
                self.top.remove(element)
        _units(self.root, self.units)
        etree.SubElement(self.root, _q(SSD, "DefaultExperiment"), startTime=repr(self.system.start_time),
                         stopTime=repr(self.system.stop_time))
        annotation = etree.SubElement(etree.SubElement(self.root, _q(SSD, "Annotations")), _q(SSC, "Annotation"),
                                      type=ANNOTATION_TYPE)
        etree.SubElement(annotation, "{urn:rover-cosim}Master").text = json.dumps(self._settings())
        files = {}
        for name, values in self.parameters.items():
            if values:
                source = parameter_file(name)
                bindings = etree.SubElement(components[name], _q(SSD, "ParameterBindings"))
                etree.SubElement(bindings, _q(SSD, "ParameterBinding"), source=source)
                files[source] = _parameter_set(values, name)
        files["SystemStructure.ssd"] = etree.tostring(self.root, xml_declaration=True, encoding="UTF-8",
                                                      pretty_print=True)
        return files

    def _used(self, name: str) -> set[str]:
        """The variables of FMU ``name`` that are connected (not to a folded constant) or recorded."""
        used = {port.variable for c in self.system.connections if c.source.instance not in self.constants
                for port in (c.source, c.target) if port.instance == name}
        return used | {port.variable for port in self.system.record if port.instance == name}

    def _component(self, elements: etree._Element, name: str) -> etree._Element:
        fmu = self.fmus[name]
        variables = fmu.variables()
        component = etree.SubElement(elements, _q(SSD, "Component"), name=name,
                                     type="application/x-fmu-sharedlibrary", source=f"resources/{fmu.path.name}")
        connectors = etree.SubElement(component, _q(SSD, "Connectors"))
        for variable in sorted(self._used(name), key=lambda v: variables[v].valueReference):
            v = variables[variable]
            _connector(connectors, variable, v.causality if v.causality in ("input", "parameter") else "output",
                       v.unit, v.type)
            self.units.update([v.unit] if v.unit else [])
        for variable, value in {**fmu.parameters, **fmu.start}.items():
            self.parameters[name].append((variable, value, variables[variable].unit))
            self.units.update([variables[variable].unit] if variables[variable].unit else [])
        return component

    def _connection(self, connections: etree._Element, c: Connection) -> None:
        if c.source.instance in self.constants:  # folded: no connector, so nobody overrides the start value
            unit = self.fmus[c.target.instance].variables()[c.target.variable].unit
            self.parameters[c.target.instance].append((c.target.variable, self.constants[c.source.instance], unit))
            return
        if c.source.instance in self.outside and c.target.instance in self.outside:
            return  # block to block: stays with the blocks
        attributes = {}
        for role, port in (("start", c.source), ("end", c.target)):
            if port.instance in self.outside:
                attributes[f"{role}Connector"] = f"{port.instance}_{port.variable}"
            else:
                attributes[f"{role}Element"] = port.instance
                attributes[f"{role}Connector"] = port.variable
        etree.SubElement(connections, _q(SSD, "Connection"), attributes)

    def _system_connectors(self, parent: etree._Element) -> None:
        for entry in self.external:
            for output in entry.block.outputs:
                _connector(parent, f"{entry.name}_{output}", "input", entry.block.units.get(output))
            for name in entry.block.inputs:
                _connector(parent, f"{entry.name}_{name}", "output", entry.block.units.get(name))
            self.units.update(u for u in entry.block.units.values() if u)

    def _settings(self) -> dict[str, Any]:
        system, kept = self.system, set(self.fmus) | self.outside
        return {"step": system.step, "algorithm": system.algorithm,
                "order": [name for name in system.order if name in kept],
                "record": [str(p) for p in system.record if p.instance in kept],
                "iteration": {"tolerance": system.iteration.tolerance,
                              "max_iterations": system.iteration.max_iterations,
                              "relaxation": system.iteration.relaxation},
                "allow_algebraic_loops": system.algebraic_loop is not None,
                "blocks": [{"name": e.name, "type": e.kind, **_keys(e)} for e in self.external],
                "block_connections": [{"from": str(c.source), "to": str(c.target)} for c in system.connections
                                      if c.source.instance in self.outside or c.target.instance in self.outside]}


def _keys(entry: BlockEntry) -> dict[str, Any]:
    if entry.keys is None:
        raise SspError(f"block {entry.name!r} ({type(entry.block).__name__}) was built in code from an object: the "
                       "archive keeps a block as its type and keys, so it cannot be exported")
    return entry.keys


def parameter_file(instance: str) -> str:
    """The parameter set of one component inside the archive."""
    return f"resources/{instance}.ssv"


def _parameter_set(parameters: list[tuple[str, Value, str | None]], name: str) -> bytes:
    root = etree.Element(_q(SSV, "ParameterSet"), nsmap={"ssv": SSV, "ssc": SSC}, version="1.0", name=name)
    values = etree.SubElement(root, _q(SSV, "Parameters"))
    for name, value, unit in parameters:
        parameter = etree.SubElement(values, _q(SSV, "Parameter"), name=name)
        if isinstance(value, bool):
            etree.SubElement(parameter, _q(SSV, "Boolean"), value="true" if value else "false")
        elif isinstance(value, int):
            etree.SubElement(parameter, _q(SSV, "Integer"), value=str(value))
        elif isinstance(value, str):
            etree.SubElement(parameter, _q(SSV, "String"), value=value)
        else:
            real = etree.SubElement(parameter, _q(SSV, "Real"), value=repr(float(value)))
            if unit:
                real.set("unit", unit)
    return etree.tostring(root, xml_declaration=True, encoding="UTF-8", pretty_print=True)


def _write_zip(out: Path, files: dict[str, bytes]) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".part", dir=out.parent)
    try:
        with open(handle, "wb") as stream, zipfile.ZipFile(stream, "w", zipfile.ZIP_DEFLATED) as archive:
            for name, data in files.items():
                archive.writestr(name, data)
        Path(temporary).replace(out)
    finally:
        Path(temporary).unlink(missing_ok=True)


def validate_ssd(archive: Path) -> None:
    """SspError with the schema's messages unless SystemStructure.ssd validates against the SSP
    1.0 schema FMPy ships."""
    from fmpy.ssp.ssd import validate_tree

    with zipfile.ZipFile(archive) as zf:
        root = etree.fromstring(zf.read("SystemStructure.ssd"))
        parameter_sets = [etree.fromstring(zf.read(n)) for n in zf.namelist() if n.endswith(".ssv")]
    try:
        validate_tree(root, "SystemStructureDescription.xsd")
        for parameter_set in parameter_sets:
            validate_tree(parameter_set, "SystemStructureParameterValues.xsd")
    except Exception as error:  # noqa: BLE001 - FMPy raises a plain Exception with the schema log
        raise SspError(f"{archive}: {error}") from None


def load_ssp(archive: Path, folder: Path) -> System:
    """The System of an SSP archive written by export_ssp (or another tool: one flat system of
    FMU components), its files unpacked into ``folder`` (which must outlive the run)."""
    archive = Path(archive)
    try:
        with zipfile.ZipFile(archive) as zf:
            zf.extractall(folder)
    except (OSError, zipfile.BadZipFile) as error:
        raise SspError(f"{archive}: not a readable SSP archive ({error})") from None
    validate_ssd(archive)
    ssd_root = etree.parse(str(folder / "SystemStructure.ssd")).getroot()  # noqa: S320 - validated above
    ns = {"ssd": SSD, "ssc": SSC, "ssv": SSV}
    top = ssd_root.find("ssd:System", ns)
    settings = _settings(ssd_root, ns)
    builder = SystemBuilder(str(archive), base=folder)
    builder.simulation(where="[simulation]", **_simulation(settings))
    for entry in _fmu_entries(top, folder, ns):
        builder.add_fmu(entry["name"], entry["path"], parameters=entry["parameters"], start=entry["start"],
                        where=f"[[fmu]] {entry['name']!r}")
    for entry in settings.get("blocks", []):
        keys = {k: v for k, v in entry.items() if k not in ("name", "type")}
        where = f"[[block]] {entry['name']!r}"
        try:
            block = make_block(entry["name"], entry["type"], keys, None)
        except ValueError as failure:
            raise builder.error(where, str(failure)) from None
        builder.add_block(entry["name"], block, kind=entry["type"], keys=keys, where=where)
    elements = [c for c in top.findall("ssd:Connections/ssd:Connection", ns)
                if c.get("startElement") and c.get("endElement")]  # system connectors: the blocks' side
    connections = [(f"{c.get('startElement')}.{c.get('startConnector')}",
                    f"{c.get('endElement')}.{c.get('endConnector')}") for c in elements]
    connections += [(c["from"], c["to"]) for c in settings.get("block_connections", [])]
    for i, (source, target) in enumerate(connections, 1):
        builder.connect(source, target, where=f"connection {i} ({source} -> {target})")
    if settings.get("record"):
        builder.record(*settings["record"], where="recorded variables")
    return builder.build()


def _simulation(settings: dict[str, Any]) -> dict[str, Any]:
    """[simulation] of the archive's experiment and master annotation."""
    simulation = {"stop_time": float(settings.get("stop_time", 1.0)), "step": float(settings["step"]),
                  "start_time": float(settings.get("start_time", 0.0)),
                  "algorithm": settings.get("algorithm", "gauss-seidel")}
    if settings.get("allow_algebraic_loops") and simulation["algorithm"] != "iterative":
        simulation["allow_algebraic_loops"] = True
    if simulation["algorithm"] == "iterative" and settings.get("iteration"):
        simulation.update(settings["iteration"])
    if settings.get("order"):
        simulation["order"] = settings["order"]
    return simulation


def _fmu_entries(top: etree._Element, folder: Path, ns: dict[str, str]) -> list[dict[str, Any]]:
    """[[fmu]] entries of the components, their bound values split into parameters and start
    values by the variable's causality (values bound to the system are named instance.variable)."""
    import fmpy

    entries = [{"name": c.get("name"), "path": str(folder / c.get("source")), "values": _bound_values(c, folder, ns)}
               for c in top.findall("ssd:Elements/ssd:Component", ns)]
    by_name = {entry["name"]: entry for entry in entries}
    for name, value in _bound_values(top, folder, ns).items():
        instance, _, variable = name.partition(".")
        if instance in by_name:
            by_name[instance]["values"][variable] = value
    for entry in entries:
        given = entry.pop("values")
        causality = {v.name: v.causality for v in fmpy.read_model_description(entry["path"]).modelVariables}
        entry["parameters"] = {k: v for k, v in given.items() if causality.get(k) == "parameter"}
        entry["start"] = {k: v for k, v in given.items() if causality.get(k) != "parameter"}
    return entries


def _settings(root: etree._Element, ns: dict[str, str]) -> dict[str, Any]:
    settings: dict[str, Any] = {}
    for annotation in root.findall("ssd:Annotations/ssc:Annotation", ns):
        if annotation.get("type") == ANNOTATION_TYPE and len(annotation):
            settings = json.loads(annotation[0].text or "{}")
    experiment = root.find("ssd:DefaultExperiment", ns)
    if experiment is not None:
        settings["start_time"] = float(experiment.get("startTime", 0.0))
        if experiment.get("stopTime") is not None:
            settings["stop_time"] = float(experiment.get("stopTime"))
    if "step" not in settings:
        raise SspError("the archive gives no communication step (no org.rover-cosim annotation); "
                       "run it with --step")
    return settings


def _bound_values(element: etree._Element, folder: Path, ns: dict[str, str]) -> dict[str, Value]:
    """name -> value of the parameter sets (files in the archive) bound to ``element`` (Real,
    Integer, Boolean and String values; the others are not read)."""
    values: dict[str, Value] = {}
    for binding in element.findall("ssd:ParameterBindings/ssd:ParameterBinding", ns):
        source = binding.get("source")
        prefix = binding.get("prefix", "")
        if not source:
            continue
        parameter_set = etree.parse(str(folder / source)).getroot()  # noqa: S320 - our own archive, validated
        for parameter in parameter_set.findall("ssv:Parameters/ssv:Parameter", ns):
            for kind, read in SSV_READERS.items():
                found = parameter.find(f"ssv:{kind}", ns)
                if found is not None:
                    values[prefix + parameter.get("name")] = read(found.get("value"))
    return values


#: How a value of each SSV element is read.
SSV_READERS: dict[str, Any] = {"Real": float, "Integer": int, "Boolean": lambda text: text.strip() in ("true", "1"),
                               "String": str}


def fmpy_parameter_set(archive: Path) -> Any:
    """The components' parameter sets as one FMPy ParameterSet with names ``instance.variable``,
    for ``fmpy.ssp.simulation.simulate_ssp(..., parameter_set=...)`` (which does not apply the
    archive's bindings by itself)."""
    from fmpy.ssp.ssd import ParameterSet, read_ssd, read_ssv

    merged = ParameterSet(name="parameters")
    for component in read_ssd(str(archive)).system.elements:
        for binding in component.parameterBindings:
            if binding.source:
                for parameter in read_ssv(str(archive), resource=binding.source).parameters:
                    parameter.name = f"{component.name}.{parameter.name}"
                    merged.parameters.append(parameter)
    return merged
