"""``modelDescription.xml`` (FMI 2.0) for a built-in FMU: ModelExchange and CoSimulation in one,
unit definitions in SI base units, every variable with causality/variability/initial, and the
complete ModelStructure (outputs and derivatives with their dependencies on states and inputs;
the initial unknowns)."""

from __future__ import annotations

import datetime
import math
import xml.etree.ElementTree as ET

from rover_cosim.common.units import base_units

from .codegen import FmuVariable, ModelLayout
from .source import Experiment

GENERATOR = "rover-cosim fmubuild (rumoca + CasADi + own FMI 2.0 runtime)"


def _number(value: float) -> str:
    return repr(float(value))


def _interfaces(root: ET.Element, model_layout: ModelLayout, sources: list[str]) -> None:
    """<ModelExchange> and <CoSimulation>, with their capability flags and C source files."""
    common = {"modelIdentifier": model_layout.name, "providesDirectionalDerivative": "true",
              "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true",
              "canNotUseMemoryManagementFunctions": "false"}
    for element, extra in (("ModelExchange", {"completedIntegratorStepNotNeeded": "true"}),
                           ("CoSimulation", {"canHandleVariableCommunicationStepSize": "true",
                                             "canInterpolateInputs": "true", "maxOutputDerivativeOrder": "0",
                                             "canRunAsynchronuously": "false"})):
        node = ET.SubElement(root, element, {**common, **extra})
        files = ET.SubElement(node, "SourceFiles")
        for name in sources:
            if name.endswith(".c"):
                ET.SubElement(files, "File", {"name": name})


#: Display units the FMUs declare: (unit, display unit) -> factor (display = factor x value).
DISPLAY_UNITS = {("rad", "deg"): 180.0 / math.pi, ("rad/s", "deg/s"): 180.0 / math.pi, ("m/s", "km/h"): 3.6}


def _display_unit(v: FmuVariable) -> str | None:
    """The variable's display unit where the FMU can declare it (one of DISPLAY_UNITS)."""
    return v.display_unit if (v.unit, v.display_unit) in DISPLAY_UNITS else None


def _unit_definitions(root: ET.Element, model_layout: ModelLayout) -> None:
    """<UnitDefinitions>: every unit used, in SI base units, with the display units of its variables."""
    units = sorted({v.unit for v in model_layout.variables if v.unit is not None})
    if not units:
        return
    shown = {(v.unit, _display_unit(v)) for v in model_layout.variables if _display_unit(v)}
    definitions = ET.SubElement(root, "UnitDefinitions")
    for unit in units:
        exponents, factor = base_units(unit)
        node = ET.SubElement(definitions, "Unit", {"name": unit})
        attributes = {k: str(e) for k, e in exponents.items()}
        if factor != 1.0:
            attributes["factor"] = _number(factor)
        ET.SubElement(node, "BaseUnit", attributes)
        for display in sorted(d for u, d in shown if u == unit and d is not None):
            ET.SubElement(node, "DisplayUnit", {"name": display, "factor": _number(DISPLAY_UNITS[unit, display])})


def variable_attributes(v: FmuVariable) -> dict[str, str]:
    """name, valueReference, causality, variability, description and initial of a variable (the
    same in FMI 2.0's ScalarVariable and FMI 3.0's Float64)."""
    attributes = {"name": v.name, "valueReference": str(v.value_reference), "causality": v.causality,
                  "variability": v.variability}
    if v.description:
        attributes["description"] = v.description
    if v.initial is not None:
        attributes["initial"] = v.initial
    return attributes


def value_attributes(v: FmuVariable) -> dict[str, str]:
    """unit, displayUnit, min, max and start of a Real (FMI 2.0) or Float64 (FMI 3.0) variable."""
    attributes: dict[str, str] = {}
    if v.unit is not None:
        attributes["unit"] = v.unit
    if _display_unit(v):
        attributes["displayUnit"] = str(v.display_unit)
    if v.minimum is not None:
        attributes["min"] = _number(v.minimum)
    if v.maximum is not None:
        attributes["max"] = _number(v.maximum)
    if v.start is not None:
        attributes["start"] = _number(v.start)
    return attributes


def _scalar_variable(parent: ET.Element, v: FmuVariable, index: dict[int, int]) -> None:
    attributes = variable_attributes(v)
    node = ET.SubElement(parent, "ScalarVariable", attributes)
    real = value_attributes(v)
    if v.derivative_of is not None:
        real["derivative"] = str(index[v.derivative_of])
    ET.SubElement(node, "Real", real)


def _model_variables(root: ET.Element, model_layout: ModelLayout) -> dict[int, int]:
    """<ModelVariables>; returns the 1-based index of each value reference."""
    variables = ET.SubElement(root, "ModelVariables")
    index: dict[int, int] = {}
    for position, v in enumerate(model_layout.variables, start=1):
        index[v.value_reference] = position
        _scalar_variable(variables, v, index)
    return index


def _model_structure(root: ET.Element, model_layout: ModelLayout, index: dict[int, int]) -> None:
    """<ModelStructure>: outputs and derivatives with their dependencies, the initial unknowns."""
    structure = ET.SubElement(root, "ModelStructure")
    for element, selected in (("Outputs", [v for v in model_layout.variables if v.causality == "output"]),
                              ("Derivatives", [v for v in model_layout.variables if v.kind == "derivative"])):
        if selected:
            node = ET.SubElement(structure, element)
            for v in selected:
                ET.SubElement(node, "Unknown", {"index": str(index[v.value_reference]),
                                                "dependencies": _dependencies(v, model_layout, index)})
    initial = [v for v in model_layout.variables if (v.causality == "output" or v.kind in ("state", "derivative"))
               and v.initial in ("approx", "calculated")]
    if initial:
        node = ET.SubElement(structure, "InitialUnknowns")
        for v in sorted(initial, key=lambda v: index[v.value_reference]):
            # No dependencies attribute: may depend on every known (parameters, inputs, exact states).
            ET.SubElement(node, "Unknown", {"index": str(index[v.value_reference])})


def model_description(model_layout: ModelLayout, guid: str, sources: list[str], description: str,
                      version: str, experiment: Experiment | None = None) -> str:
    """The modelDescription.xml text of an FMU of ``model_layout``; ``experiment`` (the model's
    ``experiment`` annotation) gives the DefaultExperiment's stop time and step size."""
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "2.0",
        "modelName": model_layout.name,
        "guid": guid,
        "description": description,
        "generationTool": f"{GENERATOR} {version}",
        "generationDateAndTime": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "variableNamingConvention": "structured",
        "numberOfEventIndicators": "0",
    })
    _interfaces(root, model_layout, sources)
    _unit_definitions(root, model_layout)
    categories = ET.SubElement(root, "LogCategories")
    ET.SubElement(categories, "Category", {"name": "logStatusError", "description": "errors, always reported"})
    ET.SubElement(categories, "Category", {"name": "logStatusWarning",
                                           "description": "warnings (assert level warning); reported unless "
                                           "fmi2SetDebugLogging switches them off"})
    ET.SubElement(categories, "Category", {"name": "logStatistics",
                                           "description": "Co-Simulation integrator counts, at fmi2Terminate, "
                                           "with debug logging on"})
    default = {"startTime": "0.0", "tolerance": "1e-06"}
    if experiment is not None:
        default = {"startTime": repr(experiment.start), "stopTime": repr(experiment.stop),
                   "tolerance": repr(experiment.tolerance or 1e-6), "stepSize": repr(experiment.interval)}
    ET.SubElement(root, "DefaultExperiment", default)
    index = _model_variables(root, model_layout)
    _model_structure(root, model_layout, index)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def _dependencies(v: FmuVariable, model_layout: ModelLayout, index: dict[int, int]) -> str:
    if v.kind == "state":
        refs = [v.value_reference]  # an output that is a state depends on that state only
    else:
        refs = model_layout.dependencies.get(v.value_reference, [])
    return " ".join(str(index[r]) for r in refs)


def documentation_html(model_layout: ModelLayout, description: str, documentation: str = "",
                       fmi_version: int = 2) -> str:
    """documentation/index.html of an FMU: what it is, every variable a user sets or reads (name,
    causality, unit and display unit, start, min, max, description), and ``documentation`` (the
    Modelica class's own Documentation: equations and sources; our own text, inserted as HTML)."""
    import html

    rows = []
    for v in model_layout.variables:
        if v.causality not in ("parameter", "input", "output"):
            continue
        unit = (v.unit or "") + (f" (shown in {v.display_unit})" if _display_unit(v) else "")
        cells = [v.name, v.causality, unit, "" if v.start is None else _number(v.start),
                 "" if v.minimum is None else _number(v.minimum), "" if v.maximum is None else _number(v.maximum),
                 v.description or ""]
        rows.append("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in cells) + "</tr>")
    style = ("body{font-family:sans-serif;font-size:15px;max-width:1000px;margin:1.5em auto;padding:0 12px}"
             "table{border-collapse:collapse;font-size:13px}td,th{border:1px solid #bbb;padding:3px 7px;"
             "text-align:left}th{background:#f2f2f2}")
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<title>{html.escape(model_layout.name)}</title><style>{style}</style></head><body>"
            f"<h1>{html.escape(model_layout.name)}</h1><p>{html.escape(description)}</p>"
            f"<p>FMI {fmi_version}.0, Model Exchange and Co-Simulation. Units are SI; min and max are the closed "
            "range a "
            "value must lie in (where the model needs a strict bound, e.g. 0 &lt; phi, the FMU also refuses the "
            "end itself at initialization, naming the variable)."
            + (" A load W of 0 N is taken as 1e-3 N (the contact needs a load to be defined)." if any(
                v.name == "W" and v.causality == "input" for v in model_layout.variables) else "") + "</p>"
            "<h2>Variables</h2><table><tr><th>name</th><th>causality</th><th>unit</th><th>start</th><th>min</th>"
            "<th>max</th><th>description</th></tr>" + "".join(rows) + "</table>"
            + (f"<h2>Model</h2>{documentation}" if documentation else "") + "</body></html>\n")
