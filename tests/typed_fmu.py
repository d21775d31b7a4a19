"""Builds the test FMU ``Typed.fmu`` from tests/fmus/typed.c (see its header for the variables):
a variable of every FMI 2.0 type, value references shared across types, an FMU that can end the
simulation (fmi2Terminated), no FMU state, no input interpolation. Compiled with the C compiler
against the FMI 2.0 headers FMPy ships; None (and why) where no compiler works."""

from __future__ import annotations

from pathlib import Path

import fmpy
from c_fmu import compile_fmu

GUID = "{7c1e5c4e-typed-fmu-rover-cosim-tests}"

#: (name, type, value reference, causality, variability, start, dependencies of an output)
VARIABLES = [
    ("x", "Real", 0, "output", "continuous", None, ""),
    ("u", "Real", 1, "input", "continuous", "0.0", None),
    ("y", "Real", 2, "output", "continuous", None, "u"),
    ("gain", "Real", 3, "parameter", "fixed", "2.0", None),
    ("counter", "Integer", 0, "output", "discrete", None, ""),
    ("k", "Integer", 1, "input", "discrete", "0", None),
    ("k2", "Integer", 2, "output", "discrete", None, "k"),
    ("stopAfter", "Integer", 3, "parameter", "fixed", "0", None),
    ("mode", "Enumeration", 4, "output", "discrete", None, ""),
    ("even", "Boolean", 0, "output", "discrete", None, ""),
    ("b", "Boolean", 1, "input", "discrete", "false", None),
    ("notb", "Boolean", 2, "output", "discrete", None, "b"),
    ("label", "String", 0, "parameter", "fixed", "none", None),
    ("s", "String", 1, "input", "discrete", "", None),
    ("sout", "String", 2, "output", "discrete", None, "s"),
]


def model_description(states: bool = False, fixed_step: bool = False) -> str:
    index = {name: i for i, (name, *_rest) in enumerate(VARIABLES, start=1)}
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<fmiModelDescription fmiVersion="2.0" modelName="Typed" guid="{GUID}" '
             'variableNamingConvention="flat" numberOfEventIndicators="0">',
             '  <CoSimulation modelIdentifier="Typed" canHandleVariableCommunicationStepSize='
             f'"{str(not fixed_step).lower()}" canGetAndSetFMUstate="{str(states).lower()}" '
             'canInterpolateInputs="false"/>',
             '  <TypeDefinitions><SimpleType name="Mode"><Enumeration>'
             '<Item name="one" value="1"/><Item name="two" value="2"/><Item name="three" value="3"/>'
             '</Enumeration></SimpleType></TypeDefinitions>',
             '  <DefaultExperiment startTime="0" stopTime="1" stepSize="0.1"/>',
             "  <ModelVariables>"]
    for name, kind, reference, causality, variability, start, _ in VARIABLES:
        initial = ' initial="exact"' if causality == "parameter" else ""
        attributes = f' start="{start}"' if start is not None else ""
        declared = ' declaredType="Mode"' if kind == "Enumeration" else ""
        lines.append(f'    <ScalarVariable name="{name}" valueReference="{reference}" causality="{causality}" '
                     f'variability="{variability}"{initial}><{kind}{declared}{attributes}/></ScalarVariable>')
    lines += ["  </ModelVariables>", "  <ModelStructure>"]
    for section in ("Outputs", "InitialUnknowns"):
        lines.append(f"    <{section}>")
        for name, _kind, _ref, causality, _var, _start, depends in VARIABLES:
            if causality == "output":
                on = " ".join(str(index[d]) for d in (depends or "").split())
                lines.append(f'      <Unknown index="{index[name]}" dependencies="{on}"/>')
        lines.append(f"    </{section}>")
    lines += ["  </ModelStructure>", "</fmiModelDescription>", ""]
    return "\n".join(lines)


def build_typed_fmu(folder: Path, name: str = "Typed", states: bool = False, fixed_step: bool = False,
                    platform: str | None = None) -> Path | str:
    """``folder``/``name``.fmu, or why it could not be built. ``states``: it says it can get and
    set its state; ``fixed_step``: that it takes one fixed step; ``platform``: where its binary goes."""
    return compile_fmu("typed.c", "Typed", folder, name, model_description(states, fixed_step),
                       platform or fmpy.platform)
