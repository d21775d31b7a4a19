"""Participants of a co-simulation: the protocol the masters step, and its two kinds.

- :class:`FmuParticipant`: an FMU instance run as Co-Simulation (FMI 2.0 or 3.0, FMPy's slave
  classes) with batched, preallocated value exchange per type (``fmi_access``; one fmi2SetReal of
  all connected inputs and one fmi2GetReal of all needed variables per step for an all-Real FMI
  2.0 FMU), errors turned into :class:`RunError` with the FMU's own message; its Model Exchange
  twin, which the engine integrates, is ``model_exchange.ModelExchangeParticipant``;
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
from pathlib import Path
from typing import Any, Protocol, TypeVar

import numpy as np
from fmpy.fmi2 import (
    FMU2Model,
    FMU2Slave,
    defaultCallbacks,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2LastSuccessfulTime,
    fmi2Terminated,
)
from fmpy.fmi3 import FMU3Model, FMU3Slave

from .blocks import Block, takes_step
from .fmi_access import Exchange, StringTable, set_by_name
from .model import Element, FmuEntry, Value, declared_start
from .native import NativeBlock, NativeCalls, function_address

T = TypeVar("T")


class RunError(RuntimeError):
    """A co-simulation run that failed; the message names the instance, the call and the time.
    ``partial``: the rows recorded before the failure (a DataFrame), when the run got that far."""

    partial: Any = None
    #: Per FMU instance, its error messages too long to print, whole (``master.fmu_log``).
    fmu_log: dict[str, list[str]] = {}


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

    def __init__(self, name: str, block: Block, step: float | None = None):
        self.name = name
        self.block = block
        #: s, the run's communication step, told to a block whose ``start`` takes it
        self.step = step if takes_step(block) else None
        self.inputs = list(block.inputs)
        self.outputs = list(block.outputs)
        self.last = np.zeros(len(self.outputs))
        self.native: NativeBlock | None = None
        self._asked = self._asked_again = False

    def ready_for_native(self) -> bool:
        """Whether a block stepped in Python now offers its C twin: its ``native_ready()`` (an
        optional method; e.g. an adaptive controller once it has switched to the law its twin
        steps) says so; :meth:`make_native` then asks it again."""
        ready = getattr(self.block, "native_ready", None)
        if self.native is not None or self._asked_again or ready is None or not ready():
            return False
        self._asked, self._asked_again = False, True  # asked again once: a block that then has none stays in Python
        return True

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
        step = self.step
        if step is not None:
            self.last = self._call("start", lambda: self.block.start(t0, u, step), t0)
        else:  # a block of the earlier protocol, start(t0, u0)
            self.last = self._call("start", lambda: self.block.start(t0, u), t0)  # type: ignore[call-arg]
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


#: How many of an FMU's error messages a participant keeps, and how long one may be (characters).
MESSAGES_KEPT, MESSAGE_LENGTH = 20, 500
#: Characters of an FMU's messages longer than MESSAGE_LENGTH kept whole for the run's FMU log.
LONG_KEPT = 1 << 20


def log_text(raw: bytes | str) -> str:
    """An FMU's message for a log file: whole, control characters but line ends and tabs as \\xNN."""
    text = raw.decode(errors="replace") if isinstance(raw, bytes) else str(raw)
    return "".join(c if c.isprintable() or c in "\n\t" else f"\\x{ord(c):02x}" for c in text)


def clean_message(raw: bytes | str | None) -> str:
    """An FMU's log message as it may reach a terminal: control characters (escape sequences, CR,
    LF) shown as spaces or ``\\xNN``, at most MESSAGE_LENGTH characters (the rest counted), a NULL
    message said as such."""
    if raw is None:
        return "(the FMU logged a NULL message)"
    text = raw.decode(errors="replace") if isinstance(raw, bytes) else str(raw)
    shown = "".join(c if c.isprintable() else (" " if c in "\r\n\t" else f"\\x{ord(c):02x}")
                    for c in text[:MESSAGE_LENGTH])
    return shown + (f"... ({len(text)} characters)" if len(text) > MESSAGE_LENGTH else "")


def interpolates_inputs(entry: FmuEntry) -> bool:
    """Whether the master may give ``entry``'s inputs slopes over a step: an FMI 2.0 FMU run as
    Co-Simulation that says canInterpolateInputs (FMI 3.0 has no fmi3SetRealInputDerivatives)."""
    return entry.fmi_version == 2 and entry.interface == "co-simulation" and bool(
        getattr(entry.capabilities, "canInterpolateInputs", False))


class FmuParticipant:
    """An FMU instance run through its Co-Simulation interface (FMI 2.0 or 3.0); ``inputs`` are
    its connected inputs, ``outputs`` the variables read from it (connected or recorded), both
    fixed by :meth:`configure`. ``folder``: where the FMU is unpacked (``unpacking.unpack``);
    ``strings``: the run's String table (``fmi_access``)."""

    iterative_start = True

    def __init__(self, entry: FmuEntry, folder: Path, strings: StringTable | None = None):
        self.name = entry.name
        self.entry = entry
        self.version = entry.fmi_version
        self.strings = strings if strings is not None else StringTable()
        self.messages: list[str] = []
        #: error messages longer than MESSAGE_LENGTH, whole (at most LONG_KEPT characters in all)
        self.long_messages: list[str] = []
        md = entry.description
        variables = entry.variables()  # the elements of FMI 3.0 arrays too, as name[i]
        self.refs = {name: v.valueReference for name, v in variables.items()}
        self.types = {name: str(v.type) for name, v in variables.items()}
        self.variability = {name: str(v.variability) for name, v in variables.items()}
        #: the elements of arrays among them: name -> (its index in the array, the array's size)
        self.elements = {name: (v.index, v.size) for name, v in variables.items() if isinstance(v, Element)}
        #: the same with the array's start values, for setting parameters and start values by element
        starts: dict[str, list[Any]] = {}  # per array: its elements' declared starts, in order
        for v in variables.values():
            if isinstance(v, Element):
                declared = declared_start(v)
                starts.setdefault(v.array.name, []).append(declared if declared is not None else 0)
        self.array_starts = {name: (v.index, starts[v.array.name]) for name, v in variables.items()
                             if isinstance(v, Element)}
        self.fmu = self._instantiate(md, folder)
        self.inputs: list[str] = []
        self.outputs: list[str] = []
        self.input_values = np.zeros(0)
        self.read_values = np.zeros(0)
        self.can_interpolate = interpolates_inputs(entry)
        self.configure([], [])

    def _instantiate(self, md: Any, folder: Path) -> Any:
        """The FMPy object of the FMU's interface, instantiated with a logger that keeps the
        FMU's error messages."""
        classes = {(2, "co-simulation"): FMU2Slave, (3, "co-simulation"): FMU3Slave,
                   (2, "model-exchange"): FMU2Model, (3, "model-exchange"): FMU3Model}
        cls = classes[(self.version, self.entry.interface)]
        try:
            fmu = cls(guid=md.guid, unzipDirectory=str(folder),
                      modelIdentifier=self.entry.capabilities.modelIdentifier, instanceName=self.entry.name)
        except Exception as error:  # noqa: BLE001 - FMPy: a library that does not load
            raise RunError(f"{self.name} ({self.entry.path.name}): its binary for this platform does not load: "
                           f"{error}") from None
        if self.version == 2:
            self._callbacks = fmi2CallbackFunctions()
            self._callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
            self._callbacks.allocateMemory = defaultCallbacks.allocateMemory
            self._callbacks.freeMemory = defaultCallbacks.freeMemory
            self._call("fmi2Instantiate", lambda: fmu.instantiate(callbacks=self._callbacks))
        else:
            kind = "CoSimulation" if self.entry.interface == "co-simulation" else "ModelExchange"
            self._call(f"fmi3Instantiate{kind}", lambda: fmu.instantiate(logMessage=self._log3))
        return fmu

    def _log(self, env, instance, status, category, message) -> None:
        if status >= 2:  # discard, error, fatal: kept (the last MESSAGES_KEPT) to name in an error
            self.messages.append(clean_message(message))
            del self.messages[:-MESSAGES_KEPT]
            if message is not None and len(message) > MESSAGE_LENGTH \
                    and sum(map(len, self.long_messages)) < LONG_KEPT:
                self.long_messages.append(log_text(message)[:LONG_KEPT])

    def _log3(self, env, status, category, message) -> None:
        self._log(env, None, status, category, message)

    def _call(self, what: str, action: Callable[[], T], t: float | None = None) -> T:
        try:
            return action()
        except RunError:
            raise
        except Exception as error:  # noqa: BLE001 - FMPy raises plain Exceptions on fmi2Error
            self.fail(what, t, str(error), getattr(error, "status", None))
            raise  # not reached

    def fail(self, what: str, t: float | None, error: str, status: int | None = None) -> None:
        """Raise the RunError of the failed call ``what``, with what the FMU logged (else
        ``error``); :class:`Terminated` when a step was discarded because the FMU ended the
        simulation (fmi2Terminated)."""
        if what == "fmi2DoStep" and status == DISCARD and self._terminated():
            self.end(t or 0.0, self._last_successful_time())
        detail = "; ".join(self.messages[-3:]) or error
        at = f" at t = {t:.6g} s" if t is not None else ""
        raise RunError(f"{self.name} ({self.entry.path.name}): {what}{at} failed: {detail}") from None

    def end(self, t: float, last: float | None) -> None:
        """Raise :class:`Terminated`: the FMU ended the simulation in the step from ``t`` (having
        got to ``last``, where it says)."""
        reached = last if last is not None and last > t else t
        said = f" ({'; '.join(self.messages[-1:])})" if self.messages else ""
        raise Terminated(f"{self.name} ({self.entry.path.name}) ended the simulation at t = {reached:.6g} s{said}",
                         t, last)

    def _last_successful_time(self) -> float | None:
        """fmi2GetRealStatus(fmi2LastSuccessfulTime) [s], None where the FMU cannot say."""
        try:
            return float(self.fmu.getRealStatus(fmi2LastSuccessfulTime))
        except Exception:  # noqa: BLE001 - optional in FMI 2.0
            return None

    @property
    def discrete_inputs(self) -> np.ndarray:
        """Per connected input: whether it is discrete (not a continuous Real or Float), which
        the iterative master never interpolates."""
        return np.array([self.types[n] not in ("Real", "Float64", "Float32") or self.variability.get(n) == "discrete"
                         for n in self.inputs], dtype=bool)

    def _terminated(self) -> bool:
        """fmi2GetBooleanStatus(fmi2Terminated), False where the FMU cannot say."""
        try:
            return bool(self.fmu.getBooleanStatus(fmi2Terminated))
        except Exception:  # noqa: BLE001 - an FMU without the status: an ordinary discard
            return False

    @property
    def real_only(self) -> bool:
        """Whether this is an FMI 2.0 Co-Simulation FMU whose every input set and variable read
        is a Real (one fmi2SetReal and one fmi2GetReal per step; the native stepper can step it)."""
        return (self.version == 2 and self.entry.interface == "co-simulation" and self._inputs.real_only
                and self._reads.real_only)

    def configure(self, inputs: list[str], reads: list[str]) -> None:
        """Fix the inputs set and the variables read at every step (preallocated arrays)."""
        self.inputs, self.outputs = list(inputs), list(reads)
        try:
            self._inputs = Exchange(self.version, self.inputs, self.types, self.refs, self.strings, self.elements)
            self._reads = Exchange(self.version, self.outputs, self.types, self.refs, self.strings, self.elements)
        except ValueError as problem:
            raise RunError(f"{self.name} ({self.entry.path.name}): {problem}") from None
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
                           self.input_references, self.output_references,
                           function_address(dll, "fmi2SetRealInputDerivatives") if self.can_interpolate else 0)

    @property
    def input_references(self) -> list[int]:
        """Value references of the connected inputs, in the order of configure."""
        return list(self._in_refs)[:len(self.inputs)]

    @property
    def output_references(self) -> list[int]:
        """Value references of the variables read, in the order of configure."""
        return list(self._read_refs)[:len(self.outputs)]

    def set_values(self, names: dict[str, Value], t: float | None = None) -> None:
        """Set variables by name, one call per FMI type (fmi2SetReal, fmi2SetInteger, ...)."""
        if names:
            set_by_name(self.fmu, self.version, names, self.types, self.refs,
                        lambda what, act: self._call(what, act, t), self.array_starts)

    def enter_initialization(self, t0: float, stop_time: float) -> None:
        """The parameters and start values and Initialization Mode (FMI 2.0: after
        fmi2SetupExperiment; FMI 3.0: fmi3EnterInitializationMode with the start and stop time)."""
        fmu = self.fmu
        if self.version == 2:
            self._call("fmi2SetupExperiment", lambda: fmu.setupExperiment(tolerance=self.tolerance, startTime=t0,
                                                                          stopTime=stop_time))
        self.set_values(self.entry.parameters)
        self.set_values(self.entry.start)
        if self.version == 2:
            self._call("fmi2EnterInitializationMode", fmu.enterInitializationMode)
        else:
            self._call("fmi3EnterInitializationMode",
                       lambda: fmu.enterInitializationMode(tolerance=self.tolerance, startTime=t0, stopTime=stop_time))

    #: The tolerance told to the FMU at its start (None: the FMU's own choice).
    tolerance: float | None = None

    def initial_outputs(self, t0: float, u: np.ndarray) -> np.ndarray:
        self.set_inputs(u, t0)
        return self.get_outputs(t0)

    def exit_initialization(self, t0: float, u: np.ndarray) -> np.ndarray:
        self.set_inputs(u, t0)
        self._call(f"fmi{self.version}ExitInitializationMode", self.fmu.exitInitializationMode)
        return self.get_outputs(t0)

    def _exchange(self, what: str, t: float) -> Callable[[str, Callable[[], Any]], Any]:
        return lambda call, action: self._call(call, action, t)

    def set_inputs(self, values: np.ndarray, t: float) -> None:
        """Set all connected inputs (values in the order given to configure): one fmi2SetReal
        for Real inputs of an FMI 2.0 FMU, else one call per type present."""
        if not self.inputs:
            return
        self.input_values[:] = values
        if self._inputs.real_only:
            self._call("fmi2SetReal", lambda: self.fmu.fmi2SetReal(self.fmu.component, self._in_refs,
                                                                   len(self.inputs), self._in_pointer), t)
        else:
            self._inputs.set(self.fmu, self.input_values, self._exchange("set", t))

    def get_outputs(self, t: float) -> np.ndarray:
        """All read variables (one fmi2GetReal for Real ones of an FMI 2.0 FMU, else one call per
        type present); the returned array is reused by the next call."""
        if self.outputs and self._reads.real_only:
            self._call("fmi2GetReal", lambda: self.fmu.fmi2GetReal(self.fmu.component, self._read_refs,
                                                                   len(self.outputs), self._read_pointer), t)
        elif self.outputs:
            self._reads.get(self.fmu, self.read_values, self._exchange("get", t))
        return self.read_values

    def do_step(self, t: float, h: float, u: np.ndarray, slopes: np.ndarray | None = None) -> None:
        """Set the inputs at ``t`` (held over the step, or interpolated with ``slopes`` [1/s] where
        the FMU can interpolate inputs), then fmi2DoStep (fmi3DoStep) from ``t`` to ``t + h``;
        :class:`Terminated` where the FMU ends the simulation in the step."""
        self.set_inputs(u, t)
        if self.version == 3:
            ended, last = self._call("fmi3DoStep", lambda: self.fmu.doStep(t, h, True)[1::2], t)
            if ended:
                self.end(t, last)
            return
        if slopes is not None and self.inputs and self._inputs.real_only:
            self.input_slopes[:] = slopes
            self._call("fmi2SetRealInputDerivatives",
                       lambda: self.fmu.fmi2SetRealInputDerivatives(self.fmu.component, self._in_refs, len(self.inputs),
                                                                    self._orders, self._slope_pointer), t)
        self._call("fmi2DoStep", lambda: self.fmu.fmi2DoStep(self.fmu.component, t, h, 1), t)

    def reset(self) -> None:
        """fmi2Reset (fmi3Reset): back to the state after instantiation (a new run on the same instance)."""
        self._call(f"fmi{self.version}Reset", self.fmu.reset)

    def terminate(self) -> None:
        """fmi2Terminate (fmi3Terminate) at the end of a run (the instance may then be reset)."""
        self._call(f"fmi{self.version}Terminate", self.fmu.terminate)

    def get_state(self, t: float) -> Any:
        """fmi2GetFMUstate (fmi3GetFMUState): a copy of the whole instance (integrator memory included)."""
        if self.version == 2:
            return self._call("fmi2GetFMUstate", self.fmu.getFMUstate, t)
        return self._call("fmi3GetFMUState", self.fmu.getFMUState, t)

    def set_state(self, state: Any, t: float) -> None:
        if self.version == 2:
            self._call("fmi2SetFMUstate", lambda: self.fmu.setFMUstate(state), t)
        else:
            self._call("fmi3SetFMUState", lambda: self.fmu.setFMUState(state), t)

    def free_state(self, state: Any) -> None:
        if self.version == 2:
            self._call("fmi2FreeFMUstate", lambda: self.fmu.freeFMUstate(state))
        else:
            self._call("fmi3FreeFMUState", lambda: self.fmu.freeFMUState(state))

    def close(self) -> None:
        """Terminate and free the instance. FMPy's freeInstance unloads the library as well (one
        dlclose per load): it is unloaded here only when freeInstance did not get that far, since
        a second dlclose would unload the library under another instance sharing it."""
        try:
            self.fmu.terminate()
        except Exception:  # noqa: BLE001 - closing after a failure must not mask it
            pass
        try:
            self.fmu.freeInstance()
            return
        except Exception:  # noqa: BLE001 - closing after a failure must not mask it
            pass
        try:
            self.fmu.freeLibrary()
        except Exception as error:  # noqa: BLE001 - unloading is best effort
            self.messages.append(f"freeLibrary: {error}")


#: fmi2Status fmi2Discard.
DISCARD = 2
