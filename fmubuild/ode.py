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

import json
import sys
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

import casadi as ca

from .expressions import (
    Evaluator,
    UnsupportedConstruct,
    Value,
    is_symbolic,
    literal,
    scalar_name,
    subscript_values,
)
from .functions import FunctionLibrary
from .implicit import implicit_solves
from .memory import bound_variables


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
    minimum: float | None = None   # the declaration's min (a literal), in ``unit``
    maximum: float | None = None   # the declaration's max (a literal), in ``unit``
    display_unit: str | None = None  # the declaration's displayUnit (e.g. deg for an angle in rad)


@dataclass(frozen=True)
class Assertion:
    """A Modelica ``assert``: the FMU reports ``message`` with the values of the variables the
    condition reads when the condition does not hold."""

    condition: ca.MX  # 1 where it holds, an expression of (t, x, u, p)
    message: str
    level: str  # "error" or "warning"
    names: tuple[str, ...]  # variables the condition reads, by the name the user knows them
    values: tuple[ca.MX, ...]  # their values, expressions of (t, x, u, p)


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
    m: ca.MX = field(default_factory=lambda: ca.MX.sym("m", 0))  # memories (fmubuild.memory)
    memories: list[str] = field(default_factory=list)
    memory_sources: list[str] = field(default_factory=list)  # observed variable each memory holds
    memory_defaults: list[float] = field(default_factory=list)  # their value before the first step
    parameter_values: dict[str, float] = field(default_factory=dict)
    calculated: dict[str, ca.MX] = field(default_factory=dict)  # dependent parameters, expressions of p
    asserts: list[Assertion] = field(default_factory=list)
    # xdot and y as the FMU's derivatives are taken from: equal values, with the derivatives of
    # implicit solves by the implicit-function theorem (fmubuild.implicit); None: xdot and y.
    xdot_derivative: ca.MX | None = None
    y_derivative: ca.MX | None = None

    def at_memory_defaults(self) -> tuple[ca.MX, ca.MX]:
        """xdot and y with every memory at its binding: what a Modelica tool without the runtime's
        memories computes (e.g. the sinkage solve started cold), expressions of (t, x, u, p)."""
        if not self.memories:
            return self.xdot, self.y
        defaults = ca.DM(self.memory_defaults)
        return ca.substitute(self.xdot, self.m, defaults), ca.substitute(self.y, self.m, defaults)

    def functions(self) -> tuple[ca.Function, ca.Function, ca.Function]:
        """``ode(t, x, u, p) -> xdot``, ``outputs(t, x, u, p) -> y`` (memories at their bindings),
        ``initial(p) -> x0``."""
        xdot, y = self.at_memory_defaults()
        ode = ca.Function("ode", [self.t, self.x, self.u, self.p], [xdot], ["t", "x", "u", "p"], ["xdot"])
        outputs = ca.Function("outputs", [self.t, self.x, self.u, self.p], [y], ["t", "x", "u", "p"], ["y"])
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


UNSUPPORTED_SECTIONS = (("when_chains", "when-clause (events)"), ("algorithms", "algorithm section in a model"),
                        ("initial_equations", "initial equation"), ("initial_algorithms", "initial algorithm"))

Info = tuple[Mapping[str, Any], list[int], str]  # (flat variable info, indices of the scalar, flat name)
Equation = tuple[Any, list[str] | None, str]     # (residual, tuple targets or None, where)


def _reject_unsupported_sections(flat: Mapping[str, Any], locate: _Locator, name: str) -> None:
    for key, what in UNSUPPORTED_SECTIONS:
        if flat.get(key):
            first = flat[key][0]
            span = first.get("span") if isinstance(first, dict) else None
            raise UnsupportedConstruct(what, f"{name}: {locate(span)}")


class _Parameters:
    """Parameters and constants as CasADi values: a literal binding is a free (tunable) parameter,
    an entry of p; a binding that is an expression of other parameters is calculated from them."""

    def __init__(self, infos: dict[str, Info], types: Mapping[str, str], library: FunctionLibrary, name: str):
        self.infos, self.types, self.library, self.name = infos, types, library, name
        self.values: dict[str, Value] = {}       # scalar name -> number or MX expression of p
        self.free: list[str] = []
        self.symbols: list[ca.MX] = []
        self.defaults: dict[str, float] = {}     # free parameter -> its value
        self.calculated: dict[str, ca.MX] = {}   # dependent parameters, expressions of p

    def __call__(self, scalar: str) -> Value:
        if scalar not in self.values:
            self.values[scalar] = self._evaluate(scalar)
        return self.values[scalar]

    def _evaluate(self, scalar: str) -> Value:
        info, indices, flat_name = self.infos[scalar]
        binding = info["binding"] if info["binding"] is not None else info["start"]
        where = f"{self.name}: parameter {scalar}"
        if binding is None:
            raise UnsupportedConstruct(f"parameter {scalar} without a value", where)
        binding = _element(binding, indices, where)
        value = Evaluator(self, self.library.call, where)(binding)
        if self.types.get(flat_name) in ("Integer", "Boolean"):
            if is_symbolic(value):
                raise UnsupportedConstruct(f"Integer/Boolean parameter {scalar} bound to a run-time value", where)
            return value
        if "Literal" in binding or (not is_symbolic(value) and "Unary" in binding):
            symbol = ca.MX.sym(scalar)
            self.free.append(scalar)
            self.symbols.append(symbol)
            self.defaults[scalar] = float(value)
            return symbol
        self.calculated[scalar] = value if is_symbolic(value) else ca.MX(float(value))
        return value

    def vector(self) -> ca.MX:
        return ca.vertcat(*self.symbols) if self.symbols else ca.MX.sym("p", 0)


def _scalar_infos(flat: Mapping[str, Any]) -> dict[str, Info]:
    infos: dict[str, Info] = {}
    for flat_name, info in flat["variables"].items():
        for scalar, indices in _scalar_names(flat_name, info["dims"]):
            infos[scalar] = (info, indices, flat_name)
    return infos


def _is_parameter(info: Mapping[str, Any]) -> bool:
    return _role_names(info)[0] in ("Parameter", "Constant")


def _equations(flat: Mapping[str, Any], locate: _Locator, name: str) -> list[Equation]:
    """The flat equations; a tuple equated to a multi-output call keeps its targets."""
    equations: list[Equation] = []
    for equation in flat["equations"]:
        where = f"{name}: equation at {locate(equation.get('span'))}"
        residual = equation["residual"]
        (kind, body), = residual.items()
        if kind == "Binary" and body["op"] == "Sub" and "Tuple" in body["lhs"]:
            equations.append((body["rhs"], [_ref_name(e, where) for e in body["lhs"]["Tuple"]["elements"]], where))
        else:
            equations.append((residual, None, where))
    return equations


def _slots(equations: list[Equation], unknowns: list[str]) -> tuple[list[tuple[int, set[str]]], list[set[str]]]:
    """One slot per scalar equation (a tuple equation has one per target): (equation, unknowns it
    can be solved for), and the unknowns each slot's equation reads."""
    slots: list[tuple[int, set[str]]] = []
    depends: list[set[str]] = []
    for index, (residual, tuple_targets, _) in enumerate(equations):
        incidence = _incidence(residual, unknowns)
        for targets in ([{t} for t in tuple_targets] if tuple_targets is not None else [incidence]):
            slots.append((index, targets))
            depends.append(incidence)
    return slots, depends


def _solve(equations: list[Equation], unknowns: list[str], known: dict[str, Value], library: FunctionLibrary,
           name: str) -> dict[str, Value]:
    """Match, sort into BLT blocks and solve them in order: every unknown as an expression."""
    slots, depends = _slots(equations, unknowns)
    if len(slots) != len(unknowns):
        raise UnsupportedConstruct(f"{len(slots)} scalar equations for {len(unknowns)} unknowns (not balanced)", name)
    assignment = _match(slots, unknowns, name, equations)
    env: dict[str, Value] = dict(known)
    for block in _blt(slots, depends, assignment):
        eq_indices = sorted({slots[s][0] for s in block})
        _solve_block(eq_indices, [assignment[s] for s in block], equations, env, library, name)
    return env


def _start_values(states: list[str], infos: dict[str, Info], parameters: _Parameters, name: str) -> ca.MX:
    """x0 as an expression of p (0 for a state without a start)."""
    x0: list[ca.MX] = []
    for s in states:
        info, indices, _ = infos[s]
        start = info["start"]
        evaluator = Evaluator(lambda n: parameters.values[n], parameters.library.call, f"{name}: start of {s}")
        x0.append(_mx(evaluator(_element(start, indices, s)) if start is not None else 0.0))
    return ca.vertcat(*x0) if x0 else ca.MX(0, 1)


def _role(scalar: str, info: Mapping[str, Any], flat_name: str, parameters: _Parameters, inputs: list[str],
          states: list[str]) -> str:
    variability, causality = _role_names(info)
    if scalar in parameters.free:
        return "parameter"
    if scalar in parameters.calculated:
        return "calculated"
    if variability in ("Parameter", "Constant"):
        return "constant"
    if scalar in inputs:
        return "input"
    if scalar in states:
        return "state"
    return "output" if causality == "Output" and "." not in flat_name else "local"


def declared_bound(info: Mapping[str, Any], key: str) -> float | None:
    """The literal ``min`` or ``max`` (``key``) a Modelica declaration gives, or None."""
    bound = info.get(key)
    if isinstance(bound, dict) and "Literal" in bound:
        return float(literal(bound["Literal"]))
    if isinstance(bound, dict) and "Unary" in bound and "Literal" in bound["Unary"].get("rhs", {}):
        return -float(literal(bound["Unary"]["rhs"]["Literal"]))
    return None


def declared_start(info: Mapping[str, Any], locate: _Locator, indices: list[int] | None = None) -> float | None:
    """The start value the Modelica source declares for a variable (``start=0``; for the element
    ``indices`` of an array, its element of ``start={...}``), or None. rumoca fills in 0.0 for an
    undeclared start; a declared one's source span is the literal itself (a negative number: a
    minus before the literal)."""
    start = info.get("start")
    for i in indices or []:
        if not isinstance(start, dict) or "Array" not in start:
            break
        elements = start["Array"]["elements"]
        if not 1 <= i <= len(elements):
            return None
        start = elements[i - 1]
    sign = 1.0
    if isinstance(start, dict) and "Unary" in start and "Literal" in start["Unary"].get("rhs", {}):
        if "Minus" not in json.dumps(start["Unary"].get("op")):
            return None
        sign, start = -1.0, start["Unary"]["rhs"]
    if not isinstance(start, dict) or "Literal" not in start:
        return None
    span = start["Literal"].get("span") or {}
    path_text = locate.files.get(span.get("source"))
    if path_text is None:
        return None
    try:
        float(path_text[1][span["start"]:span["end"]])
    except (KeyError, ValueError):
        return None
    return sign * float(literal(start["Literal"]))


def _variables(infos: dict[str, Info], types: Mapping[str, str], parameters: _Parameters, inputs: list[str],
               states: list[str], locate: _Locator) -> dict[str, Variable]:
    variables = {}
    for s, (info, indices, flat_name) in infos.items():
        start = parameters.defaults.get(s)
        if start is None and isinstance(parameters.values.get(s), (int, float)):
            start = float(parameters.values[s])
        if start is None and s in inputs:
            start = declared_start(info, locate, indices)  # an input the source gives a default, or None
        is_output = _role_names(info)[1] == "Output" and "." not in flat_name
        variables[s] = Variable(s, _role(s, info, flat_name, parameters, inputs, states), types.get(flat_name, "Real"),
                                info["unit"], info["description"], start, is_output, declared_bound(info, "min"),
                                declared_bound(info, "max"), info.get("display_unit") or None)
    return variables


def translate(model: Any, name: str) -> OdeModel:
    """Translate a loaded rumoca model (``fmubuild.source.load``) to an :class:`OdeModel`."""
    flat = model.to_dict("flat")
    locate = _Locator(model.to_dict("dae"))
    _reject_unsupported_sections(flat, locate, name)
    library = FunctionLibrary(flat["functions"], implicit_solves(flat["functions"], locate.files))
    types = flat["variable_type_names"]
    infos = _scalar_infos(flat)
    parameters = _Parameters(infos, types, library, name)
    for scalar, (info, _, _) in infos.items():
        if _is_parameter(info):
            parameters(scalar)
    _fold_subscripts(flat["equations"], parameters, name)

    state_names = _states(flat["equations"])
    inputs = [s for s, (info, _, flat_name) in infos.items()
              if _role_names(info)[1] == "Input" and "." not in flat_name]
    states = [s for s in infos if s in state_names]
    t, x, u, p = ca.MX.sym("time"), ca.MX.sym("x", len(states)), ca.MX.sym("u", len(inputs)), parameters.vector()
    memories, binding_equations = bound_variables(flat, locate.files, _is_parameter, name)
    m = ca.MX.sym("m", len(memories))
    known: dict[str, Value] = {"time": t, **{s: x[i] for i, s in enumerate(states)},
                               **{s: u[i] for i, s in enumerate(inputs)}, **parameters.values,
                               **{memory.name: m[i] for i, memory in enumerate(memories)}}
    unknowns = [f"der({s})" for s in states] + [s for s in infos if s not in known and not _is_parameter(infos[s][0])]
    equations = _equations(flat, locate, name) + binding_equations
    env = _solve(equations, unknowns, known, library, name)
    derivative_env = _solve(equations, unknowns, known, library.for_derivatives(), name) if library.implicit else env

    xdot = ca.vertcat(*[_mx(env[f"der({s})"]) for s in states]) if states else ca.MX(0, 1)
    xdot_derivative = ca.vertcat(*[_mx(derivative_env[f"der({s})"]) for s in states]) if states else ca.MX(0, 1)
    observed = [s for s in unknowns if not s.startswith("der(")]
    x0 = _start_values(states, infos, parameters, name)
    states, observed, renamed = _public_state_names(states, observed, env, x, infos)
    y = ca.vertcat(*[_mx(env[s]) for s in observed]) if observed else ca.MX(0, 1)
    y_derivative = ca.vertcat(*[_mx(derivative_env[s]) for s in observed]) if observed else ca.MX(0, 1)
    variables = _variables(infos, types, parameters, inputs, states, locate)
    for public, inner in renamed.items():  # the public name keeps the inner state's start and description
        variables[public] = replace(variables[public], start=variables[inner].start,
                                    description=variables[public].description or variables[inner].description)
    asserts = _asserts(flat, env, parameters, library, locate, name)
    for memory in memories:
        if memory.source not in observed:
            raise UnsupportedConstruct(f"memory {memory.name}: {memory.source} is not an observed variable", name)
    memory_defaults = [_constant_binding(memory.name, memory.binding, parameters, library, name) for memory in memories]
    return OdeModel(name, variables, states, inputs, parameters.free, observed, t, x, u, p, xdot, y, x0, m,
                    [memory.name for memory in memories], [memory.source for memory in memories], memory_defaults,
                    parameters.defaults, parameters.calculated, asserts, xdot_derivative, y_derivative)


def _constant_binding(variable: str, binding: Mapping[str, Any], parameters: _Parameters, library: FunctionLibrary,
                      name: str) -> float:
    where = f"{name}: binding of {variable}"
    value = _evaluator(parameters.values, library, where)(binding)
    if is_symbolic(value):
        raise UnsupportedConstruct(f"memory {variable} bound to a value that is not a constant", where)
    return float(value)


def _public_state_names(states: list[str], observed: list[str], env: Mapping[str, Value], x: ca.MX,
                        infos: dict[str, Info]) -> tuple[list[str], list[str], dict[str, str]]:
    """States named by the top-level output that equals them (``omega = rigidWheel.omega``
    makes ``omega`` the state, ``rigidWheel.omega`` an observed alias), so that importers set a
    state's start under its public name. Returns states, observed and {public: inner name}."""
    public_of: dict[str, str] = {}
    for name in observed:
        info, _, flat_name = infos[name]
        if _role_names(info)[1] != "Output" or "." in flat_name or not isinstance(env[name], ca.MX):
            continue
        for i, state in enumerate(states):
            if "." in state and state not in public_of and ca.is_equal(env[name], x[i], 2):
                public_of[state] = name
                break
    renamed = {public: inner for inner, public in public_of.items()}
    new_states = [public_of.get(s, s) for s in states]
    new_observed = [renamed.get(o, o) for o in observed]
    return new_states, new_observed, renamed


def _asserts(flat: Mapping[str, Any], env: Mapping[str, Value], parameters: _Parameters, library: FunctionLibrary,
             locate: _Locator, name: str) -> list[Assertion]:
    """The model's ``assert(condition, "message")`` equations as CasADi expressions, one per
    distinct (message, variables); conditions are checked by the FMU, not turned into events."""
    asserts: dict[tuple[str, tuple[str, ...]], Assertion] = {}
    for equation in flat.get("assert_equations", []):
        where = f"{name}: assert at {locate(equation.get('span'))}"
        message_node = equation["message"]
        if "Literal" not in message_node or "String" not in message_node["Literal"]["value"]:
            raise UnsupportedConstruct("assert message that is not a string literal", where)
        message = message_node["Literal"]["value"]["String"]
        level = "warning" if "warning" in json.dumps(equation.get("level")).lower() else "error"
        condition = Evaluator(partial(_lookup, env, where=where), library.call, where)(equation["condition"])
        referenced = sorted(n for n in _incidence(equation["condition"], list(env)) if n != "time")
        names = tuple(_public_name(n, parameters) for n in referenced)
        values = tuple(_mx(env[n]) for n in referenced)
        asserts.setdefault((message, names), Assertion(_mx(condition), message, level, names, values))
    return list(asserts.values())


def _public_name(scalar: str, parameters: _Parameters) -> str:
    """A parameter bound to another one (``wheels[1].soil.phi = soil.phi``) by the name of that one."""
    value = parameters.calculated.get(scalar)
    return value.name() if isinstance(value, ca.MX) and value.is_symbolic() else scalar


def _mx(value: Value) -> ca.MX:
    return value if isinstance(value, ca.MX) else ca.MX(float(value))


def _fold_subscripts(node: Any, parameters: _Parameters, name: str) -> None:
    """Subscripts that are expressions of structural parameters (``W[j + rover.nAxles]`` in a
    for-loop rumoca unrolled) replaced in place by their integer value, so that an equation's
    incidence sees which element it names."""
    if isinstance(node, list):
        for item in node:
            _fold_subscripts(item, parameters, name)
        return
    if not isinstance(node, dict):
        return
    ref = node.get("VarRef")
    if isinstance(ref, dict) and any("Expr" in sub for sub in ref.get("subscripts") or []):
        where = f"{name}: subscript of {ref.get('name', {}).get('name', '?')}"
        evaluate = Evaluator(parameters, parameters.library.call, where)
        folded = []
        for sub in ref["subscripts"]:
            try:
                value = subscript_values([sub], evaluate, where)[0] if "Expr" in sub else None
                folded.append(sub if value is None else {"Index": {"value": value}})
            except (UnsupportedConstruct, KeyError):  # a run-time subscript: refused where it is used
                folded.append(sub)
        ref["subscripts"] = folded
    for value in node.values():
        _fold_subscripts(value, parameters, name)


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


def _edges(slots: list[tuple[int, set[str]]], depends: list[set[str]], assignment: list[str]) -> list[set[int]]:
    """Per slot, the slots it needs first: those solving the unknowns it reads, and the other
    slots of its tuple equation (a multi-output call is one block)."""
    solved_by = {variable: slot for slot, variable in enumerate(assignment)}
    groups: dict[int, list[int]] = {}
    for slot, (equation, _) in enumerate(slots):
        groups.setdefault(equation, []).append(slot)
    edges: list[set[int]] = []
    for slot, (equation, _) in enumerate(slots):
        deps = {solved_by[v] for v in depends[slot] if v in solved_by and solved_by[v] != slot}
        deps |= {other for other in groups[equation] if other != slot}
        edges.append(deps)
    return edges


class _Tarjan:
    """Strongly connected components of a graph, iteratively, each emitted after the components
    it depends on (Tarjan's algorithm)."""

    def __init__(self, edges: list[set[int]]):
        self.edges = edges
        self.index_of: dict[int, int] = {}
        self.low: dict[int, int] = {}
        self.stack: list[int] = []
        self.on_stack: set[int] = set()
        self.components: list[list[int]] = []

    def _open(self, node: int, work: list[tuple[int, Iterator[int]]]) -> None:
        self.index_of[node] = self.low[node] = len(self.index_of)
        self.stack.append(node)
        self.on_stack.add(node)
        work.append((node, iter(sorted(self.edges[node]))))

    def _close(self, node: int) -> None:
        if self.low[node] != self.index_of[node]:
            return
        component = []
        while True:
            member = self.stack.pop()
            self.on_stack.discard(member)
            component.append(member)
            if member == node:
                break
        self.components.append(component)

    def _visit(self, root: int) -> None:
        work: list[tuple[int, Iterator[int]]] = []
        self._open(root, work)
        while work:
            node, children = work[-1]
            child = next((c for c in children if c not in self.index_of or c in self.on_stack), None)
            if child is not None and child not in self.index_of:
                self._open(child, work)
                continue
            if child is not None:  # on the stack: a back edge
                self.low[node] = min(self.low[node], self.index_of[child])
                continue
            work.pop()
            if work:
                self.low[work[-1][0]] = min(self.low[work[-1][0]], self.low[node])
            self._close(node)

    def components_in_order(self) -> list[list[int]]:
        for root in range(len(self.edges)):
            if root not in self.index_of:
                self._visit(root)
        return self.components


def _blt(slots: list[tuple[int, set[str]]], depends: list[set[str]], assignment: list[str]) -> list[list[int]]:
    """Strongly connected components of the slot dependency graph in evaluation order. Slots of
    one tuple equation are one block."""
    return _Tarjan(_edges(slots, depends, assignment)).components_in_order()


def _evaluator(env: Mapping[str, Value], library: FunctionLibrary, where: str) -> Evaluator:
    return Evaluator(partial(_lookup, env, where=where), library.call, where, allow_events=False)


def _solve_tuple(eq_indices: list[int], equations: list[Equation], env: dict[str, Value],
                 library: FunctionLibrary) -> None:
    """A tuple equated to a multi-output call: one call gives every target."""
    tuple_equations = [i for i in eq_indices if equations[i][1] is not None]
    if len(eq_indices) != 1:
        raise UnsupportedConstruct("a multi-output function call inside an algebraic loop",
                                   equations[tuple_equations[0]][2])
    residual, targets, where = equations[eq_indices[0]]
    assert targets is not None  # a tuple equation
    if all(target in env for target in targets):
        return  # solved with its first target: one call for all outputs
    for target, value in zip(targets, _evaluator(env, library, where).call_outputs(residual)):
        env[target] = value


def _solve_explicit(equation: Equation, unknown: str, env: dict[str, Value], library: FunctionLibrary) -> bool:
    """``unknown = expression`` (the common case), evaluated as it stands, keeping shared nodes;
    False when the equation is not of that form."""
    residual, _, where = equation
    explicit = _explicit_side(residual, unknown)
    if explicit is None:
        return False
    env[unknown] = _evaluator(env, library, where)(explicit)
    return True


def _solve_linear(eq_indices: list[int], block_unknowns: list[str], equations: list[Equation],
                  env: dict[str, Value], library: FunctionLibrary) -> None:
    """A block linear in its unknowns, solved symbolically; a nonlinear one is rejected."""
    symbols = [ca.MX.sym(f"unknown_{i}") for i in range(len(block_unknowns))]
    trial = dict(env)
    trial.update(zip(block_unknowns, symbols))
    residuals = [_mx(_evaluator(trial, library, equations[i][2])(equations[i][0])) for i in eq_indices]
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
        env[block_unknowns[0]] = ca.simplify((-offset / jacobian)[0])
        return
    solution = -ca.solve(jacobian, offset)
    for i, variable in enumerate(block_unknowns):
        env[variable] = solution[i]


def _solve_block(eq_indices: list[int], block_unknowns: list[str], equations: list[Equation], env: dict[str, Value],
                 library: FunctionLibrary, name: str) -> None:
    """Solve one BLT block for its unknowns into ``env``."""
    if any(equations[i][1] is not None for i in eq_indices):
        _solve_tuple(eq_indices, equations, env, library)
        return
    if len(eq_indices) == 1 and len(block_unknowns) == 1 and _solve_explicit(
            equations[eq_indices[0]], block_unknowns[0], env, library):
        return
    _solve_linear(eq_indices, block_unknowns, equations, env, library)


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
