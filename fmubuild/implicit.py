"""Derivatives of iterative solves by the implicit-function theorem.

A Modelica function that solves an equation by iterating (the wheel's sinkage solve,
``Functions.wheelContact``) is differentiated wrongly by automatic differentiation through its
iterations when it starts at the solution: warm-started from the previous step's result it
converges at the first evaluation, takes no step, and its result carries no derivative with respect
to the load, the slip or anything else (dFz/dW = 0 instead of 1). The function's declaration can
say what it solves:

    annotation(__RoverCosim(implicit(unknown="logSinkage", residual="Pkg.contactResidual")))

``unknown`` is one of its outputs, ``residual`` a Modelica function whose first input is that
unknown and whose other inputs take the solving function's inputs of the same name (inputs it has
and the solver lacks take their defaults); its first output is the residual r, which the solve
drives to 0, and any further outputs named like the solver's outputs are what the solver returns at
its solution. In the graphs the FMU's derivatives are taken from (directional derivatives and the
Co-Simulation integrator's Jacobian), such a call keeps the solver's values bit for bit and gets
the derivative of the implicit function at the solution u* it returned:

    du = -(dr/dargs · dargs) / (dr/du),

and the outputs the residual function also returns get (d/du · du + d/dargs · dargs) of the
residual function at u*. Where the solve did not converge (|r| > 1e-6: e.g. the soil cannot carry
the wheel, which then rests on its clamp h = r), du is 0. The other outputs (iteration counts, warm
starts) carry no derivative. Values in the evaluated model are untouched: the exporter's
``model_evaluate`` does not use this.

rumoca's flat model keeps no annotations, so the annotation is read from the function's source text.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca

from .expressions import UnsupportedConstruct, Value, is_symbolic

_IMPLICIT = re.compile(
    r'__RoverCosim\s*\(\s*implicit\s*\(\s*unknown\s*=\s*"(\w+)"\s*,\s*residual\s*=\s*"([\w.]+)"\s*\)\s*\)')

#: |r| above which a solve is taken as not converged (its result then has no derivative by u).
CONVERGED = 1e-6


@dataclass(frozen=True)
class ImplicitSolve:
    """What a function's ``__RoverCosim(implicit(...))`` annotation says: the output that solves
    ``residual(unknown, ...) = 0``."""

    unknown: str
    residual: str


def implicit_solves(functions: Mapping[str, Mapping[str, Any]],
                    files: Mapping[Any, tuple[str, str]]) -> dict[str, ImplicitSolve]:
    """The flat functions that carry the annotation, by their flat name."""
    found: dict[str, ImplicitSolve] = {}
    for name, definition in functions.items():
        span = definition.get("span") or {}
        entry = files.get(span.get("source"))
        if entry is None or "start" not in span:
            continue
        match = _IMPLICIT.search(entry[1][span["start"]:span.get("end", len(entry[1]))])
        if match is None:
            continue
        outputs = [d["name"] for d in definition["outputs"]]
        if match.group(1) not in outputs:
            raise UnsupportedConstruct(f'__RoverCosim(implicit(unknown="{match.group(1)}")): no output of that name',
                                       name)
        found[name] = ImplicitSolve(match.group(1), match.group(2))
    return found


def differentiable_outputs(solve: ImplicitSolve, solver: Mapping[str, Any], residual: Mapping[str, Any],
                           values: Sequence[Value], outputs: Sequence[Value],
                           call: Callable[[str, list[Value]], tuple[Value, ...]]) -> tuple[Value, ...]:
    """The solver's ``outputs`` (computed from ``values``, its inputs in declaration order) with
    the derivatives of the implicit function; ``call`` evaluates the residual function (its own
    inputs in order, defaults filled in by the caller's library)."""
    names = [d["name"] for d in solver["outputs"]]
    by_name = {d["name"]: v for d, v in zip(solver["inputs"], values)}
    residual_inputs = residual["inputs"]
    arguments: list[Value] = []
    for declared in residual_inputs[1:]:
        if declared["name"] in by_name:
            arguments.append(by_name[declared["name"]])
        elif declared["default"] is None:
            raise UnsupportedConstruct(f"residual input {declared['name']}: not an input of {solver['name']} "
                                       "and without default", residual["name"])
        else:
            break  # this one and the rest take their defaults (inputs are positional)
    if any(d["name"] in by_name for d in residual_inputs[1 + len(arguments):]):
        raise UnsupportedConstruct(f"residual {residual['name']}: an input the solver lacks comes before one it has",
                                   residual["name"])
    u_star = ca.stop_diff(_mx(outputs[names.index(solve.unknown)]), 1)
    # One evaluation of the residual function at the solution carries the derivatives with respect
    # to the arguments (r_a da, o_a da); its derivatives with respect to u (r_u, o_u) are values.
    at_solution = [_mx(v) for v in call(residual["name"], [u_star, *arguments])]
    frozen = [ca.stop_diff(a, 1) if is_symbolic(a) else a for a in arguments]
    by_u = ca.stop_diff(_by_unknown(residual["name"], u_star, frozen, call), 1)
    r, slope = at_solution[0], by_u[0]
    converged = ca.logic_and(ca.fabs(ca.stop_diff(r, 1)) <= CONVERGED, slope != 0)
    # du: value 0, derivative -(r_a da)/r_u (r - stop_diff(r) is 0 and carries r's derivative).
    du = ca.if_else(converged, -(r - ca.stop_diff(r, 1)) / ca.if_else(slope != 0, slope, 1.0), 0.0)
    moved = {d["name"]: (v - ca.stop_diff(v, 1)) + by_u[i + 1] * du
             for i, (d, v) in enumerate(zip(residual["outputs"][1:], at_solution[1:]))}
    result: list[Value] = []
    for name, value in zip(names, outputs):
        if not is_symbolic(value):
            result.append(value)
        elif name == solve.unknown:
            result.append(u_star + du)
        elif name in moved:  # the solver's value, the implicit function's derivative
            result.append(ca.stop_diff(_mx(value), 1) + moved[name])
        else:
            result.append(ca.stop_diff(_mx(value), 1))
    return tuple(result)


def _by_unknown(residual: str, u_star: ca.MX, arguments: Sequence[Value],
               call: Callable[[str, list[Value]], tuple[Value, ...]]) -> ca.MX:
    """d(outputs)/du of the residual function at (u_star, arguments) (the residual's first: its
    slope), through a Function of its own."""
    u = ca.MX.sym("u")
    symbols = {i: ca.MX.sym(f"a{i}") for i, a in enumerate(arguments) if is_symbolic(a)}
    outputs = ca.vertcat(*[_mx(v) for v in call(residual, [u, *[symbols.get(i, a) for i, a in enumerate(arguments)]])])
    name = "by_unknown_" + "".join(c if c.isalnum() else "_" for c in residual)
    function = ca.Function(name, [u, *symbols.values()], [ca.jacobian(outputs, u)])
    return function(u_star, *[arguments[i] for i in symbols])


def _mx(value: Value) -> ca.MX:
    return value if isinstance(value, ca.MX) else ca.MX(float(value))
