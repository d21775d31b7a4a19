"""An FMU file as an FMI 2.0 Co-Simulation slave (FMPy's FMU2Slave), instantiated and initialized
at t = 0 (with start values, if given), for tests that drive one of our FMUs call by call; shared
by test_affine_inputs.py, test_input_ramps.py and test_legwheel.py."""

from __future__ import annotations

from pathlib import Path

import fmpy
from fmpy.fmi2 import FMU2Slave


class Slave:
    """``fmu`` unpacked into ``tmp`` and initialized; ``refs``: value references by name."""

    def __init__(self, fmu: Path, tmp: Path, name: str = "slave", start: dict[str, float] | None = None):
        self.description = fmpy.read_model_description(str(fmu))
        self.refs = {v.name: v.valueReference for v in self.description.modelVariables}
        folder = fmpy.extract(str(fmu), unzipdir=str(tmp))
        self.slave = FMU2Slave(guid=self.description.guid, unzipDirectory=folder,
                               modelIdentifier=self.description.coSimulation.modelIdentifier, instanceName=name)
        self.slave.instantiate()
        self.slave.setupExperiment(startTime=0.0)
        self.slave.enterInitializationMode()
        if start:  # start values of parameters and states (initial exact), set before the equations start
            self.slave.setReal([self.refs[name] for name in start], list(start.values()))
        self.slave.exitInitializationMode()

    def statistic(self, name: str) -> float:
        """The runtime's statistic ``statistics.<name>``."""
        return self.slave.getReal([self.refs[f"statistics.{name}"]])[0]

    def close(self) -> None:
        self.slave.terminate()
        self.slave.freeInstance()
