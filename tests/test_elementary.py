"""The FMUs' own elementary functions (fmubuild/runtime/elementary.h, ``build-fmus --elementary
own``): their accuracy against mpmath, the C99 special cases against the C library, the constants
against their generator, and the renaming of the generated C. That every host then computes the
same bits is tests/test_platforms.py's (Wheel under qemu and wine)."""

from __future__ import annotations

import ctypes
import math
import shutil
import zipfile
from pathlib import Path

import mpmath
import numpy as np
import pytest
from c_harness import RUNTIME, compiled
from fmpy.validation import validate_fmu

from rover_cosim.fmubuild import build, elementary, elementary_constants
from rover_cosim.fmubuild.artifact import stored_elementary

HARNESS = Path(__file__).with_name("elementary_harness.c")
#: The harness's function numbers.
NUMBER = {name: i for i, name in enumerate(("exp", "log", "pow", "sin", "cos", "tan", "asin", "acos", "atan",
                                            "atan2", "tanh"))}
mpmath.mp.prec = 130


@pytest.fixture(scope="module")
def harness(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    return compiled(tmp_path_factory, "elementary", HARNESS)


def apply(lib: ctypes.CDLL, name: str, ours: bool, x: np.ndarray, y: np.ndarray | None = None) -> np.ndarray:
    x = np.ascontiguousarray(x, dtype=float)
    y = np.zeros_like(x) if y is None else np.ascontiguousarray(y, dtype=float)
    out = np.empty_like(x)
    pointer = ctypes.POINTER(ctypes.c_double)
    lib.apply(ctypes.c_int(NUMBER[name]), ctypes.c_int(int(ours)), ctypes.c_long(len(x)), x.ctypes.data_as(pointer),
              y.ctypes.data_as(pointer), out.ctypes.data_as(pointer))
    return out


REFERENCE = {"exp": mpmath.exp, "log": mpmath.log, "pow": mpmath.power, "sin": mpmath.sin, "cos": mpmath.cos,
             "tan": mpmath.tan, "asin": mpmath.asin, "acos": mpmath.acos, "atan": mpmath.atan,
             "atan2": mpmath.atan2, "tanh": mpmath.tanh}


def ulp_errors(values: np.ndarray, name: str, *args: np.ndarray) -> np.ndarray:
    """|value - exact| in units in the last place of the correctly rounded exact value."""
    errors = np.empty(len(values))
    for i, value in enumerate(values):
        exact = REFERENCE[name](*(mpmath.mpf(float(a[i])) for a in args))
        rounded = float(exact)
        assert math.isfinite(value) and math.isfinite(rounded), (name, [a[i] for a in args], value)
        errors[i] = float(abs(mpmath.mpf(float(value)) - exact) / math.ulp(rounded))
    return errors


def magnitudes(rng: np.random.Generator, low: float, high: float, n: int) -> np.ndarray:
    return np.exp(rng.uniform(math.log(low), math.log(high), n))


N = 3000
RNG = np.random.default_rng(49)
#: (function, what, arguments, largest error allowed [ulp]): the bounds elementary.h states (its
#: measured errors rounded up).
CASES = [
    ("exp", "whole range", (RNG.uniform(-745.0, 709.7, N),), 1.0),
    ("exp", "[-1, 1]", (RNG.uniform(-1.0, 1.0, N),), 1.0),
    ("log", "1e-310..1e308", (magnitudes(RNG, 1e-310, 1e308, N),), 1.0),
    ("log", "[0.5, 2]", (RNG.uniform(0.5, 2.0, N),), 1.0),
    ("pow", "x 1e-3..1e3, |y log x| <= 64", None, 1.0),
    ("pow", "x 1e-300..1e300, |y log x| <= 700", None, 1.0),
    ("sin", "[-pi, pi]", (RNG.uniform(-np.pi, np.pi, N),), 1.0),
    ("sin", "[-8e5, 8e5]", (RNG.uniform(-8e5, 8e5, N),), 1.0),
    ("cos", "[-pi, pi]", (RNG.uniform(-np.pi, np.pi, N),), 1.0),
    ("cos", "[-8e5, 8e5]", (RNG.uniform(-8e5, 8e5, N),), 1.0),
    ("tan", "[-1.5, 1.5]", (RNG.uniform(-1.5, 1.5, N),), 1.0),
    ("asin", "[-1, 1]", (RNG.uniform(-1.0, 1.0, N),), 1.0),
    ("acos", "[-1, 1]", (RNG.uniform(-1.0, 1.0, N),), 1.0),
    ("acos", "1 - 1e-16..1 - 0.1", (1.0 - magnitudes(RNG, 1e-16, 0.1, N),), 1.0),
    ("atan", "1e-10..1e10, both signs", (magnitudes(RNG, 1e-10, 1e10, N) * RNG.choice([-1.0, 1.0], N),), 1.0),
    ("atan2", "every quadrant", (RNG.normal(size=N) * magnitudes(RNG, 1e-3, 1e3, N),
                                 RNG.normal(size=N) * magnitudes(RNG, 1e-3, 1e3, N)), 1.0),
    ("tanh", "[-25, 25]", (RNG.uniform(-25.0, 25.0, N),), 1.0),
    ("tanh", "1e-10..1e-2", (magnitudes(RNG, 1e-10, 1e-2, N),), 1.0),
]
_BASES, _WIDE = magnitudes(RNG, 1e-3, 1e3, N), magnitudes(RNG, 1e-300, 1e300, N)
CASES[4] = (*CASES[4][:2], (_BASES, RNG.uniform(-64.0, 64.0, N) / np.abs(np.log(_BASES))), 1.0)
CASES[5] = (*CASES[5][:2], (_WIDE, RNG.uniform(-700.0, 700.0, N) / np.abs(np.log(_WIDE))), 1.0)


@pytest.mark.parametrize("name, what, args, bound", CASES, ids=[f"{c[0]} {c[1]}" for c in CASES])
def test_accuracy_against_mpmath(harness: ctypes.CDLL, name: str, what: str, args: tuple[np.ndarray, ...],
                                 bound: float):
    values = apply(harness, name, True, *args)
    errors = ulp_errors(values, name, *args)
    worst = int(np.argmax(errors))
    assert errors[worst] <= bound, f"{name}({', '.join(repr(float(a[worst])) for a in args)}): " \
                                   f"{errors[worst]:.3f} ulp > {bound}"


SPECIAL = [0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 2.0, -2.0, 3.0, -3.0, 0.25, 1e-320, -1e-320, 1e-300, 1e300, -1e300,
           709.78, 709.79, -745.2, -745.1, 710.0, 1e6, -1e6, math.inf, -math.inf, math.nan]


def same(a: float, b: float) -> bool:
    """Equal values, equal signs of zero, or both NaN."""
    return (math.isnan(a) and math.isnan(b)) or (a == b and math.copysign(1.0, a) == math.copysign(1.0, b))


@pytest.mark.parametrize("name", sorted(NUMBER))
def test_special_values_are_the_c_librarys(harness: ctypes.CDLL, name: str):
    """C99 Annex F's results where they are exact (zeros, infinities, NaN, overflow, underflow,
    pow's integer exponents of negative numbers and of +-0 and +-inf): the same as glibc's."""
    if name in ("pow", "atan2"):
        pairs = [(a, b) for a in SPECIAL for b in SPECIAL]
        x, y = np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])
    else:
        x, y = np.array(SPECIAL), None
    ours, libm = apply(harness, name, True, x, y), apply(harness, name, False, x, y)
    for i in range(len(x)):
        exact = libm[i] in (0.0, 1.0, -1.0) or not math.isfinite(libm[i]) or ours[i] == libm[i]
        arguments = (x[i],) if y is None else (x[i], y[i])
        if exact:
            assert same(ours[i], libm[i]), f"{name}{arguments}: ours {ours[i]!r}, C library {libm[i]!r}"
        else:  # a finite, inexact result: within the accuracy tests' bound
            assert abs(ours[i] - libm[i]) <= 3 * math.ulp(libm[i]), f"{name}{arguments}: {ours[i]!r} {libm[i]!r}"


def test_integer_powers_of_exact_numbers_are_exact(harness: ctypes.CDLL):
    bases = np.repeat(np.array([2.0, 3.0, 10.0, 0.5, 1.5, -2.0, -3.0]), 7)
    exponents = np.tile(np.arange(-3.0, 4.0), 7)
    ours = apply(harness, "pow", True, bases, exponents)
    np.testing.assert_array_equal(ours, [b ** e for b, e in zip(bases, exponents)])


def test_the_constants_are_their_generators():
    """elementary.h's GENERATED CONSTANTS block is what elementary_constants computes (exact values
    rounded once); and a few of them are what Python's math module knows."""
    text = (RUNTIME / elementary.HEADER).read_text()
    assert elementary_constants.with_block(text) == text
    constants = dict(elementary_constants.constants())
    assert constants["PI"][0] == math.pi and constants["PI_OVER_2"][0] == math.pi / 2
    assert constants["EXP_N_OVER_LN2"][0] == 128 / math.log(2)
    assert sum(constants["LN2"]) == math.log(2) and abs(constants["LN2"][1]) < 1e-12
    table = constants["EXP_TABLE"]
    assert all(abs(table[2 * j] - 2.0 ** (j / 128)) <= math.ulp(1.0) for j in range(128))
    assert constants["ATAN_OF_BREAKPOINT"][6] == math.pi / 4


def test_calls_are_renamed_outside_comments_and_the_header_included():
    code = ('#include <math.h>\n/* #1: @2 = exp(@1) */\n  w2 = exp(w1);\n  w3 = atan2(w2,w1);\n'
            '  w4 = casadi_exp(w1) + myexp(w2) + sqrt(w3) + pow (w1, w2);\n')
    out = elementary.use_own_elementary(code)
    assert out.startswith('#include <math.h>\n#include "elementary.h"\n')
    assert "/* #1: @2 = exp(@1) */" in out and "w2 = rcm_exp(w1);" in out and "rcm_atan2(w2,w1)" in out
    assert "casadi_exp(w1)" in out and "myexp(w2)" in out and "sqrt(w3)" in out and "rcm_pow(w1, w2)" in out
    assert elementary.remaining_calls(out) == []
    with pytest.raises(ValueError, match="math.h"):
        elementary.use_own_elementary("w = exp(x);\n")
    with pytest.raises(ValueError, match="expected one of libm, own"):
        elementary.check("fast")


def test_an_own_build_calls_no_elementary_function_of_the_c_library(fmus: dict[str, Path], tmp_path: Path):
    """Wheel.fmu with --elementary own: its generated C and integrator call rcm_* only, it carries
    the header and records the choice; built over the default build (up to date for the default
    choice) it is built, not taken for up to date."""
    default = tmp_path / "Wheel.fmu"
    shutil.copy2(fmus["Wheel"], default)
    with zipfile.ZipFile(default) as fmu:
        assert "sources/elementary.h" not in fmu.namelist()
        assert elementary.remaining_calls(fmu.read("sources/model_casadi.c").decode())
    own = build.build_fmu("Wheel", tmp_path, elementary="own")
    assert own.rebuilt and own.path == default
    with zipfile.ZipFile(own.path) as fmu:
        assert "sources/elementary.h" in fmu.namelist()
        for source in ("sources/model_casadi.c", "sources/ode23s.c"):
            text = fmu.read(source).decode()
            assert elementary.remaining_calls(text) == [] and "rcm_" in text, source
        record = fmu.read("documentation/build.json").decode()
    assert '"elementary": "own"' in record
    assert stored_elementary(own.path) == "own" and stored_elementary(fmus["Rover"]) == "libm"
    assert validate_fmu(str(own.path)) == []
    assert stored_elementary(tmp_path / "missing.fmu") == "libm"
