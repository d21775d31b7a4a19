import math

import pytest

from rover_cosim.terramechanics import Soil, Wheel


def test_defaults_are_table_2():
    wheel, soil = Wheel(), Soil()
    assert (wheel.r, wheel.b) == (0.355, 0.175)
    assert wheel.J > 0
    assert soil.c == 800.0
    assert soil.phi == pytest.approx(math.radians(37.2))
    assert soil.phi_deg == pytest.approx(37.2)
    assert (soil.kc, soil.kphi, soil.n, soil.kx) == (1.37e3, 8.14e5, 1.0, 0.036)
    assert (soil.a0, soil.a1, soil.lam) == (0.4, 0.15, 0.90)


def test_friction_angle_in_degrees():
    soil = Soil.from_degrees(30.0, c=100.0)
    assert soil.phi == pytest.approx(math.pi / 6)
    assert soil.c == 100.0
    with pytest.raises(ValueError, match=r"phi_deg=95.0.*0 < phi_deg < 90"):
        Soil.from_degrees(95.0)


def test_bekker_modulus():
    assert Soil().bekker_modulus(0.175) == pytest.approx(1.37e3 / 0.175 + 8.14e5)


@pytest.mark.parametrize("field, value, expected", [
    ("r", 0.0, "r > 0"), ("r", -0.1, "r > 0"), ("b", 0.0, "b > 0"), ("J", -1.0, "J > 0"),
    ("r", float("nan"), "finite"), ("b", float("inf"), "finite"),
])
def test_wheel_rejects_non_physical(field, value, expected):
    with pytest.raises(ValueError, match=rf"{field}={value!r}.*{expected}"):
        Wheel(**{field: value})


@pytest.mark.parametrize("field, value, expected", [
    ("phi", 0.0, "0 < phi < pi/2"), ("phi", math.pi / 2, "0 < phi < pi/2"), ("phi", 37.2, "0 < phi < pi/2"),
    ("lam", 0.0, "0 < lam <= 1"), ("lam", 1.2, "0 < lam <= 1"),
    ("n", 0.0, "n > 0"), ("n", -1.0, "n > 0"),
    ("kx", 0.0, "kx > 0"), ("kx", -0.01, "kx > 0"),
    ("c", -1.0, "c >= 0"), ("kc", -5.0, "kc >= 0"), ("kphi", 0.0, "kphi > 0"),
    ("a0", 1.0, "0 < a0 < 1"), ("a1", 0.5, "a1 <"), ("a1", -0.1, "a1 <"),
    ("c", float("nan"), "finite"),
])
def test_soil_rejects_non_physical(field, value, expected):
    with pytest.raises(ValueError, match=rf"{field}={value!r}.*{expected}"):
        Soil(**{field: value})


def test_non_numbers_are_rejected():
    with pytest.raises(TypeError, match="r='0.3'"):
        Wheel(r="0.3")  # type: ignore[arg-type]  # the run-time check is what is tested


def test_numpy_scalars_are_accepted_as_floats():
    import numpy as np

    wheel = Wheel(r=np.float32(0.3), b=np.int64(1))  # type: ignore[arg-type]  # numpy scalars, converted
    assert type(wheel.r) is float and type(wheel.b) is float
    assert wheel.r == pytest.approx(0.3)


def test_the_modelica_records_declare_the_ranges_of_the_python_table():
    """One range table (terramechanics.parameters.RANGES): the Modelica records' min/max (and so
    the FMUs') equal it, field by field."""
    import re
    from pathlib import Path

    from rover_cosim.terramechanics.library import MODELICA_NAMES
    from rover_cosim.terramechanics.parameters import RANGES

    root = Path(__file__).resolve().parents[1] / "modelica" / "RoverTerramechanics" / "Parameters"
    declared: dict[str, tuple[float | None, float | None]] = {}
    for record in ("SoilParameters.mo", "WheelParameters.mo"):
        for name, attributes in re.findall(r"parameter Real (\w+)\(([^)]*)\)", (root / record).read_text()):
            found = dict(re.findall(r"(min|max)=([-0-9.e]+)", attributes))
            declared[name] = (float(found["min"]) if "min" in found else None,
                              float(found["max"]) if "max" in found else None)
    for field, bounds in RANGES.items():
        assert declared[MODELICA_NAMES.get(field, field)] == bounds, field


def test_the_soil_record_is_the_python_soil_and_the_wheel_blends_every_field():
    """One table of soil fields: terramechanics.Soil. The Modelica record SoilParameters declares the
    same fields in the same order, with the units of parameters.UNITS, and RigidWheel blends each of
    them, once, as (1 - soilShare) soil.F + soilShare soilB.F, xc as each soil's own angle (its 0: 45 deg -
    phi/2 of that soil) (the exporter cannot yet translate a
    function returning a record, so the blend is written field by field there: this test is what
    keeps it whole when a field is added)."""
    import re
    from dataclasses import fields
    from pathlib import Path

    from rover_cosim.terramechanics import Soil
    from rover_cosim.terramechanics.library import MODELICA_NAMES
    from rover_cosim.terramechanics.parameters import UNITS

    package = Path(__file__).resolve().parents[1] / "modelica" / "RoverTerramechanics"
    record = (package / "Parameters" / "SoilParameters.mo").read_text()
    declared = re.findall(r"parameter Real (\w+)\(unit=\"([^\"]*)\"", record)
    python = [MODELICA_NAMES.get(f.name, f.name) for f in fields(Soil)]
    assert [name for name, _ in declared] == python
    modelica_units = {"N/m^(n+1)": "N/m2", "N/m^(n+2)": "N/m3", "kg/m^3": "kg/m3", "m/s^2": "m/s2"}
    for field, (name, unit) in zip(fields(Soil), declared):
        assert modelica_units.get(UNITS[field.name], UNITS[field.name]) == unit, name
    wheel = (package / "Components" / "RigidWheel.mo").read_text()
    blended = re.findall(r"(\w+)=\(1 - soilShare\)\*soil\.(\w+) \+ soilShare\*soilB\.(\w+)", wheel)
    # xc blends each soil's own angle (0: 45 deg - phi/2 of that soil's phi), as Soil.blend does
    resolved = r"RoverTerramechanics\.Functions\.destructiveAngle\({0}\.xc, {0}\.phi\)"
    angle = re.findall(r"(xc)=\(1 - soilShare\)\*" + resolved.format("soil") + r"\s*\+ soilShare\*"
                       + resolved.format("soilB"), wheel)
    rule = (package / "Functions" / "destructiveAngle.mo").read_text()
    assert "angle := if noEvent(xc > 0) then xc else 0.7853981633974483 - phi/2;" in rule
    assert math.isclose(0.7853981633974483, math.pi / 4, rel_tol=0, abs_tol=0)
    assert sorted(blended + [(name, name, name) for name in angle]) == sorted((name, name, name) for name in python)
