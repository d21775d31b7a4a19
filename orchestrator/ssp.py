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
import os
import tempfile
import zipfile
from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lxml import etree

from rover_cosim.common.outputs import result_mode
from rover_cosim.common.units import base_units

from .archives import LIMIT_VARIABLE, UnpackError, unpack_archive
from .archives import size_limit as archive_limit
from .blocks import BLOCK_TYPES, REGISTERED_FACTORIES, make_block
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


#: The SSP element of each FMI type (an Enumeration travels as its number, an Integer; SSP 1.0
#: has one Real and one Integer for FMI 3.0's several float and integer types).
SSP_TYPES = {"Real": "Real", "Float64": "Real", "Float32": "Real", "Integer": "Integer", "Enumeration": "Integer",
             "Int8": "Integer", "UInt8": "Integer", "Int16": "Integer", "UInt16": "Integer", "Int32": "Integer",
             "UInt32": "Integer", "Int64": "Integer", "UInt64": "Integer", "Boolean": "Boolean", "String": "String"}


def _connector(parent: etree._Element, name: str, kind: str, unit: str | None, variable_type: str = "Real") -> None:
    connector = etree.SubElement(parent, _q(SSD, "Connector"), name=name, kind=kind)
    typed = etree.SubElement(connector, _q(SSC, SSP_TYPES[variable_type]))
    if unit and SSP_TYPES[variable_type] == "Real":
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
        self.block_files: dict[str, bytes] = {}  # files of blocks (a csv block's), by their name in the archive
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
        files.update(self.block_files)
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
                "blocks": [self._block(e) for e in self.external],
                "interfaces": {f.name: f.interface for f in system.fmus if f.interface != "co-simulation"},
                "block_connections": [{"from": str(c.source), "to": str(c.target)} for c in system.connections
                                      if c.source.instance in self.outside or c.target.instance in self.outside]}


    def _block(self, entry: BlockEntry) -> dict[str, Any]:
        """A block as the annotation keeps it; a csv block's file goes into the archive."""
        keys = dict(_keys(entry))
        if entry.kind == "csv":
            inner = f"resources/{entry.name}.csv"
            self.block_files[inner] = Path(entry.block.file).read_bytes()  # type: ignore[attr-defined]
            keys["file"] = inner
        return {"name": entry.name, "type": entry.kind, **keys}


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
        os.chmod(temporary, result_mode())  # mkstemp makes 0600; an archive is an ordinary result
        Path(temporary).replace(out)
    finally:
        Path(temporary).unlink(missing_ok=True)


def validate_ssd(archive: Path) -> None:
    """SspError with the schema's messages unless SystemStructure.ssd validates against the SSP
    1.0 schema FMPy ships."""
    from fmpy.ssp.ssd import validate_tree

    parser = etree.XMLParser(resolve_entities=False, no_network=True)
    try:
        with zipfile.ZipFile(archive) as zf:
            root = etree.fromstring(zf.read("SystemStructure.ssd"), parser)
            parameter_sets = [etree.fromstring(zf.read(n), parser) for n in zf.namelist() if n.endswith(".ssv")]
    except KeyError:
        raise SspError(f"{archive}: no SystemStructure.ssd at the top of the archive") from None
    except etree.XMLSyntaxError as error:
        raise SspError(f"{archive}: not well-formed XML ({error})") from None
    try:
        validate_tree(root, "SystemStructureDescription.xsd")
        for parameter_set in parameter_sets:
            validate_tree(parameter_set, "SystemStructureParameterValues.xsd")
    except Exception as error:  # noqa: BLE001 - FMPy raises a plain Exception with the schema log
        raise SspError(f"{archive}: {error}") from None


#: The largest archive load_ssp unpacks [bytes, uncompressed, all entries together]; the
#: environment variable ROVER_COSIM_SSP_MAX_BYTES sets another.
SIZE_LIMIT = 4 * 2**30


def size_limit() -> int:
    """The size limit of SSP archives [bytes]: ROVER_COSIM_SSP_MAX_BYTES, else :data:`SIZE_LIMIT`."""
    try:
        return archive_limit("ROVER_COSIM_SSP_MAX_BYTES", SIZE_LIMIT)
    except UnpackError as error:
        raise SspError(str(error)) from None


def _unpack(archive: Path, folder: Path, limit: int) -> None:
    """Every entry of ``archive`` into ``folder`` (``archives.unpack_archive``: none outside it,
    no links, the bytes counted with every other archive this process unpacks, the FMUs inside
    included); SspError otherwise."""
    try:
        unpack_archive(archive, folder, limit)
    except UnpackError as error:
        raise SspError(str(error).replace(LIMIT_VARIABLE, "ROVER_COSIM_SSP_MAX_BYTES")
                       .replace("not a readable zip archive", "not a readable SSP archive")) from None


def inside(folder: Path, source: str | None, what: str) -> Path:
    """The file ``source`` (a relative path in the archive) under ``folder``; SspError for a path
    that leaves the archive, a URI or a file that is not there."""
    if not source:
        raise SspError(f"{what}: no source given")
    if "://" in source or source.startswith(("/", "\\")) or ":" in source.split("/")[0]:
        raise SspError(f"{what}: source {source!r}: expected a relative path inside the archive")
    root = folder.resolve()
    path = (root / source).resolve()
    if not path.is_relative_to(root):
        raise SspError(f"{what}: source {source!r} lies outside the archive")
    if not path.is_file():
        raise SspError(f"{what}: source {source!r} is not in the archive")
    return path


def load_ssp(archive: Path, folder: Path, settings: dict[str, Any] | None = None, validation: str = "strict",
             factories: Collection[str] = ()) -> System:
    """The System of an SSP 1.0 archive, written by export_ssp or by another tool (one flat system
    of FMU components; what is not supported is named), its files unpacked into ``folder`` (which
    must outlive the run). ``settings``: simulation settings that override the archive's (as the
    command line's --step, --stop-time); a step neither gives comes from the FMUs' DefaultExperiment.
    ``validation``: how the FMUs' model descriptions are checked (``model.VALIDATION``).
    ``factories``: the Python block factories the user allows the archive to name, besides those
    registered (``blocks.register_factory``): "module:callable", or "module" for any of its
    callables; such a module is looked up beside the archive first."""
    archive = Path(archive)
    _unpack(archive, folder, size_limit())
    if not (folder / "SystemStructure.ssd").is_file():
        raise SspError(f"{archive}: no SystemStructure.ssd at the top of the archive")
    validate_ssd(archive)
    parser = etree.XMLParser(resolve_entities=False, no_network=True)
    ssd_root = etree.parse(str(folder / "SystemStructure.ssd"), parser).getroot()  # noqa: S320 - validated
    ns = {"ssd": SSD, "ssc": SSC, "ssv": SSV}
    top = ssd_root.find("ssd:System", ns)
    _refuse_unsupported(top, ns)
    annotation = _annotation(ssd_root, ns)
    builder = SystemBuilder(str(archive), base=folder, validation=validation)
    builder.simulation(where="[simulation]", **_simulation(annotation, ssd_root, ns))
    if settings:
        builder.simulation(where="command line", **settings)
    interfaces = annotation.get("interfaces", {})
    for entry in _fmu_entries(top, folder, ns):
        builder.add_fmu(entry["name"], entry["path"], parameters=entry["parameters"], start=entry["start"],
                        interface=interfaces.get(entry["name"]), where=f"component {entry['name']!r}")
    for entry in annotation.get("blocks", []):
        _annotation_block(builder, entry, folder, set(factories), archive.parent)
    elements = [c for c in top.findall("ssd:Connections/ssd:Connection", ns)
                if c.get("startElement") and c.get("endElement")]  # system connectors: the blocks' side
    connections = [(f"{c.get('startElement')}.{c.get('startConnector')}",
                    f"{c.get('endElement')}.{c.get('endConnector')}") for c in elements]
    connections += [(c["from"], c["to"]) for c in annotation.get("block_connections", [])]
    for i, (source, target) in enumerate(connections, 1):
        builder.connect(source, target, where=f"connection {i} ({source} -> {target})")
    if annotation.get("record"):
        builder.record(*annotation["record"], where="recorded variables")
    return builder.build()


def _refuse_unsupported(top: etree._Element | None, ns: dict[str, str]) -> None:
    """SspError naming what the archive uses that the engine does not run."""
    if top is None:
        raise SspError("the archive's SystemStructure.ssd has no system")
    nested = top.findall("ssd:Elements/ssd:System", ns)
    if nested:
        raise SspError(f"nested systems ({', '.join(str(n.get('name')) for n in nested)}) are not supported: "
                       "flatten them into one system of FMU components")
    for component in top.findall("ssd:Elements/ssd:Component", ns):
        kind = component.get("type", "application/x-fmu-sharedlibrary")
        if kind != "application/x-fmu-sharedlibrary":
            raise SspError(f"component {component.get('name')!r}: type {kind!r} is not supported (expected an FMU, "
                           "application/x-fmu-sharedlibrary)")
    if top.findall("ssd:Elements/ssd:SignalDictionaryReference", ns) or top.find("ssd:SignalDictionaries", ns) \
            is not None:
        raise SspError("signal dictionaries are not supported: connect the components directly")


def _annotation_block(builder: SystemBuilder, entry: dict[str, Any], folder: Path, allowed: set[str],
                      beside: Path) -> None:
    """One block of our annotation: a built-in type, or a Python factory the user allows
    (``allowed``: "module:callable" or "module"; or registered with the engine), its module looked up
    in ``beside`` (the archive's folder) first."""
    name, kind = entry.get("name"), entry.get("type")
    keys = {k: v for k, v in entry.items() if k not in ("name", "type")}
    where = f"annotation block {name!r}"
    factory = str(keys.get("factory"))
    if kind == "python" and not (factory in REGISTERED_FACTORIES or factory in allowed
                                 or factory.partition(":")[0] in allowed):
        raise builder.error(where, f"the archive names the Python block factory {keys.get('factory')!r}, which you "
                            "have not allowed (an archive may name the built-in block types, "
                            f"{', '.join(BLOCK_TYPES)}, and the factories you allow: `rover-cosim run --allow-factory "
                            f"{factory.partition(':')[0]}`, or rover_cosim.orchestrator.blocks.register_factory; "
                            "it would run code chosen by the archive's author otherwise)")
    if kind != "python" and kind not in BLOCK_TYPES:
        raise builder.error(where, f"type {kind!r}: expected one of {', '.join(BLOCK_TYPES)}")
    if kind == "csv":
        keys["file"] = str(inside(folder, keys.get("file"), where))
    try:
        block = make_block(str(name), str(kind), keys, beside if kind == "python" else None)
    except ValueError as failure:
        raise builder.error(where, str(failure)) from None
    builder.add_block(str(name), block, kind=str(kind), keys=keys, where=where)


def _simulation(annotation: dict[str, Any], root: etree._Element, ns: dict[str, str]) -> dict[str, Any]:
    """The simulation settings of the archive: its DefaultExperiment and our master annotation
    (a foreign archive has none: its step and any missing stop time come from the FMUs)."""
    simulation: dict[str, Any] = {}
    experiment = root.find("ssd:DefaultExperiment", ns)
    if experiment is not None:
        for key, attribute in (("start_time", "startTime"), ("stop_time", "stopTime")):
            if experiment.get(attribute) is not None:
                simulation[key] = _float(experiment.get(attribute), f"DefaultExperiment {attribute}")
    if "step" in annotation:
        simulation["step"] = annotation["step"]
    simulation["algorithm"] = annotation.get("algorithm", "gauss-seidel")
    if annotation.get("allow_algebraic_loops") and simulation["algorithm"] != "iterative":
        simulation["allow_algebraic_loops"] = True
    if simulation["algorithm"] == "iterative" and annotation.get("iteration"):
        simulation.update(annotation["iteration"])
    if annotation.get("order"):
        simulation["order"] = annotation["order"]
    return simulation


def _float(text: str | None, what: str) -> float:
    try:
        return float(text)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise SspError(f"{what} = {text!r}: expected a number") from None


def _fmu_entries(top: etree._Element, folder: Path, ns: dict[str, str]) -> list[dict[str, Any]]:
    """[[fmu]] entries of the components, their bound values split into parameters and start
    values by the variable's causality (values bound to the system are named instance.variable;
    an enumeration value by its item name)."""
    import fmpy

    entries = []
    for c in top.findall("ssd:Elements/ssd:Component", ns):
        name = c.get("name")
        path = inside(folder, c.get("source"), f"component {name!r}")
        entries.append({"name": name, "path": str(path), "values": _bound_values(c, folder, ns)})
    by_name = {entry["name"]: entry for entry in entries}
    for name, value in _bound_values(top, folder, ns).items():
        instance, _, variable = name.partition(".")
        if instance in by_name:
            by_name[instance]["values"][variable] = value
    for entry in entries:
        given = entry.pop("values")
        try:
            variables = {v.name: v for v in fmpy.read_model_description(entry["path"]).modelVariables}
        except Exception as error:  # noqa: BLE001 - fmpy raises many kinds
            raise SspError(f"component {entry['name']!r}: {Path(entry['path']).name} is not a readable FMU: "
                           f"{error}") from None
        given = {k: _enumeration_value(variables.get(k), v, entry["name"]) for k, v in given.items()}
        entry["parameters"] = {k: v for k, v in given.items()
                               if k in variables and variables[k].causality == "parameter"}
        entry["start"] = {k: v for k, v in given.items() if k not in entry["parameters"]}
    return entries


def _enumeration_value(variable: Any, value: Value, instance: str) -> Value:
    """An SSV enumeration value (its item name) as the item's number; other values as they are."""
    if variable is None or variable.type != "Enumeration" or not isinstance(value, str):
        return value
    items = {item.name: int(item.value) for item in getattr(variable.declaredType, "items", [])}
    if value not in items:
        raise SspError(f"component {instance!r}: {variable.name} = {value!r}: expected one of its items "
                       f"({', '.join(items)})")
    return items[value]


def _annotation(root: etree._Element, ns: dict[str, str]) -> dict[str, Any]:
    """Our master annotation (settings, blocks), {} where the archive has none (a foreign one)."""
    for annotation in root.findall("ssd:Annotations/ssc:Annotation", ns):
        if annotation.get("type") == ANNOTATION_TYPE and len(annotation):
            try:
                settings = json.loads(annotation[0].text or "{}")
            except ValueError as error:
                raise SspError(f"the {ANNOTATION_TYPE} annotation is not valid JSON ({error})") from None
            if not isinstance(settings, dict):
                raise SspError(f"the {ANNOTATION_TYPE} annotation: expected a JSON object")
            _check_shapes(settings)
            return settings
    return {}


#: The keys of our annotation, and what each must be (checked before any is used: an archive's
#: author chooses them): a JSON type, or for lists and objects that of their items.
ANNOTATION_SHAPES: dict[str, tuple[type, type | None]] = {
    "step": (float, None), "algorithm": (str, None), "order": (list, str), "record": (list, str),
    "iteration": (dict, float), "allow_algebraic_loops": (bool, None), "blocks": (list, dict),
    "interfaces": (dict, str), "block_connections": (list, dict)}


def _check_shapes(settings: dict[str, Any]) -> None:
    """SspError naming the first key of our annotation that is unknown or of another shape."""
    names = {"float": "a number", "str": "text", "bool": "true or false", "dict": "an object", "list": "a list"}
    for key, value in settings.items():
        if key not in ANNOTATION_SHAPES:
            raise SspError(f"the {ANNOTATION_TYPE} annotation: unknown key {key!r}; expected "
                           f"{', '.join(ANNOTATION_SHAPES)}")
        kind, item = ANNOTATION_SHAPES[key]
        wanted = (int, float) if kind is float else kind
        items = value.values() if isinstance(value, dict) else value if isinstance(value, list) else ()
        item_types = (int, float) if item is float else item
        if not isinstance(value, wanted) or isinstance(value, bool) != (kind is bool) or (
                item_types is not None and not all(isinstance(v, item_types) and not isinstance(v, bool)
                                                   for v in items)):
            plural = {"float": "numbers", "str": "texts", "dict": "objects"}
            said = names[kind.__name__] + (f" of {plural[item.__name__]}" if item else "")
            raise SspError(f"the {ANNOTATION_TYPE} annotation: {key} = {str(value)[:80]!r}: expected {said}")
    for k, connection in enumerate(settings.get("block_connections", []), 1):
        if set(connection) != {"from", "to"} or not all(isinstance(v, str) for v in connection.values()):
            raise SspError(f"the {ANNOTATION_TYPE} annotation: block_connections {k}: expected "
                           "{\"from\": \"instance.variable\", \"to\": \"instance.variable\"}")
    for k, block in enumerate(settings.get("blocks", []), 1):
        if not isinstance(block.get("name"), str) or not isinstance(block.get("type"), str):
            raise SspError(f"the {ANNOTATION_TYPE} annotation: block {k}: expected a name and a type (text)")


def _bound_values(element: etree._Element, folder: Path, ns: dict[str, str]) -> dict[str, Value]:
    """name -> value of the parameter sets bound to ``element``: files in the archive or inline
    ``ssd:ParameterValues`` (Real, Integer, Boolean, String and Enumeration values)."""
    values: dict[str, Value] = {}
    parser = etree.XMLParser(resolve_entities=False, no_network=True)
    for binding in element.findall("ssd:ParameterBindings/ssd:ParameterBinding", ns):
        source = binding.get("source")
        prefix = binding.get("prefix", "")
        inline = binding.find("ssd:ParameterValues/ssv:ParameterSet", ns)
        if source:
            path = inside(folder, source, f"parameter binding of {element.get('name')!r}")
            parameter_set = etree.parse(str(path), parser).getroot()  # noqa: S320 - no entities, no network
        elif inline is not None:
            parameter_set = inline
        else:
            continue
        for parameter in parameter_set.findall("ssv:Parameters/ssv:Parameter", ns):
            for kind, read in SSV_READERS.items():
                found = parameter.find(f"ssv:{kind}", ns)
                if found is not None:
                    try:
                        values[prefix + str(parameter.get("name"))] = read(found.get("value"))
                    except (TypeError, ValueError):
                        raise SspError(f"parameter {parameter.get('name')!r}: {found.get('value')!r} is not a "
                                       f"{kind} value") from None
    return values


#: How a value of each SSV element is read.
SSV_READERS: dict[str, Any] = {"Real": float, "Integer": int, "Boolean": lambda text: text.strip() in ("true", "1"),
                               "String": str, "Enumeration": str}


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
