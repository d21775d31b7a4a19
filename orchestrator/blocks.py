"""Python-side blocks that take part in a co-simulation like FMUs: sources and controllers.

The interface is small and mirrors an FMU slave at a fixed communication step:

- ``inputs`` and ``outputs``: variable names; ``units``: optional unit per variable (checked
  against the FMU variables a block is connected to);
- ``start(t0, u0, h) -> y0``: outputs at the start time, given the inputs there; ``h`` [s] is the
  run's communication step (a block that discretises a law at the step learns it here; a block
  written as ``start(t0, u0)`` still runs, without being told);
- ``step(t, h, u) -> y``: advance from ``t`` to ``t + h`` with the inputs ``u`` (the values the
  master algorithm makes available: at ``t`` for Jacobi, possibly at ``t + h`` for upstream
  participants under Gauss-Seidel) and return the outputs at ``t + h``.

Optional: ``feedthrough`` (bool; default True for a block with inputs: its outputs depend on
its inputs at the same instant, which the algebraic-loop check follows); ``ramped_outputs``
(names): outputs that move linearly over each step from their value at ``t`` to the one at
``t + h`` (a first-order hold, not a sample and hold), which ``gauss-seidel-interpolated`` gives
an FMU after the block that can interpolate its inputs as that line; ``get_state() -> state``
and ``set_state(state)`` for the iterative master, which repeats a step (without them the
master keeps a deep copy of the block's attributes); ``native() -> native.NativeBlock | None``:
the block's C twin, made from its state after ``start``, which the Jacobi and Gauss-Seidel masters
step from C with the FMUs (see ``orchestrator.native``; the closed-loop controller has one);
``use_native(enabled)``: told before the run steps whether C code may step for it (the system's
``native`` setting under an explicit master), for a block that calls C of its own from its Python
step (the adaptive controller's law while it calibrates).

Sources ignore their inputs (they have none). A user block is any class with this interface;
``type = "python"`` in a system file loads it from ``factory = "module:callable"`` (the module
is looked up beside the system file first); ``rover-cosim blocks`` lists the built-in types.
"""

from __future__ import annotations

import importlib
import inspect
import math
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np


class Block(Protocol):
    name: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]

    @property
    def units(self) -> Mapping[str, str]: ...

    def start(self, t0: float, u0: np.ndarray, h: float) -> np.ndarray: ...

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray: ...


class Source:
    """A block without inputs whose single output ``y`` is a function of time."""

    inputs: tuple[str, ...] = ()
    outputs: tuple[str, ...] = ("y",)

    def __init__(self, name: str, unit: str | None = None):
        self.name = name
        self.units = {"y": unit} if unit else {}

    def value(self, t: float) -> float:
        raise NotImplementedError

    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        return np.array([self.value(t0)])

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        return np.array([self.value(t + h)])


class Constant(Source):
    """y = value."""

    def __init__(self, name: str, value: float, unit: str | None = None):
        super().__init__(name, unit)
        self.constant = float(value)

    def value(self, t: float) -> float:
        return self.constant


class Step(Source):
    """y = offset before ``time`` [s], offset + height from then on."""

    def __init__(self, name: str, height: float, time: float = 0.0, offset: float = 0.0, unit: str | None = None):
        super().__init__(name, unit)
        self.height, self.time, self.offset = float(height), float(time), float(offset)
        #: s: where the signal jumps, for a Model Exchange FMU an input event there
        self.jump_times = np.array([self.time] if self.height != 0 else [])

    def value(self, t: float) -> float:
        return self.offset + (self.height if t >= self.time else 0.0)


class Ramp(Source):
    """y rises linearly by ``height`` over ``duration`` [s] from ``time`` [s], from ``offset``."""

    def __init__(self, name: str, height: float, duration: float, time: float = 0.0, offset: float = 0.0,
                 unit: str | None = None):
        super().__init__(name, unit)
        if not duration > 0:
            raise ValueError(f"block {name!r}: duration = {duration!r}: expected > 0 s")
        self.height, self.duration, self.time, self.offset = float(height), float(duration), float(time), float(offset)

    def value(self, t: float) -> float:
        fraction = min(max((t - self.time) / self.duration, 0.0), 1.0)
        return self.offset + self.height * fraction


class TanhStep(Source):
    """y = end + (begin - end) (1 - tanh((t - time)/width)) / 2: a smooth change from ``begin`` to
    ``end`` around ``time`` [s] over about ``width`` [s] (the rover's open-loop torque profile)."""

    def __init__(self, name: str, begin: float, end: float, time: float, width: float, unit: str | None = None):
        super().__init__(name, unit)
        if not width > 0:
            raise ValueError(f"block {name!r}: width = {width!r}: expected > 0 s")
        self.begin, self.end, self.time, self.width = float(begin), float(end), float(time), float(width)

    def value(self, t: float) -> float:
        return self.end + (self.begin - self.end) * 0.5 * (1.0 - math.tanh((t - self.time) / self.width))


class Table(Source):
    """y interpolated linearly in a table of (time [s], value); held constant outside it."""

    def __init__(self, name: str, time: Sequence[float], values: Sequence[float], unit: str | None = None):
        super().__init__(name, unit)
        times = np.asarray(time, dtype=float)
        data = np.asarray(values, dtype=float)
        if times.ndim != 1 or times.size < 1 or times.shape != data.shape:
            raise ValueError(f"block {name!r}: time and values must be lists of the same length >= 1 "
                             f"(got {times.size} and {data.size})")
        if np.any(np.diff(times) < 0):
            raise ValueError(f"block {name!r}: time must not decrease")
        self.times, self.data = times, data
        #: s: where the table jumps (a repeated time), for a Model Exchange FMU an input event there
        self.jump_times = repeated_times(times)

    def value(self, t: float) -> float:
        return float(np.interp(t, self.times, self.data))


def repeated_times(times: np.ndarray) -> np.ndarray:
    """The times [s] a non-decreasing time column holds twice or more: where a signal jumps."""
    return np.unique(times[1:][np.diff(times) == 0])


def _header(path: Path) -> list[str]:
    """The column names of a CSV file's first line (as written: pandas renames a repeated one)."""
    import csv

    with open(path, newline="", errors="replace") as stream:
        return [c.strip() for c in next(csv.reader(stream), [])]


class CsvInput:
    """Signals read from a CSV file, FMPy's convention: the first column is time [s], increasing
    (a repeated time is a step: from that time on the later row holds), every other column an
    output of that name, interpolated linearly, or held from row to row for the columns in
    ``hold`` (discrete signals: integers, Booleans as true/false or 1/0); before the first time
    the first row holds, after the last the last. ``types``: the FMI type of each output where
    it is not Real (e.g. {"k" = "Integer"}), so it may drive an input of that type."""

    inputs: tuple[str, ...] = ()

    def __init__(self, name: str, file: str | Path, hold: Sequence[str] = (), types: Mapping[str, str] | None = None):
        import pandas as pd

        self.name = name
        self.file = Path(file)
        try:
            table = pd.read_csv(self.file, skipinitialspace=True)
        except (OSError, ValueError) as error:
            raise ValueError(f"block {name!r}: file {self.file}: cannot be read as CSV ({error})") from None
        header = _header(self.file)
        twice = sorted({c for c in header if header.count(c) > 1})
        if twice:
            raise ValueError(f"block {name!r}: file {self.file}: column {twice[0]!r} appears more than once; "
                             "expected one column per signal")
        if table.shape[1] < 2 or len(table) < 1:
            raise ValueError(f"block {name!r}: file {self.file}: expected a time column and at least one signal "
                             f"column with at least one row (got {table.shape[1]} columns, {len(table)} rows)")
        table = table.replace({"true": 1.0, "false": 0.0, "True": 1.0, "False": 0.0})
        try:
            data = table.to_numpy(dtype=float)
        except ValueError as error:
            raise ValueError(f"block {name!r}: file {self.file}: every value must be a number, true or false "
                             f"({error})") from None
        self.times, self.values = data[:, 0], data[:, 1:]
        if not np.all(np.isfinite(data)):
            raise ValueError(f"block {name!r}: file {self.file}: empty or non-finite values")
        if np.any(np.diff(self.times) < 0):
            row = int(np.argmax(np.diff(self.times) < 0)) + 2
            raise ValueError(f"block {name!r}: file {self.file}: time decreases at data row {row}")
        self.outputs = tuple(str(c).strip() for c in table.columns[1:])
        unknown = sorted(set(hold) - set(self.outputs)) + sorted(set(types or {}) - set(self.outputs))
        if unknown:
            raise ValueError(f"block {name!r}: hold/types name columns {unknown} that {self.file.name} does not "
                             f"have (its columns: {', '.join(self.outputs)})")
        self.held = np.array([c in set(hold) for c in self.outputs], dtype=bool)
        self.types = dict(types or {})
        self.units: dict[str, str] = {}
        #: s: where the signals jump (a repeated time), for a Model Exchange FMU an input event there
        self.jump_times = repeated_times(self.times)

    def values_at(self, t: float) -> np.ndarray:
        """Every output at ``t`` [s]."""
        k = int(np.searchsorted(self.times, t, side="right")) - 1  # the last row at or before t
        if k < 0:
            return self.values[0].copy()
        if k >= len(self.times) - 1:
            return self.values[-1].copy()
        weight = (t - self.times[k]) / (self.times[k + 1] - self.times[k])
        interpolated = self.values[k] + weight * (self.values[k + 1] - self.values[k])
        return np.where(self.held, self.values[k], interpolated)

    def start(self, t0: float, u0: np.ndarray, h: float | None = None) -> np.ndarray:
        return self.values_at(t0)

    def step(self, t: float, h: float, u: np.ndarray) -> np.ndarray:
        return self.values_at(t + h)


BLOCK_TYPES: dict[str, type] = {
    "constant": Constant,
    "step": Step,
    "ramp": Ramp,
    "tanh_step": TanhStep,
    "table": Table,
    "csv": CsvInput,
}


#: Python block factories ("module:callable") an SSP archive's annotation may name; an archive
#: naming another is refused (it would run code chosen by whoever wrote the archive).
REGISTERED_FACTORIES: set[str] = set()


def register_factory(factory: str) -> None:
    """Allow SSP archives to name the Python block factory ``factory`` ("module:callable")."""
    if not isinstance(factory, str) or ":" not in factory:
        raise ValueError(f"{factory!r}: expected \"module:callable\"")
    REGISTERED_FACTORIES.add(factory)


def takes_step(block: object) -> bool:
    """Whether ``block.start`` takes the communication step (``start(t0, u0, h)``); a block written
    for the earlier protocol, ``start(t0, u0)``, is started without it."""
    try:
        parameters = list(inspect.signature(block.start).parameters.values())  # type: ignore[attr-defined]
    except (AttributeError, TypeError, ValueError):
        return False
    positional = [p for p in parameters if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    return len(positional) >= 3 or any(p.kind == p.VAR_POSITIONAL for p in parameters)


def make_block(name: str, kind: str, params: Mapping[str, Any], folder: Path | None = None) -> Block:
    """A block from its system-file entry; ValueError naming the block for bad entries. A
    ``type = "python"`` block's module is looked up in ``folder`` (the system file's) first."""
    if kind == "python":
        return _python_block(name, params, folder)
    if kind not in BLOCK_TYPES:
        raise ValueError(f"block {name!r}: type {kind!r}: expected one of {', '.join([*BLOCK_TYPES, 'python'])}")
    _check_keys(name, f"type {kind!r}", BLOCK_TYPES[kind], params)
    _check_numbers(name, kind, params)
    if kind == "csv" and folder is not None and isinstance(params.get("file"), str) \
            and not Path(params["file"]).is_absolute():
        params = {**params, "file": folder / params["file"]}
    try:
        return BLOCK_TYPES[kind](name=name, **params)
    except TypeError as error:
        raise ValueError(f"block {name!r} (type {kind}): {error}") from None


def _real(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


#: What each key that is not a single number must be: (check, what is expected).
_SHAPES: dict[str, tuple[Any, str]] = {
    "unit": (lambda v: isinstance(v, str) and bool(v), "text"),
    "file": (lambda v: isinstance(v, str) and bool(v), "text"),
    "hold": (lambda v: isinstance(v, (list, tuple)) and all(isinstance(x, str) for x in v), "a list of column names"),
    "types": (lambda v: isinstance(v, dict) and all(isinstance(x, str) for x in v.values()), "a table of type names"),
}


def _check_numbers(name: str, kind: str, params: Mapping[str, Any]) -> None:
    """ValueError naming the key, unless every key of a built-in block has its shape: numbers are
    finite real numbers (true, "575" or NaN are not), a table's time and values lists of them,
    unit and file text, hold a list of names, types a table of type names."""
    for key, value in params.items():
        if key in _SHAPES:
            check, expected = _SHAPES[key]
        elif kind == "table" and key in ("time", "values"):
            check, expected = (lambda v: isinstance(v, (list, tuple)) and all(_real(x) for x in v),
                               "a list of finite numbers")
        else:
            check, expected = _real, "a finite number"
        if not check(value):
            raise ValueError(f"block {name!r} (type {kind}): {key} = {value!r}: expected {expected}")


def _import(module_name: str, folder: Path | None) -> Any:
    """The module, looked up in ``folder`` first (a module beside the system file), then on sys.path."""
    if folder is not None and (folder / f"{module_name.split('.')[0]}.py").is_file():
        sys.path.insert(0, str(folder))
        try:
            return importlib.import_module(module_name)
        finally:
            sys.path.remove(str(folder))
    return importlib.import_module(module_name)


def _python_block(name: str, params: Mapping[str, Any], folder: Path | None = None) -> Block:
    """A ``type = "python"`` block made by its ``factory = "module:callable"`` with the other keys."""
    factory = params.get("factory")
    if not isinstance(factory, str) or ":" not in factory:
        raise ValueError(f"block {name!r}: type 'python' needs factory = \"module:callable\"")
    module_name, _, attribute = factory.partition(":")
    try:
        constructor = getattr(_import(module_name, folder), attribute)
    except (ImportError, AttributeError) as error:
        where = f" (looked up beside the system file in {folder} and on sys.path)" if folder else ""
        raise ValueError(f"block {name!r}: cannot load factory {factory!r}: {error}{where}") from None
    options = {k: v for k, v in params.items() if k != "factory"}
    _check_keys(name, factory, constructor, options)
    try:
        block = constructor(name=name, **options)
    except ValueError:
        raise
    except Exception as error:  # noqa: BLE001 - user code: name the block
        raise ValueError(f"block {name!r}: {factory}(...) failed: {type(error).__name__}: {error}") from None
    for attribute in ("inputs", "outputs", "start", "step"):
        if not hasattr(block, attribute):
            raise ValueError(f"block {name!r}: {factory} made an object without {attribute!r}")
    if not hasattr(block, "units"):
        setattr(block, "units", {})  # noqa: B010 - the protocol reads it as a property
    return block


def _check_keys(name: str, what: str, constructor: Any, params: Mapping[str, Any]) -> None:
    """Unknown or missing keys of a block entry, named with the keys the block accepts."""
    try:
        signature = inspect.signature(constructor)
    except (TypeError, ValueError):
        return
    accepted = [p for p in signature.parameters.values() if p.name != "name"]
    if any(p.kind is inspect.Parameter.VAR_KEYWORD for p in accepted):
        return
    names = [p.name for p in accepted]
    needed = [p.name for p in accepted if p.default is inspect.Parameter.empty]
    unknown = sorted(set(params) - set(names))
    missing = [key for key in needed if key not in params]
    if unknown or missing:
        problem = f"unknown key(s) {unknown}" if unknown else f"missing key(s) {missing}"
        required = f" (required: {', '.join(needed)})" if needed else ""
        raise ValueError(f"block {name!r} ({what}): {problem}; it accepts {', '.join(names) or 'no keys'}{required}")


@dataclass(frozen=True)
class BlockKey:
    """One key of a block type: its name, default (``None``: required) and meaning with its unit."""

    name: str
    default: str | None
    meaning: str


def block_reference() -> list[tuple[str, str, list[BlockKey]]]:
    """Every built-in block type: (type, what it does, its keys), from the constructors' signatures
    and docstrings and ``KEY_MEANINGS`` (for ``rover-cosim blocks`` and the documentation)."""
    types = []
    for kind, constructor in BLOCK_TYPES.items():
        doc = " ".join((constructor.__doc__ or "").split()).replace("``", "")
        keys = [BlockKey(p.name, None if p.default is inspect.Parameter.empty else repr(p.default),
                         KEY_MEANINGS.get(f"{kind}.{p.name}", KEY_MEANINGS.get(p.name, "")))
                for p in inspect.signature(constructor).parameters.values() if p.name != "name"]
        types.append((kind, doc, keys))
    return types


PYTHON_BLOCK = ('your own block, factory = "module:callable" (the module is looked up beside the system file '
                "first); every other key goes to the callable")


def describe_blocks() -> str:
    """A plain-text table of the block types: each key with its default, for ``rover-cosim blocks``."""
    lines = []
    for kind, doc, keys in block_reference():
        lines.append(f"type = \"{kind}\": {doc}")
        for key in keys:
            default = "required" if key.default is None else f"default {key.default}"
            lines.append(f"    {key.name:9s} {default:16s} {key.meaning}")
    lines.append(f'type = "python": {PYTHON_BLOCK}')
    return "\n".join(lines)


#: What each block key means, with its unit.
KEY_MEANINGS = {
    "value": "the constant output [unit of y]",
    "height": "size of the step or ramp [unit of y]",
    "time": "when it starts [s]",
    "offset": "output before it starts [unit of y]",
    "duration": "how long the ramp takes [s]",
    "begin": "output long before `time` [unit of y]",
    "end": "output long after `time` [unit of y]",
    "width": "time scale of the tanh blend [s]",
    "values": "output values at the table's times [unit of y] (linear between them, held beyond)",
    "table.time": "the table's times [s], increasing",
    "unit": "unit of the output y, checked against what it drives (e.g. \"N.m\")",
    "file": "the CSV file (relative: to the system file's folder); first column time [s], one output per other column",
    "hold": "columns held from row to row (discrete signals) instead of interpolated",
    "types": "FMI type of an output that is not Real, e.g. { k = \"Integer\" }",
}
