"""Bindings of continuous variables, and solve memory: variables the FMU runtime keeps between steps.

A continuous variable with a binding (``Real y = expr``) is the equation ``y = expr``. A binding
whose declaration carries the vendor annotation ``__RoverCosim(previous="name")`` is instead a
*memory* of the FMU: the runtime holds there the value ``name`` (a variable of the same component)
had at the end of the previous step, per instance, saved with the FMU state; before the first
step, and in every other Modelica tool, the variable is its binding. It is meant as the start of
an iterative solve whose result does not depend on it beyond the solve's tolerance (the wheel's
sinkage, ``Components.RigidWheel``): a warm start the Modelica source asks for without an
algebraic loop.

rumoca's flat model keeps no annotations, so the annotation is read from the declaration in the
source text (the variable's source span up to the ``;`` that ends it).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from .expressions import UnsupportedConstruct

_PREVIOUS = re.compile(r'__RoverCosim\s*\(\s*previous\s*=\s*"([A-Za-z_][\w.\[\]]*)"\s*\)')


@dataclass(frozen=True)
class Memory:
    """A memory variable: its flat name, the variable whose previous value it holds, its binding."""

    name: str
    source: str
    binding: Mapping[str, Any]


def declaration_text(text: str, start: int) -> str:
    """The declaration starting at ``start`` up to its ``;`` (strings and comments skipped)."""
    i, depth = start, 0
    while i < len(text):
        ch = text[i]
        if ch == '"':
            i += 1
            while i < len(text) and text[i] != '"':
                i += 2 if text[i] == "\\" else 1
        elif text.startswith("//", i):
            i = text.find("\n", i) if "\n" in text[i:] else len(text)
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == ";" and depth <= 0:
            return text[start:i]
        i += 1
    return text[start:]


def previous_of(info: Mapping[str, Any], files: Mapping[Any, tuple[str, str]]) -> str | None:
    """The ``name`` of ``__RoverCosim(previous="name")`` in the declaration of ``info``, or None."""
    span = info.get("source_span") or {}
    entry = files.get(span.get("source"))
    if entry is None or "start" not in span:
        return None
    match = _PREVIOUS.search(declaration_text(entry[1], span["start"]))
    return match.group(1) if match else None


def _component_prefix(flat_name: str) -> str:
    """``wheels[2].sinkageStart`` -> ``wheels[2].``; a top-level name -> ``""``."""
    depth, cut = 0, -1
    for i, ch in enumerate(flat_name):
        if ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
        elif ch == "." and depth == 0:
            cut = i
    return flat_name[:cut + 1]


def bound_variables(flat: Mapping[str, Any], files: Mapping[Any, tuple[str, str]],
                    is_parameter: Callable[[Mapping[str, Any]], bool],
                    name: str) -> tuple[list[Memory], list[tuple[Any, list[str] | None, str]]]:
    """Memories, and the binding equations of the other bound continuous variables (scalars), as
    ``fmubuild.ode`` equations (residual, no tuple targets, where)."""
    memories: list[Memory] = []
    equations: list[tuple[Any, list[str] | None, str]] = []
    for flat_name, info in flat["variables"].items():
        if info.get("binding") is None or is_parameter(info):
            continue
        where = f"{name}: binding of {flat_name}"
        if info["dims"]:
            raise UnsupportedConstruct(f"binding of the array variable {flat_name}", where)
        previous = previous_of(info, files)
        if previous is not None:
            source = _component_prefix(flat_name) + previous
            if source not in flat["variables"]:
                raise UnsupportedConstruct(f'__RoverCosim(previous="{previous}"): no variable {source}', where)
            memories.append(Memory(flat_name, source, info["binding"]))
            continue
        reference = {"VarRef": {"name": {"name": flat_name}, "subscripts": []}}
        equations.append(({"Binary": {"op": "Sub", "lhs": reference, "rhs": info["binding"]}}, None, where))
    return memories, equations
