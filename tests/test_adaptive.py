"""The rover that learns its soil (issue 33): the calibration's excitation, the telemetry the
adaptive controller samples against the plant's own outputs, the soil it estimates against the
truth, the switch-over, and the adaptive Monte Carlo's outputs."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest

from rover_cosim.control.calibration import Calibration
from rover_cosim.identification import online
from rover_cosim.identification.soil_estimation import NOT_SEARCHED
from rover_cosim.identification.testbed_data import TestBedData
from rover_cosim.jobs import simulate
from rover_cosim.jobs.montecarlo import run_montecarlo
from rover_cosim.jobs.montecarlo.study import StudyError, parse_study
from rover_cosim.orchestrator.builder import SystemBuilder
from rover_cosim.orchestrator.master import run
from rover_cosim.terramechanics import library

#: A soil off the paper's: softer, less cohesive, another friction angle and exponent.
TRUTH = {"c": 430.0, "phi_deg": 32.4, "kphi": 2.5e5, "n": 0.9, "kx": 0.029}


def test_the_excitation_is_zero_sum_per_side_and_drives_and_brakes_every_wheel():
    calibration = Calibration(duration=3.0, segment=0.25, amplitude=20.0)
    levels = set()
    for t in np.arange(0.0, 3.0, 0.05):
        torques = calibration.excitation(float(t))
        assert torques[:3].sum() == pytest.approx(0.0) and torques[3:].sum() == pytest.approx(0.0)
        levels |= set(np.round(torques, 9).tolist())
    assert levels == {-20.0, -10.0, 0.0, 10.0, 20.0}  # full and half amplitude, driving and braking
    # every wheel drives and brakes during the phase
    per_wheel = np.array([calibration.excitation(float(t)) for t in np.arange(0.0, 3.0, 0.25)])
    assert (per_wheel.max(axis=0) > 0).all() and (per_wheel.min(axis=0) < 0).all()


@pytest.mark.parametrize("changes, message", [({"duration": 0.0}, "duration = 0.0"),
                                              ({"amplitude": math.nan}, "amplitude = nan"),
                                              ({"segment": 5.0, "duration": 3.0}, "segment = 5.0 s")])
def test_a_bad_calibration_is_refused_naming_the_value(changes, message):
    with pytest.raises(ValueError, match=message):
        Calibration(**changes)


def test_a_study_reads_its_calibration_table_and_names_bad_keys():
    base = {"runs": 2, "seed": 1, "parameters": {"soil.c": {"distribution": "uniform", "lower": 100.0,
                                                            "upper": 1000.0}}}
    study = parse_study({**base, "calibration": {"duration": 2.0, "sinkage_sensor": True}}, "s")
    assert study.calibration == Calibration(duration=2.0, sinkage_sensor=True)
    assert study.adapted().scenarios == ("straight", "straight_adapted")
    optional = parse_study({**base, "calibration": {"optional_parameters": True}}, "s")
    assert optional.calibration == Calibration(optional_parameters=True)
    for table, message in (({"duratoin": 2.0}, "calibration = "), ({"duration": -1.0}, "duration = -1.0"),
                           ({"sinkage_sensor": "yes"}, "sinkage_sensor = 'yes'"),
                           ({"optional_parameters": 1}, "optional_parameters = 1: expected true or false")):
        with pytest.raises(StudyError, match=message):
            parse_study({**base, "calibration": table}, "s")


def test_simulate_adapt_takes_the_calibrations_switches_from_the_command_line():
    from rover_cosim.cli import build_parser
    from rover_cosim.cli.simulate import _calibration

    parser = build_parser()
    assert _calibration(parser.parse_args(["simulate", "--adapt"])) == Calibration()
    given = parser.parse_args(["simulate", "--adapt", "--calibration", "2", "--sinkage-sensor",
                               "--optional-parameters"])
    assert _calibration(given) == Calibration(duration=2.0, sinkage_sensor=True, optional_parameters=True)
    assert _calibration(parser.parse_args(["simulate", "--optional-parameters"])) is None  # no adaptive run


def test_a_runs_cache_key_holds_the_calibration_it_depends_on():
    """An adaptive run's key holds its whole calibration; another run's only the duration (its RMS
    window after the calibration): a sensor or the optional parameters do not run it again."""
    from rover_cosim.jobs.montecarlo.runs import cache_key

    shared = {"fmus": {"Rover.fmu": "r", "SingleWheel.fmu": "s", "SteerableRover.fmu": "p"}, "model": "m"}

    def key(scenario: str, calibration: Calibration) -> str:
        return cache_key(shared, scenario, 20.0, (), (), calibration)

    plain, sensing, searching = Calibration(), Calibration(sinkage_sensor=True), Calibration(optional_parameters=True)
    assert key("straight", plain) == key("straight", sensing) == key("straight", searching)
    assert key("straight", plain) != key("straight", Calibration(duration=2.0))
    assert len({key("straight_adapted", c) for c in (plain, sensing, searching)}) == 3


#: The calibration of the module's short adaptive runs: the runs of a scenario on TRUTH estimate the
#: same soil from the same telemetry, so their sweeps are computed once (sweep_cache).
SHORT_CALIBRATION = Calibration(duration=1.5, segment=0.25)


@pytest.fixture(scope="module")
def sweep_cache(tmp_path_factory) -> Path:
    """One sweep cache for the module's adaptive runs (the re-identification is not what they test)."""
    return tmp_path_factory.mktemp("adapt")


@pytest.fixture(scope="module")
def adaptive_run(fmu_dir, identified, sweep_cache):
    """The adaptive closed loop on TRUTH for 2 s, calibrating for 1.5 s (the adapter spied on)."""
    model = identified.files[0].parent / "model.json"
    nominal = library.choose()
    truth = library.vary(nominal, TRUTH, {})
    seen: dict[str, object] = {}

    def spy(data: TestBedData, *args: object) -> online.Adaptation:
        seen["data"] = data
        seen["adaptation"] = online.adapt_model(data, *args)  # type: ignore[arg-type]
        return seen["adaptation"]  # type: ignore[return-value]

    system = simulate.adaptive_system(fmu_dir, model, truth, calibration=SHORT_CALIBRATION, cache_dir=sweep_cache)
    system = SystemBuilder.from_system(system, "adaptive, short").simulation(stop_time=2.0).build()
    original, simulate.adapt_model = simulate.adapt_model, spy  # type: ignore[assignment] # the adapter calls it
    try:
        outcome = run(system)
    finally:
        simulate.adapt_model = original
    block = next(b.block for b in system.blocks if b.name == "ctrl")
    return outcome, block, seen, truth


def test_the_telemetry_samples_are_the_plants_own_slip_load_and_torque(adaptive_run):
    outcome, block, _, _ = adaptive_run
    data = outcome.data.set_index("time")
    rows = np.vstack(block.samples)
    assert len(rows) >= 6 * 4  # every wheel at the end of every level once the rover moves
    for k, (t, load, slip, torque, _sinkage) in enumerate(rows):
        near = data.index[np.argmin(np.abs(data.index - t))]
        assert abs(near - t) < 1e-9
        i = k % 6 + 1  # each level's rows: wheels 1..6
        assert load == pytest.approx(data.loc[near, f"rover.Fz[{i}]"], abs=1e-9)
        assert slip == pytest.approx(data.loc[near, f"rover.slip[{i}]"], abs=2e-5)
        assert torque == pytest.approx(data.loc[near, f"rover.Tx[{i}]"], abs=0.05)


def test_the_rover_estimates_the_soil_it_is_on_and_switches_at_the_end_of_the_calibration(adaptive_run):
    outcome, block, seen, truth = adaptive_run
    report = block.report()
    assert report["switched_at_s"] == pytest.approx(1.5, abs=1e-9)
    estimated = report["estimated_soil"]
    for name in ("phi", "kx", "n"):
        assert estimated[name] == pytest.approx(getattr(truth.soil, name), rel=0.02), name
    # k_c and k_phi act together as k_c/b + k_phi for one wheel width
    b = truth.wheel.b
    assert estimated["kc"] / b + estimated["kphi"] == pytest.approx(truth.soil.kc / b + truth.soil.kphi, rel=0.05)
    assert isinstance(seen["data"], TestBedData) and seen["data"].sinkage_m is None  # no sinkage sensor
    # the plan's parameters only (Calibration.optional_parameters off): a1, a0, λ kept, said so
    fixed = seen["adaptation"].estimate.fixed
    assert all(fixed[name].reason == NOT_SEARCHED for name in ("a1", "a0", "lam"))
    # after the switch the torques are the law's alone (no excitation): the wheels of a side agree
    data = outcome.data
    late = data[data["time"] > 1.6]
    assert np.allclose(late["ctrl.tau[1]"] - late["ctrl.tau[4]"], 0.0, atol=1e-9)
    json.dumps(report)  # the record is plain data


@pytest.fixture(scope="module")
def adaptive_study(fmu_dir, identified, tmp_path_factory):
    study = parse_study({"runs": 2, "seed": 5, "stop_time": 3.0, "calibration": {"duration": 1.5},
                         "parameters": {"soil.kphi": {"distribution": "lognormal", "median": 8.14e5, "sigma": 0.8,
                                                      "lower": 2e5, "upper": 3e6}}}, "adaptive test study")
    out = tmp_path_factory.mktemp("montecarlo") / "montecarlo"
    return run_montecarlo(study.adapted(), fmu_dir, identified.files[0].parent / "model.json", out, workers=1), out


def test_the_adaptive_study_reports_both_shares_side_by_side(adaptive_study):
    result, out = adaptive_study
    straight = result.summary["scenarios"]["straight"]
    for key in ("share_meeting_1N_rms_of_completed", "share_meeting_1N_rms_after_calibration_of_completed",
                "adapted_share_meeting_1N_rms_of_completed", "adapted_share_meeting_1N_rms_whole_run_of_completed"):
        assert key in straight and (straight[key] is None or 0.0 <= straight[key] <= 1.0), key
    adapted = result.runs[result.runs["scenario"] == "straight_adapted"]
    assert (adapted["status"] == "ok").all() and len(adapted) == 2
    assert np.allclose(adapted["switched_at_s"], 1.5) and (adapted["estimate_rows"] > 0).all()
    assert np.isfinite(adapted["estimated_kphi"]).all() and (adapted["adapt_wall_s"] > 0).all()
    assert (out / "fig_adaptation.png").stat().st_size > 10_000
    # sample 1 is off the nominal soil: adaptation improves its force tracking after the calibration
    plain = result.runs[(result.runs["scenario"] == "straight") & (result.runs["sample"] == 1)].iloc[0]
    learned = adapted[adapted["sample"] == 1].iloc[0]
    assert learned["rms_Fx_max_after_calibration_N"] < plain["rms_Fx_max_after_calibration_N"]


def test_an_adapted_run_shorter_than_its_calibration_is_refused(fmu_dir, identified, tmp_path):
    study = parse_study({"runs": 1, "seed": 1, "stop_time": 1.0, "calibration": {"duration": 1.5},
                         "parameters": {"soil.c": {"distribution": "uniform", "lower": 100.0, "upper": 900.0}}}, "s")
    with pytest.raises(StudyError, match="needs more than its calibration"):
        run_montecarlo(study.adapted(), fmu_dir, identified.files[0].parent / "model.json", tmp_path / "mc")
    assert not (tmp_path / "mc" / "summary.json").exists()


def test_a_rover_that_crawls_calibrates_longer_then_keeps_its_model_and_says_why(identified):
    from rover_cosim.control.adaptive import LONGEST, AdaptiveController

    def adapter(data: TestBedData) -> online.Adaptation:
        raise AssertionError("no adaptation without samples")

    block = AdaptiveController("ctrl", identified.files[0].parent / "model.json", adapter,
                               calibration=Calibration(duration=0.5, segment=0.1), step=1e-3)
    model = block.model
    u = np.concatenate([[0.0, 0.01], np.full(6, 424.0), np.full(6, 0.01 / 0.355), [0.0]])  # 1 cm/s
    block.start(0.0, u)
    t, h = 0.0, 1e-3
    while t < LONGEST * 0.5 + 0.01:
        out = block.step(t, h, u)
        t += h
        if t < 0.5:
            assert abs(out[:3].sum() - block.torque[:3].sum()) < 1e-9 and np.ptp(out[:3]) > 0  # excited
    assert block.calibrated_until == pytest.approx(LONGEST * 0.5, abs=2e-3) and block.switched_at is None
    assert block.model is model and "the nominal model is kept" in block.report()["not_adapted"]
    later = block.step(t, h, u)
    assert np.ptp(later[:3]) == pytest.approx(0.0, abs=1e-9)  # the excitation has stopped


def test_sweep_loads_cover_the_rovers_range_with_a_margin():
    loads = online.sweep_loads(np.array([360.0, 420.0, 480.0]))
    assert len(loads) == online.LOAD_POINTS and loads[0] == pytest.approx(0.8 * 360, abs=1)
    assert loads[-1] == pytest.approx(1.2 * 480, abs=1) and all(np.diff(loads) > 0)
    assert Path(online.__file__).name == "online.py"


def test_simulate_adapt_records_what_it_estimated_and_when_it_switched(fmu_dir, identified, tmp_path):
    import subprocess
    import sys

    out = tmp_path / "simulation"
    done = subprocess.run([sys.executable, "-P", "-m", "rover_cosim", "simulate", "--only", "straight", "--adapt",
                           "--calibration", "2", "--soil", "lunar_nominal", "--fmu-dir", str(fmu_dir), "--model",
                           str(identified.files[0].parent / "model.json"), "--out", str(out), "-q"],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "Adaptive run: the model switched at 2 s" in done.stdout
    record = json.loads((out / "simulation.json").read_text())
    adaptation = record["adaptation"]
    truth = library.choose("lunar_nominal").soil
    assert adaptation["switched_at_s"] == pytest.approx(2.0) and adaptation["calibration"]["duration"] == 2.0
    assert adaptation["estimated_soil"]["phi"] == pytest.approx(truth.phi, rel=0.01)
    assert max(adaptation["rms_after_calibration_N"]) < 1.0
    assert (out / "trajectories_adaptive.csv").stat().st_size > 0 and (out / "rms_adaptive.csv").exists()
    assert record["model_mismatch"]  # the model's soil is not lunar_nominal, and the record says so


def test_simulate_refuses_a_bad_calibration_length(tmp_path):
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-P", "-m", "rover_cosim", "simulate", "--adapt", "--calibration", "25",
                           "--out", str(tmp_path / "s"), "--model", str(tmp_path / "none.json")],
                          capture_output=True, text=True, check=False)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "--calibration: calibration 25.0 s: expected a length in (0, 20) s" in done.stderr


def test_the_path_controller_learns_the_soil_on_the_first_straight(fmu_dir, identified, sweep_cache):
    from rover_cosim.jobs import path_following

    truth = library.vary(library.choose(), TRUTH, {})
    system = path_following.adaptive_system(fmu_dir, identified.files[0].parent / "model.json", "lane_change", truth,
                                            calibration=SHORT_CALIBRATION, cache_dir=sweep_cache, straight=3.0)
    system = SystemBuilder.from_system(system, "adaptive path, short").simulation(stop_time=2.0).build()
    outcome = run(system)
    block: Any = next(b.block for b in system.blocks if b.name == "ctrl")
    report = block.report()
    assert report["switched_at_s"] == pytest.approx(1.5) and report["lateral_identified_again"]
    assert report["estimated_soil"]["phi"] == pytest.approx(truth.soil.phi, rel=0.02)
    data = outcome.data.set_index("time")
    for k, (t, load, slip, torque, _sinkage) in enumerate(np.vstack(block.samples)):
        near = data.index[np.argmin(np.abs(data.index - t))]
        i = k % 6 + 1  # the hubs' speeds from the body's velocity, attitude rates and the steering
        assert load == pytest.approx(data.loc[near, f"rover.Fz[{i}]"], abs=1e-9)
        assert slip == pytest.approx(data.loc[near, f"rover.slip[{i}]"], abs=2e-5)
        assert torque == pytest.approx(data.loc[near, f"rover.Tx[{i}]"], abs=0.05)


@pytest.mark.parametrize("scenario", ["straight", "path"])
def test_after_the_switch_the_laws_c_twin_takes_over_bit_for_bit(fmu_dir, identified, sweep_cache, monkeypatch,
                                                                  scenario):
    """Once calibrated, an adaptive block steps its law alone and offers that law's C twin: the
    engine hands the block over to the native stepper at that step (once), and the run equals
    the one stepped in Python throughout, to the bit. While calibrating, the straight run's block
    steps its law through the law's twin from Python: the same bits as the Python law."""
    from rover_cosim.jobs import path_following
    from rover_cosim.orchestrator import master
    from rover_cosim.orchestrator.builder import replace_settings

    model = identified.files[0].parent / "model.json"
    truth = library.vary(library.choose(), TRUTH, {})

    def system(native: bool) -> Any:
        made = (simulate.adaptive_system(fmu_dir, model, truth, calibration=SHORT_CALIBRATION, cache_dir=sweep_cache)
                if scenario == "straight" else
                path_following.adaptive_system(fmu_dir, model, "lane_change", truth, calibration=SHORT_CALIBRATION,
                                               cache_dir=sweep_cache, straight=3.0))
        return replace_settings(made, stop_time=2.0, native=native)

    handovers: list[float] = []
    original = master._handed_over

    def counted(*args: Any) -> Any:
        after = original(*args)
        handovers.append(1.0)
        assert after.all_native  # the FMU and the controller both stepped from C from here on
        return after

    monkeypatch.setattr(master, "_handed_over", counted)
    from rover_cosim.control.controller import LawTwin

    through_twin: list[float] = []
    step_at = LawTwin.step_at

    def counted_step(self: Any, t: float, h: float, u: Any) -> Any:
        through_twin.append(t)
        return step_at(self, t, h, u)

    monkeypatch.setattr(LawTwin, "step_at", counted_step)
    python = run(system(False))
    assert not handovers and not through_twin  # native stepping off: nothing to hand over, no twin stepped
    ours = system(True)
    native = run(ours)
    block: Any = next(b.block for b in ours.blocks if b.name == "ctrl")
    assert block.switched_at is not None and block.switched_at < 1.9 and len(handovers) == 1  # (a crawling rover
    # calibrates a little longer)
    pd.testing.assert_frame_equal(python.data, native.data, check_exact=True)
    if scenario == "straight":
        # the native run's law stepped through its twin (from Python) every calibrating step, freed at the
        # switch; the run stepped in Python (native off) never: they agree to the bit, as above
        assert len(through_twin) >= 1400 and all(t < 1.6 for t in through_twin) and block._stepping is None
