"""An FMU instance in a co-simulation: FMPy's FMI 2.0 slave with batched, preallocated value
exchange (one fmi2SetReal of all connected inputs and one fmi2GetReal of all needed variables
per step), and errors turned into :class:`RunError` with the FMU's own message."""

from __future__ import annotations

import ctypes
from pathlib import Path

import fmpy
import numpy as np
from fmpy.fmi2 import (
    FMU2Slave,
    defaultCallbacks,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)

from .system import FmuEntry


class RunError(RuntimeError):
    """A co-simulation run that failed; the message names the instance, the call and the time."""


class FmuParticipant:
    def __init__(self, entry: FmuEntry, unzip_root: Path):
        self.name = entry.name
        self.entry = entry
        self.messages: list[str] = []
        folder = unzip_root / entry.name
        fmpy.extract(str(entry.path), str(folder))
        md = entry.description
        self.refs = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(folder),
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=entry.name)
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self._callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self._callbacks.freeMemory = defaultCallbacks.freeMemory
        self._call("fmi2Instantiate", lambda: self.fmu.instantiate(callbacks=self._callbacks))
        self.inputs: list[str] = []
        self.reads: list[str] = []
        self.input_values = np.zeros(0)
        self.read_values = np.zeros(0)

    def _log(self, env, instance, status, category, message) -> None:
        if status >= 2:  # discard, error, fatal
            self.messages.append(message.decode(errors="replace"))

    def _call(self, what: str, action, t: float | None = None):
        try:
            return action()
        except Exception as error:  # noqa: BLE001 - FMPy raises plain Exceptions on fmi2Error
            detail = "; ".join(self.messages[-3:]) or str(error)
            at = f" at t = {t:.6g} s" if t is not None else ""
            raise RunError(f"{self.name} ({self.entry.path.name}): {what}{at} failed: {detail}") from None

    def configure(self, inputs: list[str], reads: list[str]) -> None:
        """Fix the inputs set and the variables read at every step (preallocated arrays)."""
        self.inputs, self.reads = list(inputs), list(reads)
        self._in_refs = (ctypes.c_uint * max(1, len(inputs)))(*[self.refs[n] for n in inputs])
        self._read_refs = (ctypes.c_uint * max(1, len(reads)))(*[self.refs[n] for n in reads])
        self.input_values = np.zeros(len(inputs))
        self.read_values = np.zeros(len(reads))
        self._in_pointer = self.input_values.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._read_pointer = self.read_values.ctypes.data_as(ctypes.POINTER(ctypes.c_double))

    def set_values(self, names: dict[str, float]) -> None:
        if names:
            self._call("fmi2SetReal", lambda: self.fmu.setReal([self.refs[n] for n in names], list(names.values())))

    def setup(self, start_time: float, stop_time: float) -> None:
        self._call("fmi2SetupExperiment", lambda: self.fmu.setupExperiment(startTime=start_time, stopTime=stop_time))
        self.set_values(self.entry.parameters)
        self.set_values(self.entry.start)
        self._call("fmi2EnterInitializationMode", self.fmu.enterInitializationMode)

    def finish_initialization(self) -> None:
        self._call("fmi2ExitInitializationMode", self.fmu.exitInitializationMode)

    def set_inputs(self, values: np.ndarray, t: float) -> None:
        """Set all connected inputs in one call (values in the order given to configure)."""
        if not self.inputs:
            return
        self.input_values[:] = values
        self._call("fmi2SetReal", lambda: self.fmu.fmi2SetReal(self.fmu.component, self._in_refs, len(self.inputs),
                                                               self._in_pointer), t)

    def get_values(self, t: float) -> np.ndarray:
        """All read variables in one call; the returned array is reused by the next call."""
        if self.reads:
            self._call("fmi2GetReal", lambda: self.fmu.fmi2GetReal(self.fmu.component, self._read_refs,
                                                                   len(self.reads), self._read_pointer), t)
        return self.read_values

    def do_step(self, t: float, h: float) -> None:
        self._call("fmi2DoStep", lambda: self.fmu.fmi2DoStep(self.fmu.component, t, h, 1), t)

    def close(self) -> None:
        for what, action in (("fmi2Terminate", self.fmu.terminate), ("fmi2FreeInstance", self.fmu.freeInstance)):
            try:
                action()
            except Exception:  # noqa: BLE001 - closing after a failure must not mask it
                if what == "fmi2FreeInstance":
                    break
        try:
            self.fmu.freeLibrary()
        except Exception as error:  # noqa: BLE001 - unloading is best effort
            self.messages.append(f"freeLibrary: {error}")
