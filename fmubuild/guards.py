"""Guarded evaluation: CasADi's straight-line C of an SX function, rewritten so that a value
is computed only when a branch that uses it is taken.

CasADi writes an SX function as straight-line code: ``if c then x else y`` becomes
``(c?x:0) + (!c?y:0)`` with both ``x`` and ``y`` computed first, so every ``if`` of a Modelica
function costs both branches (e.g. ``exp`` of both signs of the shear displacement, ``pow``
for a negative base that never occurs). This pass reads each such function of the generated C
and writes it again with every statement wrapped in the condition under which its value can
reach an output:

- need(output) = true; for ``v = (c ? x : 0)`` need(x) gains need(v) and c, need(c) gains need(v);
  any other statement passes its need on to every value it reads;
- needs are kept as a disjunction of conjunctions of condition values; a need that grows past
  a few terms is taken as "always" (weaker guards only compute more: always correct);
- a condition computed after the statement it would guard is dropped from that guard;
- consecutive statements with the same guard share one ``if``.

Variables are renamed to single assignment (CasADi reuses them), and the condition variables
start at 0, so a guard never reads an unset value. A function whose text has any statement of
another form is left exactly as CasADi wrote it, and so is any function of MX (call) code.
Results are bit-identical to CasADi's code: the same operations on the same values, fewer of
them.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

#: Most terms a need may have before it is taken as "always"; most conditions in one term.
MAX_TERMS = 4
MAX_CONDITIONS = 4

_FUNCTION = re.compile(
    r"(static int casadi_f\d+\(const casadi_real\*\* arg, casadi_real\*\* res, casadi_int\* iw, "
    r"casadi_real\* w, int mem\) \{\n)(.*?)(\n\}\n)", re.S)
_DECLARATION = re.compile(r"^  casadi_real (a\d+(, a\d+)*);$")
_ASSIGNMENT = re.compile(r"^  (a\d+)=(.*);$")
_OUTPUT = re.compile(r"^  if \(res\[(\d+)\]!=0\) res\[\1\]\[(\d+)\]=(a\d+);$")
_RETURN = "  return 0;"
_PARAMETERS = ("arg", "res", "iw", "w", "mem")
_EMPTY_RELEASE = re.compile(r"^(void \w+_release\(int mem\) \{\n)\}", re.M)
_VARIABLE = re.compile(r"\ba\d+\b")
_SELECT = re.compile(r"^\((a\d+)\?(a\d+):0\)$")

Term = frozenset[int]          # condition values (by SSA number) that must all be nonzero
Need = frozenset[Term] | None  # a disjunction of terms; None: always


@dataclass
class _Statement:
    target: int | None      # SSA number assigned (None for an output)
    text: str               # C expression (assignment) or the output's store, with SSA names
    reads: list[int]        # SSA numbers read
    select: tuple[int, int] | None  # (condition, value) of a ``(c?x:0)``


def _or(a: Need, b: Need) -> Need:
    if a is None or b is None:
        return None
    terms = set(a) | set(b)
    if frozenset() in terms:
        return None
    # Absorption: a term implied by a shorter one adds nothing.
    kept = frozenset(t for t in terms if not any(o < t for o in terms))
    return None if len(kept) > MAX_TERMS else kept


def _and(need: Need, condition: int) -> Need:
    terms = [frozenset()] if need is None else list(need)
    return frozenset(t | {condition} if len(t) < MAX_CONDITIONS else t for t in terms)


def _parse(body: str) -> list[_Statement] | None:
    """The body's statements with variables in single assignment, or None if any line is not
    of the straight-line forms CasADi writes for SX."""
    current: dict[str, int] = {}
    statements: list[_Statement] = []
    count = 0

    def rename(match: re.Match[str]) -> str:
        if match.group(0) not in current:
            raise KeyError(match.group(0))
        return f"v{current[match.group(0)]}"

    lines = body.split("\n")
    for index, line in enumerate(lines):
        if _DECLARATION.match(line) or not line.strip():
            continue
        if line == _RETURN and index == len(lines) - 1:
            continue
        try:
            if (output := _OUTPUT.match(line)) is not None:
                value = current[output.group(3)]
                statements.append(_Statement(None, f"if (res[{output.group(1)}]!=0) res[{output.group(1)}]"
                                             f"[{output.group(2)}]=v{value};", [value], None))
                continue
            assignment = _ASSIGNMENT.match(line)
            if assignment is None:
                return None
            expression = assignment.group(2)
            reads = [current[name] for name in _VARIABLE.findall(expression)]
            text = _VARIABLE.sub(rename, expression)
            select = _SELECT.match(expression)
            current[assignment.group(1)] = count
            statements.append(_Statement(count, text, reads, (reads[0], reads[1]) if select else None))
            count += 1
        except KeyError:
            return None  # a variable read before it is set: not the expected form
    return statements


def _needs(statements: list[_Statement]) -> dict[int, Need]:
    """Need of every SSA value; values no output reads are absent."""
    needs: dict[int, Need] = {}
    for statement in reversed(statements):
        need: Need = None if statement.target is None else needs.get(statement.target, frozenset())
        if need == frozenset():
            continue  # never read: CasADi does not write such statements, kept for safety
        if statement.select is not None:
            condition, value = statement.select
            needs[condition] = _or(needs.get(condition, frozenset()), need)
            needs[value] = _or(needs.get(value, frozenset()), _and(need, condition))
            continue
        for value in statement.reads:
            needs[value] = _or(needs.get(value, frozenset()), need)
    return needs


def _guard(need: Need, defined_before: int) -> str | None:
    """C condition of a need at a statement (conditions not yet computed dropped), or None."""
    if need is None:
        return None
    terms = []
    for term in sorted(need, key=sorted):
        known = sorted(c for c in term if c < defined_before)
        if not known:
            return None
        terms.append(" && ".join(f"v{c}!=0" for c in known))
    return " || ".join(f"({t})" for t in terms) if len(terms) > 1 else terms[0]


def _emit(statements: list[_Statement], needs: dict[int, Need]) -> str:
    conditions = {c for need in needs.values() if need for term in need for c in term}
    guards = {s.target: _guard(needs.get(s.target), s.target) for s in statements if s.target is not None}
    # Conditions and every value computed under a guard start at 0: a guard never reads an unset
    # value, and the compiler sees no path that reads one (no -Wmaybe-uninitialized).
    declared = [f"v{s.target}" + (" = 0" if s.target in conditions or guards[s.target] is not None else "")
                for s in statements if s.target is not None]
    lines = [f"  casadi_real {', '.join(declared[i:i + 8])};" for i in range(0, len(declared), 8)]
    open_guard: str | None = None
    for statement in statements:
        if statement.target is None:
            guard = None
            code = statement.text
        else:
            guard = guards[statement.target]
            code = f"v{statement.target}={statement.text};"
        if guard != open_guard:
            if open_guard is not None:
                lines.append("  }")
            if guard is not None:
                lines.append(f"  if ({guard}) {{")
            open_guard = guard
        lines.append(("    " if guard is not None else "  ") + code)
    if open_guard is not None:
        lines.append("  }")
    lines.append(_RETURN)
    return "\n".join(lines)


def guard_function_body(body: str) -> str:
    """One function body rewritten with guards (unchanged if it is not SX straight-line code
    or has no conditional values)."""
    statements = _parse(body)
    if statements is None or not any(s.select for s in statements):
        return body
    return _emit(statements, _needs(statements))


def guard_generated_code(code: str) -> tuple[str, int]:
    """Every SX function of CasADi's generated C with guarded evaluation; returns the code and
    the number of functions rewritten."""
    rewritten = 0

    def replace(match: re.Match[str]) -> str:
        nonlocal rewritten
        original = match.group(2)
        body = guard_function_body(original)
        rewritten += body is not original
        # CasADi's one signature for every function: say which arguments this one does not use
        # (no -Wunused-parameter).
        unused = "".join(f"  (void){name};\n" for name in _PARAMETERS if not re.search(rf"\b{name}\b", body))
        return match.group(1) + unused + body + match.group(3)

    code = _FUNCTION.sub(replace, code)
    return _EMPTY_RELEASE.sub(r"\1  (void)mem;\n}", code), rewritten
