"""The masters' inner loop for FMU participants in C (``stepper.c``), loaded with ctypes.

The Jacobi and Gauss-Seidel masters hand their FMU participants to a :class:`NativeStepper`:
one ctypes call steps a group of FMUs (gather inputs, fmi2SetReal, fmi2DoStep, fmi2GetReal,
scatter outputs, finite check), on the stepper's own threads where the group has several, and a
system whose participants are all stepped natively runs whole stretches of steps in one call. The
FMUs see the same calls in the same order as from the Python master, so the results are
identical (tests).

A block may be stepped natively as well: its ``native()`` returns a :class:`NativeBlock`, a C
object with functions shaped like fmi2SetReal, fmi2DoStep and fmi2GetReal (inputs and outputs
numbered 0, 1, ... in the block's order), which the stepper calls as it calls an FMU.

``stepper.c`` (and a native block's source) is compiled on first use with the C compiler (``$CC``
or ``cc``) into the user's cache folder (``$ROVER_COSIM_CACHE`` or ``~/.cache/rover-cosim``), named
by a digest of the source and the headers beside it that it includes, written atomically so
that parallel workers may race. Where no compiler works the masters stay in Python: :func:`unavailable_reason` says why.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from rover_cosim.common.scratch import cache_folder

SOURCE = Path(__file__).with_name("stepper.c")
#: What a failed unit's call was (stepper.c).
CALLS = {1: "fmi2SetReal", 2: "fmi2DoStep", 3: "fmi2GetReal", 4: "finite outputs", 5: "fmi2SetRealInputDerivatives"}
NOT_FINITE = 4


def _compile(source: Path, target: Path) -> None:
    compiler = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not compiler:
        raise OSError("no C compiler ($CC, cc or gcc) on PATH")
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=target.parent) as scratch:
        built = Path(scratch) / target.name
        # -ffp-contract=off: no fused multiply-adds, so that C arithmetic rounds as Python's does
        # (native blocks give their Python twins' results bit for bit).
        command = [compiler, "-O2", "-ffp-contract=off", "-shared", "-fPIC", "-pthread", str(source), "-o",
                   str(built), "-lm"]
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            raise OSError(f"{' '.join(command)} failed: {done.stderr.strip()[:500]}")
        os.replace(built, target)


def _declare(library: ctypes.CDLL) -> ctypes.CDLL:
    pointer, integer, real = ctypes.c_void_p, ctypes.c_int, ctypes.c_double
    library.stepper_new.restype = pointer
    library.stepper_new.argtypes = [integer] + [pointer] * 10 + [integer, pointer, integer, integer]
    library.stepper_step.restype = integer
    library.stepper_step.argtypes = [pointer, pointer, real, real]
    library.stepper_group.restype = integer
    library.stepper_group.argtypes = [pointer, pointer, integer, real, real]
    library.stepper_run.restype = integer
    library.stepper_run.argtypes = [pointer, pointer, pointer, integer, integer, real, pointer, integer, pointer,
                                    pointer]
    library.stepper_ramp.restype = integer
    library.stepper_ramp.argtypes = [pointer, integer, pointer, pointer]
    library.stepper_mark.restype = None
    library.stepper_mark.argtypes = [pointer, pointer]
    for name, restype in (("stepper_failed_call", integer), ("stepper_status", integer),
                          ("stepper_seconds", real)):
        getattr(library, name).restype = restype
        getattr(library, name).argtypes = [pointer, integer]
    library.stepper_free.restype = None
    library.stepper_free.argtypes = [pointer]
    return library


def _checksum(target: Path) -> Path:
    return target.with_name(target.name + ".sha256")


def _cache_problem(target: Path) -> str | None:
    """Why the cached library ``target`` may not be loaded (None: it is the one we compiled,
    whole): no checksum beside it, or a content that does not match it (cut short, or another
    library under its name). Checked before loading: a truncated library would crash the process."""
    try:
        expected = _checksum(target).read_text().strip()
    except OSError:
        return "it has no checksum beside it (not compiled here, or its compilation was cut short)"
    if hashlib.sha256(target.read_bytes()).hexdigest() != expected:
        return "its content does not match its checksum (cut short or replaced)"
    return None


def _write_checksum(target: Path) -> None:
    handle, temporary = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    with os.fdopen(handle, "w") as stream:
        stream.write(hashlib.sha256(target.read_bytes()).hexdigest() + "\n")
    os.replace(temporary, _checksum(target))


def local_headers(source: Path) -> list[Path]:
    """The headers that ``source`` includes with quotes (``#include "name.h"``, relative to the
    including file), and those they include in turn, each once in the order first met: the
    cached library's digest covers them as well."""
    found: list[Path] = []
    pending = [source]
    while pending:
        including = pending.pop(0)
        names = re.findall(r'^\s*#\s*include\s+"([^"]+)"', including.read_text(), flags=re.MULTILINE)
        for name in names:
            header = including.parent / name
            if header.is_file() and header.resolve() not in {h.resolve() for h in found}:
                found.append(header)
                pending.append(header)
    return found


@cache
def load_library(source: Path, symbols: tuple[str, ...] = ()) -> ctypes.CDLL | str:
    """The C file ``source`` compiled into a shared library (cached by its digest, with a
    checksum beside it) and loaded, or why that failed. A cached library that is not whole or
    not ours is named in one line on stderr and compiled again; ``symbols``: functions it must have."""
    digest = hashlib.sha256(b"".join(path.read_bytes() for path in (source, *local_headers(source)))).hexdigest()[:16]
    target = cache_folder() / f"{source.stem}-{digest}.so"
    try:
        problem = _cache_problem(target) if target.exists() else "absent"
        if problem is not None:
            if problem != "absent" and _checksum(target).exists():  # no checksum: a cache of an older version
                print(f"rover-cosim: native cache {target}: {problem}; compiled again", file=sys.stderr)
            _compile(source, target)
            _write_checksum(target)
        library = ctypes.CDLL(str(target))
    except OSError as error:
        return str(error)
    missing = [name for name in symbols if not hasattr(library, name)]
    if missing:
        return f"{target} lacks {', '.join(missing)} (remove it to have it compiled again)"
    return library


@cache
def _library() -> ctypes.CDLL | str:
    """The loaded stepper library, or why there is none."""
    library = load_library(SOURCE, ("stepper_new", "stepper_step", "stepper_group", "stepper_run",
                                     "stepper_failed_call", "stepper_status", "stepper_seconds", "stepper_free",
                                     "stepper_ramp", "stepper_mark"))
    if isinstance(library, str):
        return f"native stepper unavailable ({library}); the masters step FMUs from Python"
    return _declare(library)


def unavailable_reason() -> str | None:
    """None when the native stepper works here, else why not."""
    library = _library()
    return library if isinstance(library, str) else None


def function_address(dll: Any, name: str) -> int:
    return ctypes.cast(getattr(dll, name), ctypes.c_void_p).value or 0


@dataclass(frozen=True)
class NativeCalls:
    """What the stepper calls for one participant: ``component`` and the addresses of functions
    shaped like fmi2SetReal, fmi2GetReal and fmi2DoStep, with the value references of the
    inputs it sets and the outputs it reads (in the participant's order)."""

    component: int
    set_real: int
    get_real: int
    do_step: int
    input_references: list[int]
    output_references: list[int]
    #: shaped like fmi2SetRealInputDerivatives (0: none; a unit that ramps inputs needs it)
    set_derivatives: int = 0


def doubles(values: object) -> ctypes.Array:
    """``values`` (any array-like) flattened into a C array of doubles for a twin's constructor
    (one element at least, so that an empty table is still a valid pointer)."""
    flat = np.ascontiguousarray(values, dtype=float).ravel()
    return (ctypes.c_double * max(1, flat.size))(*flat.tolist())


class NativeBlock:
    """A block's C twin: ``component`` (made by the library) and the library's functions
    ``<prefix>_set_real``, ``<prefix>_get_real``, ``<prefix>_do_step`` (fmi2-shaped: status 0 ok,
    3 error), ``<prefix>_message`` (the last error, a C string) and ``<prefix>_free``. Inputs
    and outputs are numbered 0, 1, ... in the block's order. ``keep``: buffers the component
    points into, kept alive with it."""

    def __init__(self, library: ctypes.CDLL, component: int, prefix: str, keep: Sequence[Any] = ()):
        self.library, self.component, self.prefix, self._keep = library, component, prefix, list(keep)
        getattr(library, f"{prefix}_message").restype = ctypes.c_char_p
        getattr(library, f"{prefix}_message").argtypes = [ctypes.c_void_p]
        getattr(library, f"{prefix}_free").argtypes = [ctypes.c_void_p]
        self._free: Callable[[int], None] | None = getattr(library, f"{prefix}_free")

    def calls(self, n_inputs: int, n_outputs: int) -> NativeCalls:
        def address(name: str) -> int:
            return function_address(self.library, f"{self.prefix}_{name}")

        return NativeCalls(self.component, address("set_real"), address("get_real"), address("do_step"),
                           list(range(n_inputs)), list(range(n_outputs)))

    def message(self) -> str:
        text: bytes | None = getattr(self.library, f"{self.prefix}_message")(self.component)
        return (text or b"").decode(errors="replace")

    def close(self) -> None:
        if self._free is not None:
            self._free(self.component)
            self._free = None


class NativeStepper:
    """Steps ``units`` (participants with ``native_calls()`` and ``fail()``, each with its input
    and output slots in the value vector) group after group (``groups``: lists of positions in
    ``units``); Jacobi gathers every input at ``t`` before any unit steps."""

    def __init__(self, units: Sequence[Any], inputs: Sequence[np.ndarray], outputs: Sequence[np.ndarray],
                 groups: Sequence[Sequence[int]], jacobi: bool, threads: int):
        library = _library()
        assert not isinstance(library, str), library
        self.library = library
        order = [i for group in groups for i in group]
        self.units = [units[i] for i in order]
        self.position = {i: k for k, i in enumerate(order)}
        self.group_of = {i: g for g, group in enumerate(groups) for i in group}
        keep: list[Any] = []  # ctypes/numpy buffers the C side points into, alive as long as self

        def array(kind: Any, values: Sequence[Any]) -> Any:
            made = (kind * max(1, len(values)))(*values)
            keep.append(made)
            return made

        def flat(kind: Any, per_unit: Sequence[Any]) -> Any:
            return array(kind, [int(v) for values in per_unit for v in values])

        calls: list[NativeCalls] = [unit.native_calls() for unit in self.units]
        self._calls = calls
        self._handle = library.stepper_new(
            len(self.units), array(ctypes.c_void_p, [c.component for c in calls]),
            array(ctypes.c_void_p, [c.set_real for c in calls]),
            array(ctypes.c_void_p, [c.get_real for c in calls]),
            array(ctypes.c_void_p, [c.do_step for c in calls]),
            array(ctypes.c_int, [len(c.input_references) for c in calls]),
            flat(ctypes.c_uint, [c.input_references for c in calls]),
            flat(ctypes.c_longlong, [inputs[i] for i in order]),
            array(ctypes.c_int, [len(c.output_references) for c in calls]),
            flat(ctypes.c_uint, [c.output_references for c in calls]),
            flat(ctypes.c_longlong, [outputs[i] for i in order]),
            len(groups), array(ctypes.c_int, list(np.cumsum([0] + [len(g) for g in groups]))),
            int(jacobi), max(1, threads))
        if not self._handle:
            raise MemoryError("native stepper: out of memory or no threads")
        self._keep = keep
        self._reached = ctypes.c_int(0)

    def ramp(self, index: int, ramped: np.ndarray) -> None:
        """Unit ``index`` (a position in the master's participants) takes the inputs flagged in
        ``ramped`` as ramps (gauss-seidel-interpolated): their values at the step's start, the
        slopes to their values when it steps by fmi2SetRealInputDerivatives."""
        position = self.position[index]
        address = self._calls[position].set_derivatives
        if not address:
            raise ValueError(f"{self.units[position].name}: no fmi2SetRealInputDerivatives to ramp its inputs with")
        flags = (ctypes.c_int * max(1, len(ramped)))(*[int(bool(v)) for v in ramped])
        if self.library.stepper_ramp(self._handle, position, address, flags) != 0:
            raise MemoryError("native stepper: out of memory")

    def mark(self, values: np.ndarray) -> None:
        """The ramped inputs' values at the step's start (before a step made group by group)."""
        self.library.stepper_mark(self._handle, _pointer(values))

    def step_group(self, values: np.ndarray, index: int, t: float, h: float) -> int:
        """Step the group holding unit ``index`` (a position in the master's participants)."""
        return self._check(self.library.stepper_group(self._handle, _pointer(values), self.group_of[index], t, h), t)

    def step(self, values: np.ndarray, t: float, h: float) -> int:
        return self._check(self.library.stepper_step(self._handle, _pointer(values), t, h), t)

    def run(self, values: np.ndarray, times: np.ndarray, first: int, last: int, record: np.ndarray,
            rows: np.ndarray, h: float = 0.0) -> int:
        """Steps ``first`` .. ``last`` - 1 (from ``times[k]`` to ``times[k + 1]``, or by ``h`` [s]
        when > 0), recording ``values[record]`` in ``rows[k + 1]``; returns -1, or the unit that
        produced a non-finite output (values hold them; the caller names it), raising the other
        failures. ``self.reached``: the steps completed."""
        failed = self.library.stepper_run(self._handle, _pointer(values), _pointer(times), first, last, h,
                                          _pointer(record), record.size, _pointer(rows), ctypes.byref(self._reached))
        return self._check(failed, float(times[min(self._reached.value, len(times) - 1)]))

    @property
    def reached(self) -> int:
        return self._reached.value

    def _check(self, failed: int, t: float) -> int:
        if failed < 0:
            return -1
        call = self.library.stepper_failed_call(self._handle, failed)
        if call == NOT_FINITE:
            return failed
        unit = self.units[failed]
        status = self.library.stepper_status(self._handle, failed)
        unit.fail(CALLS[call], t, f"status {status}", status)
        return failed  # not reached: fail raises

    def seconds(self) -> dict[str, float]:
        """Time inside each unit's FMI calls so far [s], by participant name."""
        return {unit.name: self.library.stepper_seconds(self._handle, k) for k, unit in enumerate(self.units)}

    def close(self) -> None:
        if self._handle:
            self.library.stepper_free(self._handle)
            self._handle = None


def _pointer(array: np.ndarray) -> int:
    assert array.flags.c_contiguous
    return array.ctypes.data


__all__ = ["NativeBlock", "NativeCalls", "NativeStepper", "cache_folder", "load_library", "unavailable_reason"]
