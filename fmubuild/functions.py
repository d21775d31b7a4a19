"""Modelica functions (as rumoca flattens them) → CasADi Functions.

Each Modelica function becomes one CasADi Function per combination of its Integer/Boolean
arguments (they are structural: loop bounds, flags). The body is executed symbolically on MX
inputs: assignments bind values, for-loops over constant ranges unroll, if-statements on
constant conditions pick their branch, and if-statements on run-time conditions execute both
branches and merge every assigned variable with ``if_else``. Calls to other Modelica functions
stay CasADi call nodes, so each function's C code is generated once. A function without such
calls is expanded to SX (faster generated code).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import casadi as ca

from .expressions import (
    Evaluator,
    UnsupportedConstruct,
    Value,
    is_symbolic,
    scalar_name,
    select,
    subscript_values,
)
from .implicit import ImplicitSolve, differentiable_outputs

UNSUPPORTED_STATEMENTS = {"While": "while-loop (unbounded iteration)", "When": "when-statement (events)",
                          "Break": "break", "Return": "return", "Reinit": "reinit", "Assert": "assert",
                          "Terminate": "terminate"}


#: Largest SX instruction count up to which a function is inlined into one SX function.
EXPAND_LIMIT = 8000

#: A function's forward derivative is generated for up to 8 directions at once: a Jacobian of n
#: colours calls it ceil(n / 8) times, each recomputing the function's value once. The rovers'
#: Jacobians have 6-8 colours (six wheels' spins in one), so one call. One direction at a time
#: (``max_num_dir`` 1, the leaner C of issue 31: Rover 1.05 MB of C, 0.41 MB library) recomputed the
#: contacts' values once per colour, and the integrator's Jacobian, refreshed every 20 steps then, took
#: 57 % of Rover.fmu's time (perf). With 8: 1.98 MB of C, 0.74 MB library; SteerableRover.fmu steps
#: a path twice as fast, Rover.fmu 1.2-1.8x (measured side by side); results within 6e-13 of each
#: signal's largest value (the same derivatives, rounded in another order); Wheel and SingleWheel
#: (one or two colours) bit for bit.
FORWARD_DIRECTIONS = {"max_num_dir": 8}


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in name)


class FunctionLibrary:
    """The flat model's functions, translated on demand and cached by (name, structural args).

    ``implicit``: the functions that solve an equation (fmubuild.implicit). A library made by
    :meth:`for_derivatives` translates the graphs the FMU's derivatives are taken from: calls of
    such functions get the implicit function's derivative, and so do the functions that call them;
    every other function is the value library's own (generated once)."""

    def __init__(self, flat_functions: Mapping[str, Any], implicit: Mapping[str, ImplicitSolve] | None = None,
                 values: FunctionLibrary | None = None):
        self.flat = dict(flat_functions)
        self.cache: dict[tuple[str, tuple[Any, ...]], ca.Function] = {}
        self.implicit = dict(implicit or {})
        self.values = values
        self._reaches: dict[str, bool] = {}

    def for_derivatives(self) -> FunctionLibrary:
        """The library of the derivative graphs (see the class)."""
        return FunctionLibrary(self.flat, self.implicit, values=self)

    def _reaches_implicit(self, name: str) -> bool:
        """Whether the function ``name`` is, or calls (at any depth), a function with an implicit solve."""
        if name not in self._reaches:
            self._reaches[name] = False  # recursion guard
            definition = self.definition(name)
            self._reaches[name] = definition["name"] in self.implicit or any(
                self._reaches_implicit(callee) for callee in _callees(definition["body"]))
        return self._reaches[name]

    def definition(self, name: str) -> Mapping[str, Any]:
        if name in self.flat:
            return self.flat[name]
        short = name.rsplit(".", 1)[-1]
        matches = [k for k in self.flat if k.rsplit(".", 1)[-1] == short]
        if len(matches) == 1:
            return self.flat[matches[0]]
        raise UnsupportedConstruct(f"call of unknown function {name}", "function call")

    def call(self, name: str, args: list[Value]) -> tuple[Value, ...]:
        """Outputs of the Modelica function ``name`` applied to ``args`` (defaults filled in)."""
        definition = self.definition(name)
        values = self._arguments(definition, args, name)
        if not any(is_symbolic(v) for v in values):
            return self._evaluate(definition, values)
        if self.values is not None and not self._reaches_implicit(definition["name"]):
            return self.values.call(name, args)  # the derivative graphs: the value graph's own function
        if self.values is not None and definition["name"] in self.implicit:
            solve = self.implicit[definition["name"]]
            # The solve's values only: its arguments without derivative, so that no derivative of its
            # iterations is computed (and thrown away) in the generated derivative functions.
            outputs = self.values.call(name, [ca.stop_diff(a, 1) if is_symbolic(a) else a for a in args])
            return differentiable_outputs(solve, definition, self.definition(solve.residual), values, outputs,
                                          self.values.call)
        inputs = definition["inputs"]
        structural = tuple(v if decl["type_name"] in ("Integer", "Boolean") else None
                           for v, decl in zip(values, inputs))
        for v, decl in zip(values, inputs):
            if decl["type_name"] in ("Integer", "Boolean") and is_symbolic(v):
                raise UnsupportedConstruct(
                    f"Integer/Boolean argument {decl['name']} of {name} depends on run-time values", name)
        key = (definition["name"], structural)
        if key not in self.cache:
            self.cache[key] = self._translate(definition, structural)
        result = self.cache[key](*[v for v, s in zip(values, structural) if s is None])
        if isinstance(result, (ca.MX, ca.SX, ca.DM)):
            result = [result]
        elif isinstance(result, dict):
            result = list(result.values())
        return tuple(result)

    def _arguments(self, definition: Mapping[str, Any], args: list[Value], name: str) -> list[Value]:
        """``args`` followed by the defaults of the inputs they leave out."""
        inputs = definition["inputs"]
        if len(args) > len(inputs):
            raise UnsupportedConstruct(f"{len(args)} arguments for the {len(inputs)} inputs of {name}", name)
        values = list(args)
        for declared in inputs[len(args):]:
            if declared["default"] is None:
                raise UnsupportedConstruct(f"missing argument {declared['name']} without default", name)
            values.append(Evaluator(lambda n: _no_lookup(n, name), self.call, name)(declared["default"]))
        return values

    def _evaluate(self, definition: Mapping[str, Any], values: list[Value]) -> tuple[Value, ...]:
        """A call whose arguments are all known at translation time (e.g. the nodes of a
        quadrature rule from loop indices) is executed at once: its outputs are numbers, which
        fold into the caller's expressions instead of becoming a call in the generated code."""
        self._check_supported(definition)
        env: dict[str, Value] = {d["name"]: v for d, v in zip(definition["inputs"], values)}
        self._defaults(definition, env)
        self._execute(definition["body"], env, definition["name"])
        return tuple(_assigned_outputs(definition, env))

    @staticmethod
    def _check_supported(definition: Mapping[str, Any]) -> None:
        name = definition["name"]
        for declared in list(definition["inputs"]) + list(definition["outputs"]) + list(definition["locals"]):
            if declared["shape_expr"]:
                raise UnsupportedConstruct(f"array variable {declared['name']} in function {name}", name)
        if definition.get("external"):
            raise UnsupportedConstruct(f"external function {name}", name)

    def _environment(self, definition: Mapping[str, Any], structural: tuple[Any, ...]) -> tuple[list[ca.MX],
                                                                                                 dict[str, Value]]:
        """Symbols of the run-time inputs, and the start environment: structural inputs fixed,
        outputs and locals at their defaults."""
        symbols = []
        env: dict[str, Value] = {}
        for declared, fixed in zip(definition["inputs"], structural):
            if fixed is None:
                symbol = ca.MX.sym(declared["name"])
                symbols.append(symbol)
                env[declared["name"]] = symbol
            else:
                env[declared["name"]] = fixed
        self._defaults(definition, env)
        return symbols, env

    def _defaults(self, definition: Mapping[str, Any], env: dict[str, Value]) -> None:
        """Outputs and locals with a declared default get it in ``env`` (inputs already there)."""
        for declared in list(definition["outputs"]) + list(definition["locals"]):
            if declared["default"] is not None:
                env[declared["name"]] = Evaluator(env.__getitem__, self.call, definition["name"])(declared["default"])

    @staticmethod
    def _outputs(definition: Mapping[str, Any], env: dict[str, Value]) -> list[ca.MX]:
        return [value if is_symbolic(value) else ca.MX(float(value)) for value in _assigned_outputs(definition, env)]

    def _translate(self, definition: Mapping[str, Any], structural: tuple[Any, ...]) -> ca.Function:
        name = definition["name"]
        self._check_supported(definition)
        symbols, env = self._environment(definition, structural)
        self._execute(definition["body"], env, name)
        outputs = self._outputs(definition, env)
        suffix = "_".join(str(int(s)) for s in structural if s is not None)
        if self.values is not None:
            suffix += "_derivative"  # the derivative graph's version of a function (another body)
        function = ca.Function(_safe(name) + (f"_{suffix}" if suffix else ""), symbols, outputs,
                               [s.name() for s in symbols], [d["name"] for d in definition["outputs"]],
                               FORWARD_DIRECTIONS)
        if self.values is not None:
            return function  # SX has no stop_diff (its derivative comes out NaN): the derivative graphs stay MX
        expanded = function.expand()
        if expanded.n_instructions() > EXPAND_LIMIT:
            return function
        # Common subexpressions of the unrolled loops (e.g. tan(phi) per quadrature point) once.
        inputs = expanded.sx_in()
        return ca.Function(expanded.name(), inputs, ca.cse(expanded.call(inputs)),
                           expanded.name_in(), expanded.name_out(), FORWARD_DIRECTIONS)

    def _execute(self, statements: list[Any], env: dict[str, Value], where: str) -> None:
        evaluate = Evaluator(lambda n: _lookup(env, n, where), self.call, where)
        for statement in statements:
            (kind, body), = statement.items()
            if kind == "Assignment":
                target = _target(body["comp"], evaluate, where)
                env[target] = evaluate(body["value"])
            elif kind == "FunctionCall":
                outputs = self.call(body["comp"]["name"], [evaluate(a) for a in body["args"]])
                targets = [_target(o, evaluate, where) for o in body["outputs"]]
                for target, value in zip(targets, outputs):
                    env[target] = value
            elif kind == "For":
                self._for(body, env, where, evaluate)
            elif kind == "If":
                self._if(body, env, where, evaluate)
            elif kind in UNSUPPORTED_STATEMENTS:
                raise UnsupportedConstruct(UNSUPPORTED_STATEMENTS[kind], where)
            else:
                raise UnsupportedConstruct(f"statement of kind {kind}", where)

    def _for(self, body: Mapping[str, Any], env: dict[str, Value], where: str, evaluate: Evaluator) -> None:
        if len(body["indices"]) != 1:
            raise UnsupportedConstruct("for-loop with several indices", where)
        index = body["indices"][0]
        (kind, rng), = index["range"].items()
        if kind != "Range":
            raise UnsupportedConstruct(f"for-loop over a {kind}", where)
        start = evaluate(rng["start"])
        end = evaluate(rng["end"])
        step = evaluate(rng["step"]) if rng.get("step") else 1
        if any(is_symbolic(v) for v in (start, end, step)):
            raise UnsupportedConstruct("for-loop whose range depends on run-time values", where)
        values = []
        i = start
        while (step > 0 and i <= end) or (step < 0 and i >= end):
            values.append(i)
            i += step
        guarded = _guarded_body(body["equations"], index["ident"])
        if guarded is not None:
            self._guarded_iterations(guarded[0], guarded[1], index["ident"], values, env, where)
        else:
            for i in values:
                env[index["ident"]] = i
                self._execute(body["equations"], env, where)
        env.pop(index["ident"], None)

    def _guarded_iterations(self, condition: Any, statements: list[Any], ident: str, values: list[Any],
                            env: dict[str, Value], where: str) -> None:
        """The iterations ``values`` of ``for ident loop if condition then statements end if; end
        for`` where ``condition`` does not refer to ``ident``: an iteration whose condition is false
        changes nothing, so every later one sees the same values and is false too. The rest of the
        loop is therefore nested in the true branch, and a run-time false skips all of it in one
        branch (a converged solve's remaining iterations cost one test, not one each)."""
        if not values:
            return
        env[ident] = values[0]
        value = Evaluator(lambda n: _lookup(env, n, where), self.call, where)(condition)

        def taken(inner: dict[str, Value]) -> None:
            self._execute(statements, inner, where)
            self._guarded_iterations(condition, statements, ident, values[1:], inner, where)

        if not is_symbolic(value):
            if value:
                taken(env)
            return
        self._switch(value, taken, lambda inner: None, env, where)

    def _if(self, body: Mapping[str, Any], env: dict[str, Value], where: str, evaluate: Evaluator) -> None:
        blocks = [(b["cond"], b["stmts"]) for b in body["cond_blocks"]]
        self._if_chain(blocks, body.get("else_block") or [], env, where)

    def _if_chain(self, blocks: list[tuple[Any, list[Any]]], otherwise: list[Any], env: dict[str, Value],
                  where: str) -> None:
        """Execute ``if c1 then s1 elseif c2 then s2 ... else otherwise`` on ``env`` (conditions
        are rumoca expressions, evaluated in order on the values they see)."""
        if not blocks:
            self._execute(otherwise, env, where)
            return
        condition = Evaluator(lambda n: _lookup(env, n, where), self.call, where)(blocks[0][0])
        statements = blocks[0][1]
        if not is_symbolic(condition):
            if condition:
                self._execute(statements, env, where)
            else:
                self._if_chain(blocks[1:], otherwise, env, where)
            return
        if _calls_function([statements, blocks[1:], otherwise]):
            self._switch(condition, lambda inner: self._execute(statements, inner, where),
                         lambda inner: self._if_chain(blocks[1:], otherwise, inner, where), env, where)
            return
        then_env, else_env = dict(env), dict(env)
        self._execute(statements, then_env, where)
        self._if_chain(blocks[1:], otherwise, else_env, where)
        for name in _merged(env, then_env, else_env):
            env[name] = select(condition, then_env[name], else_env[name])

    def _switch(self, condition: ca.MX, then: Callable[[dict[str, Value]], None],
                otherwise: Callable[[dict[str, Value]], None], env: dict[str, Value], where: str) -> None:
        """A run-time if-statement whose branches call Modelica functions: only the branch taken is
        evaluated (a CasADi Switch), e.g. the skipped iterations of a converged solve. Each branch
        (``then`` and ``otherwise`` execute it on an environment) becomes a Function of the
        symbolic values it can see, so the graphs stay local."""
        live = sorted(n for n, v in env.items() if is_symbolic(v))
        inner = {n: ca.MX.sym(_safe(n)) for n in live}
        then_env = {**env, **inner}
        else_env = {**env, **inner}
        then(then_env)
        otherwise(else_env)
        merged = _merged(env, then_env, else_env)
        if not merged:
            return
        arguments = [inner[n] for n in live]
        branches = [ca.Function(f"branch_{i}", arguments, [ca.vertcat(*[_as_mx(e[n]) for n in merged])])
                    for i, e in enumerate((then_env, else_env))]
        chosen = ca.Function.if_else("switch", branches[0], branches[1])(condition, *[env[n] for n in live])
        for i, name in enumerate(merged):
            env[name] = chosen[i]


def _guarded_body(statements: list[Any], ident: str) -> tuple[Any, list[Any]] | None:
    """(condition, statements) if a loop body is one ``if condition then statements end if``
    (no elseif, no else) whose statements call a Modelica function (a Switch: without a call both
    branches are computed anyway) and whose condition does not refer to the loop index ``ident``,
    else None."""
    if len(statements) != 1 or "If" not in statements[0]:
        return None
    body = statements[0]["If"]
    if len(body["cond_blocks"]) != 1 or body.get("else_block"):
        return None
    condition, guarded = body["cond_blocks"][0]["cond"], body["cond_blocks"][0]["stmts"]
    if not _calls_function(guarded) or _refers_to(condition, ident):
        return None
    return condition, guarded


def _refers_to(node: Any, name: str) -> bool:
    """Whether a rumoca expression refers to the variable ``name``."""
    if isinstance(node, dict):
        if "VarRef" in node:
            parts = node["VarRef"].get("name", {})
            if parts.get("name") == name or any(_refers_to(s, name) for s in node["VarRef"].get("subscripts", [])):
                return True
        return any(_refers_to(v, name) for v in node.values())
    if isinstance(node, (list, tuple)):
        return any(_refers_to(v, name) for v in node)
    return False


def _assigned_outputs(definition: Mapping[str, Any], env: Mapping[str, Value]) -> list[Value]:
    """The function's outputs from ``env``, in declaration order; each must have been assigned."""
    for declared in definition["outputs"]:
        if declared["name"] not in env:
            raise UnsupportedConstruct(f"output {declared['name']} of {definition['name']} is never assigned",
                                       definition["name"])
    return [env[declared["name"]] for declared in definition["outputs"]]


def _merged(env: Mapping[str, Value], then_env: Mapping[str, Value], else_env: Mapping[str, Value]) -> list[str]:
    """Variables the two branches of an if-statement leave with different values (a variable
    assigned in one branch only and unset before stays local to that branch)."""
    names = []
    for name in sorted(set(then_env) & set(else_env)):
        if then_env[name] is not else_env[name]:
            names.append(name)
    return names


def _lookup(env: Mapping[str, Value], name: str, where: str) -> Value:
    if name not in env:
        raise UnsupportedConstruct(f"variable {name} used before it is assigned", where)
    return env[name]


def _calls_function(node: Any) -> bool:
    """Whether statements or expressions (rumoca's nested dicts and lists) call a Modelica function."""
    if isinstance(node, dict):
        return "FunctionCall" in node or any(_calls_function(v) for v in node.values())
    if isinstance(node, (list, tuple)):
        return any(_calls_function(v) for v in node)
    return False


def _callees(node: Any) -> set[str]:
    """Names of the Modelica functions that statements or expressions call."""
    found: set[str] = set()
    if isinstance(node, dict):
        for kind, body in node.items():
            if kind == "FunctionCall" and isinstance(body, dict):
                name = (body.get("comp") or body.get("name") or {}).get("name")
                if isinstance(name, str):
                    found.add(name)
            found |= _callees(body)
    elif isinstance(node, (list, tuple)):
        for item in node:
            found |= _callees(item)
    return found


def _as_mx(value: Value) -> ca.MX:
    return value if isinstance(value, ca.MX) else ca.MX(float(value))


def _target(comp: Mapping[str, Any], evaluate: Evaluator, where: str) -> str:
    parts = comp["parts"]
    if len(parts) != 1:
        raise UnsupportedConstruct("assignment to a record field", where)
    indices = subscript_values(parts[0]["subs"], evaluate, where)
    return scalar_name(parts[0]["ident"], indices)


def _no_lookup(name: str, where: str) -> Value:
    raise UnsupportedConstruct(f"default argument refers to {name}", where)
