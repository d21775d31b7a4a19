"""Modelica unit strings (``"N.m"``, ``"m/s2"``, ``"kg.m2"``) → exponents of the SI base units, for
the ``<UnitDefinitions>`` of an FMI 2.0 model description (``BaseUnit kg=.. m=.. s=.. rad=..``)."""

from __future__ import annotations

import re

BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")

# Symbol -> (exponents over BASE, factor to SI).
_SYMBOLS: dict[str, tuple[tuple[int, ...], float]] = {
    "kg": ((1, 0, 0, 0, 0, 0, 0, 0), 1.0),
    "g": ((1, 0, 0, 0, 0, 0, 0, 0), 1e-3),
    "m": ((0, 1, 0, 0, 0, 0, 0, 0), 1.0),
    "s": ((0, 0, 1, 0, 0, 0, 0, 0), 1.0),
    "A": ((0, 0, 0, 1, 0, 0, 0, 0), 1.0),
    "K": ((0, 0, 0, 0, 1, 0, 0, 0), 1.0),
    "mol": ((0, 0, 0, 0, 0, 1, 0, 0), 1.0),
    "cd": ((0, 0, 0, 0, 0, 0, 1, 0), 1.0),
    "rad": ((0, 0, 0, 0, 0, 0, 0, 1), 1.0),
    "deg": ((0, 0, 0, 0, 0, 0, 0, 1), 3.141592653589793 / 180.0),
    "N": ((1, 1, -2, 0, 0, 0, 0, 0), 1.0),
    "Pa": ((1, -1, -2, 0, 0, 0, 0, 0), 1.0),
    "J": ((1, 2, -2, 0, 0, 0, 0, 0), 1.0),
    "W": ((1, 2, -3, 0, 0, 0, 0, 0), 1.0),
    "Hz": ((0, 0, -1, 0, 0, 0, 0, 0), 1.0),
}

_FACTOR = re.compile(r"^([A-Za-z]+)(-?\d+)?$")


def base_units(unit: str) -> tuple[dict[str, int], float]:
    """Exponents (only the non-zero ones) and the factor to SI of a Modelica unit string.

    Raises ValueError naming the unit for anything outside the grammar used in ``modelica/``.
    """
    text = unit.strip()
    if text in ("", "1"):
        return {}, 1.0
    numerator, _, denominator = text.partition("/")
    exponents = [0] * len(BASE)
    factor = 1.0
    for part, sign in ((numerator, 1), (denominator, -1)):
        if not part or part == "1":
            continue
        if part.startswith("(") and part.endswith(")"):
            part = part[1:-1]
        for token in part.split("."):
            match = _FACTOR.match(token)
            if not match or match.group(1) not in _SYMBOLS:
                raise ValueError(f"unit {unit!r}: cannot read {token!r} (expected SI symbols such as "
                                 f"{', '.join(_SYMBOLS)} with integer exponents, joined by '.' and one '/')")
            symbol_exponents, symbol_factor = _SYMBOLS[match.group(1)]
            power = sign * int(match.group(2) or 1)
            for i, e in enumerate(symbol_exponents):
                exponents[i] += power * e
            factor *= symbol_factor ** power
    return {b: e for b, e in zip(BASE, exponents) if e}, factor
