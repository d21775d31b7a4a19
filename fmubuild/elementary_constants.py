"""The constants of the FMUs' own elementary functions (``runtime/elementary.h``), computed here
exactly (Python's ``decimal`` at 80 digits and ``fractions``) and written as C99 hexadecimal
literals, so that every compiler reads the same bits.

``python -m rover_cosim.fmubuild.elementary_constants`` writes the block that ``elementary.h`` holds
between its ``BEGIN``/``END GENERATED CONSTANTS`` lines; ``tests/test_elementary.py`` checks that the
two agree. Nothing here runs when an FMU is built.

What is computed (each named as in ``elementary.h``):
- Taylor coefficients (correctly rounded): 1/n! for exp's and sin's and cos's polynomials,
  (-1)^(n+1)/n for log(1 + g), (-1)^k/(2k+1) for atan's and the first terms of tanh's series;
- ``LOG_TABLE``: for c = 1 + j/128, j = -37..53: 1/c (nearest), log c on the grid 2^-42, and the
  rest of log c;
- ``EXP_TABLE``: 2^(j/128) for j = 0..127 as a double and the double nearest its remainder;
- splittings of ln 2, ln 2/128 and pi/2 into a leading part with trailing zero bits (so that an
  integer times it is exact) and the remainder (Cody & Waite's argument reduction);
- atan(c) for the breakpoints c = 1/4, 1/2, 3/4, 1 and pi, pi/2, 3 pi/4 as leading double and
  remainder.
"""

from __future__ import annotations

import math
from decimal import Decimal, getcontext
from fractions import Fraction
from pathlib import Path

getcontext().prec = 80

EXP_TABLE_SIZE = 128
#: Degrees of the Taylor polynomials (the largest power kept); elementary.h's comments give the
#: truncation error each leaves on its reduced interval.
EXP_DEGREE = 5          # |r| <= ln2/256
SIN_DEGREE = 17         # |r| <= pi/4
COS_DEGREE = 16
LOG_DEGREE = 10         # |g| < 2^-6.5
#: log's table: c = 1 + j/LOG_TABLE_SIZE for j from LOG_TABLE_FIRST (the mantissas from sqrt(1/2))
#: to LOG_TABLE_LAST (up to sqrt(2)), rounded toward 1.
LOG_TABLE_SIZE = 128
LOG_TABLE_FIRST = -37
LOG_TABLE_LAST = 53
#: The grid [absolute] of the leading parts of k ln2 and log c: their sum is exact.
LOG_GRID = Fraction(1, 2 ** 42)
ATAN_TERMS = 10         # |u| <= 1/8
ATAN_BREAKPOINTS = (Fraction(1, 4), Fraction(1, 2), Fraction(3, 4), Fraction(1))


def atan_series(x: Decimal) -> Decimal:
    """atan(x) for |x| <= 1 by its Taylor series, after halving the angle until |x| < 0.1."""
    halvings = 0
    while abs(x) > Decimal("0.1"):
        x = x / (1 + (1 + x * x).sqrt())    # atan(x) = 2 atan(x / (1 + sqrt(1 + x^2)))
        halvings += 1
    total, power, k = Decimal(0), x, 0
    eps = Decimal(10) ** -(getcontext().prec + 2)
    while abs(power) > eps:
        total += power / (2 * k + 1) * (-1 if k % 2 else 1)
        power *= x * x
        k += 1
    return total * (2 ** halvings)


PI = 16 * atan_series(Decimal(1) / 5) - 4 * atan_series(Decimal(1) / 239)   # Machin's formula
LN2 = Decimal(2).ln()


def nearest(value: Decimal | Fraction) -> float:
    """The double nearest ``value`` (both conversions round correctly)."""
    return float(Fraction(value))


def leading(value: Decimal | Fraction, bits: int) -> float:
    """``value`` truncated to its ``bits`` leading significant bits (exact as a double)."""
    exact = Fraction(value)
    exponent = math.floor(math.log2(abs(exact)))
    unit = Fraction(2) ** (exponent - bits + 1)
    return float(math.floor(exact / unit) * unit)


def split(value: Decimal | Fraction, bits: int) -> tuple[float, float]:
    """``value`` as a leading part of ``bits`` bits and the double nearest the rest."""
    high = leading(value, bits)
    return high, nearest(Fraction(value) - Fraction(high))


def hi_lo(value: Decimal | Fraction) -> tuple[float, float]:
    """``value`` as the nearest double and the double nearest the rest."""
    high = nearest(value)
    return high, nearest(Fraction(value) - Fraction(high))


def _literal(x: float) -> str:
    return x.hex() if x != 0.0 else "0.0"


def constants() -> list[tuple[str, list[float]]]:
    """(C name, values) in the order elementary.h declares them."""
    inverse_factorial = [nearest(Fraction(1, math.factorial(n))) for n in range(SIN_DEGREE + 1)]
    table: list[float] = []
    for j in range(EXP_TABLE_SIZE):
        table += hi_lo((Decimal(j) / EXP_TABLE_SIZE * LN2).exp())
    atan_table: list[float] = []
    for c in ATAN_BREAKPOINTS:
        atan_table += hi_lo(atan_series(Decimal(c.numerator) / Decimal(c.denominator)))
    return [
        ("EXP_TAYLOR", [inverse_factorial[n] for n in range(2, EXP_DEGREE + 1)]),
        ("EXP_TABLE", table),
        ("EXP_N_OVER_LN2", [nearest(EXP_TABLE_SIZE / LN2)]),
        # k ln2/128 exact for |k| < 2^18 (exp's arguments reach +-746 * 128 / ln2 < 2^18)
        ("EXP_LN2_OVER_N", list(split(LN2 / EXP_TABLE_SIZE, 53 - 18))),
        # on the grid 2^-42 (42 bits): k ln2 exact for |k| < 2^11 (the exponents of doubles, subnormals
        # scaled), and k ln2 + log c exact (both on the grid, below 2^10)
        ("LN2", list(on_grid(LN2))),
        ("LOG1P_TAYLOR", [nearest(Fraction((-1) ** (n + 1), n)) for n in range(2, LOG_DEGREE + 1)]),
        ("LOG_TABLE", _log_table()),
        ("SIN_TAYLOR", [nearest(Fraction((-1) ** i, math.factorial(2 * i + 1)))
                        for i in range(1, (SIN_DEGREE - 1) // 2 + 1)]),
        ("COS_TAYLOR", [nearest(Fraction((-1) ** i, math.factorial(2 * i)))
                        for i in range(2, COS_DEGREE // 2 + 1)]),
        # pi/2 in three parts of 33, 33 and 53 bits: n pi/2 reduced exactly for |n| < 2^20
        ("PIO2_PARTS", _pio2_parts()),
        ("TWO_OVER_PI", [nearest(2 / PI)]),
        ("ATAN_TAYLOR", [nearest(Fraction((-1) ** k, 2 * k + 1)) for k in range(1, ATAN_TERMS + 1)]),
        ("ATAN_BREAKPOINT", [float(c) for c in ATAN_BREAKPOINTS]),
        ("ATAN_OF_BREAKPOINT", atan_table),
        ("PI", list(hi_lo(PI))),
        ("PI_OVER_2", list(hi_lo(PI / 2))),
        ("THREE_PI_OVER_4", [nearest(3 * PI / 4)]),
        # tanh(x) = x + x^3 (-1/3 + x^2 (2/15 + x^2 (-17/315))) for |x| < 2^-8
        ("TANH_TAYLOR", [nearest(Fraction(-1, 3)), nearest(Fraction(2, 15)), nearest(Fraction(-17, 315))]),
    ]


def on_grid(value: Decimal | Fraction) -> tuple[float, float]:
    """``value`` as its nearest multiple of LOG_GRID and the double nearest the rest."""
    exact = Fraction(value)
    high = Fraction(round(exact / LOG_GRID)) * LOG_GRID
    return float(high), nearest(exact - high)


def _log_table() -> list[float]:
    table: list[float] = []
    for j in range(LOG_TABLE_FIRST, LOG_TABLE_LAST + 1):
        c = 1 + Fraction(j, LOG_TABLE_SIZE)
        table += [nearest(1 / c), *on_grid((Decimal(c.numerator) / Decimal(c.denominator)).ln())]
    return table


def _pio2_parts() -> list[float]:
    first = leading(PI / 2, 33)
    second = leading(Fraction(PI / 2) - Fraction(first), 33)
    return [first, second, nearest(Fraction(PI / 2) - Fraction(first) - Fraction(second))]


def c_block() -> str:
    """The C text between elementary.h's GENERATED CONSTANTS markers."""
    lines = []
    for name, values in constants():
        literals = [_literal(v) for v in values]
        rows = [", ".join(literals[i:i + 4]) for i in range(0, len(literals), 4)]
        if len(rows) == 1:
            lines.append(f"static const double {name}[{len(values)}] = {{{rows[0]}}};")
        else:
            lines.append(f"static const double {name}[{len(values)}] = {{")
            lines += [f"    {row}," for row in rows]
            lines.append("};")
    return "\n".join(lines) + "\n"


HEADER = Path(__file__).parent / "runtime" / "elementary.h"
BEGIN = "/* BEGIN GENERATED CONSTANTS"
END = "/* END GENERATED CONSTANTS */"


def with_block(text: str) -> str:
    """``text`` (elementary.h) with its generated block replaced by :func:`c_block`'s."""
    start = text.index("\n", text.index(BEGIN)) + 1
    return text[:start] + c_block() + text[text.index(END):]


if __name__ == "__main__":
    HEADER.write_text(with_block(HEADER.read_text()))
    print(f"wrote the constants of {HEADER}")
