"""Identification (paper Sec. 3): the fit metric, the first-order fit, the sweep's cache,
failures, atomic files and Dask execution, the cross-check against the numpy reference test bed,
and the whole `make identify` job against the paper's Table 1."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rover_cosim.identification import cache
from rover_cosim.identification import sweep as sweep_module
from rover_cosim.identification.fits import (
    IdentifiedModel,
    first_order_fit,
    fit_percent,
    fx_per_load,
    identify,
    step_table,
)
from rover_cosim.identification.sweep import Case, SweepPlan, compute_run, run_file, run_sweep
from rover_cosim.identification.validate import PAPER_FIT
from rover_cosim.jobs.identify import RECORD_INTERVAL, IdentificationResult

SMALL = SweepPlan(loads=(300.0, 600.0), torques=(10.0, 30.0), stop_time=0.02, sample_time=1e-3)


@pytest.fixture(scope="session")
def single_wheel(fmus) -> Path:
    return fmus["SingleWheel"]


def test_fit_percent_is_equation_15():
    plant = np.array([0.0, 1.0, 2.0, 3.0])
    assert fit_percent(plant, plant) == 100.0
    assert fit_percent(np.full(4, plant.mean()), plant) == pytest.approx(0.0)
    assert fit_percent(plant + 0.5, plant) == pytest.approx(100 * (1 - 1.0 / np.sqrt(5.0)))
    with pytest.raises(ValueError, match="constant"):
        fit_percent(plant, np.ones(4))


def test_first_order_fit_recovers_gain_and_time_constant():
    t = np.linspace(0.0, 0.5, 501)
    slip = 0.004 * 30.0 * (1.0 - np.exp(-t / 0.05))
    gain, constant = first_order_fit(t, slip, 30.0)
    assert gain == pytest.approx(0.004, rel=1e-6) and constant == pytest.approx(0.05, rel=1e-6)


def test_sweep_caches_runs_and_recomputes_only_what_is_missing(single_wheel, tmp_path):
    first = run_sweep(single_wheel, SMALL, tmp_path, workers=2)
    assert (first.computed, first.cached, first.failures) == (4, 0, {})
    assert first.cache_folder is not None
    run_file(first.cache_folder, 600.0, 30.0).unlink()
    again = run_sweep(single_wheel, SMALL, tmp_path, workers=2)
    assert (again.computed, again.cached) == (1, 3)
    for key, run in first.runs.items():
        pd.testing.assert_frame_equal(run, again.runs[key])
    run = first.runs[Case(600.0, 30.0)]
    assert list(run.columns) == ["time", "tau", "slip", "Fx", "Fz", "Tx", "sinkage", "omega", "v", "Fy", "beta"]
    assert len(run) == 21
    assert not list(first.cache_folder.glob("*.part"))


@pytest.mark.parametrize("workers", [1, 2])
def test_a_sweep_without_a_cache_keeps_its_runs_in_memory_at_full_precision(single_wheel, tmp_path, workers):
    """No cache folder (an adaptive run's sweep on its own soil): the same runs as a cached sweep's,
    to the 12 digits a cache file keeps, from the worker process or this one, and no file written."""
    cached = run_sweep(single_wheel, SMALL, tmp_path / "cache", workers=2)
    before = set(tmp_path.rglob("*"))
    kept = run_sweep(single_wheel, SMALL, None, workers=workers)
    assert set(tmp_path.rglob("*")) == before and kept.cache_folder is None
    assert (kept.computed, kept.cached, kept.failures) == (4, 0, {}) and set(kept.runs) == set(cached.runs)
    for case, run in cached.runs.items():
        assert list(kept.runs[case].columns) == list(run.columns)
        np.testing.assert_allclose(kept.runs[case].to_numpy(), run.to_numpy(), rtol=1e-11, atol=1e-300)
        assert not kept.runs[case].equals(run) or case.torque == 0  # full precision, not the file's 12 digits


def test_a_failing_run_is_recorded_and_the_sweep_goes_on(single_wheel, tmp_path, monkeypatch):
    real = sweep_module.shared_test_bed

    class Broken:
        def run(self, load, *args, **kwargs):
            if load == 600.0:
                raise RuntimeError("the carriage fell off")
            return real(single_wheel).run(load, *args, **kwargs)

    monkeypatch.setattr(sweep_module, "shared_test_bed", lambda path: Broken())
    outcome = run_sweep(single_wheel, SMALL, tmp_path, workers=1)
    assert set(outcome.failures) == {(600.0, 10.0, 0.0), (600.0, 30.0, 0.0)}
    assert "the carriage fell off" in outcome.failures[Case(600.0, 10.0)]
    assert set(outcome.runs) == {(300.0, 10.0, 0.0), (300.0, 30.0, 0.0)}
    assert outcome.cache_folder is not None
    assert sorted(p.name for p in outcome.cache_folder.glob("*.csv.gz")) == ["W300_tau10.csv.gz", "W300_tau30.csv.gz"]


def test_the_run_files_fast_writer_gives_pandas_bytes():
    """cache._csv (one %-format of the table) writes what DataFrame.to_csv writes, for a run's
    floats (tiny, huge, negative, integral, infinite) and, by pandas itself, for a table with NaN."""
    rng = np.random.default_rng(3)
    values = rng.normal(size=(50, 4)) * 10.0 ** rng.integers(-300, 300, size=(50, 4))
    values[0] = [0.0, -0.0, 1.0, np.inf]
    table = pd.DataFrame(values, columns=["time", "tau", "Fx", "slip"])
    for float_format in ("%.12g", "%.17g"):
        assert cache._csv(table, float_format) == table.to_csv(index=False, float_format=float_format).encode()
    table.iloc[3, 2] = np.nan
    assert cache._csv(table, "%.12g") == table.to_csv(index=False, float_format="%.12g").encode()
    assert b",," in cache._csv(table, "%.12g")  # pandas' empty field for NaN


def test_an_interrupted_write_leaves_no_file(single_wheel, tmp_path, monkeypatch):
    def interrupted(self, *args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(pd.DataFrame, "to_csv", interrupted)  # the writer of tables with NaN
    monkeypatch.setattr(cache, "_csv", interrupted)  # the run's fast writer
    target = tmp_path / "W300_tau10.csv"
    _case, error, _, _ = compute_run(str(single_wheel), Case(300.0, 10.0), 0.01, 1e-3, 1e-8, 1.0, str(target))
    assert error is not None and "disk full" in error
    assert list(tmp_path.iterdir()) == []


def test_sweep_on_a_dask_cluster_gives_the_local_results(single_wheel, tmp_path):
    distributed = pytest.importorskip("distributed", reason="dask.distributed not installed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None,
                                  processes=True) as cluster:
        remote = run_sweep(single_wheel, SMALL, tmp_path / "dask", scheduler=cluster.scheduler_address)
    local = run_sweep(single_wheel, SMALL, tmp_path / "local", workers=1)
    assert remote.computed == 4 and not remote.failures
    for key, run in local.runs.items():
        pd.testing.assert_frame_equal(run, remote.runs[key])


def test_reference_test_bed_and_fmu_give_the_same_a_and_b(single_wheel, tmp_path):
    """The same identification on the numpy reference test bed and on SingleWheel.fmu: the
    per-load a(W), b(W) of Eq. (14) and their quadratics in W agree within 1 %."""
    plan = SweepPlan(torques=(5.0, 10.0, 15.0, 20.0, 30.0, 40.0), stop_time=0.01, sample_time=1e-3)
    reference = run_sweep(None, plan, tmp_path, workers=2)
    fmu = run_sweep(single_wheel, plan, tmp_path, workers=2)
    assert not reference.failures and not fmu.failures
    fmu_runs, reference_runs = fmu.at_slip_angle(0.0), reference.at_slip_angle(0.0)
    ours, theirs = fx_per_load(step_table(fmu_runs)), fx_per_load(step_table(reference_runs))
    np.testing.assert_allclose(ours["c1"], theirs["c1"], rtol=0.01)  # a(W)
    np.testing.assert_allclose(ours["c0"], theirs["c0"], rtol=0.01)  # b(W)
    loads = np.array(plan.loads)
    model_fmu, model_reference = identify(step_table(fmu_runs), 1), identify(step_table(reference_runs), 1)
    for k in (0, 1):
        np.testing.assert_allclose(np.polyval(model_fmu.fx_coefficients[k][::-1], loads),
                                   np.polyval(model_reference.fx_coefficients[k][::-1], loads), rtol=0.01)


@pytest.fixture(scope="module")
def out(identified: IdentificationResult) -> Path:
    """The folder `make identify` wrote (the session's shared identification)."""
    return identified.files[0].parent


def test_identify_writes_every_output(out, identified):
    assert set(identified.files) <= set(out.iterdir()) and all(p.parent == out for p in identified.files)
    names = {p.name for p in out.iterdir()}
    assert {"runs.csv", "steps.csv", "model.json", "fit_table.csv", "fit_models.csv", "fit_detail.csv", "failures.csv",
            "fig5_fx_vs_slip.png", "fig6_a_of_W.png", "fig7_b_of_W.png", "fig8_validation_575N.png",
            "identification.json"} <= names
    runs = pd.read_csv(out / "runs.csv")
    plan = SweepPlan()
    kept = round(RECORD_INTERVAL / plan.sample_time)  # a row every 1 ms of the 0.1 ms samples (and the last)
    samples = round(plan.stop_time / plan.sample_time) + 1
    assert kept == 10 and len(runs) == len(plan.loads) * len(plan.torques) * len(range(0, samples, kept))
    one = runs[(runs["load_N"] == plan.loads[0]) & (runs["torque_N_m"] == plan.torques[0])]
    np.testing.assert_allclose(np.diff(one["time"]), RECORD_INTERVAL, rtol=1e-9)
    assert one["time"].iloc[-1] == pytest.approx(plan.stop_time)
    assert list(runs.columns[:4]) == ["load_N", "torque_N_m", "time", "tau"]
    table = pd.read_csv(out / "fit_table.csv")
    assert list(table.columns) == ["load_N", "fit_percent"] and list(table["load_N"]) == [275.0, 575.0, 875.0]
    model = json.loads((out / "model.json").read_text())
    assert model["fmu"]["sha256"] and model["plan"]["loads"] == list(plan.loads)


def test_identified_model_meets_table_1(out):
    """Fit (Eq. 15) of the recommended (quadratic) model at least the paper's Table 1 at each load;
    the linear model of Eq. (14) is reported beside it."""
    fits = pd.read_csv(out / "fit_models.csv").set_index("load_N")
    for load, paper in PAPER_FIT.items():
        assert fits.loc[load, "fit_percent_quadratic"] >= paper, (load, fits.loc[load].to_dict())
    assert np.isfinite(fits["fit_percent_linear"]).all()


def test_model_json_round_trips(out):
    model = json.loads((out / "model.json").read_text())
    for label, data in model["models"].items():
        restored = IdentifiedModel.from_dict(data)
        assert restored.degree == {"linear": 1, "quadratic": 2}[label]
        assert np.isfinite(restored.fx(575.0, 0.05)) and restored.gain_at(575.0, 20.0) > 0


def test_the_test_bed_steps_natively_to_the_bits_of_its_python_loop(single_wheel, monkeypatch):
    """Between level changes the bed's samples are stepped by the native stepper: the same FMI calls
    as its Python loop (a staircase of torques and a turning track: several stretches), the same
    rows to the bit."""
    import math

    from rover_cosim.identification.testbed import Staircase, WheelTestBed
    from rover_cosim.orchestrator import native

    if native.unavailable_reason() is not None:
        pytest.skip(str(native.unavailable_reason()))
    torque = Staircase.staircase((10.0, 40.0, 25.0), 0.05)
    track = Staircase((0.0, 0.07), (0.0, math.radians(5.0)))
    bed = WheelTestBed(single_wheel)
    stretches: list[tuple[int, int]] = []
    steps = bed._steps

    def counted(stepper, times, first, last, h, rows):
        stretches.append((first, last))
        return steps(stepper, times, first, last, h, rows)

    monkeypatch.setattr(bed, "_steps", counted)
    natively = bed.run(575.0, torque, 0.15, 1e-4, start_speed=0.1, track_angle=track)
    assert stretches == [(0, 500), (500, 700), (700, 1000), (1000, 1500)]
    monkeypatch.setattr(native, "unavailable_reason", lambda: "switched off by the test")
    in_python = bed.run(575.0, torque, 0.15, 1e-4, start_speed=0.1, track_angle=track)
    pd.testing.assert_frame_equal(natively, in_python, check_exact=True)
    assert natively["beta"].iloc[-1] != natively["beta"].iloc[100]  # the track turned
