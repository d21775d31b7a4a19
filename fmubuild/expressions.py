"""rumoca flat-model expressions and function algorithms → CasADi expressions.

Values are either Python numbers (integers, booleans and anything computable at translation
time: loop bounds, ``i == 0``, ``mod(i, 2)``) or CasADi MX/SX expressions. Keeping the constant
parts as Python values lets for-loops unroll and constant ``if`` branches be chosen at
translation time; only conditions on run-time values become ``if_else``.

Anything not handled raises :class:`UnsupportedConstruct`, which names the construct and where
it came from and suggests the omc backend.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import casadi as ca

Value = Any  # int | float | bool | ca.MX | ca.SX

OMC_HINT = "the built-in exporter cannot translate it; build this model with the omc backend (make fmus BACKEND=omc)"


class UnsupportedConstruct(ValueError):
    """A Modelica construct the built-in exporter does not translate."""

    def __init__(self, what: str, where: str):
        super().__init__(f"{where}: {what}: {OMC_HINT}")
        self.what = what
        self.where = where

    def __reduce__(self) -> tuple[type[UnsupportedConstruct], tuple[str, str]]:
        """Pickled with its two arguments, so that a parallel build's worker can hand it to the
        parent (pickled as a plain ValueError it failed to unpickle there, and the pool reported
        only "a process in the process pool was terminated abruptly")."""
        return UnsupportedConstruct, (self.what, self.where)


def is_symbolic(value: Value) -> bool:
    return isinstance(value, (ca.MX, ca.SX))


def _fmin(a: Value, b: Value) -> Value:
    return min(a, b) if not (is_symbolic(a) or is_symbolic(b)) else ca.fmin(a, b)


def _fmax(a: Value, b: Value) -> Value:
    return max(a, b) if not (is_symbolic(a) or is_symbolic(b)) else ca.fmax(a, b)


def _unary_math(numeric: Callable[[float], float], symbolic: Callable[[Any], Any]) -> Callable[[Value], Value]:
    def apply(a: Value) -> Value:
        return symbolic(a) if is_symbolic(a) else numeric(a)
    return apply


def _sign(a: Value) -> Value:
    return ca.sign(a) if is_symbolic(a) else float((a > 0) - (a < 0))


def _integer_division(a: Value, b: Value) -> Value:
    if is_symbolic(a) or is_symbolic(b):
        return ca.sign(a / b) * ca.floor(ca.fabs(a / b))
    return int(a / b)


def _mod(a: Value, b: Value) -> Value:
    if is_symbolic(a) or is_symbolic(b):
        return a - ca.floor(a / b) * b
    return a - math.floor(a / b) * b


BUILTINS: dict[str, Callable[..., Value]] = {
    "NoEvent": lambda a: a,
    "Smooth": lambda order, a: a,
    "Min": _fmin,
    "Max": _fmax,
    "Abs": _unary_math(abs, ca.fabs),
    "Sign": _sign,
    "Sqrt": _unary_math(math.sqrt, ca.sqrt),
    "Sin": _unary_math(math.sin, ca.sin),
    "Cos": _unary_math(math.cos, ca.cos),
    "Tan": _unary_math(math.tan, ca.tan),
    "Asin": _unary_math(math.asin, ca.asin),
    "Acos": _unary_math(math.acos, ca.acos),
    "Atan": _unary_math(math.atan, ca.atan),
    "Atan2": lambda a, b: ca.atan2(a, b) if is_symbolic(a) or is_symbolic(b) else math.atan2(a, b),
    "Sinh": _unary_math(math.sinh, ca.sinh),
    "Cosh": _unary_math(math.cosh, ca.cosh),
    "Tanh": _unary_math(math.tanh, ca.tanh),
    "Exp": _unary_math(math.exp, ca.exp),
    "Log": _unary_math(math.log, ca.log),
    "Log10": _unary_math(math.log10, lambda a: ca.log(a) / math.log(10.0)),
    "Floor": _unary_math(math.floor, ca.floor),
    "Ceil": _unary_math(math.ceil, ca.ceil),
    "Div": _integer_division,
    "Mod": _mod,
    "Rem": lambda a, b: a - _integer_division(a, b) * b,
}

#: Builtins whose use means events, discrete time or other semantics the exporter lacks.
EVENT_BUILTINS = {"Pre", "Edge", "Change", "Initial", "Terminal", "Sample", "Reinit", "Delay",
                  "Cardinality", "Terminate", "Integer"}


def _compare(op: str, a: Value, b: Value) -> Value:
    """A relation; CasADi overloads the operators, so one form serves both kinds of values."""
    return {"Lt": a < b, "Le": a <= b, "Gt": a > b, "Ge": a >= b, "Eq": a == b, "Neq": a != b}[op]


def _logic(op: str, a: Value, b: Value) -> Value:
    """``and``/``or``; a constant side decides at translation time where it can (``flag or c``
    with a true flag is true), so a structural flag can switch a run-time condition off."""
    if is_symbolic(a) and is_symbolic(b):
        return ca.logic_and(a, b) if op == "And" else ca.logic_or(a, b)
    if is_symbolic(a) or is_symbolic(b):
        constant, other = (b, a) if is_symbolic(a) else (a, b)
        if op == "And":
            return other if constant else False
        return True if constant else other
    return (a and b) if op == "And" else (a or b)


def power(a: Value, b: Value) -> Value:
    """a ^ b. With a run-time exponent, CasADi's pow has the partial derivative log(a)·a^b
    with respect to b, which is NaN at a = 0 (-inf · 0) and poisons every Jacobian even when b
    is a constant parameter; so a > 0 goes through exp(b log a), a = 0 gives 0 (1 if b = 0)
    with zero derivative, and only a < 0 uses pow."""
    if not (is_symbolic(a) or is_symbolic(b)):
        return a ** b
    if not is_symbolic(b):
        return ca.power(a, b)  # constant exponent: derivative b·a^(b-1), no log term
    at_zero = ca.if_else(b == 0, 1.0, 0.0)
    return ca.if_else(a > 0, ca.exp(b * ca.log(a)), ca.if_else(a < 0, ca.power(a, b), at_zero))


def select(condition: Value, then: Value, otherwise: Value) -> Value:
    """``if condition then then else otherwise`` for constant or run-time conditions."""
    if not is_symbolic(condition):
        return then if condition else otherwise
    if not is_symbolic(then) and not is_symbolic(otherwise) and then == otherwise:
        return then
    return ca.if_else(condition, then, otherwise)


def literal(node: Mapping[str, Any]) -> Value:
    (kind, value), = node["value"].items() if isinstance(node["value"], dict) else (("Real", node["value"]),)
    if kind == "Integer":
        return int(value)
    if kind == "Real":
        return float(value)
    if kind == "Boolean":
        return bool(value)
    raise UnsupportedConstruct(f"literal of kind {kind} ({value!r})", "expression")


def subscript_values(subscripts: list[Any], evaluate: Callable[[Any], Value], where: str) -> list[int]:
    """Constant integer subscripts of a reference."""
    values = []
    for sub in subscripts:
        (kind, body), = sub.items()
        if kind == "Index":
            value = body["value"]
        elif kind == "Expr":
            value = evaluate(body["expr"])
        else:
            raise UnsupportedConstruct(f"array subscript of kind {kind}", where)
        if is_symbolic(value) or not float(value).is_integer():
            raise UnsupportedConstruct("an array subscript that depends on run-time values", where)
        values.append(int(value))
    return values


def scalar_name(name: str, indices: list[int]) -> str:
    return f"{name}[{','.join(str(i) for i in indices)}]" if indices else name


class Evaluator:
    """Evaluates expression trees against ``lookup`` (scalar name → value) and ``call``
    (function name, argument values → tuple of output values)."""

    def __init__(self, lookup: Callable[[str], Value], call: Callable[[str, list[Value]], tuple[Value, ...]],
                 where: str, allow_events: bool = True):
        self.lookup = lookup
        self.call = call
        self.where = where
        self.allow_events = allow_events
        self._no_event_depth = 0

    def __call__(self, node: Mapping[str, Any]) -> Value:
        (kind, body), = node.items()
        method = getattr(self, f"_{kind}", None)
        if method is None:
            raise UnsupportedConstruct(f"expression of kind {kind}", self.where)
        return method(body)

    def _VarRef(self, body: Mapping[str, Any]) -> Value:
        indices = subscript_values(body["subscripts"], self, self.where)
        return self.lookup(scalar_name(body["name"]["name"], indices))

    def _Literal(self, body: Mapping[str, Any]) -> Value:
        return literal(body)

    def _Binary(self, body: Mapping[str, Any]) -> Value:
        op = body["op"]
        a, b = self(body["lhs"]), self(body["rhs"])
        if op in ("Add", "AddElem"):
            return a + b
        if op in ("Sub", "SubElem"):
            return a - b
        if op in ("Mul", "MulElem"):
            return a * b
        if op in ("Div", "DivElem"):
            return a / b
        if op in ("Exp", "ExpElem"):
            return power(a, b)
        if op in ("Lt", "Le", "Gt", "Ge", "Eq", "Neq"):
            self._check_event(a, b, op)
            return _compare(op, a, b)
        if op in ("And", "Or"):
            return _logic(op, a, b)
        raise UnsupportedConstruct(f"binary operator {op}", self.where)

    def _Unary(self, body: Mapping[str, Any]) -> Value:
        op = body["op"]
        a = self(body["rhs"])
        if op in ("Minus", "DotMinus"):
            return -a
        if op in ("Plus", "DotPlus"):
            return a
        if op == "Not":
            return ca.logic_not(a) if is_symbolic(a) else (not a)
        raise UnsupportedConstruct(f"unary operator {op}", self.where)

    def _check_event(self, a: Value, b: Value, op: str) -> None:
        if not self.allow_events and self._no_event_depth == 0 and (is_symbolic(a) or is_symbolic(b)):
            raise UnsupportedConstruct(
                f"relation '{op}' on run-time values outside noEvent (it would generate state events)", self.where)

    def _BuiltinCall(self, body: Mapping[str, Any]) -> Value:
        name = body["function"]
        if name in EVENT_BUILTINS:
            raise UnsupportedConstruct(f"built-in {name}() (events or discrete time)", self.where)
        if name == "Der":
            (kind, ref), = body["args"][0].items()
            if kind != "VarRef":
                raise UnsupportedConstruct("der() of an expression (only der(variable) is supported)", self.where)
            indices = subscript_values(ref["subscripts"], self, self.where)
            return self.lookup(f"der({scalar_name(ref['name']['name'], indices)})")
        if name == "Sum":
            values = self._elements(body["args"][0])
            total: Value = 0
            for value in values:
                total = total + value
            return total
        if name in ("NoEvent", "Smooth"):
            self._no_event_depth += 1
            try:
                return self(body["args"][-1])
            finally:
                self._no_event_depth -= 1
        function = BUILTINS.get(name)
        if function is None:
            raise UnsupportedConstruct(f"built-in function {name}()", self.where)
        return function(*[self(arg) for arg in body["args"]])

    def _elements(self, node: Mapping[str, Any]) -> list[Value]:
        (kind, body), = node.items()
        if kind == "Array":
            values = []
            for element in body["elements"]:
                values.extend(self._elements(element) if "Array" in element else [self(element)])
            return values
        raise UnsupportedConstruct(f"array argument of kind {kind}", self.where)

    def _Array(self, body: Mapping[str, Any]) -> Value:
        raise UnsupportedConstruct("an array expression outside sum() or an array equation", self.where)

    def _If(self, body: Mapping[str, Any]) -> Value:
        result = self(body["else_branch"])
        for condition, value in reversed(body["branches"]):
            cond = self(condition)
            result = select(cond, self(value), result)
        return result

    def _FunctionCall(self, body: Mapping[str, Any]) -> Value:
        outputs = self.call(body["name"]["name"], [self(arg) for arg in body["args"]])
        return outputs[0]

    def call_outputs(self, node: Mapping[str, Any]) -> tuple[Value, ...]:
        """All outputs of a function-call expression (for tuple equations)."""
        (kind, body), = node.items()
        if kind != "FunctionCall":
            raise UnsupportedConstruct(f"a tuple equated to a {kind} expression", self.where)
        return self.call(body["name"]["name"], [self(arg) for arg in body["args"]])
