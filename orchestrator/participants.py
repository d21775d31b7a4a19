"""Participants of a co-simulation: the protocol the masters step, and its two kinds.

- :class:`FmuParticipant`: an FMU instance, FMPy's FMI 2.0 slave with batched, preallocated value
  exchange (one fmi2SetReal of all connected inputs and one fmi2GetReal of all needed variables
  per step), errors turned into :class:`RunError` with the FMU's own message;
- :class:`BlockParticipant`: a Python block (``blocks.Block``), its exceptions turned into
  :class:`RunError` naming the block.

Initialization follows FMI 2.0: every participant enters initialization, participants with
``iterative_start`` (FMUs, in Initialization Mode) exchange their initial outputs with the
others until the chains settle, the others (blocks) compute theirs once from the settled
inputs, and everyone exits initialization.
"""

from __future__ import annotations

import copy
import ctypes
from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any, Protocol, TypeVar

import fmpy
import numpy as np
from fmpy.fmi2 import (
    FMU2Slave,
    defaultCallbacks,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2LastSuccessfulTime,
    fmi2Terminated,
)

from .blocks import Block
from .model import FmuEntry, Value
from .native import NativeBlock, NativeCalls, function_address

T = TypeVar("T")


class RunError(RuntimeError):
    """A co-simulation run that failed; the message names the instance, the call and the time.
    ``partial``: the rows recorded before the failure (a DataFrame), when the run got that far."""

    partial: Any = None


class Terminated(RunError):
    """An FMU ended the simulation (fmi2DoStep returned fmi2Discard with fmi2Terminated true)
    in the step from ``t``: the run stops there, cleanly, with every row recorded before it.
    ``last``: the FMU's fmi2LastSuccessfulTime, where it says (it got that far in the step)."""

    def __init__(self, message: str, t: float, last: float | None = None):
        super().__init__(message)
        self.t, self.last = t, last


class Participant(Protocol):
    """What a master needs of a participant. ``u`` is always in the order of ``inputs``; the
    returned arrays are in the order of ``outputs`` and may be reused by the next call."""

    name: str
    inputs: list[str]
    outputs: list[str]
    iterative_start: bool  # initial outputs exchanged with the others before exiting initialization

    def enter_initialization(self, t0: float, stop_time: float) -> None: ...

    def initial_outputs(self, t0: float, u: np.ndarray) -> np.ndarray: ...

    def exit_initialization(self, t0: float, u: np.ndarray) -> np.ndarray: ...

    def do_step(self, t: float, h: float, u: np.ndarray, slopes: np.ndarray | None = None) -> None: ...

    def get_outputs(self, t: float) -> np.ndarray: ...

    def get_state(self, t: float) -> Any: ...

    def set_state(self, state: Any, t: float) -> None: ...

    def free_state(self, state: Any) -> None: ...

    def close(self) -> None: ...


class BlockParticipant:
    """A Python block in a run; ``outputs`` are the block's, ``inputs`` its (connected) inputs.
    A block with a ``native()`` method may be stepped by the native stepper instead
    (:meth:`make_native`)."""

    iterative_start = False

    def __init__(self, name: str, block: Block):
        self.name = name
        self.block = block
        self.inputs = list(block.inputs)
        self.outputs = list(block.outputs)
        self.last = np.zeros(len(self.outputs))
        self.native: NativeBlock | None = None
        self._asked = False

    def make_native(self) -> bool:
        """Ask the block once for its C twin (``native()``, made from the block's state now, after
        its start); False when it has none (no such method, or it returned None)."""
        if not self._asked:
            self._asked = True
            maker = getattr(self.block, "native", None)
            if maker is not None:
                try:
                    self.native = maker()
                except Exception as error:  # noqa: BLE001 - user code: name the block
                    raise RunError(f"{self.name} (block): native() failed: {type(error).__name__}: {error}") from error
        return self.native is not None

    def native_calls(self) -> NativeCalls:
        """The C twin's calls for the native stepper (after make_native returned True)."""
        assert self.native is not None
        return self.native.calls(len(self.inputs), len(self.outputs))

    def fail(self, what: str, t: float | None, error: str, status: int | None = None) -> None:
        """Raise the RunError of a failed native step, with the C twin's message."""
        detail = (self.native.message() if self.native is not None else "") or error
        at = f" at t = {t:.6g} s" if t is not None else ""
        raise RunError(f"{self.name} (block): step{at} failed: {detail}") from None

    def _call(self, what: str, action: Callable[[], Any], t: float) -> np.ndarray:
        try:
            values = np.asarray(action(), dtype=float)
        except RunError:
            raise
        except Exception as error:  # noqa: BLE001 - any failure of user code names the block
            raise RunError(f"{self.name} (block): {what} at t = {t:.6g} s failed: "
                           f"{type(error).__name__}: {error}") from error
        if values.shape != (len(self.outputs),):
            raise RunError(f"{self.name} (block): {what} at t = {t:.6g} s returned {values.size} values; "
                           f"expected {len(self.outputs)} ({', '.join(self.outputs)})")
        return values

    def enter_initialization(self, t0: float, stop_time: float) -> None:
        """Nothing to do: a block starts in ``initial_outputs``."""

    def initial_outputs(self, t0: float, u: np.ndarray) -> np.ndarray:
        self.last = self._call("start", lambda: self.block.start(t0, u), t0)
        return self.last

    def exit_initialization(self, t0: float, u: np.ndarray) -> np.ndarray:
        return self.last

    def do_step(self, t: float, h: float, u: np.ndarray, slopes: np.ndarray | None = None) -> None:
        """Blocks compute their outputs at t + h from ``u``; ``slopes`` are not used."""
        self.last = self._call("step", lambda: self.block.step(t, h, u), t)

    def get_outputs(self, t: float) -> np.ndarray:
        return self.last

    def get_state(self, t: float) -> Any:
        """The block's state (its ``get_state()``, else a deep copy of its attributes) and its last outputs."""
        getter = getattr(self.block, "get_state", None)
        try:
            state = getter() if getter is not None else copy.deepcopy(vars(self.block))
        except Exception as error:  # noqa: BLE001 - user code
            raise RunError(f"{self.name} (block): get_state at t = {t:.6g} s failed: {error}") from error
        return state, self.last.copy()

    def set_state(self, state: Any, t: float) -> None:
        block_state, last = state
        setter = getattr(self.block, "set_state", None)
        try:
            if setter is not None:
                setter(block_state)
            else:
                vars(self.block).update(copy.deepcopy(block_state))
        except Exception as error:  # noqa: BLE001 - user code
            raise RunError(f"{self.name} (block): set_state at t = {t:.6g} s failed: {error}") from error
        self.last = last.copy()

    def free_state(self, state: Any) -> None:
        """Nothing to free: the state is a Python object."""

    def close(self) -> None:
        """Free the C twin, if one was made."""
        if self.native is not None:
            self.native.close()


class FmuParticipant:
    """An FMU instance in a run; ``inputs`` are its connected inputs, ``outputs`` the variables
    read from it (connected or recorded), both fixed by :meth:`configure`."""

    iterative_start = True

    def __init__(self, entry: FmuEntry, unzip_root: Path):
        self.name = entry.name
        self.entry = entry
        self.messages: list[str] = []
        folder = unzip_root / entry.name
        fmpy.extract(str(entry.path), str(folder))
        md = entry.description
        self.refs = {v.name: v.valueReference for v in md.modelVariables}
        self.types = {v.name: str(v.type) for v in md.modelVariables}
        self.variability = {v.name: str(v.variability) for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(folder),
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=entry.name)
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self._callbacks.allocateMemory = defaultCallbacks.allocateMemory
        self._callbacks.freeMemory = defaultCallbacks.freeMemory
        self._call("fmi2Instantiate", lambda: self.fmu.instantiate(callbacks=self._callbacks))
        self.inputs: list[str] = []
        self.outputs: list[str] = []
        self.input_values = np.zeros(0)
        self.read_values = np.zeros(0)
        self.can_interpolate = bool(getattr(md.coSimulation, "canInterpolateInputs", False))

    def _log(self, env, instance, status, category, message) -> None:
        if status >= 2:  # discard, error, fatal
            self.messages.append(message.decode(errors="replace"))

    def _call(self, what: str, action: Callable[[], T], t: float | None = None) -> T:
        try:
            return action()
        except Exception as error:  # noqa: BLE001 - FMPy raises plain Exceptions on fmi2Error
            self.fail(what, t, str(error), getattr(error, "status", None))
            raise  # not reached

    def fail(self, what: str, t: float | None, error: str, status: int | None = None) -> None:
        """Raise the RunError of the failed call ``what``, with what the FMU logged (else
        ``error``); :class:`Terminated` when a step was discarded because the FMU ended the
        simulation (fmi2Terminated)."""
        if what == "fmi2DoStep" and status == DISCARD and self._terminated():
            last = self._last_successful_time()
            reached = last if last is not None and t is not None and last > t else t
            when = f" at t = {reached:.6g} s" if reached is not None else ""
            said = f" ({'; '.join(self.messages[-1:])})" if self.messages else ""
            raise Terminated(f"{self.name} ({self.entry.path.name}) ended the simulation{when}{said}", t or 0.0, last)
        detail = "; ".join(self.messages[-3:]) or error
        at = f" at t = {t:.6g} s" if t is not None else ""
        raise RunError(f"{self.name} ({self.entry.path.name}): {what}{at} failed: {detail}") from None

    def _last_successful_time(self) -> float | None:
        """fmi2GetRealStatus(fmi2LastSuccessfulTime) [s], None where the FMU cannot say."""
        try:
            return float(self.fmu.getRealStatus(fmi2LastSuccessfulTime))
        except Exception:  # noqa: BLE001 - optional in FMI 2.0
            return None

    @property
    def discrete_inputs(self) -> np.ndarray:
        """Per connected input: whether it is discrete (not a continuous Real), which the
        iterative master never interpolates."""
        return np.array([self.types[n] != "Real" or self.variability.get(n) == "discrete" for n in self.inputs],
                        dtype=bool)

    def _terminated(self) -> bool:
        """fmi2GetBooleanStatus(fmi2Terminated), False where the FMU cannot say."""
        try:
            return bool(self.fmu.getBooleanStatus(fmi2Terminated))
        except Exception:  # noqa: BLE001 - an FMU without the status: an ordinary discard
            return False

    @property
    def real_only(self) -> bool:
        """Whether every input set and variable read is a Real (one fmi2SetReal and one
        fmi2GetReal per step; the native stepper can step it)."""
        return self._inputs.real_only and self._reads.real_only

    def configure(self, inputs: list[str], reads: list[str]) -> None:
        """Fix the inputs set and the variables read at every step (preallocated arrays)."""
        self.inputs, self.outputs = list(inputs), list(reads)
        self._inputs = _Typed(self.inputs, self.types, self.refs)
        self._reads = _Typed(self.outputs, self.types, self.refs)
        self._in_refs = (ctypes.c_uint * max(1, len(inputs)))(*[self.refs[n] for n in inputs])
        self._read_refs = (ctypes.c_uint * max(1, len(reads)))(*[self.refs[n] for n in reads])
        self.input_values = np.zeros(len(inputs))
        self.input_slopes = np.zeros(len(inputs))
        self._orders = (ctypes.c_int * max(1, len(inputs)))(*([1] * len(inputs)))
        self._slope_pointer = self.input_slopes.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self.read_values = np.zeros(len(reads))
        self._in_pointer = self.input_values.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
        self._read_pointer = self.read_values.ctypes.data_as(ctypes.POINTER(ctypes.c_double))

    def native_calls(self) -> NativeCalls:
        """The instance and its fmi2SetReal, fmi2GetReal, fmi2DoStep for the native stepper."""
        dll = self.fmu.dll
        return NativeCalls(self.fmu.component, function_address(dll, "fmi2SetReal"),
                           function_address(dll, "fmi2GetReal"), function_address(dll, "fmi2DoStep"),
                           self.input_references, self.output_references)

    @property
    def input_references(self) -> list[int]:
        """Value references of the connected inputs, in the order of configure."""
        return list(self._in_refs)[:len(self.inputs)]

    @property
    def output_references(self) -> list[int]:
        """Value references of the variables read, in the order of configure."""
        return list(self._read_refs)[:len(self.outputs)]

    def set_values(self, names: dict[str, Value]) -> None:
        """Set variables by name, one call per FMI type (fmi2SetReal, fmi2SetInteger, ...)."""
        by_type: dict[str, dict[str, Value]] = {}
        for name, value in names.items():
            kind = "Integer" if self.types[name] == "Enumeration" else self.types[name]
            by_type.setdefault(kind, {})[name] = value
        for kind, values in by_type.items():
            self._call(f"fmi2Set{kind}", partial(getattr(self.fmu, f"set{kind}"), [self.refs[n] for n in values],
                                                 list(values.values())))

    def enter_initialization(self, t0: float, stop_time: float) -> None:
        """fmi2SetupExperiment, the parameters and start values, fmi2EnterInitializationMode."""
        self._call("fmi2SetupExperiment", lambda: self.fmu.setupExperiment(startTime=t0, stopTime=stop_time))
        self.set_values(self.entry.parameters)
        self.set_values(self.entry.start)
        self._call("fmi2EnterInitializationMode", self.fmu.enterInitializationMode)

    def initial_outputs(self, t0: float, u: np.ndarray) -> np.ndarray:
        self.set_inputs(u, t0)
        return self.get_outputs(t0)

    def exit_initialization(self, t0: float, u: np.ndarray) -> np.ndarray:
        self.set_inputs(u, t0)
        self._call("fmi2ExitInitializationMode", self.fmu.exitInitializationMode)
        return self.get_outputs(t0)

    def set_inputs(self, values: np.ndarray, t: float) -> None:
        """Set all connected inputs (values in the order given to configure): one fmi2SetReal
        for Real inputs, one call per other type present."""
        if not self.inputs:
            return
        self.input_values[:] = values
        if self._inputs.real_only:
            self._call("fmi2SetReal", lambda: self.fmu.fmi2SetReal(self.fmu.component, self._in_refs,
                                                                   len(self.inputs), self._in_pointer), t)
        else:
            self._inputs.set(self, self.input_values, t)

    def get_outputs(self, t: float) -> np.ndarray:
        """All read variables (one fmi2GetReal for Real ones, one call per other type present);
        the returned array is reused by the next call."""
        if self.outputs and self._reads.real_only:
            self._call("fmi2GetReal", lambda: self.fmu.fmi2GetReal(self.fmu.component, self._read_refs,
                                                                   len(self.outputs), self._read_pointer), t)
        elif self.outputs:
            self._reads.get(self, self.read_values, t)
        return self.read_values

    def do_step(self, t: float, h: float, u: np.ndarray, slopes: np.ndarray | None = None) -> None:
        """Set the inputs at ``t`` (held over the step, or interpolated with ``slopes`` [1/s] where
        the FMU can interpolate inputs), then fmi2DoStep from ``t`` to ``t + h``."""
        self.set_inputs(u, t)
        if slopes is not None and self.inputs and self._inputs.real_only:
            self.input_slopes[:] = slopes
            self._call("fmi2SetRealInputDerivatives",
                       lambda: self.fmu.fmi2SetRealInputDerivatives(self.fmu.component, self._in_refs, len(self.inputs),
                                                                    self._orders, self._slope_pointer), t)
        self._call("fmi2DoStep", lambda: self.fmu.fmi2DoStep(self.fmu.component, t, h, 1), t)

    def reset(self) -> None:
        """fmi2Reset: back to the state after instantiation (a new run on the same instance)."""
        self._call("fmi2Reset", self.fmu.reset)

    def terminate(self) -> None:
        """fmi2Terminate at the end of a run (the instance may then be reset)."""
        self._call("fmi2Terminate", self.fmu.terminate)

    def get_state(self, t: float) -> Any:
        """fmi2GetFMUstate: a copy of the whole instance (integrator memory included)."""
        return self._call("fmi2GetFMUstate", self.fmu.getFMUstate, t)

    def set_state(self, state: Any, t: float) -> None:
        self._call("fmi2SetFMUstate", lambda: self.fmu.setFMUstate(state), t)

    def free_state(self, state: Any) -> None:
        self._call("fmi2FreeFMUstate", lambda: self.fmu.freeFMUstate(state))

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


#: fmi2Status fmi2Discard.
DISCARD = 2


class _Typed:
    """Variables of an FMU grouped by FMI type for the fmi2Set/Get calls: value references and
    positions (in the caller's order) per type. Integer and Enumeration share fmi2Get/SetInteger;
    Booleans travel as fmi2Boolean (an int) and are held as 1.0 / 0.0."""

    def __init__(self, names: list[str], types: dict[str, str], refs: dict[str, int]):
        unknown = [n for n in names if types[n] not in ("Real", "Integer", "Enumeration", "Boolean")]
        if unknown:
            raise RunError(f"variables {unknown}: type {types[unknown[0]]} cannot be exchanged at every step")
        # kind -> (value references, positions, a buffer of the kind's C type), made once
        self.groups: dict[str, tuple[Any, np.ndarray, Any]] = {}
        for kind in ("Real", "Integer", "Boolean"):
            positions = [k for k, n in enumerate(names) if _call_type(types[n]) == kind]
            if positions:
                references = (ctypes.c_uint * len(positions))(*[refs[names[k]] for k in positions])
                buffer = ((ctypes.c_double if kind == "Real" else ctypes.c_int) * len(positions))()
                self.groups[kind] = (references, np.array(positions, dtype=int), buffer)
        self.real_only = set(self.groups) <= {"Real"}

    def set(self, participant: FmuParticipant, values: np.ndarray, t: float) -> None:
        fmu = participant.fmu
        for kind, (references, positions, buffer) in self.groups.items():
            chosen = values[positions].tolist()
            buffer[:] = chosen if kind == "Real" else [int(round(v)) for v in chosen]
            participant._call(f"fmi2Set{kind}", partial(getattr(fmu, f"fmi2Set{kind}"), fmu.component, references,
                                                         len(references), buffer), t)

    def get(self, participant: FmuParticipant, out: np.ndarray, t: float) -> None:
        fmu = participant.fmu
        for kind, (references, positions, buffer) in self.groups.items():
            participant._call(f"fmi2Get{kind}", partial(getattr(fmu, f"fmi2Get{kind}"), fmu.component, references,
                                                         len(references), buffer), t)
            out[positions] = buffer[:]


def _call_type(variable_type: str) -> str:
    """The type whose fmi2Get/Set functions a variable uses (Enumeration: Integer's)."""
    return "Integer" if variable_type == "Enumeration" else variable_type
