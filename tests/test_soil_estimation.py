"""Soil parameters estimated from single-wheel test-bed data (issue 33): known truths recovered from
generated data (exactly without noise, inside the intervals with noise), predictions at loads and
slips not in the data, what missing columns leave unestimated, bad data named by row and column
(reader and command line), soil.toml read back by the soil library. No FMU: the fast tier."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from rover_cosim.cli import build_parser, main
from rover_cosim.common.outputs import file_sha256
from rover_cosim.identification.soil_estimation import (
    NOT_SEARCHED,
    PATCH_STATEMENT,
    SoilEstimate,
    estimate_soil,
    plan_parameters,
    soil_toml,
)
from rover_cosim.identification.testbed_data import (
    TestBedData,
    generate_testbed_data,
    parse_testbed_csv,
    prediction_error,
    read_testbed_csv,
)
from rover_cosim.terramechanics import Soil, Wheel
from rover_cosim.terramechanics.library import choose

#: Loads and slips not in the generated data (150-750 N, slips -0.2 ... 0.8 by 0.1).
HELD_LOADS, HELD_SLIPS = (225.0, 525.0, 675.0), (-0.15, 0.05, 0.25, 0.45, 0.65)


@pytest.fixture(scope="module")
def lunar() -> Soil:
    return choose("lunar_nominal").soil


@pytest.fixture(scope="module")
def exact_fit(lunar: Soil) -> SoilEstimate:
    """The lunar soil from noise-free data (55 rows: Fx, Tx, sinkage), searched from the paper's soil."""
    return estimate_soil(generate_testbed_data(lunar), Wheel(), Soil())


def test_noise_free_data_give_back_the_truth(exact_fit: SoilEstimate, lunar: Soil):
    estimated = exact_fit.parameters
    assert {"c", "phi", "kx", "kphi", "n"} <= set(estimated)
    for name in ("c", "phi", "kx", "n", "a0", "a1", "lam"):
        if name in estimated:
            assert estimated[name].value == pytest.approx(getattr(lunar, name), rel=1e-6), name
    # k_c stays at the prior's (paper) value; what the data see is k_c/b + k_phi, the truth's
    assert exact_fit.fixed["kc"].value == Soil().kc and "one wheel width" in exact_fit.fixed["kc"].reason
    assert exact_fit.bekker_modulus.value == pytest.approx(lunar.bekker_modulus(0.175), rel=1e-6)
    assert exact_fit.seconds < 30 and exact_fit.evaluations < 2000
    held = generate_testbed_data(lunar, loads=HELD_LOADS, slips=HELD_SLIPS)
    for error in prediction_error(exact_fit.predict(held.load_N, held.slip), held).values():
        assert error.max_percent < 1e-4, error


def test_without_the_optional_parameters_the_plans_own_are_searched_and_the_others_said_kept(
        exact_fit: SoilEstimate, lunar: Soil):
    """``optional=False`` (the online adaptation's default): a1, a0 and λ keep the prior's values,
    each with the reason, in fewer evaluations; the plan's parameters still come back from
    noise-free data (the lunar soil has the paper's a0, a1, λ)."""
    data = generate_testbed_data(lunar)
    plain = estimate_soil(data, Wheel(), Soil(), optional=False)
    for name in ("a1", "a0", "lam"):
        assert name not in plain.parameters and plain.fixed[name].reason == NOT_SEARCHED, name
        assert plain.fixed[name].value == getattr(Soil(), name)
    for name in ("c", "phi", "kx", "n"):
        assert plain.parameters[name].value == pytest.approx(getattr(lunar, name), rel=1e-6), name
    assert set(plain.parameters) == set(exact_fit.parameters) - {"a1", "a0", "lam"}
    assert plain.evaluations < exact_fit.evaluations / 2
    said = plain.identifiability.statements
    assert "a1 was not searched (optional parameters off) and is kept at the prior's value." in said
    assert PATCH_STATEMENT not in said and PATCH_STATEMENT in exact_fit.identifiability.statements


def test_noisy_data_hold_the_truth_in_the_intervals_and_predict_held_out_points(lunar: Soil):
    """2 % noise on every channel: every parameter the data determine holds the truth in its 95 %
    interval (the prior has the truth's k_c, so k_phi itself is comparable), and Fx, Tx and the
    sinkage at loads and slips not in the data are within 2 % of their range."""
    data = generate_testbed_data(lunar, noise=0.02, seed=7)
    estimate = estimate_soil(data, Wheel(), replace(Soil(), kc=lunar.kc))
    for name, e in estimate.parameters.items():
        if e.determined == "well":
            assert e.low <= getattr(lunar, name) <= e.high, e.text()
    assert estimate.parameters["phi"].determined == "well"
    for channel in ("Fx_N", "Tx_Nm", "sinkage_m"):  # noise estimated within 30 % of what was added
        added = 0.02 * np.ptp(generate_testbed_data(lunar).channel(channel))
        assert estimate.residuals[channel].noise_scale == pytest.approx(added, rel=0.3)
    held = generate_testbed_data(lunar, loads=HELD_LOADS, slips=HELD_SLIPS)
    errors = prediction_error(estimate.predict(held.load_N, held.slip), held)
    assert max(e.rms_percent for e in errors.values()) < 2.0, errors
    names = list(estimate.parameters)
    assert estimate.correlation.shape == (len(names), len(names))
    np.testing.assert_allclose(np.diag(estimate.correlation), 1.0)


def test_the_lateral_moduli_come_from_fy_at_slip_angles():
    truth = replace(Soil(), ky=0.02, ky_beta=0.03, kx_beta=0.05)
    data = generate_testbed_data(truth, loads=(200, 500), slips=(0.0, 0.2, 0.5, 0.8), slip_angles_deg=(0, 8, 16))
    assert data.channels == ("Fx_N", "Tx_Nm", "sinkage_m", "Fy_N")
    estimate = estimate_soil(data, Wheel(), Soil())
    assert estimate.parameters["ky"].value == pytest.approx(0.02, rel=1e-5)
    for name, value in (("ky_beta", 0.03), ("kx_beta", 0.05)):
        if name in estimate.parameters:
            assert estimate.parameters[name].value == pytest.approx(value, rel=1e-5)
        else:
            assert "the data do not determine it" in estimate.fixed[name].reason


def test_missing_columns_are_said_to_leave_parameters_unestimated():
    data = generate_testbed_data(Soil(), loads=(200, 400), slips=(0.1, 0.5))
    plan = plan_parameters(data.without("sinkage_m"))
    assert "No sinkage_m: k_φ and n are seen only through their effect on the forces" in " ".join(plan.statements)
    assert {"c", "phi", "kphi", "n", "kx"} <= set(plan.estimated)
    only_sinkage = plan_parameters(data.without("Fx_N", "Tx_Nm"))
    fixed = {f.name: f.reason for f in only_sinkage.fixed}
    assert {"c", "phi", "kx"} <= set(fixed) and "need a force or torque" in fixed["c"]
    assert set(only_sinkage.estimated) == {"kphi", "n"}
    assert "no Fy_N at a slip angle other than 0" in fixed["ky"]
    one_load = plan_parameters(data.subset(data.load_N == 200))
    assert "c" not in one_load.estimated and "n" not in one_load.estimated
    assert any("One load only" in s for s in one_load.statements)
    with pytest.raises(ValueError, match=r"parameter ky \(lateral shear modulus k_y\) cannot be estimated from these "
                                         r"data: it needs Fy_N at a slip angle other than 0"):
        estimate_soil(data, parameters=["phi", "ky"])


def test_kc_and_kphi_asked_together_are_reported_as_inseparable():
    data = generate_testbed_data(Soil(), loads=(200, 400, 600), slips=(0.1, 0.3, 0.6), channels=("sinkage_m",))
    estimate = estimate_soil(data, parameters=["kc", "kphi"])
    assert {e.determined for e in estimate.parameters.values()} == {"not"}
    assert abs(estimate.correlation[0, 1]) == pytest.approx(1.0)
    assert estimate.bekker_modulus.value == pytest.approx(Soil().bekker_modulus(0.175), rel=1e-6)
    assert any("cannot separate them" in s for s in estimate.identifiability.statements)


def test_a_grousered_wheel_with_slip_sinkage_gives_back_the_truth_and_a_smooth_fit_does_not(lunar: Soil):
    """Issue 48: data of a grousered wheel on a soil with slip-sinkage. With the wheel's grousers and
    slip-sinkage on in the prior, the noise-free data give back the soil, n_slip too; a smooth wheel's
    fit puts the grousers' thrust into c and phi; the plan says what the grousers and n_slip mean."""
    truth = replace(lunar, n_slip=0.3)
    wheel = replace(Wheel(), grouser_height=0.01, grouser_count=24.0)
    data = generate_testbed_data(truth, wheel)
    right = estimate_soil(data, wheel, replace(Soil(), n_slip=0.1), ["c", "phi", "kphi", "n", "kx", "n_slip"])
    for name in ("c", "phi", "kx", "n", "n_slip"):
        assert right.parameters[name].value == pytest.approx(getattr(truth, name), rel=1e-6), name
    statements = " ".join(right.identifiability.statements)
    assert "grousers (24 of 10 mm) are part of the model" in statements
    smooth = estimate_soil(data, Wheel(), Soil())
    assert smooth.parameters["c"].value > 1.5 * truth.c and smooth.parameters["phi"].value > truth.phi + 0.05
    # the default plan: n_slip estimated where the prior has slip-sinkage on and a load has 3+ slips
    plan = plan_parameters(data, replace(Soil(), n_slip=0.1), wheel=wheel)
    assert "n_slip" in plan.estimated and any("Slip-sinkage on" in s for s in plan.statements)
    few = generate_testbed_data(truth, wheel, slips=(0.1, 0.4))
    fixed = {f.name: f.reason for f in plan_parameters(few, replace(Soil(), n_slip=0.1), wheel=wheel).fixed}
    assert "3 or more slips" in fixed["n_slip"]
    with pytest.raises(ValueError, match=r"parameter n_slip .* cannot be estimated from these data: it needs a load "
                                         r"measured at 3 or more slips"):
        estimate_soil(few, wheel, parameters=["phi", "n_slip"])
    # slip-sinkage off in the prior: the plan as before, n_slip nowhere
    off = plan_parameters(data)
    assert "n_slip" not in off.estimated and "n_slip" not in {f.name for f in off.fixed}


def test_too_few_points_for_the_parameters_are_refused_with_the_counts():
    data = generate_testbed_data(Soil(), loads=(200, 400), slips=(0.1, 0.5), channels=("Fx_N",))
    with pytest.raises(ValueError, match=r"4 rows x 1 measured columns = 4 measurements for 5 parameters \(c, phi, "
                                         r"kx, kphi, n\): too few points; expected at least 11"):
        estimate_soil(data)


def test_soil_toml_round_trips_through_the_library(exact_fit: SoilEstimate, tmp_path: Path):
    path = tmp_path / "soil.toml"
    path.write_text(soil_toml(exact_fit, title='from "data.csv"'))
    chosen = choose(str(path))
    assert chosen.soil == exact_fit.soil and chosen.soil_name == "estimated"
    assert chosen.soil_entry["title"] == 'from "data.csv"'
    assert "estimated: phi = " in chosen.soil_entry["notes"]["phi"]
    assert "one wheel width" in chosen.soil_entry["notes"]["kc"]
    assert math.isclose(chosen.soil.xc, math.radians(45) - chosen.soil.phi / 2)  # follows the estimated phi


def test_the_csv_round_trips(tmp_path: Path):
    data = generate_testbed_data(Soil(), loads=(100, 300), slips=(0.0, 0.4), slip_angles_deg=(0, 5), noise=0.01)
    (tmp_path / "d.csv").write_text("# a note\n" + data.to_csv() + "\n")
    back = read_testbed_csv(tmp_path / "d.csv")
    for name, values in data.columns().items():
        np.testing.assert_allclose(back.columns()[name], values, rtol=1e-11)
    assert back.source == str(tmp_path / "d.csv") and back.lines == tuple(range(3, 3 + data.rows))
    assert back.subset(back.load_N > 200).row_name(0) == f"row 1 (line {3 + data.rows // 2})"


@pytest.mark.parametrize(("text", "message"), [
    ("load_N,slip,Fx_N\n100,0.1,5\n200,0.2,nan\n", "row 2 (line 3), column Fx_N: nan is not a finite number"),
    ("load_N,slip,Fx_N\n100,0.1,5\n-200,0.2,7\n", "row 2 (line 3), column load_N: -200.0 N: expected a load > 0 N"),
    ("load_N,slip,Tx_Nm\n100,1.5,5\n", "row 1 (line 2), column slip: 1.5: expected a slip ratio in [-1, 1]"),
    ("load_N,slip,Fx_N\n100,0.1,5\n\n# comment\n100,0.2,abc\n",
     "row 2 (line 5), column Fx_N: 'abc' is not a number"),
    ("load_N,slip,Fx_N\n100,0.1,\n", "row 1 (line 2), column Fx_N: empty"),
    ("load_N,slip,Fx_N\n100,0.1\n", "row 1 (line 2): 2 values, expected 3 (one per column of the header)"),
    ("load_N,slip,sinkage_m\n100,0.1,-0.01\n", "row 1 (line 2), column sinkage_m: -0.01 m: expected a sinkage >= 0 m"),
    ("load_N,slip,slip_angle_deg,Fy_N\n100,0.1,95,3\n",
     "row 1 (line 2), column slip_angle_deg: 95.0 deg: expected a slip angle in (-90, 90) deg"),
    ("load_N,slip,Fx\n100,0.1,5\n", "unknown column 'Fx' (column 3 of the header): expected some of load_N, slip"),
    ("load_N,slip,Fx_N,Fx_N\n100,0.1,5,5\n", "column Fx_N appears twice in the header (columns 3 and 4)"),
    ("load_N,Fx_N\n100,5\n", "no column slip: every row needs load_N and slip"),
    ("load_N,slip\n100,0.1\n", "no measured column: expected at least one of Fx_N, Tx_Nm, sinkage_m, Fy_N"),
    ("load_N,slip,Fx_N\n", "no data rows"),
    ("", "empty: expected a header line"),
])
def test_bad_data_are_named_by_row_and_column(text: str, message: str):
    with pytest.raises(ValueError) as error:
        parse_testbed_csv(text, "data.csv")
    assert str(error.value).startswith("data.csv: ") and message in str(error.value), str(error.value)


@pytest.mark.parametrize(("content", "message"), [
    ("load_N,slip,Fx_N\n100,0.1,5\n200,0.2,inf\n", "row 2 (line 3), column Fx_N: inf is not a finite number"),
    ("load_N,slip,Fx_N\n0,0.1,5\n", "row 1 (line 2), column load_N: 0.0 N: expected a load > 0 N"),
    ("load_N,slip,Fx_N\n100,-1.2,5\n", "row 1 (line 2), column slip: -1.2: expected a slip ratio in [-1, 1]"),
    ("load_N,slip,Fx_N,load_N\n100,0.1,5,100\n", "column load_N appears twice in the header"),
    ("load_N,slip,Fx_N\n100,0.1,5\n200,0.2,7\n", "too few points; expected at least 11"),
    ("load_N,slip,sinkage_m\n100,0.1,0.01\n# deep\n200,0.1,0.5\n",
     "row 2 (line 4), column sinkage_m: 0.5 m: expected a sinkage below the wheel's radius 0.355 m"),
    (None, "no such file"),
])
def test_bad_data_on_the_command_line_are_one_line_and_exit_2(content: str | None, message: str, tmp_path: Path,
                                                               capsys: pytest.CaptureFixture[str]):
    data = tmp_path / "data.csv"
    if content is not None:
        data.write_text(content)
    assert main(["estimate-soil", str(data), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"rover-cosim estimate-soil: {data}") and message in err, err
    assert "Traceback" not in err and not (tmp_path / "out").exists()


def test_generated_data_estimated_on_the_command_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    data = tmp_path / "data.csv"
    assert main(["testbed-data", "--soil", "lunar_nominal", "--loads", "200,400,600", "--slips", "0,0.2,0.4,0.7",
                 "--no-sinkage", "--noise", "0.01", "--seed", "3", "--out", str(data)]) == 0
    record = json.loads(data.with_suffix(".json").read_text())
    assert record["command"] == "rover-cosim testbed-data" and record["parameters"]["truth"]["soil"]["name"] == \
        "lunar_nominal"
    assert data.read_text().splitlines()[0] == "load_N,slip,Fx_N,Tx_Nm"
    out = tmp_path / "estimate"
    assert main(["estimate-soil", str(data), "--out", str(out), "--parameters", "c,phi,kx,kphi"]) == 0
    printed = capsys.readouterr().out
    assert "phi = " in printed and f"wrote {out / 'soil.toml'}" in printed
    assert sorted(p.name for p in out.iterdir()) == ["estimate.json", "fit.csv", "fit.png", "residuals.png",
                                                    "soil.toml"]
    estimate = json.loads((out / "estimate.json").read_text())
    assert estimate["parameters"]["data_sha256"] == file_sha256(data)
    assert estimate["command"] == "rover-cosim estimate-soil" and estimate["parameters"]["wheel"]["name"] == "paper"
    assert set(estimate["estimate"]["estimates"]) == {"c", "phi", "kx", "kphi"}
    assert len(estimate["estimate"]["residuals"]["Fx_N"]["residuals"]) == 12
    assert "not asked (--parameters)" in estimate["estimate"]["fixed"]["n"]["reason"]
    assert (out / "fit.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert choose(str(out / "soil.toml")).soil.phi == pytest.approx(estimate["estimate"]["soil"]["phi"], abs=0)


def test_testbed_data_replaces_only_its_own_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]):
    foreign = tmp_path / "measured.csv"
    foreign.write_text("load_N,slip,Fx_N\n100,0.1,5\n")
    arguments = ["testbed-data", "--loads", "200", "--slips", "0.1,0.2", "--out", str(foreign)]
    assert main(arguments) == 2
    assert "is not a result of rover-cosim testbed-data: pass --overwrite" in capsys.readouterr().err
    assert main([*arguments, "--overwrite"]) == 0 and main(arguments) == 0
    assert main(["testbed-data", "--out", str(tmp_path / "data.json")]) == 2
    assert "expected a .csv file name" in capsys.readouterr().err
    with pytest.raises(SystemExit) as ended:
        main(["testbed-data", "--noise", "2", "--out", str(tmp_path / "x.csv")])
    assert ended.value.code == 2 and "expected a fraction of each channel's range in [0, 1]" in capsys.readouterr().err
    with pytest.raises(SystemExit) as ended:
        main(["estimate-soil", str(foreign), "--parameters", "c,nu"])
    assert ended.value.code == 2 and "parameters='c,nu': expected distinct names of c, phi" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["estimate-soil", "testbed-data"])
def test_help_shows_every_default(command: str):
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices[command]  # type: ignore[index]
    for action in sub._actions:
        if action.option_strings and action.default not in (None, False, [], "==SUPPRESS==") and action.nargs != 0:
            assert "default" in (sub.formatter_class(prog="x")._get_help_string(action) or ""), action.dest


def test_data_record_checks_its_own_columns():
    with pytest.raises(ValueError, match="columns of different lengths"):
        TestBedData(load_N=np.array([100.0, 200.0]), slip=np.array([0.1]), Fx_N=np.array([1.0, 2.0]))
    with pytest.raises(ValueError, match=r"row 2, column slip: -3.0: expected a slip ratio in \[-1, 1\]"):
        TestBedData(load_N=np.array([100.0, 200.0]), slip=np.array([0.1, -3.0]), Fx_N=np.array([1.0, 2.0]))


def test_a_failed_figure_leaves_the_previous_results_whole(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    from rover_cosim.jobs import estimate_soil as job

    data = generate_testbed_data(Soil(), loads=(200, 400, 600), slips=(0.0, 0.2, 0.4, 0.7))
    out = tmp_path / "out"
    first = job.run_estimate_soil(data, out, parameters=["phi", "kx"])
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    assert sorted(before) == sorted(job.FILES) and first.estimate.parameters["phi"].determined == "well"

    def broken(estimate: SoilEstimate, title: str) -> None:
        raise RuntimeError("renderer failed")

    monkeypatch.setattr(job, "residual_figure", broken)
    with pytest.raises(RuntimeError, match="renderer failed"):
        job.run_estimate_soil(data, out, parameters=["phi", "kx", "n"])
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_the_command_lines_channel_names_are_the_readers():
    from rover_cosim.cli.testbed_data import CHANNEL_NAMES
    from rover_cosim.identification.testbed_data import CHANNELS

    assert CHANNEL_NAMES == tuple(CHANNELS)


def test_the_intervals_t_quantile_is_scipy_stats_bit_for_bit():
    """The confidence intervals' Student's t quantile comes from scipy.special (scipy.stats is a
    second of imports in every Monte Carlo worker): the same bits as scipy.stats.t.ppf, NaN where
    it gives NaN (no degrees of freedom)."""
    from scipy import stats

    from rover_cosim.identification.soil_estimation import _t_quantile

    rng = np.random.default_rng(3)
    cases = [(0.975, dof) for dof in (0.0, -1.0, 0.5, 1.0, 2.0, 3.7, 10.0, 1e6, math.inf)]
    cases += [(float(rng.uniform(0.5, 1.0)), float(rng.uniform(0.0, 500.0))) for _ in range(500)]
    for probability, dof in cases:
        ours, theirs = _t_quantile(probability, dof), float(stats.t.ppf(probability, dof))
        assert ours == theirs or (math.isnan(ours) and math.isnan(theirs)), (probability, dof)
