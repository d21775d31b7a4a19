"""Builds the test FMU ``Arrays.fmu`` (FMI 3.0 Co-Simulation) from tests/fmus/arrays3.c: array
inputs, outputs and parameters (see its header). None (and why) where no C compiler works."""

from __future__ import annotations

from pathlib import Path

import fmpy
from c_fmu import compile_fmu

DESCRIPTION = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="3.0" modelName="Arrays" instantiationToken="{a7f0c3e2-arrays-rover-cosim-tests}"
  variableNamingConvention="structured">
  <CoSimulation modelIdentifier="Arrays" canHandleVariableCommunicationStepSize="true"/>
  <DefaultExperiment startTime="0" stopTime="1" stepSize="0.1"/>
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    <Float64 name="u" valueReference="1" causality="input" variability="continuous" start="0 0 0">
      <Dimension start="3"/></Float64>
    <Float64 name="y" valueReference="2" causality="output" variability="continuous"><Dimension start="3"/></Float64>
    <Float64 name="gain" valueReference="3" causality="parameter" variability="fixed" start="2"/>
    <Float64 name="offset" valueReference="4" causality="parameter" variability="fixed" start="1 2 3">
      <Dimension start="3"/></Float64>
    <Float64 name="m" valueReference="5" causality="output" variability="continuous">
      <Dimension start="2"/><Dimension start="2"/></Float64>
    <Int32 name="k" valueReference="6" causality="output" variability="discrete"><Dimension start="2"/></Int32>
    <Float64 name="s" valueReference="7" causality="output" variability="continuous"/>
  </ModelVariables>
  <ModelStructure>
    <Output valueReference="2" dependencies="1"/>
    <Output valueReference="5"/>
    <Output valueReference="6"/>
    <Output valueReference="7" dependencies="1"/>
    <InitialUnknown valueReference="2"/>
    <InitialUnknown valueReference="5"/>
    <InitialUnknown valueReference="6"/>
    <InitialUnknown valueReference="7"/>
  </ModelStructure>
</fmiModelDescription>
"""


def build_arrays(folder: Path) -> Path | str:
    """``folder``/Arrays.fmu, or why it could not be built."""
    return compile_fmu("arrays3.c", "Arrays", folder, "Arrays", DESCRIPTION, platform=fmpy.platform_tuple)
