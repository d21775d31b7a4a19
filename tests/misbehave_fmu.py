"""Builds the test FMU ``Misbehave.fmu`` from tests/fmus/misbehave.c (FMI 2.0 Co-Simulation): x =
time until t >= ``at``, then the call chosen by the parameter ``mode`` segfaults, aborts, calls
exit(), hangs, ... (see the C file). None (and why) where no C compiler works."""

from __future__ import annotations

from pathlib import Path

from c_fmu import compile_fmu

GUID = "{8a1e0f37-misbehave-rover-cosim-tests}"
#: The misbehaviours by the value of the parameter ``mode``.
MODES = {"fine": 0, "segfault": 1, "abort": 2, "exit": 3, "busy": 4, "sleep": 5, "free-segfault": 6,
         "terminate-hang": 7, "getreal-segfault": 8, "exit-at-init": 9, "long-message": 10}


def model_description() -> str:
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Misbehave" guid="{GUID}" variableNamingConvention="flat"
  numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="Misbehave" canHandleVariableCommunicationStepSize="true"/>
  <DefaultExperiment startTime="0" stopTime="1" stepSize="0.1"/>
  <ModelVariables>
    <ScalarVariable name="x" valueReference="0" causality="output" variability="continuous"><Real/>
    </ScalarVariable>
    <ScalarVariable name="at" valueReference="1" causality="parameter" variability="fixed" initial="exact">
      <Real start="0.5"/></ScalarVariable>
    <ScalarVariable name="mode" valueReference="0" causality="parameter" variability="fixed" initial="exact">
      <Integer start="0"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure>
    <Outputs><Unknown index="1"/></Outputs>
  </ModelStructure>
</fmiModelDescription>
"""


def build_misbehave(folder: Path) -> Path | str:
    """``folder``/Misbehave.fmu, or why it could not be built."""
    return compile_fmu("misbehave.c", "Misbehave", folder, "Misbehave", model_description())
