"""Monte Carlo over soil uncertainty: the study file and its errors, seeded and correlated
samples, the metrics on synthetic runs, the sensitivity ranking, and short real studies on
Rover.fmu (the nominal sample reproduces make simulate's RMS to the last bit, a failing sample is
recorded while the study completes, the cache makes a rerun compute nothing and recomputes a
damaged file, a Dask LocalCluster gives the rows of local processes)."""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from rover_cosim.jobs import simulate
from rover_cosim.jobs.montecarlo import metrics, run_montecarlo, sensitivity
from rover_cosim.jobs.montecarlo.runs import nominal_values
from rover_cosim.jobs.montecarlo.sampling import draw, sample_table
from rover_cosim.jobs.montecarlo.study import STUDIES, StudyError, load_study, parse_study
from rover_cosim.terramechanics.library import choose

BASE: dict[str, Any] = {"runs": 5, "seed": 1,
                        "parameters": {"soil.c": {"distribution": "uniform", "lower": 100.0, "upper": 1000.0},
                                       "soil.phi_deg": {"distribution": "normal", "mean": 37.0, "std": 5.0,
                                                        "lower": 30.0, "upper": 50.0},
                                       "soil.kc": {"distribution": "lognormal", "median": 1370.0, "sigma": 1.0}}}


def _study(**changes: Any) -> Any:
    data = {**BASE, **changes}
    return parse_study(data, "test study")


# --- the study file ---------------------------------------------------------------------------------

def test_the_shipped_study_parses_centred_on_the_paper_soil():
    study = load_study("lunar_regolith")
    assert study.soil == "paper" and study.runs >= 100 and study.scenarios == ("straight",)
    assert {"soil.c", "soil.phi_deg", "soil.kc", "soil.kphi"} <= set(study.names)
    assert study.correlation.shape == (len(study.names),) * 2
    assert "Carrier" in (STUDIES / "lunar_regolith.toml").read_text()


@pytest.mark.parametrize("change, message", [
    ({"parameters": {"soil.c": {"distribution": "weibull", "lower": 1.0, "upper": 2.0}}}, "distribution = 'weibull'"),
    ({"parameters": {"soil.c": {"distribution": "uniform", "lower": 5.0, "upper": 1.0}}}, "lower = 5.0 >= upper"),
    ({"parameters": {"soil.c": {"distribution": "normal", "mean": 5.0, "std": 1.0, "lower": 9.0, "upper": 3.0}}},
     "lower = 9.0 >= upper = 3.0"),
    ({"parameters": {"soil.c": {"distribution": "normal", "mean": 5.0, "std": -1.0}}}, "std = -1.0"),
    ({"parameters": {"soil.c": {"distribution": "lognormal", "median": -5.0, "sigma": 1.0}}}, "median = -5.0"),
    ({"parameters": {"soil.c": {"distribution": "normal", "mean": 5.0}}}, "std missing"),
    ({"parameters": {"soil.cohesion": {"distribution": "uniform", "lower": 1.0, "upper": 2.0}}}, "'cohesion'"),
    ({"runs": 0}, "runs = 0"),
    ({"seed": "x"}, "seed = 'x'"),
    ({"scenarios": ["moon"]}, "scenarios = ['moon']"),
    ({"stopp_time": 3.0}, "unknown key(s) ['stopp_time']"),
    ({"correlation": {"parameters": ["soil.c", "soil.kc"], "matrix": [[1.0, 1.2], [1.2, 1.0]]}}, "entries in [-1, 1]"),
    ({"correlation": {"parameters": ["soil.c", "soil.phi_deg", "soil.kc"],
                      "matrix": [[1.0, 0.9, -0.9], [0.9, 1.0, 0.9], [-0.9, 0.9, 1.0]]}}, "not positive definite"),
    ({"correlation": {"parameters": ["soil.c", "soil.x"], "matrix": [[1.0, 0.0], [0.0, 1.0]]}}, "'soil.x' is not"),
    ({"correlation": {"parameters": ["soil.c", "soil.kc"], "matrix": [[1.0, 0.5]]}}, "expected 2 x 2"),
])
def test_a_bad_study_is_refused_naming_the_key(change, message):
    with pytest.raises(StudyError, match="test study") as error:
        _study(**change)
    assert message in str(error.value)


def test_a_missing_study_names_the_shipped_ones(tmp_path):
    with pytest.raises(StudyError, match="lunar_regolith"):
        load_study(tmp_path / "nope.toml")


def test_command_line_overrides_of_runs_and_seed(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text((STUDIES / "lunar_regolith.toml").read_text())
    study = load_study(path, runs=7, seed=3)
    assert (study.runs, study.seed, study.path) == (7, 3, path)


# --- sampling ----------------------------------------------------------------------------------------

NOMINAL = {"soil.c": 800.0, "soil.phi_deg": 37.2, "soil.kc": 1370.0}


def test_the_same_seed_gives_the_same_samples_and_another_seed_others():
    first, again = sample_table(_study(), NOMINAL), sample_table(_study(), NOMINAL)
    pd.testing.assert_frame_equal(first, again)
    other = sample_table(_study(seed=2), NOMINAL)
    assert not np.allclose(first.iloc[1:, 3:].to_numpy(), other.iloc[1:, 3:].to_numpy())


def test_sample_zero_is_the_nominal_and_more_runs_keep_the_first_samples():
    table = sample_table(_study(), NOMINAL)
    assert table["nominal"].tolist() == [True, False, False, False, False]
    assert table.iloc[0][list(NOMINAL)].to_dict() == NOMINAL
    longer = sample_table(_study(runs=50), NOMINAL)
    pd.testing.assert_frame_equal(table, longer.iloc[:5])


def test_bounds_are_honoured_and_the_marginals_are_right():
    from scipy import stats  # here: a second of imports that every test worker's collection would pay

    values = draw(_study(seed=7), 20000)
    c, phi, kc = values.T
    assert c.min() >= 100 and c.max() <= 1000 and abs(c.mean() - 550) < 10
    assert phi.min() >= 30 and phi.max() <= 50
    expected_mean = stats.truncnorm.mean((30 - 37) / 5, (50 - 37) / 5, loc=37, scale=5)
    assert abs(phi.mean() - expected_mean) < 0.1
    assert abs(np.median(np.log(kc)) - math.log(1370)) < 0.03 and abs(np.std(np.log(kc)) - 1.0) < 0.03


def test_the_requested_correlation_is_honoured():
    from scipy import stats

    rho = 0.6
    study = _study(correlation={"parameters": ["soil.c", "soil.kc"], "matrix": [[1.0, rho], [rho, 1.0]]})
    values = draw(study, 20000)
    spearman = stats.spearmanr(values[:, 0], values[:, 2]).statistic
    assert abs(spearman - 6 / math.pi * math.asin(rho / 2)) < 0.02   # the Gaussian copula's rank correlation
    assert abs(stats.spearmanr(values[:, 0], values[:, 1]).statistic) < 0.03   # the others stay independent


def test_bounds_far_in_the_tail_are_refused():
    study = _study(parameters={"soil.c": {"distribution": "normal", "mean": 0.0, "std": 1.0, "lower": 50.0,
                                          "upper": 60.0}})
    with pytest.raises(ValueError, match="soil.c: bounds"):
        draw(study, 3)


# --- metrics and sensitivity on synthetic data -------------------------------------------------------

def _run(v: np.ndarray, dt: float = 0.01, slip: float = 0.05, force_error: float = 0.5) -> pd.DataFrame:
    time = np.arange(len(v)) * dt
    table = {"time": time, "v": v, "x": np.concatenate([[0.0], np.cumsum(v[:-1]) * dt])}
    for i in range(1, 7):
        table |= {f"Fx_{i}": np.full(len(v), 20.0 + force_error * i), f"Fx_des_{i}": np.full(len(v), 20.0),
                  f"slip_{i}": np.full(len(v), slip)}
    return pd.DataFrame(table)


def test_metrics_of_a_run_that_reaches_the_target():
    v = np.minimum(0.1 * np.arange(2001) * 0.01, 1.0)   # 0.1 m/s² up to 1 m/s at 10 s, then steady, 20 s
    row = metrics.straight_metrics(_run(v))
    assert row["rms_Fx_3_N"] == pytest.approx(1.5) and row["rms_Fx_max_N"] == pytest.approx(3.0)
    assert row["time_to_98_s"] == pytest.approx(9.8)
    assert row["steady_v_error_m_s"] == pytest.approx(0.0, abs=1e-12)
    x_end = _run(v)["x"].iloc[-1]
    assert row["position_lag_m"] == pytest.approx(20.0 - x_end) and 4.9 < row["position_lag_m"] < 5.1
    assert row["max_slip"] == pytest.approx(0.05) and row["stuck"] is False


def test_metrics_of_a_stuck_rover():
    v = np.minimum(0.1 * np.arange(2001) * 0.01, 0.05)   # never faster than 5 cm/s
    row = metrics.straight_metrics(_run(v, slip=0.95))
    assert math.isnan(row["time_to_98_s"]) and row["stuck"] is True
    assert row["steady_v_error_m_s"] == pytest.approx(-0.95) and row["max_slip"] == pytest.approx(0.95)
    spinning = metrics.straight_metrics(_run(np.full(2001, 0.5), slip=0.95))
    assert spinning["stuck"] is True   # moving, but every wheel spinning out
    assert metrics.straight_metrics(_run(np.full(2001, 0.5)))["stuck"] is False


def test_sensitivity_ranks_the_parameter_that_drives_the_output_first():
    rng = np.random.default_rng(0)
    runs = pd.DataFrame({"a": rng.uniform(size=300), "b": rng.uniform(size=300), "c": rng.uniform(size=300)})
    runs["rms_Fx_max_N"] = np.exp(3 * runs["b"]) + 0.3 * runs["a"] + 0.05 * rng.normal(size=300)
    runs["time_to_98_s"] = np.where(runs["c"] > 0.8, np.nan, 10 + runs["c"])   # NaN: never, the slowest
    table = sensitivity.sensitivity(runs, ["a", "b", "c"])
    rms = table[table["output"] == "rms_Fx_max_N"].set_index("parameter")
    assert rms.loc["b", "rank"] == 1 and rms.loc["a", "rank"] == 2 and rms.loc["b", "prcc"] > 0.95
    assert abs(rms.loc["c", "prcc"]) < 0.2 and rms.loc["c", "p_value"] > 0.01 > rms.loc["a", "p_value"]
    late = table[table["output"] == "time_to_98_s"].set_index("parameter")
    assert late.loc["c", "spearman"] > 0.99 and late.loc["c", "rank"] == 1


def test_sensitivity_finds_an_output_that_worsens_both_ways_from_the_nominal():
    """A V around the nominal (the controller is exact there): invisible to PRCC, caught by the
    rank correlation with the distance from the nominal value (in ln for a log-normal parameter)."""
    rng = np.random.default_rng(1)
    runs = pd.DataFrame({"a": rng.uniform(size=300), "k": np.exp(rng.normal(size=300))})
    runs["rms_Fx_max_N"] = np.abs(np.log(runs["k"])) + 0.5 * runs["a"] + 0.01 * rng.normal(size=300)
    table = sensitivity.sensitivity(runs, ["a", "k"], nominal={"a": 0.5, "k": 1.0}, logarithmic={"k"})
    rms = table[table["output"] == "rms_Fx_max_N"].set_index("parameter")
    assert abs(rms.loc["k", "prcc"]) < 0.2 and rms.loc["k", "distance_spearman"] > 0.95
    assert rms.loc["k", "rank"] == 1 and rms.loc["k", "strongest"] == "distance from nominal"
    assert rms.loc["a", "strongest"] == "monotonic" and rms.loc["a", "p_value"] < 0.01 < rms.loc["k", "p_value"]


def test_the_ranks_and_p_values_are_scipy_stats_bit_for_bit():
    """The sensitivity ranks with pandas and takes Student's t from scipy.special (scipy.stats is a
    second of imports): the same bits as scipy.stats' rankdata and t.sf, ties and NaN included."""
    from scipy import stats

    rng = np.random.default_rng(7)
    for trial in range(200):
        n = int(rng.integers(3, 120))
        values = rng.integers(0, 4, n).astype(float) if trial % 2 else rng.standard_normal(n)
        values[rng.random(n) < 0.15] = np.nan
        expected = stats.rankdata(np.where(np.isnan(values), np.inf, values))
        assert np.array_equal(sensitivity._ranks(values), expected)
        t, freedom = float(rng.standard_normal() * 10 ** rng.uniform(-3, 2)), int(rng.integers(1, 300))
        assert sensitivity._two_sided_p(t, freedom) == float(2 * stats.t.sf(abs(t), freedom))


def test_sensitivity_of_too_few_runs_is_empty_not_wrong():
    runs = pd.DataFrame({"a": [1.0, 2.0, 3.0], "b": [3.0, 1.0, 2.0], "rms_Fx_max_N": [1.0, 2.0, 3.0]})
    table = sensitivity.sensitivity(runs, ["a", "b"])
    assert table["prcc"].isna().all() and table["rank"].isna().all()


# --- short real studies on Rover.fmu (2 s of the paper's loop; the 20 s run costs ~9 s per sample) ---

SHORT = 2.0  # s
OUTCOMES = [*metrics.STRAIGHT]


@pytest.fixture(scope="module")
def model(identified) -> Path:
    """The identified model of `make identify` (the session's)."""
    return identified.files[0].parent / "model.json"


@pytest.fixture(scope="module")
def short_study() -> Any:
    return _study(runs=3, seed=11, stop_time=SHORT,
                  parameters={"soil.c": {"distribution": "uniform", "lower": 300.0, "upper": 1200.0},
                              "soil.phi_deg": {"distribution": "normal", "mean": 37.2, "std": 4.0,
                                               "lower": 30.0, "upper": 50.0},
                              "rover.M": {"distribution": "uniform", "lower": 1400.0, "upper": 1700.0}})


@pytest.fixture(scope="module")
def samples(short_study, fmu_dir) -> pd.DataFrame:
    """The study's 3 samples and a 4th the soil model refuses (a friction angle of 95 deg)."""
    table = sample_table(short_study, nominal_values(short_study, choose(), fmu_dir))
    bad = table.iloc[[1]].assign(sample=3, **{"soil.phi_deg": 95.0})
    return pd.concat([table, bad], ignore_index=True)


@pytest.fixture(scope="module")
def study_run(short_study, samples, fmu_dir, model, tmp_path_factory):
    """The short study on 2 local processes, with make simulate's folder beside it."""
    out = tmp_path_factory.mktemp("montecarlo")
    return run_montecarlo(short_study, fmu_dir, model, out / "montecarlo", workers=2, samples=samples,
                          simulation=out / "simulation")


def test_a_failing_sample_is_recorded_and_the_study_completes(study_run):
    runs = study_run.runs
    assert runs["status"].tolist() == ["ok", "ok", "ok", "failed"] and study_run.computed == 4
    assert "phi_deg = 95.0 is not physical" in runs["error"].iloc[3]
    assert study_run.failures[["sample", "scenario"]].values.tolist() == [[3, "straight"]]
    assert study_run.failures["soil.phi_deg"].tolist() == [95.0]
    out = study_run.files[0].parent
    assert {p.name for p in out.iterdir()} >= {"runs.csv", "failures.csv", "sensitivity.csv", "summary.json",
                                              "fig_distributions.png", "fig_scatter.png", "cache"}
    assert pd.read_csv(out / "runs.csv")["status"].tolist() == runs["status"].tolist()
    numbers = study_run.summary["scenarios"]["straight"]
    assert (numbers["runs"], numbers["completed"], numbers["failed"]) == (4, 3, 1)
    assert numbers["meeting_1N_rms"] == 3 and numbers["share_meeting_1N_rms_of_all"] == 0.75
    assert study_run.summary["simulate_check"]["compared"] is False   # no make simulate beside it yet


def test_the_nominal_sample_reproduces_make_simulate_to_the_last_bit(study_run, short_study, samples, fmu_dir,
                                                                     model, monkeypatch):
    """make simulate's own code (run_simulation with the paper's soil, as the CLI calls it) at the
    study's stop time against the Monte Carlo's sample 0: the same RMS per limb, bit for bit; and
    the study's own check finds the same once simulation.json is beside it (recomputing nothing)."""
    monkeypatch.setattr(simulate, "STOP_TIME", SHORT)
    out = study_run.files[0].parent.parent
    simulated = simulate.run_simulation(fmu_dir, model, out / "simulation", choose())
    nominal = study_run.runs.iloc[0]
    assert bool(nominal["nominal"])
    assert [nominal[f"rms_Fx_{i}_N"] for i in range(1, 7)] == simulated.rms["monolithic"]["rms_N"].tolist()
    again = run_montecarlo(short_study, fmu_dir, model, out / "montecarlo", workers=1, samples=samples,
                           simulation=out / "simulation")
    check = again.summary["simulate_check"]
    assert check["compared"] and check["equal"] and check["largest_difference_N"] == 0.0


def test_a_rerun_computes_nothing_and_a_damaged_cache_file_is_computed_again(study_run, short_study, samples,
                                                                            fmu_dir, model):
    out = study_run.files[0].parent
    cache_files = sorted((out / "cache").glob("*.csv"))
    assert len(cache_files) == 3   # the failed sample is not cached: a rerun tries it again
    rerun = run_montecarlo(short_study, fmu_dir, model, out, workers=1, samples=samples)
    assert (rerun.computed, rerun.cached) == (1, 3)   # only the failing sample, which fails again
    pd.testing.assert_frame_equal(rerun.runs, study_run.runs)
    cache_files[0].write_bytes(cache_files[0].read_bytes()[:-5])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        repaired = run_montecarlo(short_study, fmu_dir, model, out, workers=1, samples=samples)
    assert not [w for w in caught if "cache" in str(w.message)]  # said in the result (the CLI: one line each)
    assert (repaired.computed, repaired.cached) == (2, 2) and list(repaired.rejected) == [cache_files[0]]
    assert "does not match its checksum" in repaired.rejected[cache_files[0]]
    pd.testing.assert_frame_equal(repaired.runs.drop(columns="wall_s"), study_run.runs.drop(columns="wall_s"))


def test_the_same_seed_gives_the_same_study(study_run, short_study, fmu_dir, model, tmp_path):
    """Drawn again from the seed (not injected) and computed afresh in another cache: the same rows."""
    fresh = run_montecarlo(short_study, fmu_dir, model, tmp_path / "again", workers=1)
    columns = ["sample", *short_study.names, *OUTCOMES]
    pd.testing.assert_frame_equal(fresh.runs[columns], study_run.runs[columns].iloc[:3])


def test_a_dask_cluster_on_loopback_gives_the_rows_of_local_processes(study_run, short_study, samples, fmu_dir,
                                                                     model, tmp_path):
    distributed = pytest.importorskip("distributed", reason="dask.distributed not installed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
                                  processes=True) as cluster:
        remote = run_montecarlo(short_study, fmu_dir, model, tmp_path / "dask", samples=samples,
                                scheduler=cluster.scheduler_address)
    assert remote.computed == 4
    pd.testing.assert_frame_equal(remote.runs.drop(columns="wall_s"), study_run.runs.drop(columns="wall_s"))


def test_the_path_scenario_runs_on_the_steerable_rover(fmu_dir, model, tmp_path):
    study = _study(runs=2, seed=3, stop_time=0.3, path_stop_time=0.3, scenarios=["straight", "path"],
                   parameters={"soil.kphi": {"distribution": "lognormal", "median": 8.14e5, "sigma": 0.5},
                               "rover.M": {"distribution": "uniform", "lower": 1500.0, "upper": 1600.0}})
    result = run_montecarlo(study, fmu_dir, model, tmp_path / "montecarlo", workers=1)
    runs = result.runs.set_index(["sample", "scenario"])
    assert (runs["status"] == "ok").all() and len(runs) == 4
    assert np.isfinite(runs.loc[(1, "path"), "cross_track_rms_m"]) and np.isnan(runs.loc[(1, "straight"),
                                                                                          "cross_track_rms_m"])
    assert set(result.summary["scenarios"]) == {"straight", "path"}


def test_a_parameter_no_fmu_has_is_refused_naming_it(fmu_dir):
    study = _study(parameters={"rover.mass": {"distribution": "uniform", "lower": 1.0, "upper": 2.0}})
    with pytest.raises(StudyError, match="'rover.mass': not a parameter of Rover.fmu"):
        nominal_values(study, choose(), fmu_dir)


# --- the command line ----------------------------------------------------------------------------------

def test_cli_refuses_bad_input_naming_it(tmp_path, capsys):
    from rover_cosim.cli import main

    bad = tmp_path / "bad.toml"
    bad.write_text('runs = 3\nseed = 1\n[parameters."soil.c"]\ndistribution = "uniform"\nlower = 9.0\nupper = 1.0\n')
    model = tmp_path / "model.json"
    model.write_text("{}")
    assert main(["montecarlo", "--study", str(bad), "--model", str(model)]) == 2
    assert "lower = 9.0 >= upper = 1.0" in capsys.readouterr().err
    assert main(["montecarlo", "--workers", "0", "--model", str(model)]) == 2
    assert "--workers 0: expected >= 1" in capsys.readouterr().err
    assert main(["montecarlo", "--model", str(tmp_path / "none.json")]) == 2
    assert "make it with `rover-cosim identify`" in capsys.readouterr().err
    assert main(["montecarlo", "--study", "nonexist", "--model", str(tmp_path / "none.json")]) == 2
    assert "nonexist" in capsys.readouterr().err  # the study is named first, not the missing model


def test_cli_runs_a_study_and_prints_the_share_meeting_1_n(model, fmu_dir, tmp_path, capsys):
    from rover_cosim.cli import main

    study = tmp_path / "tiny.toml"
    study.write_text('runs = 2\nseed = 4\nstop_time = 0.5\n[parameters."soil.kphi"]\ndistribution = "lognormal"\n'
                     'median = 8.14e5\nsigma = 0.5\n')
    out = tmp_path / "montecarlo"
    assert main(["montecarlo", "--study", str(study), "--model", str(model), "--fmu-dir", str(fmu_dir),
                 "--out", str(out), "--workers", "1", "-q"]) == 0
    printed = capsys.readouterr().out
    assert "2 runs computed, 0 from the cache, 0 failed" in printed and "RMS(Fx - Fx_des) <= 1 N" in printed
    assert len(pd.read_csv(out / "runs.csv")) == 2


# --- the report ----------------------------------------------------------------------------------------

def test_the_report_shows_the_study_when_it_was_run(study_run, tmp_path):
    from rover_cosim.report import build_report
    from rover_cosim.report.sections import montecarlo_section

    folder = study_run.files[0].parent
    section = "\n".join(montecarlo_section(folder))
    text = re.sub(r"src='data:[^']*'", "", section)
    assert "Monte Carlo over soil uncertainty" in text and "RMS ≤ 1 N on every limb [% of completed]" in text
    assert "<td>75</td>" not in text and ">100<" in text   # 3 of the 3 completed runs meet 1 N
    assert "nan" not in text.lower() and text.count("<table") == text.count("<div class='scroll'><table") >= 1
    assert "not produced" not in text and "No sensitivity ranking" not in text and "PRCC [-]" in text
    assert section.count("<img") == 3   # distributions, ranking, scatter
    assert montecarlo_section(tmp_path / "none") == []   # no study run: no section
    page = build_report(folder.parent)
    assert "Monte Carlo over soil uncertainty" in page and "rover-cosim montecarlo" in page   # provenance too


# --- a model on another soil -----------------------------------------------------------------------------

def test_a_model_identified_on_another_soil_is_refused_naming_both(fmu_dir, model, tmp_path, capsys):
    """simulate, the path following and the Monte Carlo refuse the session's model (identified on
    the paper's soil) on lete_sand, naming both soils, before running anything; the flag lets it
    through and says why in what it returns (and so in the records)."""
    from rover_cosim.cli import main
    from rover_cosim.identification.model_set import ModelMismatch
    from rover_cosim.jobs.path_following import run_path_following
    from rover_cosim.jobs.simulate import checked_models, run_simulation

    other = choose(soil="lete_sand")
    for job in (lambda: run_simulation(fmu_dir, model, tmp_path / "s", other),
                lambda: run_path_following(fmu_dir, model, tmp_path / "p", choice=other)):
        with pytest.raises(ModelMismatch, match=r"soil 'paper' \(identified on\) is not soil 'lete_sand' \(in use\)"):
            job()
    assert not (tmp_path / "s").exists() and not (tmp_path / "p").exists()
    _, why = checked_models(model, other, allow_mismatch=True)
    assert why is not None and "--allow-model-mismatch" in why
    assert checked_models(model, choose(), allow_mismatch=False)[1] is None
    with pytest.raises(ModelMismatch, match="study's nominal soil and wheel: lete_sand"):
        run_montecarlo(_study(soil="lete_sand"), fmu_dir, model, tmp_path / "m", workers=1)
    assert main(["simulate", "--model", str(model), "--fmu-dir", str(fmu_dir), "--soil", "lete_sand",
                 "--out", str(tmp_path / "cli")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "was identified on another soil or wheel" in err and "Warning" not in err
