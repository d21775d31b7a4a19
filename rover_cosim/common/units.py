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


#: The unit of each column name the jobs write (trajectories, sweeps, metrics), by its stem: the
#: name without a wheel's number ``_1``..``_N``. SI; "1" for ratios.
COLUMN_UNITS: dict[str, str] = {
    "time": "s", "x": "m", "y": "m", "z": "m", "yaw": "rad", "v": "m/s", "vy": "m/s", "yawRate": "rad/s",
    "s": "m", "s_ref": "m", "x_t": "m", "cross_track": "m", "heading_error": "rad", "tau": "N.m", "Tx": "N.m",
    "steer": "rad", "Fx": "N", "Fy": "N", "Fz": "N", "Fx_des": "N", "Fy_des": "N", "W": "N", "slip": "1",
    "slipAngle": "rad", "beta": "rad", "sinkage": "m", "omega": "rad/s", "v_hub": "m/s", "pitch": "rad",
}
#: Units said by a column name's ending (load_N, torque_N_m, sinkage_m, rms_Fx_max_N, wall_s, ...).
_ENDINGS = (("_N_m", "N.m"), ("_Nm", "N.m"), ("_N", "N"), ("_m_s", "m/s"), ("_rad_s", "rad/s"), ("_deg", "deg"),
            ("_rad", "rad"), ("_percent", "%"), ("_J_m", "J/m"), ("_m", "m"), ("_s", "s"), ("_Pa", "Pa"))


def column_unit(name: str) -> str | None:
    """The unit of a column the jobs write (``Fz_3`` -> N, ``load_N`` -> N), None where its name
    does not say."""
    stem = re.sub(r"_\d+$", "", name)
    if stem in COLUMN_UNITS:
        return COLUMN_UNITS[stem]
    for ending, unit in _ENDINGS:
        if stem.endswith(ending) and len(stem) > len(ending):
            return unit
    return None


def column_units(names: list[str]) -> dict[str, str]:
    """Each of ``names`` whose unit is known, with it."""
    return {name: unit for name in names if (unit := column_unit(name)) is not None}
