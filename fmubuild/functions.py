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

from collections.abc import Mapping
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

UNSUPPORTED_STATEMENTS = {"While": "while-loop (unbounded iteration)", "When": "when-statement (events)",
                          "Break": "break", "Return": "return", "Reinit": "reinit", "Assert": "assert",
                          "Terminate": "terminate"}


#: Largest SX instruction count up to which a function is inlined into one SX function.
EXPAND_LIMIT = 8000


def _safe(name: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in name)


class FunctionLibrary:
    """The flat model's functions, translated on demand and cached by (name, structural args)."""

    def __init__(self, flat_functions: Mapping[str, Any]):
        self.flat = dict(flat_functions)
        self.cache: dict[tuple[str, tuple[Any, ...]], ca.Function] = {}

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
        inputs = definition["inputs"]
        if len(args) > len(inputs):
            raise UnsupportedConstruct(f"{len(args)} arguments for the {len(inputs)} inputs of {name}", name)
        values = list(args)
        for declared in inputs[len(args):]:
            if declared["default"] is None:
                raise UnsupportedConstruct(f"missing argument {declared['name']} without default", name)
            values.append(Evaluator(lambda n: _no_lookup(n, name), self.call, name)(declared["default"]))
        structural = tuple(v if decl["type_name"] in ("Integer", "Boolean") else None
                           for v, decl in zip(values, inputs))
        for v, decl in zip(values, inputs):
            if decl["type_name"] in ("Integer", "Boolean") and is_symbolic(v):
                raise UnsupportedConstruct(
                    f"Integer/Boolean argument {decl['name']} of {name} depends on run-time values", name)
        key = (definition["name"], structural)
        if key not in self.cache:
            self.cache[key] = self._translate(definition, structural)
        function = self.cache[key]
        real_args = [v for v, s in zip(values, structural) if s is None]
        result = function(*real_args)
        if isinstance(result, (ca.MX, ca.SX, ca.DM)):
            result = [result]
        elif isinstance(result, dict):
            result = list(result.values())
        return tuple(result)

    def _translate(self, definition: Mapping[str, Any], structural: tuple[Any, ...]) -> ca.Function:
        name = definition["name"]
        for declared in list(definition["inputs"]) + list(definition["outputs"]) + list(definition["locals"]):
            if declared["shape_expr"]:
                raise UnsupportedConstruct(f"array variable {declared['name']} in function {name}", name)
        if definition.get("external"):
            raise UnsupportedConstruct(f"external function {name}", name)
        symbols = []
        env: dict[str, Value] = {}
        for declared, fixed in zip(definition["inputs"], structural):
            if fixed is None:
                symbol = ca.MX.sym(declared["name"])
                symbols.append(symbol)
                env[declared["name"]] = symbol
            else:
                env[declared["name"]] = fixed
        for declared in list(definition["outputs"]) + list(definition["locals"]):
            if declared["default"] is not None:
                env[declared["name"]] = Evaluator(env.__getitem__, self.call, name)(declared["default"])
        self._execute(definition["body"], env, name)
        outputs = []
        for declared in definition["outputs"]:
            if declared["name"] not in env:
                raise UnsupportedConstruct(f"output {declared['name']} of {name} is never assigned", name)
            value = env[declared["name"]]
            outputs.append(value if is_symbolic(value) else ca.MX(float(value)))
        suffix = "_".join(str(int(s)) for s in structural if s is not None)
        function = ca.Function(_safe(name) + (f"_{suffix}" if suffix else ""), symbols, outputs,
                               [s.name() for s in symbols], [d["name"] for d in definition["outputs"]])
        expanded = function.expand()
        return expanded if expanded.n_instructions() <= EXPAND_LIMIT else function

    def _execute(self, statements: list[Any], env: dict[str, Value], where: str) -> None:
        def lookup(n: str) -> Value:
            if n not in env:
                raise UnsupportedConstruct(f"variable {n} used before it is assigned", where)
            return env[n]
        evaluate = Evaluator(lookup, self.call, where)
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
        i = start
        while (step > 0 and i <= end) or (step < 0 and i >= end):
            env[index["ident"]] = i
            self._execute(body["equations"], env, where)
            i += step
        env.pop(index["ident"], None)

    def _if(self, body: Mapping[str, Any], env: dict[str, Value], where: str, evaluate: Evaluator) -> None:
        blocks = [(evaluate(b["cond"]), b["stmts"]) for b in body["cond_blocks"]]
        self._if_chain(blocks, body.get("else_block") or [], env, where)

    def _if_chain(self, blocks: list[tuple[Value, list[Any]]], otherwise: list[Any], env: dict[str, Value],
                  where: str) -> None:
        if not blocks:
            self._execute(otherwise, env, where)
            return
        condition, statements = blocks[0]
        if not is_symbolic(condition):
            if condition:
                self._execute(statements, env, where)
            else:
                self._if_chain(blocks[1:], otherwise, env, where)
            return
        then_env, else_env = dict(env), dict(env)
        self._execute(statements, then_env, where)
        self._if_chain(blocks[1:], otherwise, else_env, where)
        for name in set(then_env) | set(else_env):
            if name not in then_env or name not in else_env:
                continue  # assigned in one branch only and unset before: stays local to it
            a, b = then_env[name], else_env[name]
            if a is b:
                env[name] = a
            else:
                env[name] = select(condition, a, b)


def _target(comp: Mapping[str, Any], evaluate: Evaluator, where: str) -> str:
    parts = comp["parts"]
    if len(parts) != 1:
        raise UnsupportedConstruct("assignment to a record field", where)
    indices = subscript_values(parts[0]["subs"], evaluate, where)
    return scalar_name(parts[0]["ident"], indices)


def _no_lookup(name: str, where: str) -> Value:
    raise UnsupportedConstruct(f"default argument refers to {name}", where)
