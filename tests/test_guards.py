"""fmubuild.guards: CasADi's straight-line C of an SX function rewritten so that a branch of a
run-time ``if`` is computed only when taken. Checked by compiling both versions: the same
results bit for bit, and libm calls counted to see the untaken branches skipped."""

from __future__ import annotations

import ctypes
import shutil
import subprocess
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from rover_cosim.fmubuild.guards import guard_function_body, guard_generated_code

pytestmark = pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc not on PATH")

#: Counts the calls of exp and log (defined before CasADi's code, which includes math.h again).
COUNTING = """#include <math.h>
long exp_calls = 0, log_calls = 0;
static double counted_exp(double x) { exp_calls++; return (exp)(x); }
static double counted_log(double x) { log_calls++; return (log)(x); }
#define exp counted_exp
#define log counted_log
"""


def generated(function: ca.Function) -> str:
    generator = ca.CodeGenerator("f.c", {"with_header": False, "casadi_real": "double"})
    generator.add(function)
    return generator.dump()


def compiled(code: str, folder: Path, name: str) -> ctypes.CDLL:
    source = folder / f"{name}.c"
    source.write_text(COUNTING + code)
    library = folder / f"{name}.so"
    subprocess.run(["gcc", "-O2", "-shared", "-fPIC", "-o", str(library), str(source), "-lm"], check=True)
    return ctypes.CDLL(str(library))


def call(library: ctypes.CDLL, name: str, inputs: list[float], n_out: int) -> tuple[list[float], int, int]:
    """Outputs of the generated function and the number of exp and log calls it made."""
    ctypes.c_long.in_dll(library, "exp_calls").value = 0
    ctypes.c_long.in_dll(library, "log_calls").value = 0
    values = [ctypes.c_double(v) for v in inputs]
    outputs = [ctypes.c_double() for _ in range(n_out)]
    arg = (ctypes.POINTER(ctypes.c_double) * len(values))(*[ctypes.pointer(v) for v in values])
    res = (ctypes.POINTER(ctypes.c_double) * n_out)(*[ctypes.pointer(o) for o in outputs])
    work = (ctypes.c_double * 1000)()
    iwork = (ctypes.c_longlong * 100)()
    assert getattr(library, name)(arg, res, iwork, work, 0) == 0
    return ([o.value for o in outputs], ctypes.c_long.in_dll(library, "exp_calls").value,
            ctypes.c_long.in_dll(library, "log_calls").value)


def shear_like() -> ca.Function:
    """Two nested run-time ifs with expensive branches, a value shared by both branches, and a
    branch (log of a negative number) that would be NaN if it were taken."""
    j, k, x = ca.SX.sym("j"), ca.SX.sym("k"), ca.SX.sym("x")
    shared = ca.sin(x)
    tau = ca.if_else(j >= 0, 1 - ca.exp(-j / k), ca.exp(j / k) - 1)
    deep = ca.if_else(x > 0, ca.if_else(j > 1, ca.log(x) * shared, ca.exp(x)), ca.log(-x) + shared)
    return ca.Function("f", [j, k, x], [tau * shared, deep])


def test_guarded_code_gives_the_same_bits_and_skips_untaken_branches(tmp_path):
    function = shear_like()
    code = generated(function)
    guarded, rewritten = guard_generated_code(code)
    assert rewritten == 1 and guarded != code
    plain, lazy = compiled(code, tmp_path, "plain"), compiled(guarded, tmp_path, "lazy")
    rng = np.random.default_rng(1)
    cases = [[float(a), float(b), float(c)]
             for a, b, c in zip(rng.uniform(-3, 3, 200), rng.uniform(0.1, 2, 200), rng.uniform(-2, 2, 200))]
    cases += [[0.0, 1.0, 0.0], [-0.0, 1.0, -0.0], [2.0, 1.0, 1e-300]]
    for inputs in cases:
        expected, exp_plain, log_plain = call(plain, "f", inputs, 2)
        got, exp_lazy, log_lazy = call(lazy, "f", inputs, 2)
        np.testing.assert_array_equal(got, expected)
        j, _, x = inputs
        taken_exp = 1 + (x > 0 and not j > 1)
        taken_log = (x > 0 and j > 1) or not x > 0
        assert (exp_lazy, log_lazy) == (taken_exp, int(taken_log)), inputs
        assert (exp_plain, log_plain) == (3, 2)  # CasADi's code computes every branch


def test_a_function_of_another_form_is_left_as_it_is():
    body = "  casadi_real a0;\n  a0=arg[0]? arg[0][0] : 0;\n  for (;;) {}\n  return 0;"
    assert guard_function_body(body) is body
    unconditional = "  casadi_real a0, a1;\n  a0=arg[0]? arg[0][0] : 0;\n  a1=exp(a0);\n" \
                    "  if (res[0]!=0) res[0][0]=a1;\n  return 0;"
    assert guard_function_body(unconditional) is unconditional  # nothing to guard


def test_a_condition_computed_after_its_use_is_left_out_of_the_guard():
    """The value feeding a select is computed before the select's condition: its guard cannot
    read the condition, so it runs unconditionally (weaker guards only compute more)."""
    body = "\n".join(["  casadi_real a0, a1, a2, a3;", "  a0=arg[0]? arg[0][0] : 0;", "  a1=exp(a0);",
                      "  a2=(a0<a1);", "  a3=(a2?a1:0);", "  if (res[0]!=0) res[0][0]=a3;", "  return 0;"])
    rewritten = guard_function_body(body)
    assert "\n  v1=exp(v0);\n" in rewritten  # at the top level of the body, not inside an if
