"""FMUs run in a child process of their own, so that one that crashes, aborts, calls exit() or
hangs ends its run with a message instead of taking the tool down (libcosim's proxy-fmu idea).

:class:`IsolatedFmu` is a participant like ``participants.FmuParticipant`` (and its Model
Exchange twin): every call goes through a pipe to a child process that holds the real participant
(:func:`_serve`). One message per communication step carries the inputs, the step and the outputs
back. What the parent makes of the child's end:

- the child died (a signal: SIGSEGV, SIGABRT, ...; or exit(): any status) -> :class:`RunError`
  naming the FMU, the FMI call and the time, e.g. ``fmi2DoStep at t = 0.5 s: the FMU's process
  ended with SIGSEGV``; the master keeps the rows recorded so far as partial, as for any failure;
- a call that does not return within ``timeout`` seconds -> the child is killed, RunError saying so;
- Ctrl-C or SIGTERM of the command: the signal's handler interrupts the parent's wait, its
  exception ends the run and :meth:`IsolatedFmu.close` kills the child.

A child never outlives the command: it ignores SIGINT (the parent decides), and on Linux the
kernel kills it when the parent dies (PR_SET_PDEATHSIG). Closing waits for fmi2Terminate and
fmi2FreeInstance at most :data:`CLOSE_SECONDS` (or the timeout); what goes wrong there is said in
``problems`` (the run's rows are kept: the master has them before the FMUs are freed).

Strings cross the pipe as text (each side numbers them in its own String table).
"""

from __future__ import annotations

import math
import multiprocessing
import os
import pickle
import signal
import socket
import struct
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from .fmi_access import StringTable
from .model import FmuEntry
from .participants import RunError, Terminated, interpolates_inputs

#: The first byte of a step message (t, h and the inputs as float64) and of its answer (the outputs).
STEP = b"S"
#: The message that ends the child's loop.
END = b"E"
#: recv's flag to ask without waiting (none on Windows: no spinning there).
DONT_WAIT = getattr(socket, "MSG_DONTWAIT", 0)
#: s, how long each side asks for the other's answer without sleeping before it sleeps: waking
#: a sleeping process costs ~50-70 us (measured on a 2-core VM: a 20 us step round trip took
#: 96 us sleeping and 30 us spinning 50-1000 us); longer steps sleep after this.
SPIN_PARENT, SPIN_CHILD = 200e-6, 100e-6
#: s, how long closing (fmi2Terminate, fmi2FreeInstance) may take before the child is killed.
CLOSE_SECONDS = 10.0
#: s, how long a child may take to load the FMU's binary and instantiate it (if no timeout is set).
START_SECONDS = 120.0


def isolated(entry: FmuEntry, timeout: float | None = None) -> bool:
    """Whether ``entry`` runs in a child process: its ``isolation`` (``ISOLATION``) says so, or
    says "auto" and the FMU is not one this project generated or a time limit is set (only an FMU
    in a child process can be ended); never in a daemonic process (multiprocessing's pool workers),
    which may not start processes."""
    if multiprocessing.current_process().daemon:  # a daemonic process may not start one: in-process there
        return False
    if entry.isolation == "auto":
        return timeout is not None or not generated_here(entry)
    return entry.isolation == "process"


#: How this project's exporter (``fmubuild``) begins the generationTool of its FMUs.
OWN_GENERATOR = "rover-cosim fmubuild"


def generated_here(entry: FmuEntry) -> bool:
    """Whether this project's exporter generated the FMU (its modelDescription's generationTool)."""
    return str(entry.description.generationTool or "").startswith(OWN_GENERATOR)


def signal_name(code: int) -> str:
    """A process's exit code as words: "SIGSEGV" for -11, "exit status 3" for 3."""
    if code < 0:
        try:
            return signal.Signals(-code).name
        except ValueError:
            return f"signal {-code}"
    return f"exit status {code}"


class _Ended(Exception):
    """The child is gone (crashed, exited or killed)."""


class _Wire:
    """One end of a socket pair carrying messages (a 4-byte length, then the bytes): a message
    each way is one system call each side where it fits the buffer."""

    def __init__(self, sock: socket.socket):
        self.sock = sock
        self.buffer = bytearray(1 << 16)

    def send(self, data: bytes) -> None:
        self.sock.sendall(len(data).to_bytes(4, "little") + data)

    def receive(self, timeout: float | None = None, spin: float = 0.0) -> bytes:
        """The next message; socket.timeout after ``timeout`` seconds (None: no limit); EOFError
        when the other end is gone. A signal's handler that raises (Ctrl-C) ends the wait.
        ``spin``: s, how long to ask again without sleeping first (a sleeping process takes tens
        of microseconds to wake up, more than a short FMU step: measured in the module's text)."""
        view = memoryview(self.buffer)
        got = self._spin(view, spin) if spin > 0 and DONT_WAIT else -1
        if got < 0:
            if timeout != self.sock.gettimeout():  # a system call: only when the limit changes
                self.sock.settimeout(timeout)
            got = self.sock.recv_into(view)
        while got < 4:
            if got == 0 or (more := self.sock.recv_into(view[got:])) == 0:
                raise EOFError
            got += more
        size = int.from_bytes(self.buffer[:4], "little") + 4
        if size > len(self.buffer):  # a message longer than the buffer: grow it (no view may hold it then)
            view.release()
            self.buffer.extend(bytes(size - len(self.buffer)))
            view = memoryview(self.buffer)
        while got < size:
            more = self.sock.recv_into(view[got:size])
            if more == 0:
                raise EOFError
            got += more
        return bytes(self.buffer[4:size])

    def _spin(self, view: memoryview, seconds: float) -> int:
        """What arrived within ``seconds`` of asking without sleeping (bytes; -1: nothing yet)."""
        if self.sock.gettimeout() is not None:
            self.sock.settimeout(None)
        end = time.perf_counter() + seconds
        while True:
            try:
                return self.sock.recv_into(view, 0, DONT_WAIT)
            except BlockingIOError:
                if time.perf_counter() > end:
                    return -1

    def close(self) -> None:
        self.sock.close()


class IsolatedFmu:
    """An FMU participant whose instance lives in a child process (see the module's text).
    ``timeout``: s, the longest any one call may take (None: no limit)."""

    iterative_start = True

    def __init__(self, entry: FmuEntry, folder: Path, strings: StringTable, relative_tolerance: float,
                 timeout: float | None = None):
        self.name, self.entry, self.timeout = entry.name, entry, timeout
        self.strings = strings
        self.inputs: list[str] = []
        self.outputs: list[str] = []
        self.problems: list[str] = []
        self.long_messages: list[str] = []  # the child's participant's, fetched when closing
        self.takes_signals = entry.interface == "model-exchange"
        self.version = entry.fmi_version
        self.can_interpolate = interpolates_inputs(entry)
        self._last, self._at = np.zeros(0), math.nan
        self._string_in: list[int] = []
        self._string_out: list[int] = []
        context = _context()
        ours, child = socket.socketpair()
        self._conn = _Wire(ours)
        self._process = context.Process(target=_serve, args=(child, entry, str(folder), relative_tolerance),
                                        name=f"rover-cosim FMU {entry.name}", daemon=True)
        try:
            self._process.start()
        except OSError as error:  # no process to be had (the system's limit, memory)
            ours.close()
            child.close()
            raise RunError(f"{self._said()}: its process could not be started ({error.strerror or error}); "
                           "--isolation none runs it in this process") from None
        child.close()
        self._closed = False
        self._busy = False  # a call sent and not answered (an interrupted run): closing kills the child
        self._call("fmi2Instantiate" if self.version == 2 else "fmi3Instantiate", "ready", (), None,
                   timeout if timeout is not None else START_SECONDS)

    # --- the pipe ------------------------------------------------------------------------------
    def _call(self, what: str, method: str, args: tuple | bytes, t: float | None, timeout: float | None = None) -> Any:
        """Call ``method`` of the child's participant (``args`` as bytes: a step message, answered
        with the outputs' bytes); RunError where the child fails, dies or takes longer than the
        time limit."""
        if self._closed:
            raise RunError(f"{self._said()}: {what}: the FMU's process has ended")
        limit = self.timeout if timeout is None else timeout
        try:
            self._busy = True
            self._conn.send(args if isinstance(args, bytes) else pickle.dumps((method, args), protocol=5))
            reply = self._receive(limit, "the FMU's time limit, --fmu-timeout" if timeout is None else "")
            self._busy = False
        except _Ended as ended:
            raise RunError(f"{self._said()}: {what}{_at(t)}: {ended}") from None
        except (BrokenPipeError, ConnectionError, EOFError, OSError):
            raise RunError(f"{self._said()}: {what}{_at(t)}: {self._death()}") from None
        kind, value = reply
        if kind == "ok":
            return value
        if kind == "terminated":
            message, t_end, last = value
            raise Terminated(message, t_end, last)
        raise RunError(value)

    def _receive(self, limit: float | None, which: str) -> Any:
        """The child's reply, waiting ``limit`` seconds at most (None: without end; ``which``
        limit it is, to say); the command's signal handlers (Ctrl-C, SIGTERM) end the wait."""
        try:
            data = self._conn.receive(limit, SPIN_PARENT)
        except TimeoutError:
            self._kill()
            raise _Ended(f"no answer within {limit:g} s{f' ({which})' if which else ''}; its process was ended") \
                from None
        return ("ok", data[1:]) if data[:1] == STEP else pickle.loads(data)

    @property
    def pid(self) -> int | None:
        """The child process's id (None before it started)."""
        return self._process.pid

    def _death(self) -> str:
        """Why the child is gone, once it is."""
        self._process.join(2.0)
        self._closed = True
        code = self._process.exitcode
        if code is None:
            self._kill()
            return "the FMU's process stopped answering and was ended"
        if code < 0:
            return f"the FMU's process ended with {signal_name(code)} (a crash inside the FMU)"
        return (f"the FMU's process ended with {signal_name(code)} (the FMU called exit() or ended its process)")

    def _kill(self) -> None:
        self._closed = True
        if self._process.is_alive():
            self._process.kill()
        self._process.join(5.0)

    def _said(self) -> str:
        return f"{self.name} ({self.entry.path.name})"

    # --- the participant ------------------------------------------------------------------------
    def configure(self, inputs: list[str], reads: list[str]) -> None:
        self.inputs, self.outputs = list(inputs), list(reads)
        types = self.entry.variables()
        self._string_in = [k for k, n in enumerate(self.inputs) if str(types[n].type) == "String"]
        self._string_out = [k for k, n in enumerate(self.outputs) if str(types[n].type) == "String"]
        self.discrete_inputs = self._call("configure", "configure", (self.inputs, self.outputs), None)
        self._last, self._at = np.zeros(len(self.outputs)), math.nan

    def _send_inputs(self, u: np.ndarray) -> tuple[np.ndarray, list[str]]:
        u = np.array(u, dtype=float)
        return u, [self.strings.text(u[k]) for k in self._string_in]

    def _got(self, reply: tuple[np.ndarray, list[str]], t: float) -> np.ndarray:
        values, texts = reply
        for k, text in zip(self._string_out, texts):
            values[k] = self.strings.number(text)
        self._last, self._at = values, t
        return values

    def enter_initialization(self, t0: float, stop_time: float) -> None:
        self._call("Initialization Mode", "enter_initialization", (t0, stop_time), t0)

    def initial_outputs(self, t0: float, u: np.ndarray) -> np.ndarray:
        return self._got(self._call("initial outputs", "initial_outputs", (t0, *self._send_inputs(u)), t0), t0)

    def exit_initialization(self, t0: float, u: np.ndarray) -> np.ndarray:
        return self._got(self._call(f"fmi{self.version}ExitInitializationMode", "exit_initialization",
                                    (t0, *self._send_inputs(u)), t0), t0)

    def do_step(self, t: float, h: float, u: np.ndarray, slopes: np.ndarray | None = None) -> None:
        """One step in the child, the outputs at ``t + h`` brought back with it (as raw bytes
        where no String crosses and no slopes are given: no pickling on the way)."""
        what = f"fmi{self.version}DoStep" if self.entry.interface == "co-simulation" else "integration"
        if slopes is not None or self._string_in or self._string_out:
            self._got(self._call(what, "step", (t, h, *self._send_inputs(u), slopes), t), t + h)
            return
        message = STEP + struct.pack("<dd", t, h) + np.ascontiguousarray(u, dtype=float).tobytes()
        self._last = np.frombuffer(self._call(what, "", message, t), dtype=float).copy()
        self._at = t + h

    def get_outputs(self, t: float) -> np.ndarray:
        """The outputs at ``t``: those the last call brought where it was at ``t``, else read."""
        if t == self._at:
            return self._last
        return self._got(self._call(f"fmi{self.version}Get", "get_outputs", (t,), t), t)

    def take_signals(self, u: np.ndarray, fed: np.ndarray, t: float, jump: bool = False) -> bool:
        taken, reply = self._call("input event", "take_signals", (t, *self._send_inputs(u), fed, jump), t)
        self._got(reply, t)
        return bool(taken)

    def get_state(self, t: float) -> Any:
        return self._call(f"fmi{self.version}GetFMUstate", "get_state", (t,), t)

    def set_state(self, state: Any, t: float) -> None:
        self._got(self._call(f"fmi{self.version}SetFMUstate", "set_state", (state, t), t), t)

    def free_state(self, state: Any) -> None:
        self._call(f"fmi{self.version}FreeFMUstate", "free_state", (state,), None)

    def close(self) -> None:
        """fmi2Terminate and fmi2FreeInstance in the child, then the child's end; a crash or hang
        there is said in ``problems`` (and the child killed), not raised."""
        if self._closed:
            self._process.join(0.1)
            return
        if self._busy:  # the run was interrupted inside a call: the child cannot be asked to close
            self._kill()
            self._conn.close()
            return
        limit = min(self.timeout, CLOSE_SECONDS) if self.timeout is not None else CLOSE_SECONDS
        try:
            self.long_messages = self._call("its messages", "long_messages", (), None, limit)
            self._call(f"fmi{self.version}Terminate/FreeInstance", "close", (), None, limit)
        except RunError as error:
            self.problems.append(str(error))
        self._closed = True
        try:
            self._conn.send(END)  # the child's loop ends
        except OSError:
            pass
        self._process.join(limit)
        if self._process.is_alive():
            self._process.kill()
            self._process.join(5.0)
        self._conn.close()


def _at(t: float | None) -> str:
    return f" at t = {t:.6g} s" if t is not None else ""


def _context() -> Any:
    """fork where the system has it (a child is a copy of this process, engine imported: a few ms,
    and nothing of the caller's script is run again), else spawn (Windows)."""
    return multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn")


def _orphan_guard() -> None:
    """The child ignores Ctrl-C (its parent decides), ends at SIGTERM without a word, keeps quiet
    when the FMU crashes it (no Python fault report: the parent says what happened) and, on Linux,
    is killed when the parent dies."""
    import faulthandler

    faulthandler.disable()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass


class _Child:
    """The child's side: the real participant and the String translation of its ports."""

    def __init__(self, entry: FmuEntry, folder: str, relative_tolerance: float):
        from .model_exchange import make_fmu_participant

        self.strings = StringTable()
        self.fmu = make_fmu_participant(entry, Path(folder), self.strings, relative_tolerance)
        self.entry = entry
        self.string_in: list[int] = []
        self.string_out: list[int] = []
        self.states: dict[int, Any] = {}

    def ready(self) -> None:
        """Instantiated (the constructor did it)."""

    def configure(self, inputs: list[str], reads: list[str]) -> list[bool]:
        self.fmu.configure(inputs, reads)
        types = self.entry.variables()
        self.string_in = [k for k, n in enumerate(inputs) if str(types[n].type) == "String"]
        self.string_out = [k for k, n in enumerate(reads) if str(types[n].type) == "String"]
        return list(self.fmu.discrete_inputs)

    def _inputs(self, u: np.ndarray, texts: list[str]) -> np.ndarray:
        for k, text in zip(self.string_in, texts):
            u[k] = self.strings.number(text)
        return u

    def _outputs(self, values: np.ndarray) -> tuple[np.ndarray, list[str]]:
        values = np.array(values, dtype=float)
        return values, [self.strings.text(values[k]) for k in self.string_out]

    def enter_initialization(self, t0: float, stop_time: float) -> None:
        self.fmu.enter_initialization(t0, stop_time)

    def initial_outputs(self, t0: float, u: np.ndarray, texts: list[str]) -> tuple[np.ndarray, list[str]]:
        return self._outputs(self.fmu.initial_outputs(t0, self._inputs(u, texts)))

    def exit_initialization(self, t0: float, u: np.ndarray, texts: list[str]) -> tuple[np.ndarray, list[str]]:
        return self._outputs(self.fmu.exit_initialization(t0, self._inputs(u, texts)))

    def step(self, t: float, h: float, u: np.ndarray, texts: list[str],
             slopes: np.ndarray | None) -> tuple[np.ndarray, list[str]]:
        self.fmu.do_step(t, h, self._inputs(u, texts), slopes)
        return self._outputs(self.fmu.get_outputs(t + h))

    def get_outputs(self, t: float) -> tuple[np.ndarray, list[str]]:
        return self._outputs(self.fmu.get_outputs(t))

    def fast_step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        """A step without Strings or slopes: the outputs at ``t + h``."""
        self.fmu.do_step(t, h, u)
        return self.fmu.get_outputs(t + h)

    def take_signals(self, t: float, u: np.ndarray, texts: list[str], fed: np.ndarray,
                     jump: bool = False) -> tuple[bool, Any]:
        taken = self.fmu.take_signals(self._inputs(u, texts), fed, t, jump)  # type: ignore[attr-defined]  # ME's
        return taken, self._outputs(self.fmu.get_outputs(t))

    def get_state(self, t: float) -> int:
        key = len(self.states) + 1 if not self.states else max(self.states) + 1
        self.states[key] = self.fmu.get_state(t)
        return key

    def set_state(self, key: int, t: float) -> tuple[np.ndarray, list[str]]:
        self.fmu.set_state(self.states[key], t)
        return self._outputs(self.fmu.get_outputs(t))

    def free_state(self, key: int) -> None:
        self.fmu.free_state(self.states.pop(key))

    def long_messages(self) -> list[str]:
        return list(self.fmu.long_messages)

    def close(self) -> None:
        self.fmu.close()


def _serve(sock: socket.socket, entry: FmuEntry, folder: str, relative_tolerance: float) -> None:
    """The child's loop: answer calls until told to end; the first ("ready") builds the participant."""
    _orphan_guard()
    conn = _Wire(sock)
    child: _Child | None = None
    while True:
        try:
            message = conn.receive(None, SPIN_CHILD)
        except (EOFError, OSError):
            break
        if message == END:
            break
        try:
            if message[:1] == STEP:  # t, h, the inputs as float64: the outputs' bytes back
                assert child is not None
                t, h = struct.unpack_from("<dd", message, 1)
                outputs = child.fast_step(t, h, np.frombuffer(message, dtype=float, offset=17).copy())
                conn.send(STEP + np.ascontiguousarray(outputs, dtype=float).tobytes())
                continue
            method, args = pickle.loads(message)
            if child is None:
                child = _Child(entry, folder, relative_tolerance)
            reply: tuple[str, Any] = ("ok", getattr(child, method)(*args))
        except Terminated as end:
            reply = ("terminated", (str(end), end.t, end.last))
        except RunError as error:
            reply = ("error", str(error))
        except Exception as error:  # noqa: BLE001 - anything else the FMU's wrapper raised: said, not a traceback
            reply = ("error", f"{entry.name} ({entry.path.name}): {type(error).__name__}: {error}")
        conn.send(pickle.dumps(reply))
    conn.close()
    os._exit(0)  # no interpreter teardown (atexit, the FMU library's destructors): the parent has what it needs
