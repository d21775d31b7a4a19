"""Values in and out of an FMU, per FMI version: which C function sets and gets a variable of
each type, its C type, and :class:`Exchange`, the variables a participant sets or reads at every
step grouped by those functions (value references resolved per type, buffers made once).

The value vector of a run holds every exchanged value as a float: numbers as they are (whole
numbers exactly up to 2^53: a connected or recorded Int64/UInt64 beyond that is rounded to the
nearest float; parameters and start values are set exactly), Booleans as 1.0 / 0.0, Strings as
their number in the run's :class:`StringTable`.

FMI 2.0: fmi2Set/GetReal, Integer (also Enumeration), Boolean (an int), String. FMI 3.0:
fmi3Set/GetFloat64, Float32, Int8 ... UInt64, Boolean (a bool), String; an Enumeration travels
as Int64. Value references are unique per type in FMI 2.0 and across all variables in FMI 3.0;
grouping by type serves both.
"""

from __future__ import annotations

import ctypes
from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np

from .model import INTEGER_RANGES

#: FMI 3.0 types -> their C type (an Enumeration is an Int64).
FMI3_C_TYPES = {"Float64": ctypes.c_double, "Float32": ctypes.c_float, "Int8": ctypes.c_int8,
                "UInt8": ctypes.c_uint8, "Int16": ctypes.c_int16, "UInt16": ctypes.c_uint16,
                "Int32": ctypes.c_int32, "UInt32": ctypes.c_uint32, "Int64": ctypes.c_int64,
                "UInt64": ctypes.c_uint64, "Boolean": ctypes.c_bool, "String": ctypes.c_char_p}
#: FMI 2.0 function families -> their C type.
FMI2_C_TYPES = {"Real": ctypes.c_double, "Integer": ctypes.c_int, "Boolean": ctypes.c_int, "String": ctypes.c_char_p}


def call_kind(version: int, variable_type: str) -> str:
    """The type name in the fmiNSet/Get function of a variable (FMI 2.0 Enumeration: Integer's;
    FMI 3.0 Enumeration: Int64's)."""
    if variable_type == "Enumeration":
        return "Integer" if version == 2 else "Int64"
    return variable_type


def c_type(version: int, kind: str) -> Any:
    """The ctypes type of one value of the function family ``kind``."""
    table = FMI2_C_TYPES if version == 2 else FMI3_C_TYPES
    if kind not in table:
        raise ValueError(f"FMI {version}.0 variables of type {kind} cannot be exchanged (expected one of "
                         f"{', '.join(table)})")
    return table[kind]


def raw_call(fmu: Any, version: int, action: str, kind: str) -> Callable[..., Any]:
    """``call(references, n, buffer[, n_values])`` of fmi2<action><kind> or fmi3<action><kind>
    (``action``: Set or Get) on the instance of the FMPy object ``fmu``; ``n_values`` (FMI 3.0):
    the values in ``buffer``, more than ``n`` where arrays are among the references."""
    function = getattr(fmu, f"fmi{version}{action}{kind}")
    component = fmu.component
    if version == 2:
        return lambda references, n, buffer, n_values=None: function(component, references, n, buffer)
    return lambda references, n, buffer, n_values=None: function(component, references, n, buffer,
                                                                 n if n_values is None else n_values)


class StringTable:
    """The Strings of a run, each held in the value vector as its number here (the same text:
    the same number, so connections copy it and the iterative master sees it settle)."""

    def __init__(self) -> None:
        self.texts: list[str] = []
        self.numbers: dict[str, int] = {}

    def number(self, text: str) -> float:
        """The number of ``text`` (given one on first sight)."""
        found = self.numbers.get(text)
        if found is None:
            found = self.numbers[text] = len(self.texts)
            self.texts.append(text)
        return float(found)

    def text(self, number: float) -> str:
        """The text of ``number`` (0.0 before any String was seen: the empty text)."""
        k = int(number)
        return self.texts[k] if 0 <= k < len(self.texts) else ""


class _Group:
    """The variables of one function family: the value references (each array once), where each
    name's value sits in the buffer (an array's elements follow each other), and the buffer."""

    def __init__(self, version: int, kind: str, names: list[str], positions: list[int], refs: dict[str, int],
                 elements: dict[str, tuple[int, int]]):
        starts: dict[int, int] = {}  # value reference -> where its values begin in the buffer
        sizes: list[int] = []
        offsets = []
        for k in positions:
            reference = refs[names[k]]
            index, size = elements.get(names[k], (0, 1))
            if reference not in starts:
                starts[reference] = sum(sizes)
                sizes.append(size)
            offsets.append(starts[reference] + index)
        self.references = (ctypes.c_uint * len(starts))(*starts)
        self.positions = np.array(positions, dtype=int)
        self.offsets = np.array(offsets, dtype=int)
        self.n_values = sum(sizes)
        self.buffer = (c_type(version, kind) * self.n_values)()
        #: whether every value of the buffer is one of ``names`` (else a set must keep the others)
        self.whole = len(set(offsets)) == self.n_values
        self.primed = self.whole
        #: the names' values are the buffer in order (no arrays, or whole arrays in order): copied at once
        self.in_order = offsets == list(range(self.n_values))


class Exchange:
    """The variables ``names`` of an FMU (of FMI ``version``) grouped by the function that sets
    or gets them; :meth:`set` and :meth:`get` move them between the FMU and a float array in the
    order of ``names``. ``elements``: the names that are elements of FMI 3.0 arrays, with their
    (index, size): an array is set and got whole, its other elements kept as the FMU has them.
    ``real_only``: a single FMI 2.0 fmi2Set/GetReal group (the native stepper's and the fast path's
    case)."""

    def __init__(self, version: int, names: list[str], types: dict[str, str], refs: dict[str, int],
                 strings: StringTable, elements: dict[str, tuple[int, int]] | None = None):
        self.version, self.strings = version, strings
        #: kind -> its group of variables, made once
        self.groups: dict[str, _Group] = {}
        for name in names:
            c_type(version, call_kind(version, types[name]))  # refuse a type that cannot travel, by name
        kinds = dict.fromkeys(call_kind(version, types[n]) for n in names)
        for kind in kinds:
            positions = [k for k, n in enumerate(names) if call_kind(version, types[n]) == kind]
            self.groups[kind] = _Group(version, kind, names, positions, refs, elements or {})
        self.real_only = version == 2 and set(self.groups) <= {"Real"}

    def _call(self, fmu: Any, action: str, kind: str, group: _Group,
              call: Callable[[str, Callable[[], Any]], Any]) -> None:
        call(f"fmi{self.version}{action}{kind}", partial(raw_call(fmu, self.version, action, kind), group.references,
                                                         len(group.references), group.buffer, group.n_values))

    def set(self, fmu: Any, values: np.ndarray, call: Callable[[str, Callable[[], Any]], Any]) -> None:
        """Set every variable from ``values``; ``call(what, action)`` makes each FMI call (and
        turns its failure into the participant's error)."""
        for kind, group in self.groups.items():
            if not group.primed:  # an array set in part: its other elements as the FMU has them
                self._call(fmu, "Get", kind, group, call)
                group.primed = True
            chosen = values[group.positions].tolist()
            converted = c_values(self.version, kind, [self.strings.text(v) for v in chosen] if kind == "String"
                                 else chosen)
            if group.in_order:
                group.buffer[:] = converted
            else:
                for offset, value in zip(group.offsets.tolist(), converted):
                    group.buffer[offset] = value
            self._call(fmu, "Set", kind, group, call)

    def get(self, fmu: Any, out: np.ndarray, call: Callable[[str, Callable[[], Any]], Any]) -> None:
        """Read every variable into ``out`` (in the order of ``names``)."""
        for kind, group in self.groups.items():
            self._call(fmu, "Get", kind, group, call)
            values = group.buffer[:]
            if not group.in_order:
                values = [values[k] for k in group.offsets.tolist()]
            if kind == "String":
                out[group.positions] = [self.strings.number((b or b"").decode(errors="replace")) for b in values]
            else:
                out[group.positions] = [float(v) for v in values]


def set_by_name(fmu: Any, version: int, values: dict[str, Any], types: dict[str, str], refs: dict[str, int],
                call: Callable[[str, Callable[[], Any]], Any],
                arrays: dict[str, tuple[int, list[Any]]] | None = None) -> None:
    """Set typed values (parameters, start values) by variable name: one call per function
    family, each value converted to its C type directly (64-bit integers stay exact). ``arrays``:
    the names that are elements of FMI 3.0 arrays, with their index and the array's start values
    (an array is set whole: its other elements keep their start)."""
    arrays = arrays or {}
    groups: dict[str, dict[int, list[Any]]] = {}  # kind -> value reference -> its values
    for name, value in values.items():
        family = groups.setdefault(call_kind(version, types[name]), {})
        if name in arrays:
            index, starts = arrays[name]
            family.setdefault(refs[name], list(starts))[index] = value
        else:
            family[refs[name]] = [value]
    for kind, family in groups.items():
        flat = [v for values_of in family.values() for v in values_of]
        references = (ctypes.c_uint * len(family))(*family)
        buffer = (c_type(version, kind) * len(flat))(*c_values(version, kind, flat))
        call(f"fmi{version}Set{kind}", partial(raw_call(fmu, version, "Set", kind), references, len(family), buffer,
                                               len(flat)))


def c_values(version: int, kind: str, values: list[Any]) -> list[Any]:
    """Python values as the C type of the function family ``kind`` takes them: text as bytes,
    floats for Real/Float, Booleans as int (FMI 2.0) or bool (FMI 3.0; a value vector's 1.0/0.0
    too), whole numbers as int (rounded from the value vector's floats, exact for Python ints)."""
    if kind == "String":
        return [str(v).encode() for v in values]
    if kind in ("Real", "Float64", "Float32"):
        return [float(v) for v in values]
    if kind == "Boolean":
        return [bool(v) if version == 3 else int(bool(v)) for v in values]
    whole = [v if isinstance(v, int) else int(round(v)) for v in values]
    if kind not in INTEGER_RANGES:
        return whole
    # a value-vector float rounded up from the type's largest value (2^63 - 1 is 2^63 as a float) saturates
    low, high = INTEGER_RANGES[kind]
    return [min(max(v, low), high - 1) for v in whole]
