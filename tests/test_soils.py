"""The soil and wheel library and its use from the command line: every shipped soil documented
and buildable, --soil/--wheel/--set, degrees, errors, the FMU against the numpy wheel on another
soil (as parameters, no rebuild), and the records of what ran."""

from __future__ import annotations

import json
import math
from dataclasses import fields

import numpy as np
import pytest

from rover_cosim.cli import main
from rover_cosim.identification.reference_plant import StartState, run_reference_test_bed
from rover_cosim.identification.testbed import TorqueProfile, WheelTestBed
from rover_cosim.terramechanics import Soil, Wheel, library


@pytest.mark.parametrize("name", library.names("soil"))
def test_every_shipped_soil_builds_and_documents_what_its_source_does_not_give(name):
    _, table = library.entry("soil", name)
    soil = library.build("soil", name, table)
    assert isinstance(soil, Soil) and table["title"] and table["source"]
    given = {library.DEGREES.get(k, k) for k in table if k not in library.METADATA}
    notes = set(table.get("notes", {}))
    # xc (45 deg - phi/2), gravity (the scenario's) and n_slip (0: none) follow the file's stated rules
    undocumented = {f.name for f in fields(Soil)} - given - notes - {"xc", "gravity", "n_slip"}
    assert not undocumented, f"{name}: no value and no note for {sorted(undocumented)}"
    if "xc" not in given:
        assert soil.xc == pytest.approx(math.radians(45.0) - soil.phi / 2)


@pytest.mark.parametrize("name", library.names("wheel"))
def test_every_shipped_wheel_builds(name):
    _, table = library.entry("wheel", name)
    wheel = library.build("wheel", name, table)
    assert isinstance(wheel, Wheel) and table["source"]
    assert set(table.get("notes", {})) | {k for k in table if k not in library.METADATA} >= {"r", "b", "J"}


def test_at_least_five_published_soils_beside_the_papers():
    assert library.DEFAULT == "paper" and len(set(library.names("soil")) - {"paper"}) >= 5
    assert len(library.names("wheel")) >= 2


def test_choose_applies_set_in_si_and_degrees():
    choice = library.choose("dry_sand", "mer", ["soil.phi_deg=30", "soil.c=500", "wheel.b=0.2"])
    assert choice.soil.phi == pytest.approx(math.radians(30.0)) and choice.soil.c == 500.0
    assert choice.soil.xc == pytest.approx(math.radians(30.0))   # 45 - 30/2, follows the new phi
    assert choice.wheel.b == 0.2 and choice.wheel.r == 0.13
    assert library.choose().soil == Soil() and library.choose().wheel == Wheel()
    values = library.fmu_parameters(choice.soil, choice.wheel)
    assert values["soil.kxBeta"] == choice.soil.kx_beta and values["wheel.r"] == 0.13
    assert library.from_fmu_parameters(values) == (choice.soil, choice.wheel)
    values["soil.xc"] = 0.0   # the FMUs' default: 45 deg - phi/2 of the soil's own phi
    assert library.from_fmu_parameters(values)[0].xc == pytest.approx(math.radians(30.0))


@pytest.mark.parametrize(("soil", "assignments", "message"), [
    ("mud", [], "expected one of paper"),
    ("paper", ["soil.cohesion=5"], "unknown key(s) ['cohesion']"),
    ("paper", ["soil.c=-1"], "c=-1.0 is not physical"),
    ("paper", ["c=5"], "expected soil.NAME=VALUE"),
    ("paper", ["soil.c=abc"], "'abc' is not a number"),
    ("paper", ["soil.phi_deg=95"], "phi"),
])
def test_bad_choices_name_the_value_and_what_was_expected(soil, assignments, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")):
        library.choose(soil, None, assignments)


def test_a_soil_file_of_ones_own(tmp_path):
    (tmp_path / "mine.toml").write_text('title = "my sand"\nsource = "measured"\nc = 300.0\nphi_deg = 33.0\n')
    choice = library.choose(str(tmp_path / "mine.toml"))
    assert choice.soil_name == "mine" and choice.soil.c == 300.0
    (tmp_path / "two.toml").write_text('[a]\nc = 1.0\n[b]\nc = 2.0\n')
    assert library.choose(f"{tmp_path / 'two.toml'}:b").soil.c == 2.0
    with pytest.raises(ValueError, match="several tables"):
        library.choose(str(tmp_path / "two.toml"))
    (tmp_path / "both.toml").write_text('phi = 0.5\nphi_deg = 30.0\n')
    with pytest.raises(ValueError, match="both phi_deg and phi"):
        library.choose(str(tmp_path / "both.toml"))


@pytest.mark.parametrize(("soil", "wheel"), [("lunar_nominal", "mer"), ("sandy_loam", "msl")])
def test_fmu_and_numpy_wheel_agree_on_another_soil_given_as_parameters(fmus, soil, wheel):
    """SingleWheel.fmu (built for the paper's soil) with another soil and wheel as parameters,
    against the numpy reference test bed on the same soil: within 0.5 % of scale."""
    choice = library.choose(soil, wheel)
    bed = WheelTestBed(fmus["SingleWheel"])
    parameters = library.fmu_parameters(choice.soil, choice.wheel)
    ours = bed.run(300.0, TorqueProfile.step(15.0), 0.05, 1e-3, start_speed=1.0, parameters=parameters)
    theirs = run_reference_test_bed(300.0, TorqueProfile.step(15.0), 0.05, 1e-3, soil=choice.soil,
                                    wheel=choice.wheel, start=StartState(v=1.0, omega=1.0 / choice.wheel.r))
    paper = bed.run(300.0, TorqueProfile.step(15.0), 0.05, 1e-3, start_speed=1.0)
    for column in ("Fx", "slip", "sinkage", "omega"):
        scale = np.abs(theirs[column]).max()
        np.testing.assert_allclose(ours[column], theirs[column], atol=5e-3 * scale, err_msg=column)
    assert abs(ours["sinkage"].iloc[-1] - paper["sinkage"].iloc[-1]) > 1e-3   # really another soil


def test_fig3_records_the_soil_it_used(tmp_path, capsys):
    assert main(["fig3", "--out", str(tmp_path), "--loads", "300", "--slip-step", "0.3",
                 "--soil", "dry_sand", "--set", "soil.c=900"]) == 0
    written = sorted(tmp_path.glob("fig3_fx_vs_slip_dry_sand_set-*.json"))  # named by the soil and the change
    assert len(written) == 1
    record = json.loads(written[0].read_text())
    assert record["parameters"]["choice"]["soil"]["name"] == "dry_sand"
    assert record["parameters"]["soil"]["c"] == 900.0 and record["parameters"]["choice"]["set"] == ["soil.c=900"]
    assert main(["fig3", "--out", str(tmp_path), "--soil", "mud"]) == 2
    assert "soil 'mud'" in capsys.readouterr().err


def test_run_gives_the_soil_to_every_fmu_that_has_it(fmu_dir, fmus, tmp_path):
    out = tmp_path / "sand.csv"
    assert main(["run", "single_wheel_step", "--fmu-dir", str(fmu_dir), "--stop-time", "0.3", "--quiet",
                 "-o", str(out), "--soil", "lunar_nominal"]) == 0
    default = tmp_path / "paper.csv"
    assert main(["run", "single_wheel_step", "--fmu-dir", str(fmu_dir), "--stop-time", "0.3", "--quiet",
                 "-o", str(default)]) == 0
    sand, paper = np.loadtxt(out, delimiter=",", skiprows=1), np.loadtxt(default, delimiter=",", skiprows=1)
    assert not np.allclose(sand[-1], paper[-1])


def test_the_destructive_angle_follows_phi_however_phi_is_entered(tmp_path):
    """X_c = 45 deg - phi/2 unless given: from a TOML file, --set, Soil.from_degrees, Soil(phi=...)
    and library.vary the same soil has the same X_c (and so the same records and cache keys)."""
    from rover_cosim.terramechanics.library import choose, fmu_parameters, vary
    from rover_cosim.terramechanics.parameters import xc_from_phi

    (tmp_path / "mine.toml").write_text("phi_deg = 35.0\n")
    ways = [choose(soil=str(tmp_path / "mine.toml")).soil, choose(assignments=["soil.phi_deg=35"]).soil,
            Soil.from_degrees(35.0), Soil(phi=math.radians(35.0)), vary(choose(), soil={"phi_deg": 35.0}).soil]
    assert {soil.xc for soil in ways} == {xc_from_phi(math.radians(35.0))}
    assert math.degrees(ways[0].xc) == pytest.approx(27.5, abs=1e-12)
    assert len({tuple(sorted(fmu_parameters(soil, choose().wheel).items())) for soil in ways}) == 1
    assert Soil().xc == math.radians(26.4)                       # the paper's Table 2 value, derived
    (tmp_path / "given.toml").write_text("phi_deg = 35.0\nxc_deg = 20.0\n")
    assert math.degrees(choose(soil=str(tmp_path / "given.toml")).soil.xc) == pytest.approx(20.0)
    assert math.degrees(Soil.from_degrees(35.0, xc=math.radians(20.0)).xc) == pytest.approx(20.0)


def test_jobs_take_a_soil_built_in_code(tmp_path):
    """write_fig3(out, choice=Soil(...)): the job takes the Soil (named "custom" in its record and
    files), as it takes a Choice; a wrong kind of value is named."""
    from rover_cosim.jobs.fig3 import write_fig3
    from rover_cosim.terramechanics.library import as_choice

    written = write_fig3(tmp_path, loads=(300.0,), slips=(0.0, 0.2), choice=Soil(c=500.0))
    record = json.loads(next(p for p in written if p.suffix == ".json").read_text())
    assert record["parameters"]["soil"]["c"] == 500.0 and record["parameters"]["choice"]["soil"]["name"] == "custom"
    assert any(p.name == "fig3_fx_vs_slip_custom.csv" for p in written)
    assert as_choice(Wheel(r=0.3)).wheel.r == 0.3 and as_choice(Wheel(r=0.3)).soil == Soil()
    with pytest.raises(ValueError, match="expected a Choice, a Soil or a Wheel"):
        as_choice("lete_sand")  # type: ignore[arg-type]
