"""Monte Carlo over soil uncertainty: the study file and its errors, seeded and correlated
samples, the metrics on synthetic runs, the sensitivity ranking, and short real studies on
Rover.fmu (the nominal sample reproduces make simulate's RMS to the last bit, a failing sample is
recorded while the study completes, the cache makes a rerun compute nothing and recomputes a
damaged file, a Dask LocalCluster gives the rows of local processes)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from rover_cosim.jobs.montecarlo.sampling import draw, sample_table
from rover_cosim.jobs.montecarlo.study import STUDIES, StudyError, load_study, parse_study

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
    values = draw(_study(seed=7), 20000)
    c, phi, kc = values.T
    assert c.min() >= 100 and c.max() <= 1000 and abs(c.mean() - 550) < 10
    assert phi.min() >= 30 and phi.max() <= 50
    expected_mean = stats.truncnorm.mean((30 - 37) / 5, (50 - 37) / 5, loc=37, scale=5)
    assert abs(phi.mean() - expected_mean) < 0.1
    assert abs(np.median(np.log(kc)) - math.log(1370)) < 0.03 and abs(np.std(np.log(kc)) - 1.0) < 0.03


def test_the_requested_correlation_is_honoured():
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
