"""A rumoca-flattened Modelica model → an explicit ODE in CasADi: xdot = f(t, x, u, p), y = g(t, x, u, p).

Causalization: every flat equation (a scalar residual, or a tuple equated to a multi-output
function call) is matched to the unknown it determines (der(x) of the states, algebraic and
output variables) by maximum bipartite matching; the strongly connected components of the
matched dependency graph, in topological order, are the blocks of the BLT form. A block is
solved symbolically when it is linear in its unknowns (explicit equations are the common case);
a nonlinear block (a nonlinear algebraic loop), events, when-clauses, initial equations and
constructs the translator does not know are rejected with :class:`UnsupportedConstruct`, which
names the equation and its source line and suggests the omc backend.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import partial
from typing import Any

import casadi as ca

from .expressions import (
    Evaluator,
    UnsupportedConstruct,
    Value,
    is_symbolic,
    scalar_name,
)
from .functions import FunctionLibrary


@dataclass(frozen=True)
class Variable:
    """One scalar variable of the model, with what the FMU's model description needs."""

    name: str
    role: str  # "state", "input", "output", "local", "parameter", "calculated", "constant"
    type_name: str  # "Real", "Integer", "Boolean"
    unit: str | None
    description: str | None
    start: float | None
    is_output: bool = False  # a top-level output (a state can be one too)


@dataclass
class OdeModel:
    """The explicit ODE of a model; CasADi expressions in the symbols t, x, u, p."""

    name: str
    variables: dict[str, Variable]
    states: list[str]
    inputs: list[str]
    parameters: list[str]  # free (tunable) Real parameters, the entries of p
    observed: list[str]  # every non-parameter variable that is not an input, in y
    t: ca.MX
    x: ca.MX
    u: ca.MX
    p: ca.MX
    xdot: ca.MX
    y: ca.MX
    x0: ca.MX  # start values of the states, an expression of p
    parameter_values: dict[str, float] = field(default_factory=dict)
    calculated: dict[str, ca.MX] = field(default_factory=dict)  # dependent parameters, expressions of p

    def functions(self) -> tuple[ca.Function, ca.Function, ca.Function]:
        """``ode(t, x, u, p) -> xdot``, ``outputs(t, x, u, p) -> y``, ``initial(p) -> x0``."""
        ode = ca.Function("ode", [self.t, self.x, self.u, self.p], [self.xdot], ["t", "x", "u", "p"], ["xdot"])
        outputs = ca.Function("outputs", [self.t, self.x, self.u, self.p], [self.y], ["t", "x", "u", "p"], ["y"])
        initial = ca.Function("initial", [self.p], [self.x0], ["p"], ["x0"])
        return ode, outputs, initial


def _role_names(info: Mapping[str, Any]) -> tuple[str, str]:
    def key(value: Any) -> str:
        return value if isinstance(value, str) else next(iter(value))
    return key(info["variability"]), key(info["causality"])


def _scalar_names(name: str, dims: list[int]) -> list[tuple[str, list[int]]]:
    if not dims:
        return [(name, [])]
    if len(dims) == 1:
        return [(scalar_name(name, [i]), [i]) for i in range(1, dims[0] + 1)]
    if len(dims) == 2:
        return [(scalar_name(name, [i, j]), [i, j]) for i in range(1, dims[0] + 1) for j in range(1, dims[1] + 1)]
    raise UnsupportedConstruct(f"array {name} with {len(dims)} dimensions", name)


class _Locator:
    """Source file and line of a span, from rumoca's source map."""

    def __init__(self, dae: Mapping[str, Any]):
        self.files = {entry[0]: (entry[1], entry[2]) for entry in dae.get("source_map", {}).get("files", [])}

    def __call__(self, span: Mapping[str, Any] | None) -> str:
        if not span or span.get("source") not in self.files:
            return "unknown source line"
        path, text = self.files[span["source"]]
        line = text.count("\n", 0, span["start"]) + 1
        snippet = text[span["start"]:span["end"]].strip().replace("\n", " ")
        return f"{path}:{line}: '{snippet}'"


def translate(model: Any, name: str) -> OdeModel:
    """Translate a loaded rumoca model (``fmubuild.source.load``) to an :class:`OdeModel`."""
    flat = model.to_dict("flat")
    locate = _Locator(model.to_dict("dae"))
    for key, what in (("when_chains", "when-clause (events)"), ("algorithms", "algorithm section in a model"),
                      ("initial_equations", "initial equation"), ("initial_algorithms", "initial algorithm")):
        if flat.get(key):
            first = flat[key][0]
            raise UnsupportedConstruct(what, f"{name}: {locate(first.get('span') if isinstance(first, dict) else None)}")
    library = FunctionLibrary(flat["functions"])
    types = flat["variable_type_names"]

    # --- variables -----------------------------------------------------------------------
    infos: dict[str, tuple[Mapping[str, Any], list[int], str]] = {}
    for flat_name, info in flat["variables"].items():
        for scalar, indices in _scalar_names(flat_name, info["dims"]):
            infos[scalar] = (info, indices, flat_name)
    state_names = _states(flat["equations"])
    parameters: dict[str, Value] = {}  # scalar name -> number or MX expression of p
    free: list[str] = []
    free_symbols: list[ca.MX] = []
    values: dict[str, float] = {}
    calculated: dict[str, ca.MX] = {}

    def parameter(scalar: str) -> Value:
        if scalar in parameters:
            return parameters[scalar]
        info, indices, flat_name = infos[scalar]
        binding = info["binding"] if info["binding"] is not None else info["start"]
        where = f"{name}: parameter {scalar}"
        if binding is None:
            raise UnsupportedConstruct(f"parameter {scalar} without a value", where)
        binding = _element(binding, indices, where)
        evaluator = Evaluator(parameter, library.call, where)
        value = evaluator(binding)
        if types.get(flat_name) in ("Integer", "Boolean"):
            if is_symbolic(value):
                raise UnsupportedConstruct(f"Integer/Boolean parameter {scalar} bound to a run-time value", where)
            parameters[scalar] = value
            return value
        if "Literal" in binding or (not is_symbolic(value) and "Unary" in binding):
            symbol = ca.MX.sym(scalar)
            free.append(scalar)
            free_symbols.append(symbol)
            values[scalar] = float(value)
            parameters[scalar] = symbol
            return symbol
        parameters[scalar] = value
        calculated[scalar] = value if is_symbolic(value) else ca.MX(float(value))
        return value

    for scalar, (info, _, _) in infos.items():
        if _role_names(info)[0] in ("Parameter", "Constant"):
            parameter(scalar)

    inputs = [s for s, (info, _, flat_name) in infos.items()
              if _role_names(info)[1] == "Input" and "." not in flat_name]
    states = [s for s in infos if s in state_names]
    t = ca.MX.sym("time")
    x = ca.MX.sym("x", len(states))
    u = ca.MX.sym("u", len(inputs))
    p = ca.vertcat(*free_symbols) if free_symbols else ca.MX.sym("p", 0)
    known: dict[str, Value] = {"time": t}
    known.update({s: x[i] for i, s in enumerate(states)})
    known.update({s: u[i] for i, s in enumerate(inputs)})
    known.update(parameters)
    unknowns = [f"der({s})" for s in states] + [
        s for s in infos if s not in known and _role_names(infos[s][0])[0] not in ("Parameter", "Constant")]

    # --- equations, matching, BLT ----------------------------------------------------------
    equations: list[tuple[Any, list[str] | None, str]] = []  # (residual, tuple targets or None, where)
    for equation in flat["equations"]:
        where = f"{name}: equation at {locate(equation.get('span'))}"
        residual = equation["residual"]
        (kind, body), = residual.items()
        if kind == "Binary" and body["op"] == "Sub" and "Tuple" in body["lhs"]:
            equations.append((body["rhs"], [_ref_name(e, where) for e in body["lhs"]["Tuple"]["elements"]], where))
        else:
            equations.append((residual, None, where))
    slots: list[tuple[int, set[str]]] = []  # (equation, unknowns it can be solved for)
    depends: list[set[str]] = []  # unknowns each slot's equation reads
    for index, (residual, tuple_targets, _) in enumerate(equations):
        incidence = _incidence(residual, unknowns)
        if tuple_targets is not None:
            for target in tuple_targets:
                slots.append((index, {target}))
                depends.append(incidence)
        else:
            slots.append((index, incidence))
            depends.append(incidence)
    if len(slots) != len(unknowns):
        raise UnsupportedConstruct(f"{len(slots)} scalar equations for {len(unknowns)} unknowns (not balanced)", name)
    assignment = _match(slots, unknowns, name, equations)
    blocks = _blt(slots, depends, assignment)

    env: dict[str, Value] = dict(known)
    for block in blocks:
        eq_indices = sorted({slots[s][0] for s in block})
        block_unknowns = [assignment[s] for s in block]
        _solve_block(eq_indices, block_unknowns, equations, env, library, name)

    xdot = ca.vertcat(*[_mx(env[f"der({s})"]) for s in states]) if states else ca.MX(0, 1)
    observed = [s for s in unknowns if not s.startswith("der(")]
    y = ca.vertcat(*[_mx(env[s]) for s in observed]) if observed else ca.MX(0, 1)
    x0_list = []
    for s in states:
        info, indices, _ = infos[s]
        start = info["start"]
        value = Evaluator(lambda n: parameters[n], library.call, f"{name}: start of {s}")(
            _element(start, indices, s)) if start is not None else 0.0
        x0_list.append(_mx(value))
    x0 = ca.vertcat(*x0_list) if x0_list else ca.MX(0, 1)

    variables = {}
    for s, (info, _, flat_name) in infos.items():
        variability, causality = _role_names(info)
        if s in free:
            role = "parameter"
        elif s in calculated:
            role = "calculated"
        elif variability in ("Parameter", "Constant"):
            role = "constant"
        elif s in inputs:
            role = "input"
        elif s in states:
            role = "state"
        elif causality == "Output" and "." not in flat_name:
            role = "output"
        else:
            role = "local"
        start = values.get(s)
        if start is None and isinstance(parameters.get(s), (int, float)):
            start = float(parameters[s])
        variables[s] = Variable(s, role, types.get(flat_name, "Real"), info["unit"], info["description"], start,
                                causality == "Output" and "." not in flat_name)
    return OdeModel(name, variables, states, inputs, free, observed, t, x, u, p, xdot, y, x0, values, calculated)


def _mx(value: Value) -> ca.MX:
    return value if isinstance(value, ca.MX) else ca.MX(float(value))


def _element(binding: Mapping[str, Any], indices: list[int], where: str) -> Mapping[str, Any]:
    """The element ``indices`` of an array binding ({a, b, ...}), or the binding itself."""
    node = binding
    for i in indices:
        (kind, body), = node.items()
        if kind == "Array":
            node = body["elements"][i - 1]
        elif kind == "VarRef" and not body["subscripts"]:
            node = {"VarRef": {**body, "subscripts": [{"Index": {"value": i}}]}}
        else:
            raise UnsupportedConstruct(f"array binding of kind {kind}", where)
    return node


def _ref_name(node: Mapping[str, Any], where: str) -> str:
    (kind, body), = node.items()
    if kind != "VarRef":
        raise UnsupportedConstruct(f"tuple element of kind {kind}", where)
    indices = [s["Index"]["value"] for s in body["subscripts"] if "Index" in s]
    if len(indices) != len(body["subscripts"]):
        raise UnsupportedConstruct("tuple element with a computed subscript", where)
    return scalar_name(body["name"]["name"], indices)


def _walk(node: Any):
    if isinstance(node, dict):
        yield node
        for value in node.values():
            yield from _walk(value)
    elif isinstance(node, list):
        for value in node:
            yield from _walk(value)


def _states(equations: list[Mapping[str, Any]]) -> set[str]:
    states = set()
    for equation in equations:
        for node in _walk(equation["residual"]):
            call = node.get("BuiltinCall")
            if isinstance(call, dict) and call.get("function") == "Der":
                states.add(_ref_name(call["args"][0], "der()"))
    return states


def _incidence(residual: Mapping[str, Any], unknowns: list[str]) -> set[str]:
    wanted = set(unknowns)
    found = set()
    for node in _walk(residual):
        call = node.get("BuiltinCall")
        if isinstance(call, dict) and call.get("function") == "Der":
            found.add(f"der({_ref_name(call['args'][0], 'der()')})")
        ref = node.get("VarRef")
        if isinstance(ref, dict) and "name" in ref and isinstance(ref["name"], dict):
            subs = ref.get("subscripts", [])
            if all("Index" in s for s in subs):
                found.add(scalar_name(ref["name"]["name"], [s["Index"]["value"] for s in subs]))
    return found & wanted


def _match(slots: list[tuple[int, set[str]]], unknowns: list[str], name: str, equations: list[Any]) -> list[str]:
    """Maximum bipartite matching slot -> unknown (augmenting paths)."""
    owner: dict[str, int] = {}
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10 * len(slots) + 1000))
    try:
        for slot in range(len(slots)):
            if not _augment(slot, slots, owner, set()):
                index = slots[slot][0]
                raise UnsupportedConstruct(
                    "structurally singular: this equation cannot be matched to an unknown "
                    f"(candidates {sorted(slots[slot][1])})", equations[index][2])
    finally:
        sys.setrecursionlimit(limit)
    assignment = [""] * len(slots)
    for variable, slot in owner.items():
        assignment[slot] = variable
    return assignment


def _augment(slot: int, slots: list[tuple[int, set[str]]], owner: dict[str, int], seen: set[str]) -> bool:
    for variable in sorted(slots[slot][1]):
        if variable in seen:
            continue
        seen.add(variable)
        if variable not in owner or _augment(owner[variable], slots, owner, seen):
            owner[variable] = slot
            return True
    return False


def _blt(slots: list[tuple[int, set[str]]], depends: list[set[str]], assignment: list[str]) -> list[list[int]]:
    """Strongly connected components of the slot dependency graph in evaluation order
    (Tarjan's algorithm, iterative). Slots of one tuple equation are one block."""
    solved_by = {variable: slot for slot, variable in enumerate(assignment)}
    groups: dict[int, list[int]] = {}
    for slot, (equation, _) in enumerate(slots):
        groups.setdefault(equation, []).append(slot)
    edges: list[set[int]] = []
    for slot, (equation, _) in enumerate(slots):
        deps = {solved_by[v] for v in depends[slot] if v in solved_by and solved_by[v] != slot}
        deps |= {other for other in groups[equation] if other != slot}
        edges.append(deps)
    index_of: dict[int, int] = {}
    low: dict[int, int] = {}
    on_stack: set[int] = set()
    stack: list[int] = []
    order: list[list[int]] = []
    counter = 0
    for root in range(len(slots)):
        if root in index_of:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index_of[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index_of:
                    index_of[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges[child]))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index_of[child])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index_of[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                order.append(component)
    return order  # Tarjan emits components after their dependencies


def _solve_block(eq_indices: list[int], block_unknowns: list[str], equations: list[Any], env: dict[str, Value],
                 library: FunctionLibrary, name: str) -> None:
    tuple_equations = [i for i in eq_indices if equations[i][1] is not None]
    if tuple_equations:
        if len(eq_indices) != 1:
            raise UnsupportedConstruct("a multi-output function call inside an algebraic loop",
                                       equations[tuple_equations[0]][2])
        residual, targets, where = equations[eq_indices[0]]
        assert targets is not None  # a tuple equation
        if all(target in env for target in targets):
            return  # solved with its first target: one call for all outputs
        evaluator = Evaluator(partial(_lookup, env, where=where), library.call, where, allow_events=False)
        outputs = evaluator.call_outputs(residual)
        for target, value in zip(targets, outputs):
            env[target] = value
        return
    if len(eq_indices) == 1 and len(block_unknowns) == 1:
        residual, _, where = equations[eq_indices[0]]
        explicit = _explicit_side(residual, block_unknowns[0])
        if explicit is not None:
            # unknown = expression (the common case): evaluated as it stands, keeping shared nodes
            evaluator = Evaluator(partial(_lookup, env, where=where), library.call, where, allow_events=False)
            env[block_unknowns[0]] = evaluator(explicit)
            return
    symbols = [ca.MX.sym(f"unknown_{i}") for i in range(len(block_unknowns))]
    trial = dict(env)
    trial.update(zip(block_unknowns, symbols))
    residuals = []
    for i in eq_indices:
        residual, _, where = equations[i]
        evaluator = Evaluator(partial(_lookup, trial, where=where), library.call, where, allow_events=False)
        residuals.append(_mx(evaluator(residual)))
    unknown_vector = ca.vertcat(*symbols)
    residual_vector = ca.vertcat(*residuals)
    jacobian = ca.jacobian(residual_vector, unknown_vector)
    if ca.depends_on(jacobian, unknown_vector):
        wheres = "; ".join(equations[i][2] for i in eq_indices)
        kind = "a nonlinear equation in its unknown" if len(eq_indices) == 1 else "a nonlinear algebraic loop"
        raise UnsupportedConstruct(f"{kind} for {', '.join(block_unknowns)}", wheres)
    # graph_substitute keeps the nodes that do not depend on the unknowns (function calls stay shared)
    offset = ca.graph_substitute(residual_vector, [unknown_vector], [ca.MX.zeros(len(symbols))])
    if len(symbols) == 1:
        solution = -offset / jacobian
    else:
        solution = -ca.solve(jacobian, offset)
    for i, variable in enumerate(block_unknowns):
        env[variable] = ca.simplify(solution[i]) if len(symbols) == 1 else solution[i]


def _explicit_side(residual: Mapping[str, Any], unknown: str) -> Mapping[str, Any] | None:
    """For a residual ``unknown - e`` or ``e - unknown`` with ``e`` free of the unknown, ``e``."""
    (kind, body), = residual.items()
    if kind != "Binary" or body["op"] != "Sub":
        return None
    for mine, other in ((body["lhs"], body["rhs"]), (body["rhs"], body["lhs"])):
        if _incidence(mine, [unknown]) == {unknown} and _is_reference(mine) and not _incidence(other, [unknown]):
            return other
    return None


def _is_reference(node: Mapping[str, Any]) -> bool:
    """A plain variable reference (constant subscripts) or der() of one."""
    (kind, body), = node.items()
    if kind == "VarRef":
        return all("Index" in s for s in body.get("subscripts", []))
    return kind == "BuiltinCall" and body.get("function") == "Der"


def _lookup(env: Mapping[str, Value], name: str, where: str) -> Value:
    if name not in env:
        raise UnsupportedConstruct(f"reference to {name}, which is not a variable of the model", where)
    return env[name]
