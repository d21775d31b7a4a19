"""The masters' inner loop for FMU participants in C (``stepper.c``), loaded with ctypes.

The Jacobi and Gauss-Seidel masters hand their FMU participants to a :class:`NativeStepper`:
one ctypes call steps a group of FMUs (gather inputs, fmi2SetReal, fmi2DoStep, fmi2GetReal,
scatter outputs, finite check), on the stepper's own threads where the group has several, and a
system without Python blocks runs whole stretches of steps in one call. The FMUs see the same
calls in the same order as from the Python master, so the results are identical (tests).

``stepper.c`` is compiled on first use with the C compiler (``$CC`` or ``cc``) into the user's
cache folder (``$ROVER_COSIM_CACHE`` or ``~/.cache/rover-cosim``), named by a digest of the source,
written atomically so that parallel workers may race. Where no compiler works the masters stay
in Python: :func:`unavailable_reason` says why.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
from collections.abc import Sequence
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

SOURCE = Path(__file__).with_name("stepper.c")
#: What a failed unit's call was (stepper.c).
CALLS = {1: "fmi2SetReal", 2: "fmi2DoStep", 3: "fmi2GetReal", 4: "finite outputs"}
NOT_FINITE = 4


def cache_folder() -> Path:
    configured = os.environ.get("ROVER_COSIM_CACHE")
    if configured:
        return Path(configured)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "rover-cosim"


def _compile(target: Path) -> None:
    compiler = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not compiler:
        raise OSError("no C compiler ($CC, cc or gcc) on PATH")
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=target.parent) as scratch:
        built = Path(scratch) / target.name
        command = [compiler, "-O2", "-shared", "-fPIC", "-pthread", str(SOURCE), "-o", str(built), "-lm"]
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
    library.stepper_run.argtypes = [pointer, pointer, pointer, integer, integer, pointer, integer, pointer, pointer]
    for name, restype in (("stepper_failed_call", integer), ("stepper_status", integer),
                          ("stepper_seconds", real)):
        getattr(library, name).restype = restype
        getattr(library, name).argtypes = [pointer, integer]
    library.stepper_free.restype = None
    library.stepper_free.argtypes = [pointer]
    return library


@cache
def _library() -> ctypes.CDLL | str:
    """The loaded stepper library, or why there is none."""
    digest = hashlib.sha256(SOURCE.read_bytes()).hexdigest()[:16]
    target = cache_folder() / f"stepper-{digest}.so"
    try:
        if not target.exists():
            _compile(target)
        return _declare(ctypes.CDLL(str(target)))
    except OSError as error:
        return f"native stepper unavailable ({error}); the masters step FMUs from Python"


def unavailable_reason() -> str | None:
    """None when the native stepper works here, else why not."""
    library = _library()
    return library if isinstance(library, str) else None


def _function_address(dll: Any, name: str) -> int:
    return ctypes.cast(getattr(dll, name), ctypes.c_void_p).value or 0


class NativeStepper:
    """Steps ``units`` (FMU participants, each with its input and output slots in the value
    vector) group after group (``groups``: lists of positions in ``units``); Jacobi gathers every
    input at ``t`` before any unit steps."""

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

        fmus = [unit.fmu for unit in self.units]
        self._handle = library.stepper_new(
            len(self.units), array(ctypes.c_void_p, [fmu.component for fmu in fmus]),
            array(ctypes.c_void_p, [_function_address(fmu.dll, "fmi2SetReal") for fmu in fmus]),
            array(ctypes.c_void_p, [_function_address(fmu.dll, "fmi2GetReal") for fmu in fmus]),
            array(ctypes.c_void_p, [_function_address(fmu.dll, "fmi2DoStep") for fmu in fmus]),
            array(ctypes.c_int, [len(unit.inputs) for unit in self.units]),
            flat(ctypes.c_uint, [list(unit.input_references) for unit in self.units]),
            flat(ctypes.c_longlong, [inputs[i] for i in order]),
            array(ctypes.c_int, [len(unit.outputs) for unit in self.units]),
            flat(ctypes.c_uint, [list(unit.output_references) for unit in self.units]),
            flat(ctypes.c_longlong, [outputs[i] for i in order]),
            len(groups), array(ctypes.c_int, list(np.cumsum([0] + [len(g) for g in groups]))),
            int(jacobi), max(1, threads))
        if not self._handle:
            raise MemoryError("native stepper: out of memory or no threads")
        self._keep = keep
        self._reached = ctypes.c_int(0)

    def step_group(self, values: np.ndarray, index: int, t: float, h: float) -> int:
        """Step the group holding unit ``index`` (a position in the master's participants)."""
        return self._check(self.library.stepper_group(self._handle, _pointer(values), self.group_of[index], t, h), t)

    def step(self, values: np.ndarray, t: float, h: float) -> int:
        return self._check(self.library.stepper_step(self._handle, _pointer(values), t, h), t)

    def run(self, values: np.ndarray, times: np.ndarray, first: int, last: int, record: np.ndarray,
            rows: np.ndarray) -> int:
        """Steps ``first`` .. ``last`` - 1, recording ``values[record]`` in ``rows[k + 1]``; returns
        -1, or the unit that produced a non-finite output (values hold them; the caller names it),
        raising the other failures. ``self.reached``: the steps completed."""
        failed = self.library.stepper_run(self._handle, _pointer(values), _pointer(times), first, last,
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
        unit.fail(CALLS[call], t, f"status {status}")
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


__all__ = ["NativeStepper", "cache_folder", "unavailable_reason"]
