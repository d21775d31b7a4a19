"""``modelDescription.xml`` (FMI 3.0) for a built-in FMU, from the same layout as the FMI 2.0 one
(:mod:`fmubuild.description`): Model Exchange and Co-Simulation in one, Float64 variables with the
same value references, the independent variable ``time`` after them (the runtime's fmi3_api.c
answers it), unit definitions, and the ModelStructure by value reference (outputs and continuous
state derivatives with their dependencies, the initial unknowns)."""

from __future__ import annotations

import datetime
import xml.etree.ElementTree as ET

from .codegen import FmuVariable, ModelLayout
from .description import _unit_definitions, value_attributes, variable_attributes
from .source import Experiment

GENERATOR = "rover-cosim fmubuild (rumoca + CasADi + own FMI 2.0/3.0 runtime)"


def time_value_reference(model_layout: ModelLayout) -> int:
    """The value reference of ``time``: the one after the layout's variables (fmi3_api.c time_vr)."""
    return max(v.value_reference for v in model_layout.variables) + 1


def _interfaces(root: ET.Element, model_layout: ModelLayout) -> None:
    common = {"modelIdentifier": model_layout.name, "providesDirectionalDerivatives": "true",
              "canGetAndSetFMUState": "true", "canSerializeFMUState": "true"}
    ET.SubElement(root, "ModelExchange", {**common, "needsCompletedIntegratorStep": "true"})
    ET.SubElement(root, "CoSimulation", {**common, "canHandleVariableCommunicationStepSize": "true",
                                         "maxOutputDerivativeOrder": "0", "hasEventMode": "false"})


def _float64(parent: ET.Element, v: FmuVariable) -> None:
    attributes = variable_attributes(v)
    attributes.update(value_attributes(v))
    if v.derivative_of is not None:
        attributes["derivative"] = str(v.derivative_of)
    ET.SubElement(parent, "Float64", attributes)


def _dependencies(v: FmuVariable, model_layout: ModelLayout) -> str:
    refs = [v.value_reference] if v.kind == "state" else model_layout.dependencies.get(v.value_reference, [])
    return " ".join(str(r) for r in refs)


def _model_structure(root: ET.Element, model_layout: ModelLayout) -> None:
    structure = ET.SubElement(root, "ModelStructure")
    for v in model_layout.variables:
        if v.causality == "output":
            ET.SubElement(structure, "Output", {"valueReference": str(v.value_reference),
                                                "dependencies": _dependencies(v, model_layout)})
    for v in model_layout.variables:
        if v.kind == "derivative":
            ET.SubElement(structure, "ContinuousStateDerivative", {"valueReference": str(v.value_reference),
                                                                   "dependencies": _dependencies(v, model_layout)})
    for v in model_layout.variables:
        if (v.causality == "output" or v.kind in ("state", "derivative")) and v.initial in ("approx", "calculated"):
            # No dependencies attribute: may depend on every known (parameters, inputs, exact states).
            ET.SubElement(structure, "InitialUnknown", {"valueReference": str(v.value_reference)})


def model_description(model_layout: ModelLayout, token: str, description: str, version: str,
                      experiment: Experiment | None = None) -> str:
    """The FMI 3.0 modelDescription.xml text of an FMU of ``model_layout``; ``token`` is its
    instantiation token (the FMI 2.0 GUID of the same model code)."""
    root = ET.Element("fmiModelDescription", {
        "fmiVersion": "3.0",
        "modelName": model_layout.name,
        "instantiationToken": token,
        "description": description,
        "generationTool": f"{GENERATOR} {version}",
        "generationDateAndTime": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "variableNamingConvention": "structured",
    })
    _interfaces(root, model_layout)
    _unit_definitions(root, model_layout)
    categories = ET.SubElement(root, "LogCategories")
    for name, text in (("logStatusError", "errors, always reported"),
                       ("logStatusWarning", "warnings (assert level warning); reported unless fmi3SetDebugLogging "
                                            "switches them off"),
                       ("logStatistics", "Co-Simulation integrator counts, at fmi3Terminate, with debug logging on")):
        ET.SubElement(categories, "Category", {"name": name, "description": text})
    default = {"startTime": "0.0", "tolerance": "1e-06"}
    if experiment is not None:
        default = {"startTime": repr(experiment.start), "stopTime": repr(experiment.stop),
                   "tolerance": repr(experiment.tolerance or 1e-6), "stepSize": repr(experiment.interval)}
    ET.SubElement(root, "DefaultExperiment", default)
    variables = ET.SubElement(root, "ModelVariables")
    ET.SubElement(variables, "Float64", {"name": "time", "valueReference": str(time_value_reference(model_layout)),
                                         "causality": "independent", "variability": "continuous",
                                         "description": "Simulation time [s]"})
    for v in model_layout.variables:
        _float64(variables, v)
    _model_structure(root, model_layout)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
