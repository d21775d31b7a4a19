"""Builds the test FMU ``Integrator.fmu`` from tests/fmus/integrator.c (FMI 2.0 Co-Simulation and
Model Exchange): x' = u, y = u and m = k fed through, r a relay on u (1 where u > 0.5) that changes at
events only; the input-timing tests know its exact answer.
None (and why) where no C compiler works."""

from __future__ import annotations

from pathlib import Path

from c_fmu import compile_fmu

GUID = "{5d3f0c2a-integrator-rover-cosim-tests}"


def model_description() -> str:
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Integrator" guid="{GUID}" variableNamingConvention="flat"
  numberOfEventIndicators="1">
  <ModelExchange modelIdentifier="Integrator" canGetAndSetFMUstate="true"/>
  <CoSimulation modelIdentifier="Integrator" canHandleVariableCommunicationStepSize="true"
    canGetAndSetFMUstate="true"/>
  <DefaultExperiment startTime="0" stopTime="1" stepSize="0.01"/>
  <ModelVariables>
    <ScalarVariable name="x" valueReference="0" causality="output" variability="continuous" initial="exact">
      <Real start="0"/></ScalarVariable>
    <ScalarVariable name="der(x)" valueReference="1" causality="local" variability="continuous">
      <Real derivative="1"/></ScalarVariable>
    <ScalarVariable name="u" valueReference="2" causality="input" variability="continuous"><Real start="0"/>
    </ScalarVariable>
    <ScalarVariable name="y" valueReference="3" causality="output" variability="continuous"><Real/>
    </ScalarVariable>
    <ScalarVariable name="k" valueReference="0" causality="input" variability="discrete"><Integer start="0"/>
    </ScalarVariable>
    <ScalarVariable name="m" valueReference="1" causality="output" variability="discrete"><Integer/>
    </ScalarVariable>
    <ScalarVariable name="r" valueReference="4" causality="output" variability="discrete"><Real/>
    </ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs>
      <Unknown index="1"/>
      <Unknown index="4" dependencies="3"/>
      <Unknown index="6" dependencies="5"/>
      <Unknown index="7" dependencies=""/>
    </Outputs>
    <Derivatives><Unknown index="2" dependencies="3"/></Derivatives>
    <InitialUnknowns>
      <Unknown index="2"/>
      <Unknown index="4"/>
      <Unknown index="6"/>
      <Unknown index="7"/>
    </InitialUnknowns>
  </ModelStructure>
</fmiModelDescription>
"""


def build_integrator(folder: Path) -> Path | str:
    """``folder``/Integrator.fmu, or why it could not be built."""
    return compile_fmu("integrator.c", "Integrator", folder, "Integrator", model_description())
