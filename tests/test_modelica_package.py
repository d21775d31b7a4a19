"""Static checks of the Modelica source: one class per file, package.order, documentation
with equation numbers, no Modelica Standard Library, the FMU sub-package and the interfaces of the
hub cut, the UsersGuide. No compiler needed."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rover_cosim.fmubuild import build
from rover_cosim.fmubuild.source import MODELICA_ROOT, PACKAGE, class_file, class_files, fmu_class

CLASS_RE = re.compile(
    r"^\s*(?:partial\s+)?(?:encapsulated\s+)?(model|block|function|record|package|connector|class)\s+(\w+)",
    re.MULTILINE)
STRING_RE = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)


def code_of(path: Path) -> str:
    """The file's text with string literals (descriptions, documentation) blanked out."""
    return STRING_RE.sub('""', path.read_text())


ALL_FILES = sorted((MODELICA_ROOT / PACKAGE).rglob("*.mo"))
REPOSITORY = Path(__file__).resolve().parents[1]


def test_the_package_has_the_models_of_the_issue():
    names = set(class_files())
    for model in ("FMUs.SingleWheel", "FMUs.Rover", "FMUs.RoverBody", "FMUs.Wheel", "Examples.RoverReconnected",
                  "Interfaces.WheelHub", "Interfaces.BodyHubs", "UsersGuide.Overview",
                  "Parameters.SoilParameters", "Parameters.WheelParameters", "Parameters.RoverParameters",
                  "Functions.slipRatio", "Functions.contactForces", "Functions.wheelContact",
                  "Components.RigidWheel", "Examples.SingleWheelStep", "Examples.RoverOpenLoop"):
        assert f"{PACKAGE}.{model}" in names


def test_the_fmu_sub_package_holds_exactly_the_fmus_make_fmus_builds():
    """``FMUs`` lists the exported models in the order ``make fmus`` builds them, and
    ``fmu_class`` is where every FMU name is mapped to its class."""
    folder = MODELICA_ROOT / PACKAGE / "FMUs"
    assert tuple((folder / "package.order").read_text().split()) == build.FMU_MODELS
    for name in build.FMU_MODELS:
        assert class_file(fmu_class(name)) == folder / f"{name}.mo"


#: Each interface of Interfaces and the classes that must extend it (the cut is declared once).
INTERFACES = {"WheelHub": ("Components.RigidWheel", "FMUs.Wheel"),
              "BodyHubs": ("Components.Chassis", "FMUs.RoverBody"),
              "SteerableBodyHubs": ("Components.SteerableChassis", "FMUs.SteerableRoverBody"),
              "PitchPlaneRover": ("FMUs.Rover", "Examples.RoverReconnected"),
              "GroundContacts": ("Interfaces.SteerableBodyHubs", "FMUs.SteerableRover")}
DECLARATION_RE = re.compile(r"^\s*(input|output)\s+Real\s+(\w+)", re.MULTILINE)


@pytest.mark.parametrize("interface", INTERFACES)
def test_the_cut_is_declared_once_in_interfaces_and_extended(interface: str):
    """The interfaces are partial; every class that uses one extends it and declares none of its
    inputs and outputs again."""
    code = code_of(class_file(f"{PACKAGE}.Interfaces.{interface}"))
    assert re.search(rf"^partial model {interface}\b", code, re.MULTILINE)
    signals = {name for _, name in DECLARATION_RE.findall(code)}
    assert signals
    for user in INTERFACES[interface]:
        text = code_of(class_file(f"{PACKAGE}.{user}"))
        assert re.search(rf"^\s*extends {PACKAGE}\.Interfaces\.{interface}\b", text, re.MULTILINE), user
        assert not signals & {name for _, name in DECLARATION_RE.findall(text)}, user


def test_the_users_guide_is_the_documentation_of_the_package():
    """The guide the MSL way (a UsersGuide package of documentation classes); modelica/README.md
    only points to it."""
    guide = MODELICA_ROOT / PACKAGE / "UsersGuide"
    assert "DocumentationClass=true" in (guide / "package.mo").read_text()
    assert (guide / "package.order").read_text().split()[0] == "Overview"
    text = "\n".join(p.read_text() for p in guide.glob("*.mo"))
    assert "DESIGN.md" not in text and "from fmubuild" not in text and "top-level README" not in text
    for page in re.findall(r"docs/(?:guide|design)/[\w-]+\.md", text):  # the site's pages it names exist
        assert (REPOSITORY / page).is_file(), page
    readme = (MODELICA_ROOT / "README.md").read_text()
    assert "RoverTerramechanics.UsersGuide" in readme and len(readme.splitlines()) < 25


@pytest.mark.parametrize("path", ALL_FILES, ids=lambda p: str(p.relative_to(MODELICA_ROOT)))
def test_one_class_per_file_named_after_the_file_within_its_folder(path: Path):
    code = code_of(path)
    classes = CLASS_RE.findall(code)
    expected = path.parent.name if path.name == "package.mo" else path.stem
    assert [name for _, name in classes] == [expected], f"{path}: classes {classes}"
    assert re.search(rf"^end\s+{expected}\s*;", code, re.MULTILINE), f"{path}: no 'end {expected};'"
    parent = path.parent if path.name != "package.mo" else path.parent.parent
    within = ".".join(parent.relative_to(MODELICA_ROOT).parts)
    if within:
        assert re.match(rf"\s*within\s+{re.escape(within)}\s*;", code), f"{path}: expected 'within {within};'"
    else:
        assert not re.search(r"^\s*within\b", code, re.MULTILINE)


@pytest.mark.parametrize("folder", sorted({p.parent for p in ALL_FILES}), ids=lambda p: p.name)
def test_package_order_lists_exactly_the_classes_of_the_folder(folder: Path):
    order = (folder / "package.order").read_text().split()
    present = {p.stem for p in folder.glob("*.mo") if p.name != "package.mo"}
    present |= {d.name for d in folder.iterdir() if (d / "package.mo").is_file()}
    assert sorted(order) == sorted(present)
    assert len(order) == len(set(order))


@pytest.mark.parametrize("path", ALL_FILES, ids=lambda p: str(p.relative_to(MODELICA_ROOT)))
def test_every_class_is_documented(path: Path):
    text = path.read_text()
    assert "Documentation(info=" in text, f"{path}: no Documentation annotation"


@pytest.mark.parametrize("name", ["Functions.slipRatio", "Functions.normalStress", "Functions.shearStress",
                                  "Functions.contactForces", "Functions.wheelContact",
                                  "Components.RigidWheel", "Parameters.SoilParameters"])
def test_physics_documentation_cites_the_paper_equations(name: str):
    text = class_file(f"{PACKAGE}.{name}").read_text()
    assert re.search(r"Eqs?\. \(\d+", text), f"{name}: no equation number in its documentation"


@pytest.mark.parametrize("path", ALL_FILES, ids=lambda p: str(p.relative_to(MODELICA_ROOT)))
def test_no_modelica_standard_library(path: Path):
    assert not re.search(r"\bModelica\.", code_of(path)), f"{path} uses the Modelica Standard Library"


@pytest.mark.parametrize("name", ["Examples.SingleWheelStep", "Examples.RoverOpenLoop",
                                  "Examples.RoverReconnectedOpenLoop"])
def test_examples_have_experiment_annotations(name: str):
    assert re.search(r"experiment\s*\(\s*StartTime\s*=.*StopTime\s*=", class_file(f"{PACKAGE}.{name}").read_text())


def test_real_declarations_in_models_and_records_carry_units():
    """Every Real declared in a model or record (functions' protected helpers aside) has a unit."""
    missing = []
    for path in ALL_FILES:
        code = path.read_text()
        match = CLASS_RE.search(STRING_RE.sub('""', code))
        assert match is not None, path
        kind = match.group(1)
        if kind in ("function", "package", "class"):
            continue
        for line in code.splitlines():
            if re.match(r"\s*(?:parameter\s+|input\s+|output\s+)*Real\b", line) and "unit=" not in line:
                missing.append(f"{path.name}: {line.strip()}")
    assert not missing, "\n".join(missing)
